"""``python -m balpipe.cli`` (as ``python -m balpipe``)."""

import sys

from . import main

sys.exit(main())
