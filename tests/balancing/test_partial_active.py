"""The partial balancing's programme written for Clarabel and solved on its active samples
(balancing/partial_active.py) against the same programme written with cvxpy on every sample
(tests/partial_reference.py): the same optima on random four-bars with every kind of part, caps,
RMS terms, several weighted terms, least-mass problems; samples added where the start missed the
peak; an unreachable cap infeasible; a stalled solve answered at Clarabel's own tolerances."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe.balancing.partial import method as P
from balpipe.balancing.partial import active as PA
from balpipe.balancing.least_mass import independent_equations
from balpipe.balancing.partial.program import Term
from balpipe.spec import Spec
from generic_specs import four_bar
from test_partial import DISC, POLYGON, SEGMENTS, method, setup

import cvxpy as cp  # noqa: E402  (the test extras' reference solver: a missing one fails, not skips)
from partial_reference import Program  # noqa: E402

CR = [{"name": "disc_crank", "carrier": "frame", "at": [0, 0], "geared_to": "crank", "ratio": -1}]


def _maps(seed: int, inertia: float | None = None):
    rng = np.random.default_rng(seed)
    budget = {"mass": 1.0, "inertia": inertia}
    d = four_bar(rng, method([SEGMENTS[0], DISC, POLYGON, {**SEGMENTS[1], "max_mass": 0.3}], counter_rotations=CR))
    d["balancing"]["budget"] = budget
    spec = Spec.model_validate(d)
    maps = setup(spec)
    return maps, P.standard_terms(maps), rng


def _reference(maps, objective, budget, caps=(), inertia=None):
    ref = Program(maps, inertia)
    prob = ref.problem(objective, list(caps))[0]
    ref.mass_budget.value = float(budget)
    return ref.solve(prob)


def _value(objective: list[Term], z: np.ndarray) -> float:
    """The design's objective on every sample."""
    return sum(t.weight * t.value(z) / t.scale for t in objective)


def _same_optimum(ours, ref, objective) -> None:
    assert ours.z is not None and ref.z is not None
    assert ours.objective == pytest.approx(ref.objective, rel=1e-7, abs=1e-9)
    # the exchange's guarantee: the design meets its bound on every sample, not only on its own
    assert _value(objective, ours.z) <= ref.objective * (1 + 1e-7) + 1e-9
    assert ours.budget_dual == pytest.approx(ref.budget_dual, rel=1e-4, abs=1e-6)


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_every_terms_optimum_equals_the_every_sample_reference(seed):
    maps, terms, rng = _maps(seed)
    force, moment, effort = terms["shaking_force"], terms["shaking_moment"], terms["effort"]
    both = [Term(force.maps, "peak", 1.0, "f"), Term(moment.maps, "peak", float(rng.uniform(0.2, 2)), "m")]
    budget = float(rng.uniform(0.2, 1.2))
    program = PA.ActiveProgram(maps)
    for objective in ([force], [moment], [effort], both):
        ours = program.solve(objective, budget)
        _same_optimum(ours, _reference(maps, objective, budget), objective)
    kept = sum(len(s) for s in program.active.values())
    every = sum(L.A.shape[0] for t in (force, moment, effort) for L in t.maps)
    assert kept < every / 4  # what makes it fast: most samples never enter a programme


@pytest.mark.parametrize("seed", [4, 5])
def test_caps_rms_terms_and_an_inertia_budget_equal_the_reference(seed):
    maps, terms, rng = _maps(seed, inertia=2e-3)
    force, moment = terms["shaking_force"], terms["shaking_moment"]
    rms = Term(tuple(maps.load("effort")), "rms", 1.0, "rms effort")
    program = PA.ActiveProgram(maps, 2e-3)
    least = program.solve([force], 0.9).objective  # a cap between the least force and the unbalanced one
    caps = [(force, least + float(rng.uniform(0.2, 0.5)) * (1 - least)), (moment, 1.5)]
    ours = program.solve([rms], 0.9, eps=caps)
    ref = _reference(maps, [rms], 0.9, caps, inertia=2e-3)
    _same_optimum(ours, ref, [rms])
    for t, bound in caps:
        assert t.value(ours.z) / t.scale <= bound * (1 + 1e-7) + 1e-9
    used = sum(ours.z[p.col + 3] for p in maps.parts) + sum(ours.z[d.col] for d in maps.discs)
    assert used <= 2e-3 * (1 + 1e-7)


