"""Benchmarks of design sweeps (issue 13, item 4). Prints numbers and ratios; asserts nothing.

    python benchmarks/bench_sweep.py [--designs 10000] [--e2e 1000] [--no-dask]

1. Mass sweep of the Scott-Russell mechanism (specs/scott_russell.yaml, stage ``full``, 501
   samples): one engine analysis of the base design (``MassSweep.build``), then peak shaking
   force, moment and actuator effort of ``--designs`` random mass designs (every body's m, mx,
   my, J scaled at random) by blocks of matrix products (``MassSweep.peaks``), in
   design-samples per second; checked against full ``engine.analyse`` runs of a few designs.
2. Anchor: Pinocchio's ``rnea`` called per sample from Python (``pip install pin``), on a planar
   chain with the same three bodies (crank: revolute, coupler: revolute, slider: prismatic) and
   masses, over the mechanism's own joint trajectories. RNEA does not close the loop, so it
   does less work per sample than the constrained inverse dynamics: a generous anchor.
3. End to end ``balpipe.sweep.run`` on ``--e2e`` designs varying crank, coupler and slider
   masses: before (every design's spec validated, templated and balanced; ``affine=False``) and
   after (the mass-only route of :mod:`balpipe.sweep_affine`), in process; the per-design route
   on a local process pool of two and on a local two-worker dask.distributed cluster (if installed).
4. A geometry sweep (a length and a mass): two engine analyses per design before, one per
   geometry after.
5. A length-only sweep: every design a new geometry of a closed loop, solved from the base
   spec's motion (warm start) against the sequential continuation.

On a machine shared with other jobs, OpenBLAS threads fight for the cores; set
``OPENBLAS_NUM_THREADS=1`` for steadier numbers (the matrix products have 12 columns).
"""

from __future__ import annotations

import argparse
import os
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "scott_russell.yaml"


def best_of(fn, repeats: int = 3) -> float:
    best = float("inf")
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def mass_sweep(designs: int) -> tuple[float, int]:
    from balpipe import registry
    from balpipe.engine import analyse
    from balpipe.loader import load
    from balpipe.balancing.mass_sweep import MassSweep
    from balpipe.study import gravity_vector

    spec = load(SPEC).spec
    res = registry.balance_designs(spec)
    model = res.stages[-1].model
    t = registry.time_grid(spec)
    g, P = gravity_vector(spec), tuple(spec.analysis.moment_point)
    build = best_of(lambda: MassSweep.build(model, t, g, P))
    ms = MassSweep.build(model, t, g, P)
    p0 = ms.parameters(model)
    rng = np.random.default_rng(0)
    Pm = p0 * rng.uniform(0.5, 2.0, size=(designs, p0.size))
    Pm[:, 3::4] = np.maximum(Pm[:, 3::4], (Pm[:, 1::4] ** 2 + Pm[:, 2::4] ** 2) / np.maximum(Pm[:, 0::4], 1e-12))
    peaks_t = best_of(lambda: ms.peaks(Pm))
    N = len(t)
    print(f"1. mass sweep, Scott-Russell 'full' stage, {N} samples, {designs} designs")
    print(f"   one-off analysis + regressors (MassSweep.build): {build * 1e3:.1f} ms")
    print(f"   peaks of all designs (matrix products): {peaks_t * 1e3:.1f} ms = "
          f"{designs / peaks_t:,.0f} designs/s = {designs * N / peaks_t:,.3g} design-samples/s")
    total = build + peaks_t
    print(f"   including the one-off analysis: {designs * N / total:,.3g} design-samples/s")
    # accuracy against the engine on a few designs (a design = the model with its bodies' p)
    from dataclasses import replace

    err = 0.0
    out = ms.peaks(Pm[:3])
    for k in range(3):
        bodies = []
        for j, b in enumerate(model.bodies):
            m, mx, my, J = Pm[k, 4 * j : 4 * j + 4]
            c = (mx / m, my / m)
            bodies.append(replace(b, mass=m, com=c, inertia=J - m * (c[0] ** 2 + c[1] ** 2), attachments=()))
        an = analyse(replace(model, bodies=tuple(bodies)), t, g, P)
        err = max(err, abs(out["max_shaking_moment"][k] - an.max_moment) / an.max_moment)
    print(f"   largest relative difference of the peak moment from engine.analyse (3 designs): {err:.1e}")
    return designs * N / peaks_t, N


