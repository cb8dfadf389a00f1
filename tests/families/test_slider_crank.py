"""Physics invariants of the slider-crank balancing (paper 000, Sec. 3.1), random parameters."""

import math


import numpy as np
import pytest

from balpipe import registry, study
from balpipe.engine import analyse
from balpipe.spec_parts import SpecFieldError

from conftest import slider_crank_spec
from _edits import replaced

LAWS = ["quintic", "cycloidal", "bang_bang", "trapezoidal", "polynomial"]


def _stage(st, name):
    return next(s for s in st.stages if s.stage.name == name)


@pytest.mark.parametrize("seed", range(12))
def test_counterweights_of_eq15_balance_the_force_for_any_law(seed):
    rng = np.random.default_rng(seed)
    spec = slider_crank_spec(rng, law=LAWS[seed % len(LAWS)], gravity=bool(seed % 2))
    st = study.run(spec)
    unb, cw = st.stages[0].analysis, _stage(st, "counterweights").analysis
    # with gravity on, the weight of the moving links stays; the inertial part cancels
    weight = _stage(st, "counterweights").stage.model.total_mass() * np.array(cw.gravity)
    assert np.max(np.linalg.norm(cw.force - weight, axis=1)) <= 1e-9 * unb.max_force
    # the total centre of mass does not move, the linear momentum stays zero
    assert np.ptp(cw.com, axis=0).max() < 1e-12
    assert np.abs(cw.momentum).max() < 1e-9 * np.abs(unb.momentum).max()
    assert st.checks["reactions_vs_momentum"] < 1e-9


@pytest.mark.parametrize("seed", range(10))
def test_eq20_cancels_the_moment_of_a_scott_russell_mechanism(seed):
    rng = np.random.default_rng(100 + seed)
    spec = slider_crank_spec(rng, scott_russell=True, moment_unknown="coupler_counterweight_inertia")
    try:
        st = study.run(spec)
    except SpecFieldError as exc:  # eq. 20 wants the inertia on the crank for these masses
        assert "crank_counterweight_inertia" in exc.message
        data = spec.model_dump(by_alias=True)
        data["balancing"]["moment_unknown"] = "crank_counterweight_inertia"
        st = study.run(type(spec).model_validate(data))
    full = _stage(st, "full").analysis
    unb = st.stages[0].analysis
    assert full.max_force <= 1e-9 * unb.max_force
    assert full.max_moment <= 1e-9 * unb.max_moment
    # angular momentum constant (zero: the mechanism starts at rest)
    assert np.abs(full.angular_momentum).max() <= 1e-9 * np.abs(unb.angular_momentum).max()
    assert st.ok, st.problems


def test_general_slider_crank_keeps_a_moment_and_says_why(rng):
    st = study.run(slider_crank_spec(rng))
    assert [s.stage.name for s in st.stages] == ["unbalanced", "counterweights"]
    assert st.stages[1].analysis.max_moment > 0.05 * st.stages[0].analysis.max_moment
    assert any("counter-rotations" in n for n in st.balance.notes)


def test_moment_unknown_on_a_general_slider_crank_is_refused(rng):
    with pytest.raises(SpecFieldError) as exc:
        study.run(slider_crank_spec(rng, moment_unknown="crank_counterweight_inertia"))
    assert exc.value.path == ("balancing", "moment_unknown")


@pytest.mark.parametrize("k", [0.5, 3.0])
def test_scaling_every_mass_and_inertia_scales_loads_and_counterweights(k):
    a = study.run(slider_crank_spec(np.random.default_rng(7), scott_russell=True,
                                    moment_unknown="coupler_counterweight_inertia"))
    b = study.run(slider_crank_spec(np.random.default_rng(7), scott_russell=True, mass_scale=k,
                                    moment_unknown="coupler_counterweight_inertia"))
    for pa, pb in zip(a.balance.parameters, b.balance.parameters):
        expected = pa.value * (k if pa.unit in ("kg", "kg m^2") else 1.0)
        assert pb.value == pytest.approx(expected, rel=1e-12)
    ua, ub = a.stages[0].analysis, b.stages[0].analysis
    assert np.allclose(ub.force, k * ua.force, rtol=1e-9, atol=1e-9 * ua.max_force)
    assert np.allclose(ub.moment, k * ua.moment, rtol=1e-9, atol=1e-9 * ua.max_moment)
    assert np.allclose(ub.efforts["crank"], k * ua.efforts["crank"], rtol=1e-9, atol=1e-9)


