"""The ``balpipe`` command line: ``main()`` and the dispatch; one module per verb.

:mod:`.build`, :mod:`.check`, :mod:`.diff`, :mod:`.schema`, :mod:`.history`, :mod:`.sweep` each
give ``add_parser(sub)`` (the verb's options and help) and ``run(args) -> exit code``;
:mod:`.common` holds the exit codes (0 ok, 1 failed, 2 usage or invalid spec, 130 interrupted,
143 terminated) and the helpers they share.
"""

from __future__ import annotations

import argparse
import gc
import importlib
import os
import signal
import sys

from .. import __version__
from .common import (  # noqa: F401  (re-exported: the public names of balpipe.cli)
    EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_TERMINATED, EXIT_USAGE, Parser, Terminated, on_sigterm,
    paths_jobs_problem,
)

VERBS = ("build", "check", "diff", "schema", "history", "sweep")  # the order of ``balpipe --help``


def _verb(name: str):
    return importlib.import_module(f"{__name__}.{name}")


def _parser() -> argparse.ArgumentParser:
    p = Parser(prog="balpipe", description="Dynamic balancing of planar mechanisms from YAML specs.")
    p.add_argument("--version", action="version", version=f"balpipe {__version__}")
    sub = p.add_subparsers(dest="command", required=True, parser_class=Parser)
    for name in VERBS:
        _verb(name).add_parser(sub)
    return p


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    from ..runtime.plotting import lean_docstrings

    lean_docstrings()  # matplotlib without help()'s docstrings in this process and its workers
    import signal
    import threading

    if threading.current_thread() is threading.main_thread():
        previous = signal.signal(signal.SIGTERM, on_sigterm)
    else:  # pragma: no cover - embedded use
        previous = None
    try:
        return _verb(args.command).run(args)
    except Terminated:
        print("balpipe: terminated; the site is as the last complete build left it", file=sys.stderr)
        return EXIT_TERMINATED
    except KeyboardInterrupt:
        print("balpipe: interrupted; the site is as the last complete build left it", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return EXIT_OK
    except OSError as exc:  # a full disk, a read-only folder, a permission: the path and the remedy
        from ..runtime.fsutil import describe

        print(f"balpipe: error: {describe(exc)}", file=sys.stderr)
        return EXIT_USAGE
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


def entry() -> None:
    """The ``balpipe`` console script and ``python -m balpipe``: :func:`main`, then exit with its
    code. What is alive at the end is frozen first (:func:`gc.freeze`), so the interpreter's
    shutdown does not walk every object of the loaded modules in a last collection: about 0.15 s
    of a 0.6 s ``balpipe check`` of one spec. (Not in :func:`main`, which tests call in-process.)

    Ctrl-C or SIGTERM at any moment from here on gives exit 130 or 143 and no traceback: one
    that arrives before :func:`main` handles it (parsing the arguments) or after it returned is
    caught here; once the command's code is known, both are blocked until the exit (the work is
    done: the pools' clean-up at exit cannot print "Exception ignored" for one)."""
    from ..runtime.threads import environment_only

    environment_only()  # BLAS libraries load after import balpipe set their thread count: no limit to set
    try:
        signal.signal(signal.SIGTERM, on_sigterm)  # main() sets it too; here it covers parsing the arguments
        try:
            code = main()
        finally:
            gc.freeze()
        if hasattr(signal, "pthread_sigmask"):
            signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT, signal.SIGTERM})
    except Terminated:
        print("balpipe: terminated; the site is as the last complete build left it", file=sys.stderr)
        code = EXIT_TERMINATED
    except KeyboardInterrupt:
        print("balpipe: interrupted; the site is as the last complete build left it", file=sys.stderr)
        code = EXIT_INTERRUPTED
    sys.exit(code)


if __name__ == "__main__":
    entry()
