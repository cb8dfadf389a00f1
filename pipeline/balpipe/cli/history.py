"""``balpipe history PATH...``: the command line of :mod:`balpipe.history`."""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

from .common import EXIT_FAILED, EXIT_INTERRUPTED, EXIT_OK, EXIT_TERMINATED, EXIT_USAGE, Terminated, paths_jobs_problem

DEFAULT_CACHE = ".balpipe-cache/history"


def add_parser(sub) -> argparse.ArgumentParser:
    h = sub.add_parser(
        "history", help="headline figures of every spec along its git history",
        description="Walk the git history of each spec (git log --follow) and record, per commit, the "
        "computed parameters, each stage's peak shaking force and moment, added mass and the validation "
        "status, in <out>/<spec>/history.json and history.html. Figures are cached by input hash (spec "
        "text, simulation on or off, balpipe's code): a revision already seen is not recomputed. Run it "
        "before 'balpipe build', which then puts the history section in each study page.")
    h.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders of specs, in a git work tree")
    h.add_argument("-o", "--out", default="reports", metavar="DIR", help="output folder (default: reports)")
    h.add_argument("--cache", default=DEFAULT_CACHE, metavar="DIR",
                   help=f"folder of cached figures (default: {DEFAULT_CACHE})")
    h.add_argument("-j", "--jobs", type=int, default=1, metavar="N", help="compute N revisions in parallel")
    h.add_argument("--no-sim", action="store_true", help="skip the pymunk validation (no validation status)")
    h.add_argument("--max-commits", type=int, default=None, metavar="N", help="only the newest N commits of each spec")
    h.add_argument("-q", "--quiet", action="store_true", help="print only problems and the summary")
    return h


def run(args) -> int:
    from .. import history

    problem = paths_jobs_problem(args.paths, args.jobs)
    if problem:
        print(f"balpipe: error: {problem}", file=sys.stderr)
        return EXIT_USAGE
    if args.max_commits is not None and args.max_commits < 1:
        print("balpipe: error: --max-commits must be at least 1", file=sys.stderr)
        return EXIT_USAGE

    def progress(k: int, total: int, o: history.SpecHistory) -> None:
        if o.status == "ok":
            if not args.quiet:
                print(f"[{k}/{total}] {o.source}: {o.commits} commit{'s' if o.commits != 1 else ''} "
                      f"({o.computed} computed, {o.cached} cached, {o.reused} from the build)", file=sys.stderr)
        else:
            print(f"[{k}/{total}] {o.source}: {o.status}", file=sys.stderr)
            if o.message:
                print("    " + o.message.replace("\n", "\n    "), file=sys.stderr)

    start = time.perf_counter()
    try:
        outcomes = history.run(args.paths, Path(args.out), Path(args.cache), simulate=not args.no_sim,
                               jobs=args.jobs, max_commits=args.max_commits, progress=progress)
    except KeyboardInterrupt as exc:  # SIGTERM (Terminated) too: each with its own code
        if isinstance(exc, Terminated):
            print("balpipe: terminated", file=sys.stderr)
            return EXIT_TERMINATED
        print("balpipe: interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    if not outcomes:
        print("balpipe: error: no spec files (*.yaml) found", file=sys.stderr)
        return EXIT_USAGE
    computed = sum(o.computed for o in outcomes)
    commits = sum(o.commits for o in outcomes)
    errors = sum(o.status == "error" for o in outcomes)
    crashes = sum(o.status == "crash" for o in outcomes)
    print(f"balpipe: history of {len(outcomes)} spec{'s' if len(outcomes) != 1 else ''}: {commits} commits, "
          f"{computed} computed, {commits - computed} from the cache or the build "
          f"({time.perf_counter() - start:.2f} s); pages: {Path(args.out) / '<spec>' / 'history.html'}",
          file=sys.stderr)
    if errors:
        return EXIT_USAGE
    return EXIT_FAILED if crashes else EXIT_OK