def test_halving_the_duration_multiplies_the_loads_by_four(rng):
    a = study.run(slider_crank_spec(np.random.default_rng(3), duration=0.4))
    b = study.run(slider_crank_spec(np.random.default_rng(3), duration=0.2))
    for sa, sb in zip(a.stages, b.stages):
        assert np.allclose(sb.analysis.force, 4 * sa.analysis.force, atol=1e-9 * sa.analysis.max_force * 4)
        assert np.allclose(sb.analysis.moment, 4 * sa.analysis.moment, atol=1e-9 * a.stages[0].analysis.max_moment * 4)


def test_moment_point_moves_the_moment_by_p_cross_f(rng):
    spec = slider_crank_spec(rng)
    model = registry.balance(spec).stages[0].model
    t = registry.time_grid(spec)
    a = analyse(model, t)
    b = analyse(model, t, moment_point=(0.3, -0.2))
    expected = a.moment - (0.3 * a.force[:, 1] - (-0.2) * a.force[:, 0])
    assert np.allclose(b.moment, expected, atol=1e-12 * a.max_moment)
    assert np.allclose(b.moment_momentum, b.moment, atol=1e-9 * a.max_moment)


def test_unreachable_motion_names_the_time_and_the_link():
    spec = slider_crank_spec(np.random.default_rng(1))
    data = spec.model_dump(by_alias=True)
    data["mechanism"]["offset"] = 0.5 * data["mechanism"]["coupler"]["length"]
    data["mechanism"]["coupler"]["length"] = 1.2 * data["mechanism"]["crank"]["length"]
    with pytest.raises(SpecFieldError) as exc:
        study.run(type(spec).model_validate(data))
    assert exc.value.path == ("mechanism", "coupler", "length")
    assert "cannot reach the guide at t =" in exc.value.message


def test_scott_russell_spec_counterweights_are_eq15_in_the_papers_form():
    """specs/scott_russell.yaml: mcp2 = -(m2 r2 + m3) / rcp2, mcp1 = -(m1 r1 + m2 + mcp2 + m3) / rcp1
    (eq. 15 with r = com / L), and the full stage is balanced to 1e-9."""
    from pathlib import Path

    from balpipe.loader import load

    spec = load(Path(__file__).resolve().parents[2] / "specs" / "scott_russell.yaml").spec
    m = spec.mechanism
    r1, r2 = m.crank.com / m.crank.length, m.coupler.com / m.coupler.length
    rcp1 = spec.balancing.crank_counterweight / m.crank.length
    rcp2 = spec.balancing.coupler_counterweight / m.coupler.length
    mcp2 = -(m.coupler.mass * r2 + m.slider.mass) / rcp2
    mcp1 = -(m.crank.mass * r1 + m.coupler.mass + mcp2 + m.slider.mass) / rcp1
    st = study.run(spec)
    got = {p.name: p.value for p in st.balance.parameters}
    assert got["mcp2"] == pytest.approx(mcp2, rel=1e-12) and got["mcp1"] == pytest.approx(mcp1, rel=1e-12)
    full, unb = st.stages[-1].analysis, st.stages[0].analysis
    assert full.max_force <= 1e-9 * unb.max_force and full.max_moment <= 1e-9 * unb.max_moment
    assert st.checks["reactions_vs_momentum"] <= 1e-9


def test_passing_near_the_scott_russell_bifurcation_is_explained():
    """Crank through 90 deg: C passes through A, where the two branches of the Scott-Russell
    mechanism meet. The engine keeps the branch but loses accuracy; the study says why."""
    from pathlib import Path

    from balpipe.loader import load

    spec = load(Path(__file__).resolve().parents[2] / "specs" / "scott_russell.yaml").spec
    data = spec.model_dump(by_alias=True)
    data["motion"]["drive"]["crank"]["to"] = math.radians(100)
    st = study.run(type(spec).model_validate(data))
    assert st.checks["max_condition_number"] > 1e3
    assert any("near a singular configuration" in n for n in st.balance.notes)
    assert all("near a singular configuration" in p for p in st.problems if "should cancel" in p)


