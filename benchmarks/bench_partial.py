"""Benchmark of optimal partial balancing (issue 21). Prints numbers; asserts nothing.

    python benchmarks/bench_partial.py [--designs 400] [--points 30]

On specs/custom_four_bar_partial.yaml (401 samples, three counterweights):

1. the force front (least peak shaking force against added mass, ``--points`` budgets) by the cone
   programme: one engine analysis for the affine maps, then the programme of each point solved by
   Clarabel on its active samples (:mod:`balpipe.balancing.partial.active`), each point globally
   optimal;
2. the same front by sampling: ``balpipe sweep`` (:func:`balpipe.sweep.run`, in this process) of
   ``--designs`` random designs of the same counterweights (masses and positions in the same
   regions, as a ``stages`` spec), its Pareto front of peak force against added mass, and how far
   above the optimal front its best designs stay (and whether any design beats the optimal front
   beyond 1e-6: none should).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
import yaml

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "custom_four_bar_partial.yaml"


def cone_front(points: int) -> tuple[list[dict], dict]:
    from balpipe import registry
    from balpipe.balancing.partial import method as P
    from balpipe.balancing.partial import fronts as PF
    from balpipe.balancing.partial import maps as PM
    from balpipe.loader import load

    from balpipe.balancing.partial.active import ActiveProgram

    t0 = time.perf_counter()
    import clarabel  # noqa: F401  (its import is a one-off cost of the process, timed apart)
    times = {"import clarabel": time.perf_counter() - t0}
    spec = load(SPEC).spec
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    t0 = time.perf_counter()
    wd, parts, discs = P.parts_from_spec(model, spec.balancing)
    maps = PM.build(wd, model, t, parts, discs)
    times["analysis and affine maps"] = time.perf_counter() - t0
    t0 = time.perf_counter()
    program = ActiveProgram(maps)
    terms = P.standard_terms(maps)
    times["programme set-up"] = time.perf_counter() - t0
    t0, c0 = time.perf_counter(), time.process_time()
    front = PF.mass_front(program, terms["shaking_force"], np.linspace(0.0, 3.0, points), terms)
    times[f"front of {points} points"] = time.perf_counter() - t0
    times[f"front of {points} points (CPU)"] = time.process_time() - c0
    return front, times


def sampled_front(designs: int) -> tuple[list[dict], float]:
    """The sweep of a ``stages`` version of the spec: the same regions (segments as a fraction
    along them; the coupler's disc as a point in polar coordinates), masses 0..1.5 kg."""
    from balpipe import sweep

    d = yaml.safe_load(SPEC.read_text())
    d["balancing"] = {"method": "stages", "stages": [{"name": "cw", "parts": [
        {"body": "crank", "name": "cw_crank", "mass": 0.5, "position": [-0.04, 0]},
        {"body": "coupler", "name": "cw_coupler", "mass": 0.5, "position": [0.14, 0]},
        {"body": "rocker", "name": "cw_rocker", "mass": 0.5, "position": [-0.06, 0]}]}]}
    d.pop("compare", None)
    d["validation"] = {"enabled": False}
    d["sweep"] = {"vary": {
        "balancing.stages.0.parts.0.mass": "0:1.5", "balancing.stages.0.parts.0.position.0": "-0.08:0",
        "balancing.stages.0.parts.1.mass": "0:1.5", "balancing.stages.0.parts.1.position.0": "-0.11:0.39",
        "balancing.stages.0.parts.2.mass": "0:1.5", "balancing.stages.0.parts.2.position.0": "-0.12:0"},
        "sample": "random", "designs": designs, "seed": 0}
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "sweep_four_bar.yaml"
        path.write_text(yaml.safe_dump(d, sort_keys=False))
        t0 = time.perf_counter()
        res = sweep.run(sweep.plan(str(path)), jobs=1)
        elapsed = time.perf_counter() - t0  # includes planning: checking the spec, probing the affine route
    rows = [r for r in res.rows if "error" not in r]
    return rows, elapsed


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=400)
    ap.add_argument("--points", type=int, default=30)
    a = ap.parse_args(argv)
    front, times = cone_front(a.points)
    print(f"load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores (wall times grow with it; CPU times less)")
    print(f"cone programme, {SPEC.name}:")
    for k, v in times.items():
        print(f"  {k:<28} {v:8.3f} s")
    print(f"  -> {a.points}-point force front in {times[f'front of {a.points} points']:.3f} s "
          f"({1e3 * times[f'front of {a.points} points'] / a.points:.1f} ms per point; "
          f"CPU {times[f'front of {a.points} points (CPU)']:.3f} s)")
    rows, elapsed = sampled_front(a.designs)
    print(f"sampling sweep (balpipe sweep, {a.designs} random designs, in process): {elapsed:.3f} s "
          f"({len(rows)} designs analysed)")
    mass = np.array([r["added_mass"] for r in rows])
    force = np.array([r["max_shaking_force"] for r in rows])
    worse, beaten = [], 0
    for p in front:
        ok = mass <= p["budget"] + 1e-12
        if ok.any():
            best = float(force[ok].min())
            worse.append(best / max(p["shaking_force"], 1e-300) if p["shaking_force"] > 1e-9 * front[0]["shaking_force"] else np.nan)
            beaten += best < p["shaking_force"] * (1 - 1e-6)
    w = np.array(worse)
    print(f"  best sampled design per budget / optimal: median {np.nanmedian(w):.3g}, worst {np.nanmax(w):.3g}"
          f" (budgets where the optimum is zero left out)")
    print(f"  budgets where a sampled design beats the optimal front beyond 1e-6: {beaten}")
    print(f"time ratio sweep / cone front: {elapsed / times[f'front of {a.points} points']:.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
