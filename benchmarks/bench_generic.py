"""Generic balancing benchmarks, run by hand: ``python benchmarks/bench_generic.py``.

Prints, for each model, the time of the condition finder (state sampling + linear-momentum
regressor + SVD + RREF: :func:`balpipe.balancing.conditions.find`), of the least-mass
counterweight synthesis alone (:func:`balpipe.balancing.least_mass.solve`, linprog), of the
moment-balance method (conditions of both momenta, joint linear programme, least-squares disc
inertias) and of a whole ``balpipe build --no-sim`` of the custom four-bar spec. Best of 5
(perf_counter); asserts nothing. The 4-RRR of paper 001 is included when its spec is present.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tests"))

from balpipe import registry  # noqa: E402
from balpipe.balancing import conditions as C  # noqa: E402
from balpipe.balancing import least_mass as LM  # noqa: E402
from balpipe.balancing.force_balance import regions_from_spec  # noqa: E402
from balpipe.loader import load  # noqa: E402
from balpipe.spec import Spec  # noqa: E402
from generic_specs import FIVE_BAR_DISCS, FIVE_BAR_REGIONS, FOUR_BAR_DISCS, FOUR_BAR_REGIONS, five_bar, four_bar  # noqa: E402


def best(fn, repeats: int = 5) -> tuple[float, object]:
    times, out = [], None
    for _ in range(repeats):
        t0 = time.perf_counter()
        out = fn()
        times.append(time.perf_counter() - t0)
    return min(times), out


def main() -> None:
    cases = [
        ("slider-crank (Scott-Russell spec)", load(ROOT / "specs/scott_russell.yaml").spec, None),
        ("five-bar, paper 004 (1 DOF, gears)", load(ROOT / "specs/paper004_five_bar.yaml").spec, None),
        ("random four-bar (custom)", Spec.model_validate(four_bar(np.random.default_rng(1), {
            "method": "moment_balance", "counterweights": FOUR_BAR_REGIONS, "counter_rotations": FOUR_BAR_DISCS})), FOUR_BAR_REGIONS),
        ("random five-bar (custom, 2 DOF)", Spec.model_validate(five_bar(np.random.default_rng(2), {
            "method": "moment_balance", "counterweights": FIVE_BAR_REGIONS, "counter_rotations": FIVE_BAR_DISCS})), FIVE_BAR_REGIONS),
    ]
    if (ROOT / "specs/paper001_4rrr.yaml").exists():  # after the rrr4 branch is merged
        cases.insert(2, ("4-RRR, paper 001 (redundant actuation)", load(ROOT / "specs/paper001_4rrr.yaml").spec, None))
    print(f"{'model':38s} {'bodies':>6s} {'conds':>5s} {'gap':>9s} {'finder ms':>10s} {'least-mass ms':>14s} {'moment_balance ms':>18s}")
    for label, spec, regions in cases:
        model = registry.unbalanced_model(spec)
        t = registry.time_grid(spec)
        tf, cond = best(lambda: C.find(model, t))
        tl = tm = float("nan")
        if regions is not None:
            from balpipe.balancing.force_balance import CounterweightRegionSpec

            regs = regions_from_spec(model, [CounterweightRegionSpec.model_validate(r) for r in regions], ())
            tl, _ = best(lambda: LM.solve(model, cond, regs))
            tm, _ = best(lambda: registry.balance(spec), 3)
        print(f"{label:38s} {len(model.bodies):6d} {cond.count:5d} {cond.gap:9.2g} {1e3 * tf:10.1f} {1e3 * tl:14.1f} {1e3 * tm:18.1f}")
    with tempfile.TemporaryDirectory() as tmp:
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "balpipe", "build", str(ROOT / "specs/custom_four_bar_balancing.yaml"),
                        "-o", tmp, "--no-sim", "--force", "-q"], check=False, capture_output=True)
        print(f"build --no-sim specs/custom_four_bar_balancing.yaml: {time.perf_counter() - t0:.2f} s (process wall time)")


if __name__ == "__main__":
    main()
