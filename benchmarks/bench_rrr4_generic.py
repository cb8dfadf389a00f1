"""The generic balancing layer on paper 001's 4-RRR, run by hand:
``python benchmarks/bench_rrr4_generic.py [--sim]``. Prints, asserts nothing.

1. the condition finder (:func:`balpipe.balancing.conditions.find`: state sampling, regressor,
   SVD, RREF) on the unbalanced 4-RRR of specs/paper001_4rrr.yaml and of the Fig. 5a spec
   (issue 8: must stay under 1 s), and on translating-platform states (Fig. 5a: eight engine
   analyses, then the finder), best of 5;
2. the least-mass synthesis alone (:func:`balpipe.balancing.least_mass.solve`, one disc per link,
   linprog) and the whole recipe (leg by leg, finder, least mass, eq. 17 design), best of 5;
3. the whole spec build: ``balpipe build specs/paper001_4rrr.yaml --no-sim`` (and with the pymunk
   validation with ``--sim``), process wall time.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import time
from pathlib import Path

from balpipe import registry
from balpipe.balancing import conditions as C
from balpipe.balancing import least_mass as LM
from balpipe.families.rrr4 import counter_masses as recipe
from balpipe.families.rrr4 import finder as G
from balpipe.loader import load
from bench_generic import best  # noqa: E402  (benchmarks/ is on sys.path when run as a script)

ROOT = Path(__file__).resolve().parent.parent
SPECS = [ROOT / "specs" / "paper001_4rrr.yaml", ROOT / "specs" / "paper001_4rrr_fig6a.yaml"]


def main() -> None:
    print(f"{'spec':28s} {'step':46s} {'ms':>9s}  result")
    for path in SPECS:
        spec = load(path).spec
        model = registry.unbalanced_model(spec)
        t = recipe.finder_grid(model)
        name = path.name
        tf, cond = best(lambda: C.find(model, t))
        print(f"{name:28s} {'finder, every motion (sample + SVD + RREF)':46s} {1e3 * tf:9.1f}  {cond.count} conditions, "
              f"gap {cond.gap:.2g}, {cond.samples} states")
        if spec.mechanism.kinematics != "general":
            ts, states = best(lambda: G.translating_states(model), 3)
            tt, tr = best(lambda: C.find(model, t, states=states))
            print(f"{name:28s} {'translating states (8 engine analyses)':46s} {1e3 * ts:9.1f}  {states.count} states")
            print(f"{name:28s} {'finder on them':46s} {1e3 * tt:9.1f}  {tr.count} conditions, gap {tr.gap:.2g}")
        radii = {b.name: (0.1 if b.name.endswith("1") else 0.08) for b in model.bodies if b.name != "platform"}
        regions = [LM.Region(f"lm {b}", b, "disc", ((0.0, 0.0),), r) for b, r in radii.items()]
        tl, sol = best(lambda: LM.solve(model, cond, regions))
        print(f"{name:28s} {'least-mass synthesis (8 discs, 128-gons, linprog)':46s} {1e3 * tl:9.1f}  "
              f"{sol.total_mass:.6g} kg")
        tr_, res = best(lambda: recipe.balance(registry.context(spec, model=model)), 3)
        print(f"{name:28s} {'recipe: all stages (finder and least mass incl.)':46s} {1e3 * tr_:9.1f}  "
              f"{len(res.stages)} stages")
    with tempfile.TemporaryDirectory() as tmp:
        for flags in (["--no-sim"], [] if "--sim" in sys.argv else None):
            if flags is None:
                continue
            t0 = time.perf_counter()
            subprocess.run([sys.executable, "-m", "balpipe", "build", str(SPECS[0]), "-o", tmp, "--force", "-q", *flags],
                           check=False, capture_output=True)
            label = "build " + (" ".join(flags) or "(with pymunk validation)")
            print(f"{SPECS[0].name:28s} {label:46s} {1e3 * (time.perf_counter() - t0):9.1f}  process wall time")


if __name__ == "__main__":
    main()