def pinocchio_anchor(N: int) -> float | None:
    try:
        import pinocchio as pin
    except ImportError:
        print("2. skipped: pinocchio is not installed (pip install pin)")
        return None
    from balpipe import registry
    from balpipe.engine import analyse
    from balpipe.loader import load

    spec = load(SPEC).spec
    model = registry.balance_designs(spec).stages[-1].model
    t = registry.time_grid(spec)
    an = analyse(model, t)
    pm = pin.Model()
    pm.gravity = pin.Motion.Zero()
    parent = 0
    joints = [pin.JointModelRZ(), pin.JointModelRZ(), pin.JointModelPX()]
    for k, b in enumerate(model.bodies):
        m, c, I = b.mass_properties()
        jid = pm.addJoint(parent, joints[k], pin.SE3.Identity(), f"j{k}")
        pm.appendBodyToJoint(jid, pin.Inertia(m, np.array([c[0], c[1], 0.0]), np.diag([1e-6, 1e-6, I])), pin.SE3.Identity())
        parent = jid
    data = pm.createData()
    # joint coordinates: crank angle, relative coupler angle, slider travel (any smooth series)
    th = an.q[:, :, 2]
    q = np.stack([th[:, 0], th[:, 1] - th[:, 0], an.q[:, 2, 0]], axis=1)
    v = np.gradient(q, t, axis=0)
    a = np.gradient(v, t, axis=0)

    def run():
        for k in range(N):
            pin.rnea(pm, data, q[k], v[k], a[k])

    dt = best_of(run, 5)
    print(f"2. Pinocchio {pin.__version__} rnea per sample from Python (3-body open chain): {N / dt:,.3g} samples/s")
    return N / dt


def end_to_end(n: int, dask: bool) -> None:
    from balpipe.sweep import csv_text, plan, run

    p = plan(str(SPEC), ["mechanism.crank.mass=0.5:2", "mechanism.coupler.mass=0.5:2", "mechanism.slider.mass=0.2:1"],
             sample="lhs", n=n, seed=1)
    print(f"3. end to end sweep.run, {n} designs (LHS over crank, coupler, slider masses), 501 samples; "
          f"{os.cpu_count()} cores on this machine")
    start = time.perf_counter()
    before = run(p, jobs=1, affine=False)
    t0 = time.perf_counter() - start
    print(f"   before: every design's spec built (validation, template, method), jobs=1: {t0:.2f} s = "
          f"{n / t0:,.0f} designs/s")
    start = time.perf_counter()
    local = run(p, jobs=1)
    t1 = time.perf_counter() - start
    print(f"   after: mass-only route (k+1 designs built, the rest as matrix products), jobs=1: {t1:.2f} s = "
          f"{n / t1:,.0f} designs/s ({local.fast} on the fast path); {t0 / t1:.1f}x")
    big = plan(str(SPEC), ["mechanism.crank.mass=0.5:2", "mechanism.coupler.mass=0.5:2", "mechanism.slider.mass=0.2:1"],
               sample="lhs", n=10 * n, seed=1)
    start = time.perf_counter()
    run(big, jobs=1)
    t10 = time.perf_counter() - start
    print(f"   after, {10 * n} designs: {t10:.2f} s = {10 * n / t10:,.0f} designs/s "
          f"({10 * n / t10 / (n / t0):.0f}x the per-design route's rate)")
    worst = max(abs(a[m] - b[m]) / max(1.0, abs(b[m])) for a, b in zip(local.rows, before.rows)
                for m in ("max_shaking_moment", "max_shaking_force", "max_actuator_effort", "added_mass"))
    print(f"   largest relative difference between the two routes: {worst:.1e}")
    t0 = time.perf_counter()
    pool = run(p, jobs=2, affine=False)
    t2 = time.perf_counter() - t0
    print(f"   per-design route on a process pool, 2 workers: {t2:.2f} s = {n / t2:,.0f} designs/s")
    geometry_sweep()
    if not dask:
        return
    try:
        from distributed import LocalCluster
    except ImportError:
        print("   dask: skipped (pip install 'balpipe[sweep]')")
        return
    import logging

    logging.getLogger("distributed").setLevel(logging.ERROR)
    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        run(p, scheduler=cl.scheduler_address, affine=False)  # warm the workers (imports)
        t0 = time.perf_counter()
        remote = run(p, scheduler=cl.scheduler_address, affine=False)
        t3 = time.perf_counter() - t0
    same = csv_text(remote) == csv_text(pool)
    print(f"   per-design route on a dask LocalCluster, 2 workers (warm): {t3:.2f} s = {n / t3:,.0f} designs/s; "
          f"ratio to the local process pool {t2 / t3:.2f}x; table identical to the local run: {same}")


