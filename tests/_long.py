"""The long random runs and their short default sample.

``python -m pytest --long`` (or ``BALPIPE_LONG_TESTS=1``) runs every random case that the default
run takes a short, seeded sample of. The assertions are the same either way; only the number of
random cases differs, and the default sample is fixed (the same cases every run).
"""

from __future__ import annotations

import os

ENV = "BALPIPE_LONG_TESTS"


def long_tests() -> bool:
    """True when the long random runs were asked for (``--long`` sets the variable)."""
    return os.environ.get(ENV, "") not in ("", "0")


def sample(short: int, long: int) -> int:
    """The number of random cases: ``short`` by default, ``long`` with ``--long``."""
    return long if long_tests() else short