def test_with_gravity_a_force_balanced_stage_keeps_exactly_its_weight(rng):
    st = study.run(slider_crank_spec(rng, gravity=True))
    m = study.stage_metrics(st.stages[1], st.stages[0], 1e-9)
    weight = st.stages[1].stage.model.total_mass() * 9.80665
    assert m.force_balanced and m.max_inertial_force <= 1e-9 * st.stages[0].analysis.max_inertial_force
    assert m.max_shaking_force == pytest.approx(weight, rel=1e-12)


# --- issue 7, item 1: the slider translates, so its centre-of-mass offset drops out of eq. 15 ---

def test_offset_slider_com_issue_example_gives_eq15_masses():
    """specs/offset_slider_crank.yaml with the slider's centre of mass 50 mm along the guide from
    C: eq. 15 gives mcp2 = 2.1 kg and mcp1 = 8.4 kg (not 2.3 / 8.8) and the force is cancelled."""
    from pathlib import Path

    from balpipe.loader import load_text

    text = (Path(__file__).resolve().parents[2] / "specs" / "offset_slider_crank.yaml").read_text()
    text = replaced(text, "slider:  {mass: 600 g}", "slider:  {mass: 600 g, com: [0.05 m, 0 m]}")
    spec, _ = load_text(text, "offset.yaml")
    st = study.run(spec)
    params = {p.name: p.value for p in st.balance.parameters}
    assert params["mcp2"] == pytest.approx(2.1, rel=1e-12)
    assert params["mcp1"] == pytest.approx(8.4, rel=1e-12)
    cw = _stage(st, "counterweights")
    assert cw.analysis.max_force <= 1e-9 * st.stages[0].analysis.max_force
    assert not st.problems


@pytest.mark.parametrize("seed", range(6))
def test_slider_com_anywhere_leaves_the_force_balanced(seed):
    """Random slider centre of mass (along and across the guide): the counterweights of eq. 15
    do not depend on it and the total centre of mass stays fixed."""
    rng = np.random.default_rng(300 + seed)
    base = slider_crank_spec(rng)
    sx, sy = (float(v) for v in rng.uniform(-0.2, 0.2, 2))
    mech = base.mechanism.model_dump(by_alias=True)
    mech["slider"]["com"] = (sx, sy)
    spec = slider_crank_spec(np.random.default_rng(300 + seed), mechanism=mech)
    st, st0 = study.run(spec), study.run(base)
    p = {q.name: q.value for q in st.balance.parameters}
    p0 = {q.name: q.value for q in st0.balance.parameters}
    assert p["mcp1"] == pytest.approx(p0["mcp1"], rel=1e-12)
    assert p["mcp2"] == pytest.approx(p0["mcp2"], rel=1e-12)
    cw = _stage(st, "counterweights").analysis
    assert cw.max_force <= 1e-9 * st.stages[0].analysis.max_force
    assert np.ptp(cw.com, axis=0).max() < 1e-12


@pytest.mark.parametrize("seed", range(4))
def test_scott_russell_with_slider_com_along_the_guide_is_fully_balanced(seed):
    """Along the guide, the slider's offset drops out of the moment too (s x v_C = 0 for s along
    the guide); eq. 20 still cancels the moment."""
    rng = np.random.default_rng(400 + seed)
    base = slider_crank_spec(rng, scott_russell=True, moment_unknown="coupler_counterweight_inertia")
    mech = base.mechanism.model_dump(by_alias=True)
    mech["slider"]["com"] = (float(rng.uniform(-0.1, 0.1)), 0.0)
    spec = slider_crank_spec(np.random.default_rng(400 + seed), scott_russell=True,
                             moment_unknown="coupler_counterweight_inertia", mechanism=mech)
    st = study.run(spec)
    full = _stage(st, "full").analysis
    unb = st.stages[0].analysis
    assert full.max_force <= 1e-9 * unb.max_force
    assert full.max_moment <= 1e-9 * unb.max_moment


def test_slider_com_across_the_guide_is_refused_only_for_the_moment(rng):
    base = slider_crank_spec(rng, scott_russell=True, moment_unknown="coupler_counterweight_inertia")
    mech = base.mechanism.model_dump(by_alias=True)
    mech["slider"]["com"] = (0.0, 0.02)
    spec = slider_crank_spec(np.random.default_rng(20261122), scott_russell=True,
                             moment_unknown="coupler_counterweight_inertia", mechanism=mech)
    with pytest.raises(SpecFieldError) as e:
        registry.balance(spec)
    assert e.value.path == ("mechanism", "slider", "com") and "across the guide" in e.value.message
