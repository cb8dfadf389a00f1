"""Paper 003's spec (eight trajectories, phi optimisation included): build time without the
simulation, and where the time goes. Run by hand: ``python benchmarks/bench_paper003.py``.

Prints (asserts nothing):

1. ``balpipe build specs/paper003_com_planning.yaml --no-sim --force``: wall time and the CPU
   time of the process (user + system; on a shared machine the wall time also counts waiting);
2. in-process, one run of each step: loading, the method (planning: optimisation of phi and
   the ramp search of case 3), the engine's analyses of the 32 stages (number of ``analyse``
   calls and time per call), the page (figures, tables), and the optimiser's objective: number
   of evaluations and time per evaluation (the explicit vectorised serial dynamics on the
   analysis grid), against one engine call on the same stage, and per point when 3 or 24 points
   are evaluated in one call (as the searches side by side ask them: a trajectory's starts in a
   build, every trajectory's in ``balpipe check``).
"""

from __future__ import annotations

import os
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SPEC = ROOT / "specs" / "paper003_com_planning.yaml"


def build_once() -> None:
    with tempfile.TemporaryDirectory(prefix="balpipe-bench-") as out:
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t0 = time.perf_counter()
        proc = subprocess.run([sys.executable, "-m", "balpipe", "build", str(SPEC.relative_to(ROOT)), "-o", out,
                               "--no-sim", "--force"], capture_output=True, text=True, cwd=ROOT)
        wall = time.perf_counter() - t0
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    print("== 1. python -m balpipe build specs/paper003_com_planning.yaml --no-sim --force ==")
    print(f"exit {proc.returncode}; wall {wall:.2f} s; CPU (user + system) {cpu:.2f} s; load average "
          f"{', '.join(f'{x:.2f}' for x in os.getloadavg())} on {os.cpu_count()} cores")
    for line in proc.stderr.strip().splitlines():
        print("   ", line)


def breakdown() -> None:
    import numpy as np

    from balpipe import engine, registry, study
    from balpipe.families.serial_arm import com_planning as cp
    from balpipe.loader import load
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict

    print("\n== 2. in-process breakdown (one run each) ==")
    c = time.process_time
    t0 = time.perf_counter()
    loaded = load(SPEC)
    spec = loaded.spec
    t_load = time.perf_counter() - t0
    calls = {"n": 0, "s": 0.0}
    real = engine.analyse

    def timed(*a, **k):
        s = time.perf_counter()
        try:
            return real(*a, **k)
        finally:
            calls["n"] += 1
            calls["s"] += time.perf_counter() - s

    study.analyse = timed
    t1, c1 = time.perf_counter(), c()
    result = registry.balance(spec)
    t_method, c_method = time.perf_counter() - t1, c() - c1
    t2, c2 = time.perf_counter(), c()
    stages = study.run_stage_analyses(spec, result)
    t_engine, c_engine = time.perf_counter() - t2, c() - c2
    study.analyse = real
    t3, c3 = time.perf_counter(), c()
    st = study.run(spec)  # (again, for the page: the method's figures need a full Study)
    t_run, c_run = time.perf_counter() - t3, c() - c3
    t4, c4 = time.perf_counter(), c()
    res = results_dict(st, str(SPEC), "bench", simulated=False)
    render_page(st, res, loaded.text)
    t_page, c_page = time.perf_counter() - t4, c() - c4
    evals = sum(int(p.value) for p in result.parameters if p.name.startswith("phi_evaluations"))
    # time per objective evaluation vs one engine call, on the first trajectory's optimised stage
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    pl = cp.Planner(model, spec.mechanism, spec.balancing, spec.motion.duration, t, (0.0, 0.0), (0.0, 0.0))
    name, start, end, path = cp.trajectories_of(spec.balancing, model)[0]
    plan = pl.plan(name, start, end, path)
    f = pl.objective(plan, path)
    c0 = np.zeros(spec.balancing.phi.degree - 5)
    n = 300
    s = time.process_time()
    for _ in range(n):
        f(c0)
    per_eval = (time.process_time() - s) / n
    # several points in one call, as the searches side by side ask them (3 per trajectory, 24 in check)
    values = pl.peaks([(plan, path)])
    per_point = {}
    for k in (3, 24):
        points = np.zeros((k, len(c0)))
        s = time.process_time()
        for _ in range(max(n // k, 10)):
            values(points, [0] * k)
        per_point[k] = (time.process_time() - s) / (max(n // k, 10) * k)
    stage = next(x for x in result.stages if x.name.endswith("com_bang_bang_phi_opt"))
    s = time.process_time()
    for _ in range(5):
        engine.analyse(stage.model, t)
    per_engine = (time.process_time() - s) / 5
    rows = [
        ("load the spec", t_load, None),
        (f"method: plan 8 trajectories ({evals} objective evaluations, ramp search)", t_method, c_method),
        (f"engine: {calls['n']} analyse calls of {len(t)} samples ({calls['s'] / max(calls['n'], 1) * 1e3:.1f} ms wall per call)", t_engine, c_engine),
        ("study.run again (method + engine + checks)", t_run, c_run),
        ("page: results.json dict and HTML (figures)", t_page, c_page),
    ]
    w = max(len(r[0]) for r in rows)
    print(f"{'step'.ljust(w)}  {'wall s':>8}  {'CPU s':>8}")
    for label, sec, cpu in rows:
        print(f"{label.ljust(w)}  {sec:8.3f}  {'-' if cpu is None else f'{cpu:.3f}':>8}")
    print(f"CPU time per objective evaluation (fast path, {len(t)} samples): {per_eval * 1e3:.3f} ms; per engine "
          f"analyse of the same stage: {per_engine * 1e3:.1f} ms ({per_engine / per_eval:.0f}x); per point evaluated "
          + ", ".join(f"{k} at once {v * 1e3:.3f} ms" for k, v in per_point.items()))
    print(f"stages: {len(stages)}; load average {', '.join(f'{x:.2f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    build_once()
    breakdown()
