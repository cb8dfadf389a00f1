"""``balpipe sweep``: design sweeps over numeric spec fields (see :mod:`balpipe.sweep`)."""

from __future__ import annotations

import argparse
import sys

from .common import EXIT_FAILED, EXIT_OK, EXIT_USAGE


def add_parser(sub) -> None:
    from .. import MAX_DESIGNS  # the limit alone: no pydantic, numpy or sweep machinery for --help

    s = sub.add_parser(
        "sweep", help="sweep numeric spec fields; table, Pareto fronts, design specs",
        description="Vary numeric fields of a spec (dotted paths, units as in the spec) over a grid or "
        "seeded random / Latin-hypercube samples, as given by --vary or else by the spec's sweep: block "
        "(flags override the block; --vary replaces its vary list); write sweep.csv, a page with the Pareto fronts of added "
        "mass against peak shaking moment and peak actuator effort, and the specs of the designs on them. "
        "Designs that change only masses, inertias and counterweights take the fast path (one analysis, "
        "a matrix product per design).",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="RANGE: LO:HI:N (grid of N values), a,b,c (listed values), LO:HI (bounds for --sample random|lhs)\n"
        "example: balpipe sweep specs/scott_russell.yaml --vary 'mechanism.crank.mass=0.5 kg:2 kg:11' "
        "--vary 'mechanism.slider.mass=0.2:1:5'",
    )
    s.add_argument("spec", metavar="SPEC", help="the base spec file")
    s.add_argument("--vary", action="append", default=[], metavar="PATH=RANGE", help="a field and its range (repeat)")
    s.add_argument("--sample", choices=["grid", "random", "lhs"], default=None, help="design of experiments (default: grid)")
    s.add_argument("-n", "--designs", type=int, default=None, metavar="N", help="number of designs for random and lhs")
    s.add_argument("--seed", type=int, default=None, help="seed of random and lhs (default 0)")
    s.add_argument("--stage", metavar="NAME", help="the stage whose loads are reported (default: the method's last)")
    s.add_argument("--max-designs", type=int, default=None, metavar="N",
                   help=f"refuse sweeps with more designs (default {MAX_DESIGNS})")
    s.add_argument("-o", "--out", default="sweep", metavar="DIR", help="output folder (default: sweep)")
    s.add_argument("--specs", choices=["pareto", "all", "none"], default="pareto",
                   help="write the specs of the designs on a Pareto front (default), of all, or none")
    s.add_argument("--parquet", action="store_true", help="also write sweep.parquet (needs pyarrow)")
    s.add_argument("-j", "--jobs", type=int, default=0, metavar="N", help="local processes (default 0: all cores)")
    s.add_argument("--scheduler", metavar="ADDRESS", help="run on a dask.distributed scheduler (tcp://host:port)")
    s.add_argument("-q", "--quiet", action="store_true", help="no progress bar")


def run(args) -> int:
    from ..loader import SpecErrors
    from ..sweep import SweepError, plan, progress_printer, write
    from ..sweep import run as run_sweep

    if args.jobs < 0:
        print("balpipe: error: --jobs must be >= 0", file=sys.stderr)
        return EXIT_USAGE
    if args.parquet:
        try:
            import pyarrow  # noqa: F401
        except ImportError:
            print("balpipe: error: --parquet needs pyarrow (pip install pyarrow)", file=sys.stderr)
            return EXIT_USAGE
    if args.scheduler:
        from ..runtime.cluster import address_problem

        bad = address_problem(args.scheduler)
        if bad:
            print(f"balpipe: error: --scheduler {args.scheduler}: {bad}", file=sys.stderr)
            return EXIT_USAGE
        try:
            import distributed  # noqa: F401
        except ImportError:
            print("balpipe: error: --scheduler needs dask.distributed (pip install 'balpipe[sweep]')", file=sys.stderr)
            return EXIT_USAGE
        from ..runtime.cluster import unreachable

        why = unreachable(args.scheduler)
        if why is not None:
            print(f"balpipe: error: cannot reach the dask scheduler at {args.scheduler}: {why}", file=sys.stderr)
            return EXIT_USAGE
    try:
        p = plan(args.spec, args.vary, args.sample, args.designs, args.seed, args.max_designs, args.stage)
    except (SweepError, SpecErrors) as exc:
        print(str(exc), file=sys.stderr)
        return EXIT_USAGE
    except FileNotFoundError as exc:
        print(f"balpipe: error: {exc}", file=sys.stderr)
        return EXIT_USAGE
    res = run_sweep(p, jobs=args.jobs, scheduler=args.scheduler, progress=progress_printer(args.quiet))
    written = write(res, args.out, args.specs, args.parquet)
    print(f"balpipe: {len(res.rows)} designs: {res.fast} mass-only (fast path), {res.full} full analyses, "
          f"{res.failed} failed; {written[-1]}", file=sys.stderr)
    return EXIT_OK if res.fast + res.full else EXIT_FAILED
