"""The partial balancing's Clarabel interface (balancing/partial_clarabel.py): re-solves that update
only the right-hand side give, bit for bit, the answers of cvxpy's own interface."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe.balancing import partial as P
from balpipe.balancing import partial_clarabel as PC
from balpipe.balancing import partial_fronts as PF
from balpipe.balancing import partial_program as PP
from balpipe.spec import Spec
from generic_specs import four_bar
from test_partial import SEGMENTS, POLYGON, method, setup

cp = pytest.importorskip("cvxpy")


def _fronts(spec: Spec, rng: np.random.Generator) -> list:
    """Two mass fronts and two trade-off fronts at random budgets and caps, and a sequence of
    re-solves of one problem at random budgets (one compiled problem each, as the page's)."""
    maps = setup(spec)
    program = P.Program(maps)
    terms = P.standard_terms(maps)
    force, moment, effort = terms["shaking_force"], terms["shaking_moment"], terms["effort"]
    masses = np.sort(rng.uniform(0.0, 1.5, 6))
    budget = float(rng.uniform(0.3, 1.0))
    out = [PF.mass_front(program, force, masses, terms), PF.mass_front(program, moment, masses, terms),
           PF.tradeoff_front(program, force, moment, budget, 5, terms),
           PF.tradeoff_front(program, effort, force, budget, 5, terms)]
    prob = program.problem([force], caps=[(effort, 1.5)])[0]
    for k, M in enumerate(rng.uniform(0.0, 1.5, 6)):  # random order: budgets up and down
        program.mass_budget.value = float(M)
        o = program.solve(prob, polish=[force], fresh=k == 0)
        out.append((None if o.z is None else o.z.tolist(), o.status, o.objective, o.budget_dual))
    return out


@pytest.mark.parametrize("seed", [11, 12])
def test_fronts_equal_cvxpys_own_clarabel_interface_bit_for_bit(seed, monkeypatch):
    spec = Spec.model_validate(four_bar(np.random.default_rng(seed), method(SEGMENTS + [POLYGON], budget=0.6)))
    calls = []
    holds = PC.Cached.holds
    monkeypatch.setattr(PC.Cached, "holds", lambda self, *a: calls.append(holds(self, *a)) or calls[-1])
    ours = _fronts(spec, np.random.default_rng(seed + 100))
    assert sum(calls) >= 15  # all re-solves but the first of each problem updated b alone
    monkeypatch.setattr(PC, "solver", lambda: cp.CLARABEL)
    theirs = _fronts(spec, np.random.default_rng(seed + 100))
    assert ours == theirs  # every number equal, not only to 1e-9


def test_a_parameter_in_the_matrix_updates_everything():
    """A parameter that enters A (not only b): each re-solve is a full update, as cvxpy's."""
    x = cp.Variable(2)
    p = cp.Parameter(nonneg=True)
    c = [cp.norm(x - np.array([1.0, 2.0])) <= p * x[0] + 1.0, x >= -5]
    rng = np.random.default_rng(3)
    answers = []
    for solver in (PC.solver(), cp.CLARABEL):
        prob = cp.Problem(cp.Minimize(x[0] + 2 * x[1]), c)
        got = []
        for v in rng.uniform(0.1, 0.9, 5):
            p.value = float(v)
            prob.solve(solver=solver, **PP.SOLVER_SETTINGS)
            got.append((x.value.tolist(), prob.value, c[0].dual_value))
        answers.append(got)
        rng = np.random.default_rng(3)
    assert answers[0] == answers[1]
    assert answers[0][0] != answers[0][1]