def test_least_masses_equal_the_reference():
    """The complete force balance's least mass (equations on every sample) and the least mass
    that meets a cap (the located error's number)."""
    maps, terms, _ = _maps(6)
    force = terms["shaking_force"]
    A = np.concatenate([L.A.reshape(-1, maps.nz) for L in force.maps])
    b = np.concatenate([L.b.reshape(-1) for L in force.maps])
    Ar, br, inconsistent = independent_equations(A, -b)
    program = PA.ActiveProgram(maps)
    ref = Program(maps)
    masses = sum((ref.z[p.col] for p in maps.parts), start=0.0)
    ref.mass_budget.value = PA.UNBOUNDED
    if not inconsistent:
        ours = program.least_mass(Ar, br)
        scale = float(np.max(np.abs(Ar)))
        theirs = ref.solve(cp.Problem(cp.Minimize(masses), ref.base + [(Ar / scale) @ ref.z == br / scale]))
        assert (ours.z is None) == (theirs.z is None)
        if ours.z is not None:
            assert maps.added_mass(ours.z) == pytest.approx(maps.added_mass(theirs.z), rel=1e-7, abs=1e-9)
    caps = [(force, 0.4)]
    ours = program.least_mass(caps=caps)
    e, c = ref.expression(force)
    theirs = ref.solve(cp.Problem(cp.Minimize(masses), ref.base + c + [e <= 0.4]))
    assert ours.z is not None and theirs.z is not None
    assert maps.added_mass(ours.z) == pytest.approx(maps.added_mass(theirs.z), rel=1e-7, abs=1e-9)
    assert force.value(ours.z) / force.scale <= 0.4 * (1 + 1e-7)


def test_a_start_without_the_peaks_grows_to_the_same_optimum(monkeypatch):
    """One sample to start with, not the largest: the loop adds every sample that exceeds the
    bound until none does, and reaches the reference's optimum."""
    maps, terms, _ = _maps(7)
    force = terms["shaking_force"]
    monkeypatch.setattr(PA, "START", 1)
    monkeypatch.setattr(PA, "_local_maxima", lambda v: np.arange(len(v))[::-1])  # the last sample only
    program = PA.ActiveProgram(maps)
    ours = program.solve([force], 0.5)
    _same_optimum(ours, _reference(maps, [force], 0.5), [force])
    assert len(program.active[(id(force), 0)]) > 1


def test_an_unreachable_cap_is_infeasible_and_no_design():
    maps, terms, _ = _maps(8)
    out = PA.ActiveProgram(maps).solve([terms["effort"]], 0.0, eps=[(terms["shaking_force"], 1e-3)])
    assert out.z is None and out.status == "infeasible"


def test_a_stalled_solve_is_answered_at_clarabels_own_tolerances(monkeypatch):
    """Where the tight settings stop without an answer (here: one iteration allowed), the
    programme is solved again with Clarabel's defaults: an answer, the reference's to its
    tolerance (1e-8)."""
    maps, terms, _ = _maps(9)
    force = terms["shaking_force"]
    seen = []
    settings = PA._settings
    monkeypatch.setattr(PA, "SOLVER_SETTINGS", {**PA.SOLVER_SETTINGS, "max_iter": 1})
    monkeypatch.setattr(PA, "_settings", lambda values: seen.append(values["max_iter"]) or settings(values))
    ours = PA.ActiveProgram(maps).solve([force], 0.5)
    assert 1 in seen and PA.FALLBACK_SETTINGS["max_iter"] in seen
    ref = _reference(maps, [force], 0.5)
    assert ours.objective == pytest.approx(ref.objective, rel=1e-6)
