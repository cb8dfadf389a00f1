"""Paper 002: decoupling a 2R arm by a gear pair and mass redistribution, then cancelling the
shaking moment with a counter-rotating gear."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe import study
from balpipe.families.serial_arm.decoupling import mass_matrix_2r
from balpipe.engine import analyse
from balpipe.engine.joint_space import mass_matrix
from balpipe.families.serial_arm.template import with_joint_laws
from balpipe.motion import Polynomial
from balpipe.spec import Spec

SPECS = Path(__file__).resolve().parents[2] / "specs"
G = 9.80665


def random_states_model(model, rng, T: float = 1.0):
    """The model driven through random joint angles, rates and accelerations (two quintic
    polynomials with random boundary values), and random sample times."""
    laws = [Polynomial.from_boundary(tuple(rng.uniform(-2, 2, 3)), tuple(rng.uniform(-2, 2, 3)), T) for _ in range(2)]
    t = np.sort(rng.uniform(0, T, 40))
    return with_joint_laws(model, laws, float(t[0])), t, laws


def joint_accelerations(laws, t) -> np.ndarray:
    return np.stack([law(t)[2] for law in laws], axis=1)


@pytest.fixture(params=["paper002_decoupling.yaml", "paper002_decoupling_horizontal.yaml"])
def paper(request, studies):
    st = studies(request.param)
    spec = st.spec
    return spec, st, {p.name: p.value for p in st.balance.parameters}


def test_paper_values_are_computed_from_the_spec(paper):
    spec, st, p = paper
    assert p["J1"] == pytest.approx(2.04, abs=1e-12)
    assert p["J2"] == pytest.approx(1.00, abs=1e-12)
    assert p["I3"] == pytest.approx(2.04, abs=1e-12)
    for name in ("condition1_residual", "condition2_residual", "condition3_residual"):
        assert abs(p[name]) < 1e-12
    assert all(r["status"] == "agrees" for r in st.references)
    assert st.ok, st.problems


def test_decoupled_torques_are_J_times_acceleration_on_random_states(paper, rng):
    spec, st, p = paper
    dec = next(s for s in st.stages if s.stage.name == "decoupled").stage.model
    g = study.gravity_vector(spec)
    for _ in range(5):
        model, t, laws = random_states_model(dec, rng)
        an = analyse(model, t, g)
        qdd = joint_accelerations(laws, t)
        for j, J in enumerate((p["J1"], p["J2"])):
            e = an.efforts[f"q{j + 1}"]
            assert np.max(np.abs(e - J * qdd[:, j])) <= 1e-9 * np.max(np.abs(e))


def test_counter_rotation_cancels_the_moment_and_the_force_is_the_weight(paper):
    spec, st, p = paper
    by = {s.stage.name: s.analysis for s in st.stages}
    dec, full = by["decoupled"], by["decoupled_counter_rotation"]
    assert full.max_moment <= 1e-9 * dec.max_moment
    weight = np.array(study.gravity_vector(spec)) * st.stages[1].stage.model.total_mass()
    for an in (dec, full):
        scale = max(np.hypot(*weight), by["unbalanced"].max_inertial_force)
        assert np.max(np.abs(an.force - weight)) <= 1e-9 * scale
    if spec.analysis.gravity:
        assert np.hypot(*weight) == pytest.approx(10 * G, rel=1e-12)  # m = 7 + 2 + 1 kg


def test_closed_form_mass_matrix_equals_the_engines(paper):
    spec, st, p = paper
    unb = st.stages[0]
    names, M = mass_matrix(unb.stage.model, unb.analysis.t)
    q2 = unb.analysis.frame_pose[:, 1, 2] - unb.analysis.frame_pose[:, 0, 2]
    closed = mass_matrix_2r(unb.stage.model, spec.mechanism.links[0].length, None).values(q2)
    assert names == ["q1", "q2"]
    assert np.max(np.abs(M - closed)) <= 1e-12 * np.max(np.abs(M))


def random_decoupling_spec(rng, gravity: bool) -> Spec:
    def link(L):
        m = float(rng.uniform(0.3, 3.0))
        return {"length": L, "mass": m, "com": float(rng.uniform(-0.2, 0.8) * L),
                "com_offset": float(rng.uniform(-0.1, 0.1) * L), "inertia": m * L * L * float(rng.uniform(0.03, 0.1))}

    l1, l2 = float(rng.uniform(0.2, 0.5)), float(rng.uniform(0.2, 0.5))
    data = {
        "name": "random decoupling",
        "mechanism": {"template": "serial_arm", "links": [link(l1), link(l2)],
                      "payload": {"mass": float(rng.uniform(0, 1))}},
        "motion": {"law": "quintic", "duration": float(rng.uniform(0.3, 1.5)),
                   "drive": {"q1": {"from": float(rng.uniform(-2, 2)), "to": float(rng.uniform(-2, 2))},
                             "q2": {"from": float(rng.uniform(-2, 2)), "to": float(rng.uniform(-2, 2))}}},
        "balancing": {
            "method": "gear_decoupling",
            "gear_1p": {"position": float(rng.uniform(0, 0.9) * l1), "mass": float(rng.uniform(0, 2)),
                        "ratio": float(-rng.uniform(0.5, 2.0))},
            "gear_2p": {"mass": float(rng.uniform(0, 1)), "inertia": float(rng.uniform(0, 0.05))},
            "counterweights": {"link1": {"distance": float(rng.uniform(0.05, 0.3)), "inertia": float(rng.uniform(0, 0.1))},
                               "link2": {"distance": float(rng.uniform(0.05, 0.3))}},
            "counter_rotation": {"position": [float(rng.uniform(-0.3, 0.3)), -0.2]},
        },
        "analysis": {"samples": 101, "gravity": gravity},
    }
    return Spec.model_validate(data)


@pytest.mark.parametrize("gravity", [False, True])
def test_random_designs_satisfy_the_conditions_and_decouple(rng, gravity):
    for _ in range(4):
        spec = random_decoupling_spec(rng, gravity)
        st = study.run(spec)
        assert st.ok, st.problems
        p = {x.name: x.value for x in st.balance.parameters}
        for name in ("condition1_residual", "condition2_residual", "condition3_residual"):
            assert abs(p[name]) < 1e-12, name
        by = {s.stage.name: s for s in st.stages}
        dec = by["decoupled"]
        # constant diagonal mass matrix (the engine's, not the closed form)
        _, M = mass_matrix(dec.stage.model, dec.analysis.t)
        assert np.max(np.abs(M[:, 0, 1])) <= 1e-12 * p["J1"]
        assert np.allclose(M[:, 0, 0], p["J1"], rtol=1e-12) and np.allclose(M[:, 1, 1], p["J2"], rtol=1e-12)
        model, t, laws = random_states_model(dec.stage.model, rng)
        an = analyse(model, t, study.gravity_vector(spec))
        qdd = joint_accelerations(laws, t)
        for j, J in enumerate((p["J1"], p["J2"])):
            e = an.efforts[f"q{j + 1}"]
            assert np.max(np.abs(e - J * qdd[:, j])) <= 1e-9 * np.max(np.abs(e))
        full = by["decoupled_counter_rotation"].analysis
        assert full.max_inertial_moment <= 1e-9 * dec.analysis.max_inertial_moment
        assert np.allclose(an.com, 0.0, atol=1e-12)  # the total centre of mass stays on A (the base)


def test_balanced_stage_passes_the_pymunk_validation(paper):
    """The reactionless design in an independent simulation: gears 1'-2' (carried by link 1) and
    gear 3 (on the frame) included."""
    from balpipe.validate import validate

    spec, st, p = paper
    full = next(s for s in st.stages if s.stage.name == "decoupled_counter_rotation")
    F0, M0 = st.unbalanced.analysis.max_inertial_force, st.unbalanced.analysis.max_inertial_moment
    v = validate(full.stage.model, full.analysis, (F0, M0), None, ("force", "moment"))
    assert v.passed, v.reasons
    assert v.moment_peak < 1e-2 and v.force_peak < 1e-2


def test_the_methods_figures_come_from_the_study_not_a_closure(paper):
    """Issue 19: the figures are the method's hook (plugins.Method.figures), drawn from the
    stages, parameters and spec; Fig. 2 of paper 002 gives F^sh with the weight said apart when
    gravity is on; round-off of the decoupled mass matrix reads 0."""
    from balpipe import registry

    spec, st = paper[0], paper[1]
    assert st.balance.figures is None
    hook = registry.METHODS["gear_decoupling"].figures
    figs = {title: (body, caption) for title, body, caption in hook(st)}
    fig2 = figs["Fig. 2 of paper 002: shaking force and shaking moment of the unbalanced manipulator"]
    an = st.unbalanced.analysis
    if spec.analysis.gravity:
        w = an.total_mass * float(np.hypot(*an.gravity))
        assert f"weight m g = {w:.4g} N" in fig2[1] and f"peaks at {an.max_inertial_force:.4g} N" in fig2[1]
        assert an.max_force > an.max_inertial_force
    else:
        assert "Gravity is off" in fig2[1]
    table = figs["Mass matrix before and after decoupling (eqs. 4-6, 17-18)"][0]
    J = {p.name: p.value for p in st.balance.parameters}
    rows = table.split("<tr>")
    d12 = next(r for r in rows if r.startswith("<td>D₁₂"))
    assert d12.endswith("<td><code>0</code></td></tr>")  # decoupled: D12 = 0 (round-off reads 0)
    assert f"<code>{J['J1']:.6g}</code>" in table and f"<code>{J['J2']:.6g}</code>" in table
    assert {"Mass matrix along the motion", "Torque against acceleration (eqs. 17-18)"} <= set(figs)


def test_the_counterweights_inertias_are_said_to_be_the_specs_choice(paper):
    """The conditions fix only the redistributed links' inertias: the note says the counterweights'
    own are the spec's choice, true of the paper's spec and of an arm of one's own alike."""
    spec, st, p = paper
    note = [n for n in st.balance.notes if n.startswith("The counterweights carry the centroidal inertias")]
    assert len(note) == 1
    assert "the counterweights' own are the spec's choice" in note[0] and "chosen to give them" not in note[0]
