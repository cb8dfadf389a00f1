"""The 4-RRR of paper 001, run by hand: ``python benchmarks/rrr4.py``. Prints, asserts nothing.

1. the engine on specs/paper001_4rrr.yaml's unbalanced model: redundant actuation (four base
   motors, least-squares positions, minimum-norm efforts) against the same mechanism driven
   square at the platform (x, y of its centre and its angle), samples per second for 10^2,
   10^3, 10^4 samples, best of 3;
2. the paper recipe (leg-by-leg counter-masses, the eq. 17 design) and eq. 17's conditions with
   their residuals;
3. ``study.run`` of each paper-001 spec (every stage analysed, no simulation, no page).
"""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

import numpy as np

from balpipe import registry, study
from balpipe.families.rrr4 import counter_masses as recipe
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.model import Driver

ROOT = Path(__file__).resolve().parent.parent
SPECS = [ROOT / "specs" / "paper001_4rrr.yaml", ROOT / "specs" / "paper001_4rrr_fig6a.yaml"]


def best(fn, repeats: int = 3) -> float:
    out = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        out.append(time.perf_counter() - t0)
    return min(out)


def platform_driven(model):
    plat = model.body("platform")
    plat = replace(plat, points={**plat.points, "O": (0.0, 0.0)})
    pose = model.drivers[0].law.pose
    return replace(model.replace_body(plat), drivers=(
        Driver("x", ("x", "platform", "O"), pose[0]), Driver("y", ("y", "platform", "O"), pose[1]),
        Driver("angle", ("angle", "platform"), pose[2])))


def main() -> None:
    spec = load(SPECS[0]).spec
    model = registry.unbalanced_model(spec)
    square = platform_driven(model)
    T = spec.motion.duration
    print("1. engine.analyse on the 4-RRR (samples per second, best of 3)")
    print(f"{'samples':>8} {'4 motors (redundant)':>22} {'platform-driven (square)':>26}")
    for n in (100, 1000, 10000):
        t = np.linspace(0.0, T, n + 1)
        a = best(lambda: analyse(model, t))
        b = best(lambda: analyse(square, t))
        print(f"{n:>8} {n / a:>22.0f} {n / b:>26.0f}")
    print("\n2. paper recipe and conditions (best of 3)")
    res = best(lambda: recipe.balance(registry.context(spec, model=model)))
    rows = best(lambda: recipe.eq17_residuals(spec.mechanism, model))
    print(f"   rrr4 recipe (leg by leg + eq. 17 design): {1000 * res:.2f} ms")
    print(f"   eq. 17's twelve conditions with residuals: {1000 * rows:.3f} ms")
    print("\n3. study.run (all stages analysed, no simulation)")
    for path in SPECS:
        s = load(path).spec
        dt = best(lambda: study.run(s), repeats=1)
        print(f"   {path.name}: {dt:.2f} s ({s.analysis.samples} samples)")


if __name__ == "__main__":
    main()
