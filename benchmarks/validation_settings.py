"""Residual of the pymunk validation against its step size and solver iterations, per stage.

For each spec and stage, runs the validation (``validate``) with the time step ``f`` times the
default (``default_settings``: min(T / STEPS_PER_MOTION, 0.01 / w_max)) and the first solver
iteration count ``it``, and prints the residuals (force, moment: max |sim - analytic| / reference
load), the iterations the run ended with and its wall time. Used to choose the defaults
(benchmarks/README.md, section "Validation settings").

    python benchmarks/validation_settings.py --specs offset_slider_crank scott_russell --factors 1 2 4 --iterations 100
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from balpipe import study as study_mod
from balpipe.loader import load
from balpipe.study import ratio_reference
from balpipe.validate import ValidationSettings, default_settings, validate

ROOT = Path(__file__).resolve().parents[1]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--specs", nargs="+", required=True)
    ap.add_argument("--factors", nargs="+", type=float, default=[1.0, 2.0, 4.0])
    ap.add_argument("--iterations", nargs="+", type=int, default=[100])
    ap.add_argument("--no-early", action="store_true", help="always double the iterations until the loads converge")
    ap.add_argument("--fixed", action="store_true", help="one run at exactly each iteration count (no doubling)")
    ap.add_argument("--stages", nargs="*", help="only these stages")
    ap.add_argument("--floor", type=float, default=None, help="mass floor (ValidationSettings.mass_floor)")
    args = ap.parse_args(argv)
    print(f"{'spec':30s} {'stage':18s} {'dt/def':>6s} {'it0':>5s} {'dt':>9s} {'force':>9s} {'moment':>9s} {'iters':>6s} {'s':>6s}")
    for name in args.specs:
        path = Path(name) if Path(name).suffix else ROOT / "specs" / f"{name}.yaml"
        st = study_mod.run(load(path).spec)
        for s in st.stages:
            if args.stages and s.stage.name not in args.stages:
                continue
            ref = ratio_reference(st.reference_stage(s))
            expect = tuple(x for x in ("force", "moment") if x in s.stage.balances)
            dt0, _ = default_settings(s.stage.model, s.analysis)
            for f in args.factors:
                for it in args.iterations:
                    # --fixed: any healthy first run is accepted (a tolerance no run misses)
                    cfg = ValidationSettings(dt=dt0 * f, iterations=it, early_accept=not args.no_early,
                                             **({"tolerance": 1e9, "balance_tolerance": 1e9} if args.fixed else {}),
                                             **({"mass_floor": args.floor} if args.floor is not None else {}))
                    t0 = time.perf_counter()
                    v = validate(s.stage.model, s.analysis, (ref.force_peak, ref.moment_peak), cfg, expect, reference=ref)
                    print(f"{path.stem[:30]:30s} {s.stage.name[:18]:18s} {f:6g} {it:5d} {v.dt:9.3g} {v.force_residual:9.2g} "
                          f"{v.moment_residual:9.2g} {v.iterations:6d} {time.perf_counter() - t0:6.2f}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
