"""Generic balancing on any model (issue 8): momentum regressors, force-balance conditions,
least-mass counterweights, counter-rotations, hand-written stages, compared designs."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry, study
from balpipe.balancing import conditions as C
from balpipe.balancing import least_mass as LM
from balpipe.balancing import regressor as R
from balpipe.families.slider_crank.counterweights import _counterweight_masses
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.report.results import results_dict
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError
from balpipe.validation_stage import simulate_study
from conftest import slider_crank_spec
from generic_specs import FIVE_BAR_DISCS, FIVE_BAR_REGIONS, FOUR_BAR_DISCS, FOUR_BAR_REGIONS, five_bar, four_bar
from _edits import replaced

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _ratios(st):
    F0, M0 = st.stages[0].analysis.max_force, st.stages[0].analysis.max_moment
    return {s.stage.name: (s.analysis.max_force / F0, s.analysis.max_moment / M0) for s in st.stages}


@pytest.mark.parametrize("seed", [1, 2, 3])
def test_regressors_reproduce_the_engine_momenta(seed):
    spec = slider_crank_spec(np.random.default_rng(seed), moment_unknown=None)
    model = registry.unbalanced_model(spec)
    an = analyse(model, registry.time_grid(spec))
    states = R.states_from_analysis(model, an)
    P = (R.linear_regressor(states) @ R.parameters(model)).reshape(-1, 2)
    H = R.angular_regressor(states) @ R.parameters(model, angular=True)
    assert np.max(np.abs(P - an.momentum)) <= 1e-12 * np.max(np.abs(an.momentum))
    assert np.max(np.abs(H - an.angular_momentum)) <= 1e-12 * np.max(np.abs(an.angular_momentum))


def test_sampled_states_are_feasible_and_span_the_mobility():
    spec = Spec.model_validate(five_bar(np.random.default_rng(4)))
    model = registry.unbalanced_model(spec)
    st = R.sample_states(model, registry.time_grid(spec))
    assert st.dof == 2 and st.count >= 2 * 4 * len(model.bodies)
    # every sampled velocity keeps the joints closed: rate of the loop closure at C is zero
    k3, k4 = st.names.index("link3"), st.names.index("link4")
    L3 = model.body("link3").point("C")[0]
    L4 = model.body("link4").point("C")[0]
    def tip_rate(k, L):
        th, w = st.pose[:, k, 2], st.rate[:, k, 2]
        return st.rate[:, k, :2] + L * w[:, None] * np.stack([-np.sin(th), np.cos(th)], 1)
    assert np.max(np.abs(tip_rate(k3, L3) - tip_rate(k4, L4))) < 1e-9 * np.max(np.abs(st.rate))


@pytest.mark.parametrize("seed", [5, 6, 7])
def test_slider_crank_eq15_lies_in_the_computed_space_and_least_mass_is_no_heavier(seed):
    spec = slider_crank_spec(np.random.default_rng(seed))
    mech = spec.mechanism
    model = registry.unbalanced_model(spec)
    cond = C.find(model, registry.time_grid(spec))
    assert cond.count == 4 and cond.gap > 1e6
    c1, c2 = spec.balancing.crank_counterweight, spec.balancing.coupler_counterweight
    mcp1, mcp2 = _counterweight_masses(mech, c1, c2)
    balanced = registry.balance(spec).stages[1].model
    assert cond.contains(R.parameters(balanced), C.scale_of(model)) <= 1e-9
    assert cond.contains(R.parameters(model), C.scale_of(model)) > 1e-3  # the bare one is not
    same = LM.solve(model, cond, [LM.Region("c1", "crank", "point", ((c1, 0.0),)),
                                  LM.Region("c2", "coupler", "point", ((c2, 0.0),))])
    assert same.total_mass == pytest.approx(mcp1 + mcp2, rel=1e-9)
    wider = LM.solve(model, cond, [LM.Region("c1", "crank", "segment", ((0.0, 0.0), (c1, 0.0))),
                                   LM.Region("c2", "coupler", "disc", ((c2 / 2, 0.0),), abs(c2) / 2)])
    assert wider.total_mass <= mcp1 + mcp2 + 1e-9


def test_paper004_closed_form_lies_in_the_computed_space_and_least_mass_is_no_heavier():
    spec = load(SPECS / "paper004_five_bar.yaml").spec
    res = registry.balance(spec)
    model = res.stages[0].model
    t = registry.time_grid(spec)
    cond = C.find(model, t)
    cw = res.stages[1].model
    assert cond.contains(R.parameters(cw), C.scale_of(model)) <= 1e-9
    assert cond.contains(R.parameters(model), C.scale_of(model)) > 1e-3
    regions = []
    for b in ("link1", "link2", "link3", "link4"):
        for a in cw.body(b).attachments:
            if a.kind == "counterweight":
                regions.append(LM.Region(a.name, b, "point", (a.position,)))
    paper_mass = cw.total_mass() - model.total_mass()
    sol = LM.solve(model, cond, regions)
    assert sol.total_mass <= paper_mass * (1 + 1e-9)


@pytest.mark.parametrize("make,regions,seed", [(four_bar, FOUR_BAR_REGIONS, s) for s in (11, 12, 13)]
                         + [(five_bar, FIVE_BAR_REGIONS, s) for s in (21, 22, 23)])
def test_random_linkages_force_balanced(make, regions, seed):
    spec = Spec.model_validate(make(np.random.default_rng(seed), {"method": "force_balance", "counterweights": regions}))
    st = study.run(spec)
    assert st.ok, st.problems
    assert _ratios(st)["counterweights"][0] <= 1e-9
    # the centre of mass stays put and the linear momentum vanishes for the whole motion
    an = st.stages[1].analysis
    assert np.max(np.linalg.norm(an.com - an.com[0], axis=1)) <= 1e-9
    assert np.max(np.abs(an.momentum)) <= 1e-9 * np.max(np.abs(st.stages[0].analysis.momentum))


@pytest.mark.parametrize("make,regions,discs,seed", [(four_bar, FOUR_BAR_REGIONS, FOUR_BAR_DISCS, s) for s in (11, 14)]
                         + [(five_bar, FIVE_BAR_REGIONS, FIVE_BAR_DISCS, s) for s in (21, 24)])
def test_random_linkages_moment_balanced(make, regions, discs, seed):
    method = {"method": "moment_balance", "counterweights": regions, "counter_rotations": discs}
    st = study.run(Spec.model_validate(make(np.random.default_rng(seed), method)))
    assert st.ok, st.problems
    f, m = _ratios(st)["counter_rotations"]
    assert f <= 1e-9 and m <= 1e-9
    an = st.stages[2].analysis
    assert np.ptp(an.angular_momentum) <= 1e-9 * np.ptp(st.stages[0].analysis.angular_momentum)


@pytest.mark.parametrize("make,regions,discs,seed", [(four_bar, FOUR_BAR_REGIONS, FOUR_BAR_DISCS, 31),
                                                     (five_bar, FIVE_BAR_REGIONS, FIVE_BAR_DISCS, 32)])
def test_balanced_random_linkages_validated_in_pymunk(make, regions, discs, seed):
    method = {"method": "moment_balance", "counterweights": regions, "counter_rotations": discs}
    data = make(np.random.default_rng(seed), method)
    data["analysis"]["samples"] = 101
    st = study.run(Spec.model_validate(data))
    simulate_study(st)
    for s in st.stages:
        assert s.validation.passed, (s.stage.name, s.validation.reasons)
    assert st.stages[2].validation.expect == ("force", "moment")


def test_force_balance_scales_with_the_masses():
    base = four_bar(np.random.default_rng(41), {"method": "force_balance", "counterweights": FOUR_BAR_REGIONS})
    heavy = json.loads(json.dumps(base))
    for b in heavy["mechanism"]["bodies"]:
        b["mass"] *= 3.0
        b["inertia"] *= 3.0
    r1, r3 = (registry.balance(Spec.model_validate(d)) for d in (base, heavy))
    m1 = {p.name: p.value for p in r1.parameters}
    m3 = {p.name: p.value for p in r3.parameters}
    assert m3["counterweight_mass"] == pytest.approx(3 * m1["counterweight_mass"], rel=1e-9)
    assert m3["cw_rocker.x"] == pytest.approx(m1["cw_rocker.x"], rel=1e-9, abs=1e-12)


def test_infeasible_region_names_the_condition():
    spec = Spec.model_validate(four_bar(np.random.default_rng(42), {
        "method": "force_balance", "counterweights": [FOUR_BAR_REGIONS[0]]}))
    with pytest.raises(SpecFieldError) as err:
        registry.balance(spec)
    assert err.value.path == ("balancing", "counterweights")
    assert "mx[" in err.value.message and "= 0 (left at" in err.value.message


def test_infeasible_spec_is_a_located_error(tmp_path, capsys):
    from balpipe.cli import main

    text = (SPECS / "custom_four_bar_balancing.yaml").read_text()
    # the coupler's counterweight a point mass, in the main design and in the compared one
    text = replaced(text, "disc: {centre: [0.14, 0], radius: 0.25}", "at: [0.1, 0]", count=2)
    bad = tmp_path / "bad.yaml"
    bad.write_text(text)
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    # the spec's signs need a negative inertia; the error names the signs that work, every disc at once
    assert (f"{bad}:41:5: balancing.counter_rotations: disc 'disc_crank' would need a negative inertia" in err
            and "the ratios disc_crank: -1, disc_coupler: +1, disc_rocker: -1 cancel the moment: set them" in err)


def test_conditions_read_cleanly():
    spec = slider_crank_spec(np.random.default_rng(8))
    model = registry.unbalanced_model(spec)
    eqs = C.find(model, registry.time_grid(spec)).equations()
    L1 = spec.mechanism.crank.length
    assert eqs[0] == f"mx[crank] + {L1:.6g} m[coupler] + {L1:.6g} m[slider] = 0"
    assert "my[crank] = 0" in eqs


def test_custom_attachments_stages_and_per_drive_laws():
    data = five_bar(np.random.default_rng(51))
    data["mechanism"]["bodies"][0]["attachments"] = [{"name": "cw", "mass": 0.5, "position": [-0.05, 0]}]
    data["balancing"] = {"method": "stages", "stages": [
        {"name": "heavier", "parts": [{"body": "link1", "name": "cw", "mass": 1.0, "position": [-0.05, 0]}]},
        {"name": "geared", "counter_rotations": [{"name": "d", "at": "A1", "geared_to": "link1", "ratio": -1,
                                                  "inertia": 0.01}], "remove": ["link1.cw"]},
    ]}
    spec = Spec.model_validate(data)
    res = registry.balance(spec)
    m0, m1, m2 = (s.model for s in res.stages)
    assert m0.body("link1").mass_properties()[0] == pytest.approx(data["mechanism"]["bodies"][0]["mass"] + 0.5)
    assert m1.body("link1").mass_properties()[0] - m0.body("link1").mass_properties()[0] == pytest.approx(0.5)
    assert not m2.body("link1").attachments and m2.body("d").inertia == 0.01
    laws = {d.name: d.law for d in m0.drivers}
    tau = np.array([0.1])
    assert laws["q1"].profile.__name__ == "quintic" and laws["q2"].profile.__name__ == "cycloidal"
    assert laws["q2"](tau)[0] != laws["q1"](tau)[0]


def test_compare_block_puts_designs_side_by_side():
    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    st = study.run(spec)
    assert st.ok, st.problems
    out = results_dict(st, "x.yaml", "h", simulated=False)
    rows = out["comparison"]["rows"]
    assert [r["stage"] for r in rows] == ["unbalanced", "counterweights", "counter_rotations",
                                          "force_only:counterweights", "crank_only:crank_cw"]
    assert rows[4]["design"] == "crank_only" and rows[4]["added_mass"] == pytest.approx(1.0)
    assert 0.05 < rows[4]["force_ratio"] < 1  # a partial balance: reduced, not cancelled
    main, other = rows[2], rows[3]
    assert main["added_inertia"] > 0 and other["added_inertia"] == 0
    assert main["max_shaking_moment"] <= 1e-9 * rows[0]["max_shaking_moment"]
    assert other["max_shaking_force"] <= 1e-9 * rows[0]["max_shaking_force"]
    fb = out["balancing_details"]["compare"]["force_only"]["force_balance"]
    assert fb["count"] == 4 and len(fb["conditions"]) == 4


def test_old_single_law_form_still_valid():
    spec = slider_crank_spec(np.random.default_rng(9), law="cycloidal")
    law = registry.unbalanced_model(spec).drivers[0].law
    assert law.profile.__name__ == "cycloidal"
    assert math.isfinite(law(np.array([0.1]))[0][0])


def test_conditions_do_not_depend_on_the_law_or_the_duration():
    base = four_bar(np.random.default_rng(61))
    other = json.loads(json.dumps(base))
    other["motion"]["law"] = "cycloidal"
    other["motion"]["duration"] = 0.2
    conds = []
    for d in (base, other):
        spec = Spec.model_validate(d)
        conds.append(C.find(registry.unbalanced_model(spec), registry.time_grid(spec)))
    assert conds[0].count == conds[1].count == 4
    assert np.allclose(conds[0].matrix, conds[1].matrix, atol=1e-9)


def test_redundant_driver_is_set_aside_by_the_sampler():
    """A model with more drivers than degrees of freedom (consistent laws): the finder samples
    with a square subset and finds the same conditions (the 4-RRR's four motors, issue 8)."""
    from dataclasses import replace as dc_replace

    from balpipe.model import Driver

    spec = Spec.model_validate(five_bar(np.random.default_rng(62)))
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    q1 = model.drivers[0]
    extra = Driver("q1_again", ("angle", "link1"), q1.law)  # link1's absolute angle = joint A1's
    redundant = dc_replace(model, drivers=model.drivers + (extra,))
    a, b = C.find(model, t), C.find(redundant, t)
    assert a.count == b.count == 6
    assert np.allclose(a.matrix, b.matrix, atol=1e-9)


def test_unknown_body_in_a_region_is_located():
    spec = Spec.model_validate(four_bar(np.random.default_rng(63), {
        "method": "force_balance", "counterweights": [{"body": "crnk", "at": [0, 0]}]}))
    with pytest.raises(SpecFieldError) as err:
        registry.balance(spec)
    assert err.value.path == ("balancing", "counterweights", 0, "body")
    assert "crnk" in err.value.message and "crank" in err.value.message


def test_moment_balance_without_counterweights_needs_a_force_balanced_mechanism():
    spec = Spec.model_validate(four_bar(np.random.default_rng(64), {
        "method": "moment_balance", "counter_rotations": FOUR_BAR_DISCS}))
    with pytest.raises(SpecFieldError) as err:
        registry.balance(spec)
    assert "not force balanced" in err.value.message and "= 0 is off by" in err.value.message


def test_moment_balance_of_an_already_force_balanced_custom_mechanism():
    """Counterweights written into the custom spec (attachments from a force_balance run), then
    moment_balance with no counterweights of its own: only the discs are solved."""
    data = four_bar(np.random.default_rng(65), {"method": "force_balance", "counterweights": FOUR_BAR_REGIONS})
    bare_spec = Spec.model_validate(data)
    fb = registry.balance(bare_spec).stages[1].model
    t = registry.time_grid(bare_spec)
    F0 = analyse(registry.unbalanced_model(bare_spec), t).max_force
    for b in data["mechanism"]["bodies"]:
        b["attachments"] = [{"name": a.name, "mass": a.mass, "position": list(a.position)}
                            for a in fb.body(b["name"]).attachments]
    data["balancing"] = {"method": "moment_balance",
                         "counter_rotations": [FOUR_BAR_DISCS[0], FOUR_BAR_DISCS[2]]}
    res = registry.balance(Spec.model_validate(data))
    # two frame discs cannot cancel the coupler's term: least squares, the stage claims the force only
    params = {p.name: p.value for p in res.parameters}
    assert params["moment_residual"] > 1e-6 and res.stages[2].balances == "force"
    assert any("unmet angular-momentum condition" in n for n in res.notes)
    an = [analyse(s.model, t) for s in res.stages]
    assert max(a.max_force for a in an) <= 1e-9 * F0  # as given, already force balanced
    assert an[2].max_moment < an[1].max_moment
    assert params["counterweight_mass"] == 0.0


def test_disc_needing_negative_inertia_is_an_error_on_its_ratio():
    data = four_bar(np.random.default_rng(66), {
        "method": "moment_balance", "counterweights": FOUR_BAR_REGIONS,
        "counter_rotations": [dict(FOUR_BAR_DISCS[0], ratio=1.0), FOUR_BAR_DISCS[1], FOUR_BAR_DISCS[2]]})
    with pytest.raises(SpecFieldError) as err:
        registry.balance(Spec.model_validate(data))
    assert err.value.path[:2] == ("balancing", "counter_rotations")


def test_error_in_a_compared_design_is_located(tmp_path, capsys):
    from balpipe.cli import main

    text = (SPECS / "custom_four_bar_balancing.yaml").read_text()
    head, _, tail = text.rpartition("{body: rocker, name: cw_rocker")
    bad = tmp_path / "bad.yaml"
    bad.write_text(head + "{body: rokker, name: cw_rocker" + tail)
    assert main(["check", str(bad)]) == 2
    err = capsys.readouterr().err
    line = 1 + (head + "{").count("\n")
    assert f"bad.yaml:{line}:" in err
    assert "compare[0].balancing.counterweights[2].body: design 'force_only': unknown body 'rokker'" in err


def test_page_shows_conditions_and_designs_side_by_side():
    from balpipe.report.page import render_page

    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    st = study.run(spec)
    html = render_page(st, results_dict(st, "x.yaml", "h", simulated=False), "text")
    assert "Designs side by side" in html and "crank counterweight only" in html
    assert "Force-balance conditions" in html and "Moment balance by counter-rotations" in html
    assert "<code>mx[crank] + 0.08 m[coupler]" in html  # the crank's condition, L1 = 0.08 m
    assert "Design force_only</strong>: 4 force-balance conditions" in html


def test_per_drive_trapezoidal_fraction():
    data = five_bar(np.random.default_rng(71))
    data["motion"]["drive"]["q1"].update({"law": "trapezoidal", "accel_fraction": 0.25})
    data["motion"]["accel_fraction"] = 0.5
    laws = {d.name: d.law for d in registry.unbalanced_model(Spec.model_validate(data)).drivers}
    T = data["motion"]["duration"]
    _, v, a = laws["q1"](np.array([0.1 * T, 0.5 * T]))
    assert a[1] == 0.0 and a[0] > 0  # cruising at mid-motion: the drive's fraction 0.25, not 0.5


@pytest.mark.parametrize("step,message", [
    ({"name": "a", "remove": ["link1.nothing"]}, "carries no part 'nothing'"),
    ({"name": "a", "parts": [{"body": "link9", "name": "p", "mass": 1.0}]}, "unknown body 'link9'"),
    ({"name": "a", "parts": [{"body": "link1", "name": "p", "mass": 1.0, "position": "Z"}]}, "no point 'Z'"),
])
def test_stage_errors_are_located(step, message):
    data = five_bar(np.random.default_rng(72), {"method": "stages", "stages": [step]})
    with pytest.raises(SpecFieldError) as err:
        registry.balance(Spec.model_validate(data))
    assert message in err.value.message and err.value.path[:3] == ("balancing", "stages", 0)


def test_custom_attachment_errors_are_located():
    data = five_bar(np.random.default_rng(73))
    data["mechanism"]["bodies"][1]["attachments"] = [{"name": "g", "mass": 0.2, "position": "Q", "kind": "gear"}]
    with pytest.raises(SpecFieldError) as err:
        registry.unbalanced_model(Spec.model_validate(data))
    assert err.value.path == ("mechanism", "bodies", 1, "attachments", 0, "position")
    data["mechanism"]["bodies"][1]["attachments"] = [{"name": "g", "mass": 0.2, "position": "B2", "kind": "gear",
                                                      "inertia": 0.001, "radius": 0.03}]
    body = registry.unbalanced_model(Spec.model_validate(data)).body("link2")
    assert body.attachments[0].kind == "gear" and body.attachments[0].position == tuple(body.points["B2"])


def test_generic_results_are_deterministic():
    from balpipe.report.results import dumps, timeseries_csv

    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    a, b = study.run(spec), study.run(spec)
    assert dumps(results_dict(a, "x", "h", False)) == dumps(results_dict(b, "x", "h", False))
    assert timeseries_csv(a) == timeseries_csv(b)


def test_generic_methods_apply_to_templates_offset_slider_crank_fully_balanced():
    """moment_balance on the slider_crank template: the offset slider-crank, whose moment eq. 15's
    counterweights cannot cancel (paper 000, Sec. 3.1), is balanced with two counter-rotations."""
    spec = slider_crank_spec(np.random.default_rng(5))
    data = spec.model_dump(by_alias=True)
    L1, L2 = spec.mechanism.crank.length, spec.mechanism.coupler.length
    data["balancing"] = {
        "method": "moment_balance",
        "counterweights": [{"body": "crank", "disc": {"centre": [-L1 / 2, 0], "radius": L1 / 2}},
                           {"body": "coupler", "disc": {"centre": [0, 0], "radius": L2}}],
        "counter_rotations": [{"name": "d1", "at": [0, 0], "geared_to": "crank", "ratio": -1},
                              {"name": "d2", "carrier": "crank", "at": "A", "geared_to": "coupler", "ratio": -1}]}
    st = study.run(Spec.model_validate(data))
    assert st.ok, st.problems
    f, m = _ratios(st)["counter_rotations"]
    assert f <= 1e-9 and m <= 1e-9
    assert _ratios(st)["counterweights"][1] > 0.1  # force balance alone leaves the moment


def test_the_unbalanced_model_is_built_once_for_every_design(monkeypatch):
    """study.run builds the spec's unbalanced model once and every design's balance starts from
    it (the designs share the spec's mechanism): the unbalanced stage is that model, and the
    stages are those of a balance that builds its own."""
    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    assert spec.compare
    own = registry.balance_designs(spec, page=False)
    built = []
    real = registry.unbalanced_model
    monkeypatch.setattr(registry, "unbalanced_model", lambda s: built.append(s) or real(s))
    st = study.run(spec, page=False)
    assert len(built) == 1
    assert [s.stage.name for s in st.stages] == [s.name for s in own.stages]
    assert all(s.stage.model == o.model for s, o in zip(st.stages, own.stages))
    given = real(spec)
    assert registry.balance_designs(spec, page=False, model=given).stages[0].model is given
