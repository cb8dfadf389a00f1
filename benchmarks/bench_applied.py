"""What one step's loads cost in the torque-driven pymunk run: ``AppliedLoads.apply`` per step.

For each spec: its unbalanced model analysed on STEPS + 1 step times of its motion (the plan:
the Coulomb friction's magnitudes), pymunk bodies set to the analysed state of each step time,
and the process time of ``apply`` alone summed over the steps, the best of ``--repeat`` passes.
``--save DIR`` writes every step's forces and torques to DIR/<spec>.npy, so that two versions'
can be compared bit for bit. Run from the repository (``PYTHONPATH=<other tree>/pipeline`` for
another version: the script uses only ``AppliedLoads(model, plan, times).bind(bodies).apply(t, dt)``):

    python benchmarks/bench_applied.py specs/custom_compressor_gas_pressure.yaml specs/custom_four_bar_loaded.yaml
    python benchmarks/bench_applied.py specs/custom_pumpjack_rod_load.yaml --save /tmp/new
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

import numpy as np
import pymunk

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.mechanics.sampling import gravity_vector
from balpipe.validate.applied import AppliedLoads


def bench(path: str, steps: int, repeat: int) -> tuple[float, np.ndarray]:
    """(process seconds of apply per step, the forces and torques (steps + 1, nb, 3))."""
    spec = load(path).spec
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    times = float(t[0]) + (float(t[-1]) - float(t[0])) * np.arange(steps + 1) / steps
    dt = float(times[1] - times[0])
    plan = analyse(model, times, tuple(np.asarray(gravity_vector(spec))))
    bodies = [pymunk.Body(1.0, 1.0) for _ in model.bodies]
    applied = AppliedLoads(model, plan, times).bind(bodies)
    states = [[((float(plan.q[k, i, 0]), float(plan.q[k, i, 1])), float(plan.q[k, i, 2]),
                (float(plan.v[k, i, 0]), float(plan.v[k, i, 1])), float(plan.v[k, i, 2])) for i in range(len(bodies))]
              for k in range(steps + 1)]
    out = np.empty((steps + 1, len(bodies), 3))
    best = float("inf")
    for _ in range(repeat):
        cpu = 0.0
        for k in range(steps + 1):
            for b, (p, a, v, w) in zip(bodies, states[k]):
                b.angle, b.position, b.velocity, b.angular_velocity = a, p, v, w
                b.force, b.torque = (0.0, 0.0), 0.0
            c0 = time.process_time()
            applied.apply(float(times[k]), dt)
            cpu += time.process_time() - c0
            out[k] = [(b.force.x, b.force.y, b.torque) for b in bodies]
        best = min(best, cpu)
    return best / (steps + 1), out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("specs", nargs="+", help="spec files with loads")
    ap.add_argument("--steps", type=int, default=2000, help="step times along the motion (default 2000)")
    ap.add_argument("--repeat", type=int, default=3, help="passes, the best kept (default 3)")
    ap.add_argument("--save", type=Path, help="write each spec's forces and torques to SAVE/<spec>.npy")
    a = ap.parse_args(argv)
    for path in a.specs:
        per_step, forces = bench(path, a.steps, a.repeat)
        print(f"{Path(path).stem}: {1e6 * per_step:.1f} us per step ({a.steps + 1} steps, best of {a.repeat})")
        if a.save is not None:
            a.save.mkdir(parents=True, exist_ok=True)
            np.save(a.save / f"{Path(path).stem}.npy", forces)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
