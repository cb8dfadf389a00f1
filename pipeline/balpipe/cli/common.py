"""What the ``balpipe`` verbs share: exit codes, the usage-error parser, SIGTERM as an
interrupt, the ``--jobs``/paths check and writing text to a file or stdout."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path
from typing import NoReturn

EXIT_OK, EXIT_FAILED, EXIT_USAGE = 0, 1, 2
EXIT_UNCONFIRMED = 3  # ``build --strict``: a simulation check could not resolve its own error (nothing shown false)
EXIT_INTERRUPTED, EXIT_TERMINATED = 130, 143  # 128 + SIGINT, 128 + SIGTERM


class Terminated(KeyboardInterrupt):
    """SIGTERM, raised in the main process so that builds stop as cleanly as on Ctrl-C."""


def on_sigterm(signum, frame) -> None:
    raise Terminated()


class Parser(argparse.ArgumentParser):
    def error(self, message: str) -> NoReturn:  # usage errors: exit 2, no traceback
        self.print_usage(sys.stderr)
        print(f"balpipe: error: {message}", file=sys.stderr)
        sys.exit(EXIT_USAGE)


def usage_error(message: str) -> int:
    """Print ``balpipe: error: message`` on stderr; the usage exit code."""
    print(f"balpipe: error: {message}", file=sys.stderr)
    return EXIT_USAGE


def missing(paths: list[str]) -> list[str]:
    return [p for p in paths if not Path(p).exists()]


def paths_jobs_problem(paths: list[str], jobs: int | None) -> str | None:
    """What is wrong with the spec paths and ``--jobs`` of a command that runs specs in parallel
    (``build``, ``history``): a usage error to print, or None."""
    gone = missing(paths)
    if gone:
        return f"no such file or folder: {', '.join(gone)}"
    if jobs is not None and jobs < 1:
        return "--jobs must be at least 1"
    return None


def emit(text: str, out: str | None) -> int:
    """Write ``text`` to the file ``out`` (or stdout); a path that cannot be written is a usage
    error with the reason, not a traceback."""
    if not out:
        sys.stdout.write(text)
        return EXIT_OK
    try:
        Path(out).write_text(text, encoding="utf-8")
    except OSError as exc:
        return usage_error(f"cannot write {out}: {exc.strerror or exc}")
    return EXIT_OK