def geometry_sweep(lengths: int = 5, masses: int = 20) -> None:
    """4. A grid over a length and a mass (offset slider-crank, 501 samples): every design has its
    own spec and model; before, two engine analyses per design (chosen and unbalanced stage);
    after, one analysis per geometry (the canonical model's regressors) shared by both stages and
    by the designs of that geometry."""
    from balpipe import sweep
    from balpipe.engine import analyse
    from balpipe.sweep import build_design, plan, run

    spec = ROOT / "specs" / "offset_slider_crank.yaml"
    p = plan(str(spec), [f"mechanism.crank.length=0.09:0.1:{lengths}", f"mechanism.crank.mass=0.5:2:{masses}"])
    n = len(p.designs)
    paths = [v.path for v in p.varies]
    m = min(n, 6)
    t0 = time.perf_counter()
    for values in p.designs[:m]:  # the previous per-design path: two engine analyses
        s, sr, base = build_design(p.data, paths, values, None)
        t, g, P = sweep._settings(s)
        analyse(sr.model, t, g, P), analyse(base.model, t, g, P)
    old = (time.perf_counter() - t0) / m
    sweep._GEOMETRIES.clear()
    start = time.perf_counter()
    res = run(p, jobs=1)
    t1 = time.perf_counter() - start
    print(f"4. geometry sweep, offset slider-crank, crank length x crank mass grid {lengths} x {masses} = {n} designs")
    print(f"   before: two engine analyses per design: {1 / old:,.1f} designs/s (timed on {m} designs)")
    print(f"   after: one analysis per geometry, jobs=1: {t1:.2f} s = {n / t1:,.1f} designs/s ({res.full} designs, "
          f"{res.failed} failed); {old * n / t1:.1f}x")


def geometry_only_sweep(lengths: int = 40) -> None:
    """5. A sweep of one length only (every design a new geometry of a closed loop, 501
    samples), jobs=1: each geometry's motion from the base spec's (the anchors of
    :mod:`balpipe.engine.warmstart`), against the sequential continuation per geometry."""
    from balpipe import sweep
    from balpipe.engine import warmstart
    from balpipe.sweep import plan, run

    spec = ROOT / "specs" / "offset_slider_crank.yaml"
    p = plan(str(spec), [f"mechanism.crank.length=0.15:0.25:{lengths}"])
    times, counts = {}, {}
    saved = warmstart.start
    for label in ("continuation", "warm start"):
        if label == "continuation":
            warmstart.start = lambda *args: None
        sweep._GEOMETRIES.clear()
        before = dict(warmstart.STATS)
        t0 = time.perf_counter()
        res = run(p, jobs=1)
        times[label] = time.perf_counter() - t0
        counts[label] = {k: warmstart.STATS[k] - before[k] for k in before}
        warmstart.start = saved
        assert res.failed == 0
    n = len(p.designs)
    print(f"5. length-only sweep, offset slider-crank, {n} crank lengths (every design a new geometry), jobs=1")
    for label in times:
        print(f"   {label}: {times[label]:.2f} s = {n / times[label]:,.1f} designs/s  (engine: {counts[label]})")
    print(f"   warm start / continuation: {times['continuation'] / times['warm start']:.2f}x designs/s")


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--designs", type=int, default=10_000)
    ap.add_argument("--e2e", type=int, default=1000)
    ap.add_argument("--no-dask", action="store_true")
    args = ap.parse_args()
    rate, N = mass_sweep(args.designs)
    anchor = pinocchio_anchor(N)
    if anchor:
        print(f"   mass sweep / Pinocchio per-sample RNEA: {rate / anchor:.1f}x (target 10x)")
    end_to_end(args.e2e, not args.no_dask)
    geometry_only_sweep()


if __name__ == "__main__":
    sys.exit(main())
