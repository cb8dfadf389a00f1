"""The engine against Pinocchio's RNEA on planar serial chains of n revolute joints (3R, 10R, 30R
by default), at 10^2 to 10^5 samples, this version against REV in one alternated run.

    python benchmarks/bench_chains.py --against 7838770
    python benchmarks/bench_chains.py --joints 3 10 30 --samples 100 10000 100000 --repeat 2

A chain: :func:`chains.serial_chain` (seed 0: random links, every joint on the 3-4-5 law over
1 s), gravity -9.81 m/s^2 in y. Pinocchio (``pip
install pin``) gets the same chain as revolute-Z joints. Every measurement runs in a fresh
interpreter with the version's ``pipeline/`` first on the path and one BLAS thread (as
``balpipe`` runs its analyses): ``balpipe.engine.analyse`` (positions, velocities,
accelerations, multipliers, reactions, both shaking-load routes) timed in CPU seconds
(``time.process_time``, best of at least 3 repeats and 0.3 s), then ``pinocchio.rnea`` called
once per sample from Python on the engine's joint angles, rates and accelerations (the same
timing); the largest difference of the joint torques relative to each joint's peak is printed
(round-off: ~1e-15). Per version and case the table gives the least CPU time of the repeats,
the engine's throughput, Pinocchio's in the same child, their ratio (engine / Pinocchio: 1 is
Pinocchio's speed), and the child's peak memory (``ru_maxrss`` from ``os.wait4``: the engine's
arrays and Pinocchio's, one analysis at a time). Nothing is asserted about speed.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_build import versions as versions_of  # noqa: E402  (this tree and a revision, checked out)

CHILD = r'''
import json, sys, time
import numpy as np
sys.path.insert(0, sys.argv[3])
from chains import serial_chain
from balpipe.engine import analyse

n, N = int(sys.argv[1]), int(sys.argv[2])
model, data = serial_chain(n)
L, r, m, I = data["L"], data["r"], data["m"], data["I"]
t = np.linspace(0.0, 1.0, N)
g = (0.0, -9.81)


def best(fn):
    times, total = [], 0.0
    while len(times) < 3 or total < 0.3:
        c0 = time.process_time()
        fn()
        dt = time.process_time() - c0
        times.append(dt)
        total += dt
    return min(times)


an = analyse(model, t, g)
cpu = best(lambda: analyse(model, t, g))
out = {"cpu": cpu}
try:
    import pinocchio as pin
except ImportError:
    pin = None
if pin is not None:
    pm = pin.Model()
    pm.gravity = pin.Motion(np.array([0.0, -9.81, 0.0, 0.0, 0.0, 0.0]))
    parent, offset = 0, 0.0
    for k in range(n):
        jid = pm.addJoint(parent, pin.JointModelRZ(), pin.SE3(np.eye(3), np.array([offset, 0.0, 0.0])), f"q{k}")
        pm.appendBodyToJoint(jid, pin.Inertia(m[k], np.array([r[k], 0.0, 0.0]), np.diag([1e-6, 1e-6, I[k]])),
                             pin.SE3.Identity())
        parent, offset = jid, L[k]
    pd = pm.createData()
    zero = np.zeros((N, 1))
    q, v, a = (np.ascontiguousarray(np.diff(np.concatenate([zero, x[:, :, 2]], axis=1), axis=1)) for x in (an.q, an.v, an.a))
    tau = np.stack([pin.rnea(pm, pd, q[k], v[k], a[k]).copy() for k in range(N)])
    mine = np.stack([an.efforts[f"q{k}"] for k in range(n)], axis=1)
    out["error"] = float((np.abs(mine - tau).max(axis=0) / np.abs(tau).max(axis=0)).max())

    def loop():
        for k in range(N):
            pin.rnea(pm, pd, q[k], v[k], a[k])

    out["pin_cpu"] = best(loop)
print(json.dumps(out))
'''


def run(python: str, pipeline: Path, n: int, N: int) -> dict:
    """The child's measurements, with its peak memory (MB) and wall time (s)."""
    import time

    env = dict(os.environ, PYTHONPATH=str(pipeline), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1",
               MKL_NUM_THREADS="1")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    with tempfile.TemporaryFile() as log:
        t0 = time.perf_counter()
        proc = subprocess.Popen([python, "-c", CHILD, str(n), str(N), str(ROOT / "benchmarks")], env=env, stdout=subprocess.PIPE, stderr=log)
        out = proc.stdout.read() if proc.stdout is not None else b""
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        if os.waitstatus_to_exitcode(status) != 0:
            log.seek(0)
            sys.stderr.write(log.read().decode(errors="replace")[-2000:])
            return {}
    res = json.loads(out.decode().strip().splitlines()[-1])
    res["peak"], res["wall"] = usage.ru_maxrss / 1024.0, wall
    return res


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--against", metavar="REV", help="git revision to compare with, alternated in the same run")
    ap.add_argument("--joints", type=int, nargs="+", default=[3, 10, 30])
    ap.add_argument("--samples", type=int, nargs="+", default=[100, 1000, 10_000, 100_000])
    ap.add_argument("--repeat", type=int, default=2, help="alternated runs of each case")
    ap.add_argument("--python", default=sys.executable)
    args = ap.parse_args(argv)
    best: dict[tuple[int, int, str], dict] = {}
    with versions_of(args.against, "bench_chains_") as (versions, _):
        for _ in range(args.repeat):
            for n in args.joints:
                for N in args.samples:
                    for v, pipeline in versions.items():
                        r = run(args.python, pipeline, n, N)
                        b = best.setdefault((n, N, v), {})
                        for k, x in r.items():
                            b[k] = max(b.get(k, 0.0), x) if k in ("peak", "error") else min(b.get(k, x), x)
                    print(".", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
    heads = ["chain", "samples"]
    for v in versions:
        heads += [f"{v}: CPU s / samples/s / peak MB", "engine / pin"]
    heads += ["pin rnea loop samples/s", "max rel torque error"]
    print("| " + " | ".join(heads) + " |")
    print("|" + " --- |" * len(heads))
    for n in args.joints:
        for N in args.samples:
            row = [f"{n}R", f"{N:,}"]
            pin_cpu = None
            for v in versions:
                b = best.get((n, N, v), {})
                if "cpu" not in b:
                    row += ["failed", "-"]
                    continue
                row.append(f"{b['cpu']:.4f} s / {N / b['cpu']:,.0f} / {b['peak']:.0f} MB")
                row.append(f"{b['pin_cpu'] / b['cpu']:.2f}" if "pin_cpu" in b else "-")
                if "pin_cpu" in b:
                    pin_cpu = b["pin_cpu"] if pin_cpu is None else min(pin_cpu, b["pin_cpu"])
            row.append(f"{N / pin_cpu:,.0f}" if pin_cpu else "pinocchio not installed")
            row.append(f"{best.get((n, N, 'this'), {}).get('error', float('nan')):.1e}")
            print("| " + " | ".join(row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
