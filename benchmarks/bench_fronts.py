"""Benchmark of the partial balancing's fronts (issue 23): active samples against every sample.
Prints numbers; asserts nothing.

    python benchmarks/bench_fronts.py [spec.yaml ...]      # default: the partial specs of specs/

For each spec, the fronts of its partial balancing (:func:`balpipe.balancing.partial.fronts.compute`:
the complete balances' least masses, four fronts and their ends) are computed twice in this process:

* as the build computes them: each programme on its active samples
  (:class:`balpipe.balancing.partial.active.ActiveProgram`);
* the same programmes on every time sample (the exchange loop switched off: every sample in
  every programme from the start), the reference.

It prints the CPU seconds of each, their ratio, the number of programmes, and the largest
relative difference between the two of the values each front minimises (the objective:
the force of the force fronts, the moment of the moment front, the effort of the effort front)
and of every other number of the fronts (the other loads of each optimal design and its added
mass: where several designs are optimal, those belong to whichever the solver returns). A
trade-off front's points are compared at their own caps, which follow the front's ends: where
an end moves (the least second load among the designs of least first load, flat), so do the
caps, and the minimised values with them (a knuckle-joint press of ours: ends 4e-5 apart, its
force-moment front's forces 1.8e-4).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
MINIMISED = {"force_vs_mass": "shaking_force", "moment_vs_mass": "shaking_moment", "force_vs_moment": "shaking_force",
             "effort_vs_force": "effort"}


def captured(spec_path: Path) -> tuple:
    """The arguments the spec's balancing passes to ``partial_fronts.compute`` (by running it)."""
    from balpipe import registry
    from balpipe.balancing.partial import fronts as PF
    from balpipe.loader import load

    seen = []
    real = PF.compute

    def spy(program, terms, budget, n, max_mass):
        seen.append((program.maps, program.inertia_budget, terms, budget, n, max_mass))
        return real(program, terms, budget, n, max_mass)

    PF.compute = spy
    try:
        registry.balance(load(spec_path).spec)
    finally:
        PF.compute = real
    return seen[0]


def timed(args: tuple, every_sample: bool) -> tuple[dict, float, int]:
    from balpipe.balancing.partial import active as PA
    from balpipe.balancing.partial import fronts as PF

    maps, inertia, terms, budget, n, max_mass = args
    solves = [0]
    samples, exchange = PA.ActiveProgram._samples, PA.ActiveProgram._exchange
    if every_sample:
        PA.ActiveProgram._samples = lambda self, term, k: np.arange(term.maps[k].A.shape[0])

    def counting(self, *a, **k):
        solves[0] += 1
        return exchange(self, *a, **k)

    PA.ActiveProgram._exchange = counting
    try:
        c0 = time.process_time()
        out = PF.compute(PA.ActiveProgram(maps, inertia), terms, budget, n, max_mass)
        return out, time.process_time() - c0, solves[0]
    finally:
        PA.ActiveProgram._samples, PA.ActiveProgram._exchange = samples, exchange


def differences(a: dict, b: dict) -> tuple[float, float]:
    """Largest relative difference of the minimised values, and of the other numbers (values
    below 1e-9 of the largest of their kind, round-off zeros, left out)."""
    mini = other = 0.0
    for front, key in MINIMISED.items():
        for p, q in zip(a.get(front, []), b.get(front, [])):
            for k in p:
                if k in ("budget", "cap", "sensitivity"):  # the inputs, and a dual value (not unique at budget 0)
                    continue
                big = max(abs(x[k]) for x in a[front] + b[front])
                if max(abs(p[k]), abs(q[k])) <= 1e-9 * big:
                    continue
                d = abs(p[k] - q[k]) / max(abs(p[k]), abs(q[k]))
                if k == key:
                    mini = max(mini, d)
                else:
                    other = max(other, d)
    return mini, other


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("specs", nargs="*", type=Path)
    a = ap.parse_args(argv)
    specs = a.specs or sorted(p for p in (ROOT / "specs").glob("*.yaml") if "partial_balance" in p.read_text())
    print(f"{'spec':40s} {'active s':>9s} {'every s':>9s} {'ratio':>6s} {'solves':>7s} {'minimised':>10s} {'other':>9s}")
    total = [0.0, 0.0]
    for path in specs:
        args = captured(path)
        ours, t_ours, n_ours = timed(args, every_sample=False)
        ref, t_ref, _ = timed(args, every_sample=True)
        mini, other = differences(ours, ref)
        total[0] += t_ours
        total[1] += t_ref
        print(f"{path.stem[:40]:40s} {t_ours:9.2f} {t_ref:9.2f} {t_ref / t_ours:6.1f} {n_ours:7d} {mini:10.1e} {other:9.1e}")
    print(f"{'total':40s} {total[0]:9.2f} {total[1]:9.2f} {total[1] / total[0]:6.1f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
