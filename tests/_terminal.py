"""Start ``python -m balpipe`` as a terminal's foreground job would be: SIGINT at its default.

A non-interactive shell starts a background command (``cmd &``) with SIGINT ignored, its
children inherit that, and Python then installs no KeyboardInterrupt handler: a Ctrl-C test run
under such a shell would see the build ignore the signal (seen when the README's test command
ran from a script started with ``&``). The launcher resets SIGINT to its default and execs
balpipe, so Python installs its handler as it does in a terminal (no ``preexec_fn``, which is
unsafe in the threaded xdist workers)."""

from __future__ import annotations

import sys

_LAUNCH = ("import os, signal, sys; signal.signal(signal.SIGINT, signal.SIG_DFL); "
           "os.execv(sys.executable, [sys.executable, '-m', 'balpipe', *sys.argv[1:]])")


def balpipe_command(*args) -> list[str]:
    """The argv of ``python -m balpipe ARGS`` with SIGINT at its default."""
    return [sys.executable, "-c", _LAUNCH, *map(str, args)]
