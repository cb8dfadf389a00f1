"""Optimal partial balancing (issue 21): affine load maps, the cone programme's optimality, the
textbook slider-crank result, fronts, located errors, the stage through the engine and pymunk."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry, study
from balpipe.balancing.partial import method as P
from balpipe.balancing.partial import fronts as PF
from balpipe.balancing.partial import maps as PM
from balpipe.balancing.partial.active import ActiveProgram
from balpipe.engine import analyse
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError
from balpipe.validation_stage import simulate_study
from _long import sample
from generic_specs import four_bar

ROOT = Path(__file__).resolve().parents[2]
SEGMENTS = [
    {"body": "crank", "name": "cw_crank", "segment": [[0, 0], [-0.08, 0]], "max_mass": 2.0},
    {"body": "rocker", "name": "cw_rocker", "segment": [[0, 0], [-0.12, 0]], "max_mass": 2.0},
]
DISCS = [{"body": "crank", "name": "cw_crank", "disc": {"centre": [-0.05, 0], "radius": 0.05}},
         {"body": "coupler", "name": "cw_coupler", "disc": {"centre": [0.15, 0], "radius": 0.3}},
         {"body": "rocker", "name": "cw_rocker", "disc": {"centre": [-0.15, 0], "radius": 0.15}}]
DISC = {"body": "coupler", "name": "cw_coupler", "disc": {"centre": [0.1, 0.02], "radius": 0.1}}
POLYGON = {"body": "coupler", "name": "cw_poly", "polygon": [[0, -0.03], [0.2, -0.03], [0.2, 0.03], [0, 0.03]]}


def method(counterweights, objective=({"load": "shaking_force"},), budget=1.0, **kw) -> dict:
    return {"method": "partial_balance", "counterweights": list(counterweights), "objective": list(objective),
            "budget": {"mass": budget}, "fronts": None, **kw}


def setup(spec: Spec):
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    wd, parts, discs = P.parts_from_spec(model, spec.balancing)
    return PM.build(wd, model, t, parts, discs)


def random_z(maps: PM.Maps, rng) -> np.ndarray:
    """A realisable design: per part a mass at a random point of its region, spread at random."""
    z = np.zeros(maps.nz)
    for p in maps.parts:
        m = rng.uniform(0.2, 1.5)
        if p.kind == "disc":
            r, a = p.radius * math.sqrt(rng.uniform()), rng.uniform(0, 2 * math.pi)
            c = np.asarray(p.points[0]) + r * np.array([math.cos(a), math.sin(a)])
        else:
            w = rng.dirichlet(np.ones(len(p.points)))
            c = w @ np.asarray(p.points)
        z[p.col : p.col + 4] = m, m * c[0], m * c[1], m * float(c @ c) + m * rng.uniform(0, 1e-3)
    for d in maps.discs:
        z[d.col] = rng.uniform(0, 0.01)
    return z


@pytest.mark.parametrize("seed", [3, 4])
def test_affine_maps_equal_a_full_reanalysis_of_a_random_design(seed):
    rng = np.random.default_rng(seed)
    cr = [{"name": "disc_crank", "carrier": "frame", "at": [0, 0], "geared_to": "crank", "ratio": -1}]
    spec = Spec.model_validate(four_bar(rng, method([SEGMENTS[0], DISC, POLYGON], counter_rotations=cr)))
    maps = setup(spec)
    z = random_z(maps, rng)
    an = analyse(maps.design(z), registry.time_grid(spec))
    F = maps.loads["shaking_force"]
    scale = np.abs(F.b).max()
    assert np.max(np.abs(np.einsum("nkj,j->nk", F.A, z) + F.b - an.force)) <= 1e-9 * scale
    M = maps.loads["shaking_moment"]
    assert np.max(np.abs(M.samples(z) - np.abs(an.moment))) <= 1e-9 * np.abs(M.b).max()
    E = maps.loads["effort:crank"]
    assert np.max(np.abs(E.samples(z) - np.abs(an.efforts["crank"]))) <= 1e-9 * np.abs(an.efforts["crank"]).max()
    for j in ("O2", "A", "B", "O4"):
        J = maps.loads[f"joint:{j}"]
        want = np.hypot(an.reactions[j]["Fx"], an.reactions[j]["Fy"])
        assert np.max(np.abs(J.samples(z) - want)) <= 1e-9 * want.max()


def slider_crank(ratio: float, budget: float = 20.0, samples: int = 721) -> Spec:
    """In-line slider-crank, coupler 0.3 m, crank ratio x 0.3 m, constant crank speed (a
    polynomial law with equal start and end speeds is linear), a crank counterweight on a segment
    behind the pivot."""
    L2, w = 0.3, 2 * math.pi * 5  # 5 turns/s
    L1 = ratio * L2
    return Spec.model_validate({
        "name": "in-line slider-crank",
        "mechanism": {"template": "slider_crank", "offset": 0.0,
                      "crank": {"length": L1, "mass": 0.5, "com": 0.4 * L1, "inertia": 1e-4},
                      "coupler": {"length": L2, "mass": 0.8, "com": 0.35 * L2, "inertia": 6e-3},
                      "slider": {"mass": 0.6}},
        "motion": {"law": "polynomial", "duration": 2 * math.pi / w,
                   "drive": {"crank": {"from": 0.0, "to": 2 * math.pi, "start_velocity": w, "end_velocity": w}}},
        "balancing": method([{"body": "crank", "name": "cw", "segment": [[0, 0], [-L1, 0]]}], budget=budget),
        "analysis": {"samples": samples},
        "validation": {"enabled": False},
    })


@pytest.mark.parametrize("ratio", [0.05, 0.1, 0.2])
def test_least_peak_force_balances_rotating_plus_half_reciprocating_mass(ratio):
    """Textbook: with l >> r the shaking force is r w^2 ((A - c) cos th, (B - c) sin th), A = m_rot
    + m_rec, B = m_rot, c the counterweight's first moment / r; its peak max(|A - c|, |B - c|) is
    least at c = m_rot + m_rec / 2. The secondary harmonic m_rec (r / l) cos 2 th moves the optimum
    by at most about m_rec (r / l) / 2: the test allows m_rec r / l."""
    spec = slider_crank(ratio)
    maps = setup(spec)
    program, out, *_ = P.solve(maps, spec.balancing)
    L1 = spec.mechanism.crank.length
    m1, r1 = spec.mechanism.crank.mass, spec.mechanism.crank.com / L1
    m2, r2 = spec.mechanism.coupler.mass, spec.mechanism.coupler.com / spec.mechanism.coupler.length
    m_rot = m1 * r1 + m2 * (1 - r2)
    m_rec = spec.mechanism.slider.mass + m2 * r2
    c = -out.z[1] / L1  # first moment along -x over the crank radius
    assert abs(c - (m_rot + m_rec / 2)) <= m_rec * ratio
    assert abs(out.z[2]) <= 1e-6 * abs(out.z[1])  # on the crank's line


def test_textbook_error_shrinks_with_the_crank_ratio():
    errs = []
    for ratio in (0.2, 0.1, 0.05):
        spec = slider_crank(ratio)
        maps = setup(spec)
        _, out, *_ = P.solve(maps, spec.balancing)
        m = spec.mechanism
        L1 = m.crank.length
        r2 = m.coupler.com / m.coupler.length
        m_rot = m.crank.mass * m.crank.com / L1 + m.coupler.mass * (1 - r2)
        m_rec = m.slider.mass + m.coupler.mass * r2
        errs.append(abs(-out.z[1] / L1 - (m_rot + m_rec / 2)) / m_rec)
    assert errs[0] > errs[1] > errs[2]


def _physical(maps, x):
    """Design z from physical parameters: per segment part (mass, position along the segment)."""
    z = np.zeros(maps.nz)
    for k, p in enumerate(maps.parts):
        m, u = x[2 * k], x[2 * k + 1]
        a, b = np.asarray(p.points[0]), np.asarray(p.points[1])
        c = a + u * (b - a)
        z[p.col : p.col + 4] = m, m * c[0], m * c[1], m * float(c @ c)
    return z


def _physical_many(maps, X: np.ndarray) -> np.ndarray:
    """:func:`_physical` of every column of ``X`` (4, S): the designs as rows (S, nz)."""
    Z = np.zeros((X.shape[1], maps.nz))
    for k, p in enumerate(maps.parts):
        m, u = X[2 * k], X[2 * k + 1]
        a, b = np.asarray(p.points[0]), np.asarray(p.points[1])
        c = a[None, :] + u[:, None] * (b - a)[None, :]
        Z[:, p.col : p.col + 4] = np.column_stack([m, m * c[:, 0], m * c[:, 1], m * np.sum(c * c, axis=1)])
    return Z


def term_values(term, Z: np.ndarray) -> np.ndarray:
    """``term.value`` of each design row of ``Z`` at once."""
    return np.max([m.measure(term.kind, Z) for m in term.maps], axis=0)


def de_minimum(term, designs, bounds, budget_row, budget, **options):
    """Differential evolution's minimum of ``term`` over the designs ``designs(X)`` (the columns
    of X, physical parameters) within ``bounds`` and the mass budget (``budget_row`` @ x <=
    ``budget``), seeded and unpolished: the whole population evaluated at once (deferred
    updating), its value checked against ``term.value`` at the minimum."""
    from scipy.optimize import LinearConstraint, differential_evolution

    res = differential_evolution(lambda X: term_values(term, designs(X)), bounds, tol=1e-14, atol=0, polish=False,
                                 updating="deferred", vectorized=True,
                                 constraints=LinearConstraint([budget_row], 0, budget), **options)
    assert res.success, res.message
    assert term.value(designs(res.x[:, None])[0]) == pytest.approx(res.fun, rel=1e-12)
    return res


@pytest.mark.parametrize("objective", [{"load": "shaking_force"}, {"load": "effort", "measure": "rms"}])
def test_cone_optimum_equals_differential_evolution(objective):
    rng = np.random.default_rng(7)
    budget = 0.6
    spec = Spec.model_validate(four_bar(rng, method(SEGMENTS, [objective], budget=budget)))
    maps = setup(spec)
    _, out, terms, *_ = P.solve(maps, spec.balancing)
    best = terms[0].value(out.z)
    x = [0.5, 0.2, 1.0, 0.7]
    assert np.array_equal(_physical_many(maps, np.array(x)[:, None])[0], _physical(maps, x))
    res = de_minimum(terms[0], lambda X: _physical_many(maps, X), [(0, 2), (0, 1), (0, 2), (0, 1)], [1, 0, 1, 0],
                     budget, seed=1, maxiter=3000, popsize=30)
    assert best <= res.fun * (1 + 1e-7)  # DE cannot beat it beyond the solver's tolerance (gaps 1e-8)
    assert abs(res.fun - best) <= 1e-6 * best


def test_no_random_design_dominates_the_front():
    rng = np.random.default_rng(11)
    spec = Spec.model_validate(four_bar(rng, method(SEGMENTS, budget=1.5, fronts={"points": 30, "max_mass": 2.0})))
    res = registry.balance(spec)
    front = res.details["partial_balance"]["fronts"]["force_vs_mass"]
    assert len(front) == 30
    maps = setup(spec)
    X = np.column_stack([rng.uniform(0, 1, 10_000), rng.uniform(0, 1, 10_000), rng.uniform(0, 1, 10_000),
                         rng.uniform(0, 1, 10_000)])
    Z = np.array([_physical(maps, x) for x in X])
    mass = Z[:, 0] + Z[:, 4]
    force = maps.loads["shaking_force"].measure("peak", Z)
    for pt in front:
        ok = mass <= pt["budget"]
        if ok.any():
            assert force[ok].min() >= pt["shaking_force"] * (1 - 1e-6)
    forces = [p["shaking_force"] for p in front]
    assert all(b <= a * (1 + 1e-7) for a, b in zip(forces, forces[1:]))  # more budget, no worse


def test_force_front_reaches_zero_at_or_below_the_complete_design():
    rng = np.random.default_rng(5)
    regions = DISCS
    d = four_bar(rng, {"method": "force_balance", "counterweights": regions})
    complete = registry.balance(Spec.model_validate(d)).details["force_balance"]["total_mass"]
    d["balancing"] = method(regions, budget=complete, fronts={"points": 30})
    res = registry.balance(Spec.model_validate(d))
    fr = res.details["partial_balance"]["fronts"]
    F0 = res.details["partial_balance"]["unbalanced"]["shaking_force"]
    assert fr["complete_force"]["added_mass"] <= complete * (1 + 1e-9)
    reached = [p for p in fr["force_vs_mass"] if p["shaking_force"] <= 1e-9 * F0]
    assert reached and reached[0]["budget"] <= complete * (1 + 1e-9)
    assert res.details["partial_balance"]["peaks"]["shaking_force"] <= 1e-9 * F0  # the budget = complete mass


def test_stage_is_analysed_and_validated_like_any_stage():
    rng = np.random.default_rng(2)
    d = four_bar(rng, method(SEGMENTS, [{"load": "shaking_force"}, {"load": "shaking_moment", "weight": 0.5}],
                             budget=0.8, caps=[{"load": "effort", "at_most": 1.3}]))
    d["validation"] = {"enabled": True}
    st = study.run(Spec.model_validate(d))
    det = st.balance.details["partial_balance"]
    part = st.stages[1]
    assert part.stage.name == "partial" and part.added_mass == pytest.approx(det["added_mass"], rel=1e-9)
    assert part.analysis.max_force == pytest.approx(det["peaks"]["shaking_force"], rel=1e-9)
    assert part.analysis.max_moment == pytest.approx(det["peaks"]["shaking_moment"], rel=1e-9)
    assert part.max_effort <= 1.3 * st.stages[0].max_effort * (1 + 1e-7)
    simulate_study(st)
    assert not st.problems, st.problems


def test_budget_sensitivity_is_the_fronts_slope():
    rng = np.random.default_rng(11)
    spec = Spec.model_validate(four_bar(rng, method(SEGMENTS, budget=0.5)))
    maps = setup(spec)
    program, out, terms, *_ = P.solve(maps, spec.balancing)
    h = 1e-4
    up = program.solve(terms, 0.5 + h).objective
    assert out.budget_dual < 0
    assert out.budget_dual == pytest.approx((up - out.objective) / h, rel=1e-3)


def test_the_tradeoff_fronts_ends_are_the_least_of_each_term_solved_once():
    """ActiveProgram.least_at solves each term's optimum at a budget once (both trade-off fronts
    and forked workers share it); the trade-off front runs from one end to the other."""
    rng = np.random.default_rng(5)
    spec = Spec.model_validate(four_bar(rng, method(SEGMENTS + [POLYGON], budget=0.6)))
    maps = setup(spec)
    program = ActiveProgram(maps)
    terms = P.standard_terms(maps)
    force, moment = terms["shaking_force"], terms["shaking_moment"]
    front = PF.mass_front(program, force, np.linspace(0.0, 1.2, 4), terms)
    assert len(front) == 4
    for term in (force, moment):
        got = program.least_at(term, 0.6)
        assert program.least_at(term, 0.6) is got
        assert got.objective == pytest.approx(ActiveProgram(maps).solve([term], 0.6).objective, rel=1e-9, abs=1e-12)
    pts = PF.tradeoff_front(program, force, moment, 0.6, 3, terms)
    assert pts[0]["cap"] == pytest.approx(moment.value(program.least_at(moment, 0.6).z), rel=1e-12)
    assert pts[-1]["shaking_force"] == pytest.approx(force.value(program.least_at(force, 0.6).z), rel=1e-6)
    assert pts[0]["shaking_force"] >= pts[1]["shaking_force"] >= pts[-1]["shaking_force"] * (1 - 1e-9)


def test_fronts_report_the_pareto_designs_not_any_optimal_one():
    """Where several designs share a front point's optimum, the front reports the one a designer
    would pick: past the complete force balance, the force front's designs are the least
    complete balance (not a heavier one that leaves budget unused); the trade-off front ends at
    the least second term of the designs where the first is least; no point dominates another."""
    rng = np.random.default_rng(12)
    spec = Spec.model_validate(four_bar(rng, method(DISCS, budget=0.6)))  # discs: the force can be balanced
    maps = setup(spec)
    program = ActiveProgram(maps)
    terms = P.standard_terms(maps)
    force, effort = terms["shaking_force"], terms["effort"]
    complete = PF.least_complete_mass(program, [force])
    assert complete is not None
    masses = np.array([0.5, 1.0, 1.5, 2.0]) * complete[0]
    front = PF.mass_front(program, force, masses, terms)
    for p in front[2:]:  # budgets past the complete balance
        assert p["shaking_force"] <= 1e-7 * force.scale
        assert p["added_mass"] == pytest.approx(complete[0], rel=1e-6)
    assert front[0]["added_mass"] == pytest.approx(masses[0], rel=1e-6)  # short of it, the budget is used
    pts = PF.tradeoff_front(program, effort, force, 0.6, 6, terms)
    least_effort = program.least_at(effort, 0.6)
    assert pts[-1]["cap"] <= force.value(least_effort.z) * (1 + 1e-7)
    assert pts[-1]["effort"] == pytest.approx(effort.value(least_effort.z), rel=1e-6)
    for p, q in zip(pts, pts[1:]):
        assert q["cap"] >= p["cap"] and q["effort"] <= p["effort"] * (1 + 1e-7)
        assert not (q["effort"] < p["effort"] * (1 - 1e-7) and q["shaking_force"] < p["shaking_force"] * (1 - 1e-7) - 1e-9)


def test_an_optimum_below_the_budget_is_its_lightest_design():
    """A budget larger than the complete force balance needs: the optimum (zero force) is the
    least-mass complete balance, not a heavier design that spends the budget."""
    rng = np.random.default_rng(12)
    spec = Spec.model_validate(four_bar(rng, method(DISCS, budget=5.0)))
    maps = setup(spec)
    program, out, terms, _ = P.solve(maps, spec.balancing)
    complete = PF.least_complete_mass(ActiveProgram(maps), [terms[0]])
    assert terms[0].value(out.z) <= 1e-7 * terms[0].scale
    assert maps.added_mass(out.z) == pytest.approx(complete[0], rel=1e-6)
    assert maps.added_mass(out.z) < 0.5 * 5.0


def test_scaling_masses_scales_the_optimal_loads():
    """Masses x k (bodies and budget): the optimal design x k, its loads x k."""
    rng = np.random.default_rng(9)
    d = four_bar(rng, method(SEGMENTS, budget=0.5))
    for k in (1.0, 3.0):
        e = {**d, "mechanism": {**d["mechanism"], "bodies": [
            {**b, "mass": b["mass"] * k, "inertia": b["inertia"] * k} for b in d["mechanism"]["bodies"]]},
             "balancing": method([{**s, "max_mass": s["max_mass"] * k} for s in SEGMENTS], budget=0.5 * k)}
        det = registry.balance(Spec.model_validate(e)).details["partial_balance"]
        if k == 1.0:
            base = det
    assert det["peaks"]["shaking_force"] == pytest.approx(3 * base["peaks"]["shaking_force"], rel=1e-6)
    assert det["objective"] == pytest.approx(base["objective"], rel=1e-6)


def _bad(tmp_path, capsys, d: dict, needle: str) -> str:
    import yaml

    from balpipe.cli import main

    p = tmp_path / "bad.yaml"
    p.write_text(yaml.safe_dump(d, sort_keys=False))
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert needle in err and "Traceback" not in err
    return err


def test_budget_too_small_for_a_cap_is_located(tmp_path, capsys):
    rng = np.random.default_rng(2)
    d = four_bar(rng, method(SEGMENTS, budget=0.01, caps=[{"load": "shaking_force", "at_most": 0.7}]))
    err = _bad(tmp_path, capsys, d, "balancing.budget.mass: a budget of 0.01 kg is too small for the caps")
    assert f"{tmp_path / 'bad.yaml'}:" in err and "they need at least" in err


def test_region_outside_the_link_is_located(tmp_path, capsys):
    rng = np.random.default_rng(2)
    far = {"body": "crank", "name": "cw", "disc": {"centre": [-2.0, 0], "radius": 0.1}}
    _bad(tmp_path, capsys, four_bar(rng, method([far])), "balancing.counterweights[0].disc: the region reaches")


def test_part_on_a_body_that_does_not_move_is_located(tmp_path, capsys):
    rng = np.random.default_rng(2)
    d = four_bar(rng, method([{"body": "idle", "name": "cw", "at": [0.05, 0]}]))
    mech = d["mechanism"]
    mech["bodies"].append({"name": "idle", "mass": 0.3, "com": [0.05, 0], "inertia": 1e-4, "pose": [0, 0, 0],
                           "points": {"O2": [0, 0]}})
    mech["joints"].append({"type": "revolute", "name": "idle_pin", "a": "frame", "b": "idle", "point_a": "O2", "point_b": "O2"})
    mech["drivers"].append({"name": "idle", "joint": "idle_pin"})
    d["motion"]["drive"]["idle"] = {"from": 0.0, "to": 0.0}
    _bad(tmp_path, capsys, d, "balancing.counterweights[0].body: 'idle' neither accelerates nor turns")


def test_non_convex_polygon_and_unknown_joint_are_located():
    rng = np.random.default_rng(2)
    bad = {"body": "coupler", "name": "p", "polygon": [[0, 0], [0.2, 0], [0.05, 0.02], [0, 0.1]]}
    with pytest.raises(SpecFieldError) as err:
        registry.balance(Spec.model_validate(four_bar(rng, method([bad]))))
    assert err.value.path == ("balancing", "counterweights", 0, "polygon")
    with pytest.raises(SpecFieldError) as err:
        registry.balance(Spec.model_validate(four_bar(rng, method(SEGMENTS, [{"load": "joint", "joint": "Z"}]))))
    assert err.value.path == ("balancing", "objective", 0, "joint")


def test_a_partial_balancing_loads_no_cvxpy_and_the_spec_no_solver():
    """The cone programmes go to Clarabel directly (cvxpy is the tests' reference only); the spec
    module loads no solver at all."""
    code = ("import sys, balpipe.spec, balpipe.registry; print('clarabel' in sys.modules);"
            "from balpipe.loader import load; balpipe.registry.balance(load(sys.argv[1]).spec);"
            "print('clarabel' in sys.modules, 'cvxpy' in sys.modules)")
    out = subprocess.run([sys.executable, "-c", code, str(ROOT / "specs" / "partial_offset_slider_crank.yaml")],
                         capture_output=True, text=True, check=True)
    assert out.stdout.split() == ["False", "True", "False"]


def test_documented_example_runs():
    import re

    import yaml

    text = (ROOT / "docs" / "partial-balancing.md").read_text()
    block = re.search(r"```yaml\n(.*?)```", text, re.S).group(1)
    spec = Spec.model_validate(yaml.safe_load(block))
    det = registry.balance(spec).details["partial_balance"]
    assert det["terms"][0]["ratio"] < 1 and len(det["fronts"]["force_vs_mass"]) == spec.balancing.fronts.points


def test_page_draws_the_fronts_and_results_hold_them():
    import json

    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict

    rng = np.random.default_rng(5)
    d = four_bar(rng, method(DISCS, budget=0.8, fronts={"points": 30}))
    d["compare"] = [{"name": "complete", "label": "complete force balance",
                     "balancing": {"method": "force_balance", "counterweights": DISCS}}]
    st = study.run(Spec.model_validate(d))
    res = results_dict(st, "x.yaml", "h", simulated=False)
    fronts = json.loads(json.dumps(res))["balancing_details"]["partial_balance"]["fronts"]
    for key in ("force_vs_mass", "moment_vs_mass", "force_vs_moment", "effort_vs_force"):
        assert len(fronts[key]) >= 30, key
    html = render_page(st, res, "text")
    for title in ("Shaking force against added mass", "Shaking moment against added mass",
                  "Shaking force against shaking moment", "Actuator effort against shaking force"):
        assert title in html
    assert "complete force balance" in html and "The chosen design removes" in html


def test_no_design_of_a_real_sweep_dominates_the_front(tmp_path):
    """The same check through ``balpipe sweep``: 10^4 random designs of hand-placed parts within the
    same bounds (issue 21), none of which beats the front beyond 1e-6 (``--long``; by default a
    seeded sample of 10^3 of them)."""
    import yaml

    from balpipe import sweep

    designs = sample(1_000, 10_000)
    rng = np.random.default_rng(11)
    d = four_bar(rng, method(SEGMENTS, budget=1.5, fronts={"points": 30, "max_mass": 4.0}))
    front = registry.balance(Spec.model_validate(d)).details["partial_balance"]["fronts"]["force_vs_mass"]
    d["balancing"] = {"method": "stages", "stages": [{"name": "cw", "parts": [
        {"body": s["body"], "name": s["name"], "mass": 1.0, "position": s["segment"][1]} for s in SEGMENTS]}]}
    d["sweep"] = {"vary": {"balancing.stages.0.parts.0.mass": "0:2", "balancing.stages.0.parts.0.position.0": "-0.08:0",
                           "balancing.stages.0.parts.1.mass": "0:2", "balancing.stages.0.parts.1.position.0": "-0.12:0"},
                  "sample": "random", "designs": designs, "seed": 3}
    path = tmp_path / "sweep.yaml"
    path.write_text(yaml.safe_dump(d, sort_keys=False))
    rows = [r for r in sweep.run(sweep.plan(str(path)), jobs=1).rows if "error" not in r]
    assert len(rows) == designs
    mass = np.array([r["added_mass"] for r in rows])
    force = np.array([r["max_shaking_force"] for r in rows])
    for pt in front:
        ok = mass <= pt["budget"]
        if ok.any():
            assert force[ok].min() >= pt["shaking_force"] * (1 - 1e-6)


def test_cone_optimum_with_a_disc_and_spread_mass_equals_differential_evolution():
    """Peak shaking moment, where the counterweights' inertias matter: a crank counterweight on a
    segment (a point mass, J = m |c|^2 at the optimum or spread between the ends) and a coupler
    counterweight anywhere in a disc with any realisable spread: centroidal inertia f m (r^2 -
    |c - c0|^2), f in [0, 1] (a ring through c's chord at f = 1)."""
    rng = np.random.default_rng(8)
    budget = 0.5
    disc = {"body": "coupler", "name": "cw_coupler", "disc": {"centre": [0.1, 0.0], "radius": 0.08}}
    spec = Spec.model_validate(four_bar(rng, method([SEGMENTS[0], disc], [{"load": "shaking_moment"}], budget=budget)))
    maps = setup(spec)
    _, out, terms, *_ = P.solve(maps, spec.balancing)
    best = terms[0].value(out.z)
    seg, dsc = maps.parts
    c0, r = np.asarray(dsc.points[0]), dsc.radius

    def z_of(X):  # the designs of the columns of X (7, S), as rows
        a, b = np.asarray(seg.points[0]), np.asarray(seg.points[1])
        L = float(np.linalg.norm(b - a))
        m, u, f = X[0], X[1], X[2]
        c = a[None, :] + u[:, None] * (b - a)[None, :]
        spread = f * m * u * (1 - u) * L * L  # spread between the ends
        one = np.column_stack([m, m * c[:, 0], m * c[:, 1], m * np.sum(c * c, axis=1) + spread])
        m2, rho, phi, f2 = X[3], X[4], X[5], X[6]
        c = c0[None, :] + (rho * r)[:, None] * np.column_stack([np.cos(phi), np.sin(phi)])
        inertia = m2 * np.sum(c * c, axis=1) + f2 * m2 * r * r * (1 - rho * rho)
        Z = np.zeros((X.shape[1], maps.nz))
        Z[:, 0:4] = one
        Z[:, 4:8] = np.column_stack([m2, m2 * c[:, 0], m2 * c[:, 1], inertia])
        return Z

    bounds = [(0, 2), (0, 1), (0, 1), (0, 2), (0, 1), (-math.pi, math.pi), (0, 1)]
    res = de_minimum(terms[0], z_of, bounds, [1, 0, 0, 1, 0, 0, 0], budget, seed=2, maxiter=4000, popsize=40)
    assert best <= res.fun * (1 + 1e-7)  # DE cannot beat it beyond the solver's tolerance (gaps 1e-8)
    assert abs(res.fun - best) <= 1e-6 * best


def test_joint_load_objective_and_inertia_budget_reach_the_analysed_stage():
    """Minimise the peak load of the crank's bearing with a polygon counterweight on the coupler
    and a counter-rotating disc under an inertia budget: the engine's analysis of the stage gives
    the predicted peak, the budget is reported active and not exceeded."""
    rng = np.random.default_rng(4)
    cr = [{"name": "disc_crank", "carrier": "frame", "at": [0, 0], "geared_to": "crank", "ratio": -1}]
    d = four_bar(rng, method([SEGMENTS[0], POLYGON], [{"load": "joint", "joint": "O2"},
                                                      {"load": "shaking_moment", "measure": "rms"}],
                             budget=0.6, counter_rotations=cr))
    d["balancing"]["budget"]["inertia"] = 2e-4
    st = study.run(Spec.model_validate(d))
    det = st.balance.details["partial_balance"]
    load = det["terms"][0]
    assert load["ratio"] < 1
    an = st.stages[1].analysis
    assert np.hypot(an.reactions["O2"]["Fx"], an.reactions["O2"]["Fy"]).max() == pytest.approx(load["value"], rel=1e-9)
    assert any(a.startswith("inertia budget") for a in det["active"])
    model = st.stages[1].stage.model
    second = model.body("disc_crank").inertia + sum(
        a.mass * (a.position[0] ** 2 + a.position[1] ** 2) + a.inertia for b in model.bodies for a in b.attachments)
    assert second <= 2e-4 * (1 + 1e-6)


def test_a_part_at_the_solvers_round_off_is_no_part():
    """Clarabel stops at its tolerance, so a counterweight it leaves at 2e-8 kg beside one of
    0.6 kg is round-off, not a part: the design has no such part, neither in the stage's model
    nor in the design table (and a part of 1e-4 of the heaviest stays)."""
    rng = np.random.default_rng(5)
    spec = Spec.model_validate(four_bar(rng, method(SEGMENTS)))
    maps = setup(spec)
    a, b = maps.parts[:2]
    z = np.zeros(maps.nz)
    for m, p in ((0.6, a), (2e-8, b)):  # each a point mass at its region's far end
        c = np.asarray(p.points[-1], dtype=float)
        z[p.col : p.col + 4] = (m, m * c[0], m * c[1], m * float(c @ c))
    r = maps.realised(z)
    assert r[a.col] == 0.6 and not r[b.col : b.col + 4].any()
    built = {att.name for body in maps.design(z).bodies for att in body.attachments}
    assert a.name in built and b.name not in built
    assert [row["mass"] for row in P.design_table(maps, z)[:2]] == [0.6, 0.0]
    z[b.col : b.col + 4] *= 1e-4 / 2e-8 * 0.6
    assert b.name in {att.name for body in maps.design(z).bodies for att in body.attachments}


def test_a_fronts_caption_says_where_more_budget_would_not_help():
    """Past the least-mass complete force balance, the force front's points are that design; the
    caption says how many budgets that concerns (the moment front, using its whole budget, not)."""
    from balpipe.loader import load
    from balpipe.report import partial_figures as PFG

    st = study.run(load(ROOT / "specs" / "custom_four_bar_partial.yaml").spec)
    det = st.balance.details["partial_balance"]
    spare = [p for p in det["fronts"]["force_vs_mass"] if p["added_mass"] < p["budget"] * (1 - 1e-6)]
    complete = det["fronts"]["complete_force"]["added_mass"]
    assert spare and all(p["added_mass"] == pytest.approx(complete, rel=1e-6) for p in spare)
    captions = {title: caption for title, _, caption in PFG.figures(st)}
    assert f"At {len(spare)} of the budgets more mass would not lower it" in captions["Shaking force against added mass"]
    assert "more mass would not lower it" not in captions["Shaking moment against added mass"]
