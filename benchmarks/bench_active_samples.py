"""Prototype measurement (not used by the pipeline): a partial balancing's main optimum over all
samples against an active-sample scheme. Prints numbers; asserts nothing.

    python benchmarks/bench_active_samples.py specs/partial_paper000_rpr3.yaml

The scheme: every 25th sample and each load's unbalanced peak, solve, add every sample whose
load exceeds the largest kept value of its term, solve again until none does (the same optimum:
a sample outside the kept set that does not exceed the bound changes nothing). Each term keeps
its scale (the unbalanced value over all samples). Printed: CPU of both (compilation and solve),
rounds, samples kept, and how far the objective and the design moved: the objective at the
solver's tolerance, the design much further where the optimal designs form a face (the interior
point returns a point of it that depends on the constraints present).
"""

from __future__ import annotations

import sys
import time
from dataclasses import dataclass
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "pipeline"))

from balpipe import registry  # noqa: E402
from balpipe.balancing import partial as P  # noqa: E402
from balpipe.balancing.partial_maps import Load  # noqa: E402
from balpipe.balancing.partial_program import Program, Term  # noqa: E402
from balpipe.loader import load  # noqa: E402


@dataclass(frozen=True)
class Kept(Term):
    """A term on some samples, divided by the full term's unbalanced value."""

    full_scale: float = 1.0

    @property
    def scale(self) -> float:
        return self.full_scale


def kept(term: Term, rows: list[np.ndarray]) -> Kept:
    maps = tuple(Load(L.name, L.unit, L.A[k], L.b[k], L.b0[k]) for L, k in zip(term.maps, rows))
    return Kept(maps, term.kind, term.weight, term.label, term.scale)


def main(path: str) -> None:
    import cvxpy  # noqa: F401  (imported before the timings)

    spec = load(path).spec
    method = spec.balancing
    model, t = registry.unbalanced_model(spec), registry.time_grid(spec)
    motions = P.motion_maps(model, t, method, spec, None)
    program = Program(motions[0], method.budget.inertia)
    objective = [P.term_of(motions, x, x.weight) for x in method.objective]
    caps = [(T, c.at_most if c.relative else c.at_most / T.scale)
            for c, T in ((c, P.term_of(motions, c)) for c in method.caps)]  # as partial.solve
    program.mass_budget.value = float(method.budget.mass)
    c0 = time.process_time()
    full = program.solve(program.problem(objective, caps)[0], polish=objective)
    t_full = time.process_time() - c0
    terms = objective + [c for c, _ in caps]
    rows = {id(T): [np.union1d(np.arange(0, L.A.shape[0], 25), [np.argmax(np.linalg.norm(L.b0, axis=1))])
                    for L in T.maps] for T in terms}
    c0, rounds = time.process_time(), 0
    while True:
        rounds += 1
        prob = program.problem([kept(T, rows[id(T)]) for T in objective],
                               [(kept(T, rows[id(T)]), b) for T, b in caps])[0]
        out = program.solve(prob, polish=[kept(T, rows[id(T)]) for T in objective])
        added = 0
        for T in terms:
            bound = max(float(np.max(L.samples(out.z)[k])) for L, k in zip(T.maps, rows[id(T)]))
            for j, L in enumerate(T.maps):
                new = np.setdiff1d(np.flatnonzero(L.samples(out.z) > bound * (1 + 1e-9)), rows[id(T)][j])
                rows[id(T)][j] = np.union1d(rows[id(T)][j], new)
                added += new.size
        if not added:
            break
    t_act = time.process_time() - c0
    big = np.abs(full.z) > 1e-6 * np.max(np.abs(full.z))
    d = np.abs(out.z - full.z) / np.maximum(np.abs(full.z), 1e-300)
    print(f"{path}: all samples {t_full:.2f} s CPU; active samples {t_act:.2f} s CPU, {rounds} rounds, "
          f"{sum(len(k) for v in rows.values() for k in v)} of {sum(L.A.shape[0] for T in terms for L in T.maps)} samples kept")
    print(f"  objective {full.objective!r} and {out.objective!r} (relative {abs(out.objective / full.objective - 1):.2g}); "
          f"design entries above 1e-6 of the largest: largest relative difference {d[big].max():.2g}")


if __name__ == "__main__":
    for p in sys.argv[1:]:
        main(p)
