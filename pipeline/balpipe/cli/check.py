"""``balpipe check PATH...``: validate specs without building."""

from __future__ import annotations

import sys

from .common import EXIT_FAILED, EXIT_OK, EXIT_USAGE, missing, usage_error


def add_parser(sub) -> None:
    c = sub.add_parser("check", help="validate specs without building",
                       description="Check specs: schema, units, geometry and balancing feasibility.")
    c.add_argument("paths", nargs="+", metavar="PATH", help="spec files or folders of specs")


def run(args) -> int:
    """Everything ``build`` checks before simulating: schema, units, limits, geometry, the
    balancing, the analysis of every stage (singular motions), the references, and the paths and
    values of a ``sweep:`` block. Keeps going past a spec that fails."""
    from ..spec_files import clashes, find_specs
    from ..runner import analyse
    from ..loader import SpecErrors, load
    from ..sweep import SweepError, plan

    gone = missing(args.paths)
    if gone:
        return usage_error(f"no such file or folder: {', '.join(gone)}")
    problems: list[str] = []
    files = find_specs(args.paths, problems)
    for msg in problems:
        print(msg, file=sys.stderr)
    clash = clashes(files)
    bad = crashed = 0
    for f in files:
        try:
            if f in clash:
                raise SpecErrors([])
            loaded = load(f)
            analyse(loaded)
            if loaded.spec.sweep is not None:  # its paths and values against the spec, as balpipe sweep does
                try:
                    plan(str(f))
                except SweepError as exc:
                    raise SpecErrors([]) from exc
            print(f"{f}: ok")
        except SpecErrors as exc:
            bad += 1
            print(str(exc) or str(exc.__cause__ or "") or clash[f], file=sys.stderr)
        except Exception as exc:  # a bug in balpipe: report it, check the other specs
            crashed += 1
            print(f"{f}: internal error: {type(exc).__name__}: {exc}", file=sys.stderr)
    bad += len(problems)
    print(f"balpipe: {len(files) - bad - crashed + len(problems)} valid, {bad} invalid"
          + (f", {crashed} internal errors" if crashed else ""), file=sys.stderr)
    if not files and not problems:
        return EXIT_USAGE
    if crashed:
        return EXIT_FAILED
    return EXIT_USAGE if bad else EXIT_OK
