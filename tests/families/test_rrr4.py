"""Paper 001's n-RRR: redundant actuation, eq. 17's conditions, leg-by-leg balancing, variants,
special kinematics and errors."""

from __future__ import annotations

import copy
import math
from dataclasses import replace

import numpy as np
import pytest
import yaml

from balpipe import registry, study
from balpipe.families.rrr4 import counter_masses as recipe
from balpipe.families.rrr4 import conditions as cond
from balpipe.engine import AnalysisError, analyse
from balpipe.loader import SpecErrors, load_text
from balpipe.families.rrr4.template import corner_motion, leg_motion, mass_parameters, resolve_legs
from balpipe.model import FRAME, Driver, Model, Revolute
from balpipe.motion import PROFILES, PointToPoint
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError
from _edits import replaced

SPEC_FILE = "specs/paper001_4rrr.yaml"


def paper_data() -> dict:
    with open(SPEC_FILE) as fh:
        return yaml.safe_load(fh)


def spec_of(data: dict) -> Spec:
    spec, _ = load_text(yaml.safe_dump(data), "s.yaml")
    return spec


def random_data(rng: np.random.Generator, legs=(1, 2, 3, 4), samples: int = 121) -> dict:
    """A random n-RRR: platform at a random pose, random leg angles at t = 0 (the pivots follow),
    random masses, inertias and centres of mass (off the link lines too), a small random move
    on a random law."""
    c5, d5 = (float(v) for v in rng.uniform(0.03, 0.1, 2))
    x0, y0, ph0 = float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-0.05, 0.05)), float(rng.uniform(-0.3, 0.3))
    signs = {1: (1, -1), 2: (-1, -1), 3: (-1, 1), 4: (1, 1)}
    out_legs = {}
    for i in legs:
        sx, sy = signs[i]
        C = np.array([x0, y0]) + np.array([[math.cos(ph0), -math.sin(ph0)], [math.sin(ph0), math.cos(ph0)]]) @ np.array([sx * c5, sy * d5])
        l1, l2 = (float(v) for v in rng.uniform(0.2, 0.4, 2))
        base = math.atan2(sy, sx) + float(rng.uniform(-0.6, 0.6))  # leg roughly outward from its corner
        bend = float(rng.uniform(0.7, 1.8)) * (1 if rng.uniform() < 0.5 else -1)
        th2 = base + math.pi  # distal link points from B to C, i.e. inward
        th1 = th2 + bend
        A = C - l2 * np.array([math.cos(th2), math.sin(th2)]) - l1 * np.array([math.cos(th1), math.sin(th1)])
        d = C - A
        cross = math.cos(th1) * d[1] - math.sin(th1) * d[0]  # B on the left of A->C: +1
        out_legs[i] = {
            "pivot": [float(A[0]), float(A[1])],
            "elbow": 1 if cross > 0 else -1,
            "proximal": link(rng, l1),
            "distal": link(rng, l2),
        }
    return {
        "name": "random n-RRR",
        "mechanism": {
            "template": "rrr4",
            "platform": {"half_width": c5, "half_height": d5, "mass": float(rng.uniform(0.3, 2.0)),
                         "com": [float(rng.uniform(-0.5, 0.5) * c5), float(rng.uniform(-0.5, 0.5) * d5)],
                         "inertia": float(rng.uniform(0.001, 0.01))},
            "legs": out_legs,
        },
        "motion": {
            "law": str(rng.choice(["quintic", "cycloidal"])),
            "duration": float(rng.uniform(0.2, 1.0)),
            "drive": {"platform": {"from": [x0, y0, ph0],
                                   "to": [x0 + float(rng.uniform(-0.03, 0.03)), y0 + float(rng.uniform(-0.03, 0.03)),
                                          ph0 + float(rng.uniform(-0.15, 0.15))]}},
        },
        "balancing": {"method": "rrr4_counter_masses",
                      "counterweights": {"proximal": float(rng.uniform(0.05, 0.15)), "distal": float(rng.uniform(0.05, 0.15))}},
        "analysis": {"samples": samples},
    }


def link(rng, L):
    m = float(rng.uniform(0.3, 2.0))
    return {"length": L, "mass": m, "com": float(rng.uniform(0.2, 0.8) * L),
            "com_offset": float(rng.uniform(-0.1, 0.1) * L), "inertia": m * L * L * float(rng.uniform(0.05, 0.1))}


def regular_random(seed: int, **kw) -> tuple[dict, Spec, Model]:
    """A random design whose motion stays inside the workspace and away from singularities."""
    rng = np.random.default_rng(seed)
    for _ in range(50):
        data = random_data(rng, **kw)
        try:
            spec = spec_of(data)
            model = registry.unbalanced_model(spec)
            an = analyse(model, registry.time_grid(spec))
        except (SpecFieldError, SpecErrors, AnalysisError):
            continue
        if an.condition.max() < 300:
            return data, spec, model
    raise AssertionError("no regular random design found")


# ---------------------------------------------------------------------------------------------
# redundant actuation


def platform_driven(model: Model) -> Model:
    """The same mechanism driven at the platform: x, y of its centre and its angle (square)."""
    plat = model.body("platform")
    plat = replace(plat, points={**plat.points, "O": (0.0, 0.0)})
    pose = model.drivers[0].law.pose
    drivers = (Driver("x", ("x", "platform", "O"), pose[0]), Driver("y", ("y", "platform", "O"), pose[1]),
               Driver("angle", ("angle", "platform"), pose[2]))
    return replace(model.replace_body(plat), drivers=drivers)


def actuated_jacobian(spec: Spec, model: Model, t: np.ndarray, h: float = 1e-6) -> np.ndarray:
    """G = d theta_Ai / d (x, y, theta5), (N, 4, 3), by central differences of the inverse
    kinematics (independent of the engine)."""
    legs = resolve_legs(spec.mechanism)
    pose = [law(t) for law in model.drivers[0].law.pose]
    G = np.zeros((len(t), len(legs), 3))
    zeros = np.zeros_like(t)
    for k in range(3):
        vals = []
        for sgn in (1, -1):
            p = [(pose[n][0] + (sgn * h if n == k else 0.0), zeros, zeros) for n in range(3)]
            vals.append(np.stack([leg_motion(lg, *corner_motion(spec.mechanism, i, p), refs(model, i)).th1
                                  for i, lg in legs.items()], axis=1))
        G[:, :, k] = (vals[0] - vals[1]) / (2 * h)
    return G


def refs(model: Model, i: int) -> tuple[float, float]:
    return next(d.law.ref for d in model.drivers if d.law.leg.i == i)


@pytest.mark.parametrize("seed", range(3))
def test_redundant_efforts_are_the_pseudo_inverse_solution(seed):
    """Four base motors for three degrees of freedom: the engine's efforts are (G^T)^+ f, f the
    generalised forces of the platform-driven mechanism, G the motors' Jacobian; the shaking
    loads do not depend on the actuation, and reactions agree with momentum to 1e-9."""
    _, spec, model = regular_random(seed)
    t = registry.time_grid(spec)
    red = analyse(model, t, gravity=(0.0, -9.81), moment_point=(0.02, -0.01))
    sq = analyse(platform_driven(model), t, gravity=(0.0, -9.81), moment_point=(0.02, -0.01))
    assert red.redundant_actuators == 1 and sq.redundant_actuators == 0
    f = np.stack([sq.efforts["x"], sq.efforts["y"], sq.efforts["angle"]], axis=1)
    G = actuated_jacobian(spec, model, t)
    tau = np.stack([red.efforts[f"A{i}"] for i in (1, 2, 3, 4)], axis=1)
    expected = np.einsum("nij,nj->ni", np.linalg.pinv(np.transpose(G, (0, 2, 1))), f)
    scale = np.abs(expected).max()
    assert np.abs(tau - expected).max() <= 1e-6 * scale  # finite-difference G: 1e-6
    # the efforts produce the motion: G^T tau = f
    assert np.abs(np.einsum("nji,nj->ni", G, tau) - f).max() <= 1e-6 * np.abs(f).max()
    # the shaking loads are those of any actuation
    for an in (red, sq):
        df, dm = an.route_difference()
        assert df <= 1e-9 * an.max_force and dm <= 1e-9 * an.max_moment
    assert np.abs(red.force - sq.force).max() <= 1e-9 * sq.max_force
    assert np.abs(red.moment - sq.moment).max() <= 1e-9 * sq.max_moment


def test_redundant_efforts_have_no_internal_preload():
    """Adding any self-stress (a null-space vector of the actuated Jacobian's transpose) to the
    engine's efforts makes their norm larger: they are the minimum-norm efforts."""
    _, spec, model = regular_random(7)
    t = registry.time_grid(spec)
    an = analyse(model, t)
    tau = np.stack([an.efforts[f"A{i}"] for i in (1, 2, 3, 4)], axis=1)
    G = actuated_jacobian(spec, model, t)
    for k in range(0, len(t), 20):
        _, _, vt = np.linalg.svd(G[k].T)
        n = vt[-1]  # G^T n = 0: an internal load of the four motors
        assert abs(tau[k] @ n) <= 1e-6 * np.linalg.norm(tau[k])


def test_inconsistent_redundant_drivers_and_over_constrained_joints_are_errors():
    """Redundant drivers must agree (a located error names time and joint), and only drivers
    may be redundant."""
    _, spec, model = regular_random(1)
    t = registry.time_grid(spec)
    bad = model.drivers[3]
    wrong = PointToPoint(float(bad.law(np.zeros(1))[0][0]), float(bad.law(np.zeros(1))[0][0]) + 0.5, 1.0,
                         PROFILES["quintic"])
    with pytest.raises(AnalysisError) as exc:
        analyse(replace(model, drivers=model.drivers[:3] + (replace(bad, law=wrong),)), t)
    assert "t = " in str(exc.value) and exc.value.time is not None
    j = model.joint("A1")
    twice = replace(model, joints=model.joints + (Revolute("A1 again", FRAME, j.b, j.point_a, j.point_b),))
    with pytest.raises(AnalysisError, match="over-constrained"):
        analyse(twice, t)


# ---------------------------------------------------------------------------------------------
# eq. 17


@pytest.mark.parametrize("seed", range(4))
def test_designs_satisfying_eq17_have_no_shaking_force(seed):
    """Random geometry, masses and motion; the first moments of eq. 17's twelve dependent
    parameters solved from it: the engine finds no shaking force (1e-9 of the unbalanced peak)."""
    data, spec, model = regular_random(100 + seed)
    g = recipe.geometry(spec.mechanism)
    rows = cond.eq17(g)
    assert len(rows) == 12
    assert np.linalg.matrix_rank(cond.as_matrix(rows, list(mass_parameters(model)))) == 12
    params = cond.solve(rows, mass_parameters(model), cond.EQ17_DEPENDENT)
    balanced = copy.deepcopy(data)
    for i in (1, 2, 3, 4):
        for j, key in ((1, "proximal"), (2, "distal")):
            m = params[f"m{i}{j}"]
            balanced["mechanism"]["legs"][i][key]["com"] = params[f"m{i}{j}p{i}{j}"] / m
            balanced["mechanism"]["legs"][i][key]["com_offset"] = params[f"m{i}{j}q{i}{j}"] / m
    bspec = spec_of(balanced)
    bmodel = registry.unbalanced_model(bspec)
    assert max(abs(r.residual(mass_parameters(bmodel))) for r in rows) < 1e-12
    t = registry.time_grid(spec)
    an0, an = analyse(model, t), analyse(bmodel, t)
    assert an.max_force <= 1e-9 * an0.max_force
    assert np.ptp(an.com, axis=0).max() <= 1e-12  # the centre of mass stays put
    # and the design as given breaks them
    assert max(abs(r.residual(mass_parameters(model))) for r in rows) > 1e-3


@pytest.mark.parametrize("seed", range(3))
def test_leg_by_leg_solution_satisfies_eq17_and_balances(seed):
    data, spec, model = regular_random(200 + seed)
    res = recipe.balance(registry.context(spec, model=model))
    names = [s.name for s in res.stages]
    assert names == ["unbalanced", "leg_by_leg", "least_mass", "general"]
    rows = cond.eq17(recipe.geometry(spec.mechanism))
    for st in res.stages[1:]:
        p = mass_parameters(st.model)
        assert all(abs(r.residual(p)) <= 1e-12 * max(r.scale(p), 1.0) for r in rows), st.name
        # link CoMs on the link lines for the leg-by-leg stage (eqs. 8-9)
        if st.name == "leg_by_leg":
            assert all(abs(p[f"m{i}{j}q{i}{j}"]) < 1e-12 for i in (1, 2, 3, 4) for j in (1, 2))
    t = registry.time_grid(spec)
    an0 = analyse(res.stages[0].model, t)
    for st in res.stages[1:]:
        an = analyse(st.model, t)
        assert an.max_force <= 1e-9 * an0.max_force, st.name
    # only the general stage leaves l12, l32 and the platform alone
    gen = res.stages[3].model
    for name in ("link12", "link32", "platform"):
        assert gen.body(name).attachments == ()


def test_paper_spec_study():
    """The paper's spec: every stage balances what it claims, eq. 17 holds to round-off for the
    balanced stages, the page says the actuation is redundant."""
    st = study.run(spec_of(paper_data()))
    assert st.ok, st.problems
    p = {x.name: x.value for x in st.balance.parameters}
    assert p["eq17_residual_unbalanced"] > 0.1
    assert p["eq17_residual_leg_by_leg"] < 1e-12 and p["eq17_residual_general"] < 1e-12
    assert sum(p[f"mu5{i}"] for i in (1, 2, 3, 4)) == pytest.approx(1.0)
    assert p["eq17_conditions"] == 12 and p["eq17_rank"] == 12
    res = recipe.eq17_residuals(st.spec.mechanism, st.stages[1].stage.model)
    assert len(res) == 12 and max(abs(r) for _, r in res) < 1e-12
    assert any("Redundant actuation: 4 actuators drive 3" in n for n in st.balance.notes)
    figs = st.extra_figures()
    titles = [f[0] for f in figs]
    assert any("eq. 17" in t for t in titles) and any("Figs. 2a, 4a;" in t for t in titles)
    table = figs[0][1]
    assert table.count("<tr>") == 13 and "eq17.12" in table
    assert "Generic condition finder" in figs[1][0] and "least-mass" in figs[1][1]
    assert "<svg" in figs[2][1]


# ---------------------------------------------------------------------------------------------
# variants and options


def drop_legs(data: dict, keep) -> dict:
    d = copy.deepcopy(data)
    d["mechanism"]["legs"] = {i: v for i, v in d["mechanism"]["legs"].items() if i in keep}
    return d


@pytest.mark.parametrize("keep,actuators,com", [
    ((1, 2, 3), None, None),
    ((1, 2), ["A1", "A2", "B1"], "C1C2"),
    ((3,), ["A3", "B3", "C3"], "C3"),
])
def test_fewer_legs_analyse_and_balance_leg_by_leg(keep, actuators, com):
    data = drop_legs(paper_data(), keep)
    if actuators:
        data["mechanism"]["actuators"] = actuators
    c5, d5 = 0.05, 0.05
    if com == "C1C2":  # on the line C1C2 (y = -d5): the split of eqs. 2-4 exists
        data["mechanism"]["platform"]["com"] = [0.01, -d5]
    elif com == "C3":
        data["mechanism"]["platform"]["com"] = [-c5, d5]
    data["analysis"] = {"samples": 101}
    st = study.run(spec_of(data))
    assert st.ok, st.problems
    assert [s.stage.name for s in st.stages] == ["unbalanced", "leg_by_leg", "least_mass"]
    assert st.stages[1].analysis.max_inertial_force <= 1e-9 * st.stages[0].analysis.max_inertial_force
    assert st.stages[0].analysis.redundant_actuators == 0
    assert st.stages[0].stage.model.name == f"{len(keep)}-RRR"


def test_two_legs_with_the_platform_com_off_their_line_cannot_be_balanced_leg_by_leg():
    data = drop_legs(paper_data(), (1, 2))
    data["mechanism"]["actuators"] = ["A1", "A2", "B1"]
    with pytest.raises(SpecFieldError, match="on the line C1C2"):
        study.run(spec_of(data))


def test_too_few_actuators_is_a_located_error():
    data = drop_legs(paper_data(), (1, 2))
    text = yaml.safe_dump(data)
    spec, _ = load_text(text, "s.yaml")
    with pytest.raises(SpecFieldError, match="3 degrees of freedom but only 2"):
        registry.unbalanced_model(spec)


def test_pose_outside_the_workspace_names_time_and_leg(tmp_path, capsys):
    """The platform driven out of leg 1's reach: exit 2, one located line naming time and leg."""
    from balpipe.cli import main

    text = replaced(open(SPEC_FILE).read(), "to: [0.05 m, 0.04 m, 10 deg]", "to: [0.3 m, 0.0 m, 10 deg]")
    path = tmp_path / "far.yaml"
    path.write_text(text)
    with pytest.raises(SpecFieldError) as exc:
        registry.unbalanced_model(spec_of(yaml.safe_load(text)))
    msg = str(exc.value)
    assert "at t = " in msg and "outside the workspace: leg 1 cannot reach C1" in msg
    assert exc.value.path == ("motion", "drive", "platform", "to")
    assert 0 < float(msg.split("at t = ")[1].split(" s")[0]) < 0.5
    assert main(["check", str(path)]) == 2
    err = capsys.readouterr().err
    line = text.splitlines().index(next(x for x in text.splitlines() if "to: [0.3 m" in x)) + 1
    assert f"far.yaml:{line}:" in err and "leg 1" in err and "Traceback" not in err



def special_data(kind: str) -> dict:
    """The paper spec with the special kinematics of Fig. 5a / 5b and a translating platform."""
    data = paper_data()
    legs = data["mechanism"]["legs"]
    for i in (3, 4):
        legs[i] = {"proximal": {"mass": 0.7, "com": 0.12, "inertia": 0.005},
                   "distal": {"mass": 0.5, "com": 0.1, "com_offset": 0.01, "inertia": 0.004}}
    legs[1]["pivot"] = [-0.35, -0.1]
    legs[2]["pivot"] = [0.3, -0.25]
    data["mechanism"]["kinematics"] = kind
    data["motion"]["drive"]["platform"] = {"from": [-0.04, -0.03, 0.0], "to": [0.03, 0.02, 0.0]}
    data["analysis"] = {"samples": 101}
    return data

@pytest.mark.parametrize("kind", ["fig5a", "fig5b"])
def test_special_kinematics_keep_links_parallel_and_balance_with_eight_conditions(kind):
    spec = spec_of(special_data(kind))
    st = study.run(spec)
    assert st.ok, st.problems
    an = st.stages[0].analysis
    th = {b: an.q[:, an.names.index(b), 2] for b in an.names}
    pairs = ({"link11": "link42", "link12": "link41", "link21": "link32", "link22": "link31"} if kind == "fig5a"
             else {"link11": "link41", "link12": "link42", "link21": "link31", "link22": "link32"})
    for a, b in pairs.items():
        assert np.abs(np.sin(th[a] - th[b])).max() < 1e-9, (a, b)
    names = [s.stage.name for s in st.stages]
    assert names == ["unbalanced", "leg_by_leg", "least_mass", "general", "special"]
    sp = st.stages[4]
    F0 = st.stages[0].analysis.max_inertial_force
    assert sp.analysis.max_inertial_force <= 1e-9 * F0
    p = mass_parameters(sp.stage.model)
    rows = cond.special(recipe.geometry(spec.mechanism), kind)
    assert len(rows) == 8 and all(abs(r.residual(p)) <= 1e-12 * r.scale(p) for r in rows)
    # Fig. 6a: counter-masses on the links l_i1 only
    with_cm = {b.name for b in sp.stage.model.bodies if b.attachments}
    if kind == "fig5a":
        assert with_cm <= {"link11", "link21", "link31", "link41"}
    # eq. 17 need not hold for this design: it balances only because the platform translates
    rows17 = cond.eq17(recipe.geometry(spec.mechanism))
    assert max(abs(r.residual(p)) for r in rows17) > 1e-6


def test_special_kinematics_with_a_turning_platform_skip_the_fig6_stage():
    data = paper_data()
    for i in (3, 4):
        data["mechanism"]["legs"][i] = {"proximal": {"mass": 0.7, "com": 0.12, "inertia": 0.005},
                                        "distal": {"mass": 0.5, "com": 0.1, "inertia": 0.004}}
    data["mechanism"]["legs"][1]["pivot"] = [-0.35, -0.1]
    data["mechanism"]["legs"][2]["pivot"] = [0.3, -0.25]
    data["mechanism"]["kinematics"] = "fig5a"
    data["motion"]["drive"]["platform"] = {"from": [-0.04, -0.03, 0.0], "to": [0.03, 0.02, 0.1]}
    spec = spec_of(data)
    res = registry.balance(spec)
    assert [s.name for s in res.stages] == ["unbalanced", "leg_by_leg", "least_mass", "general"]
    assert any("does not rotate" in n for n in res.notes)


def test_special_kinematics_check_given_geometry():
    data = paper_data()
    data["mechanism"]["kinematics"] = "fig5b"
    with pytest.raises(SpecFieldError, match="kinematics fig5b"):
        registry.unbalanced_model(spec_of(data))


def test_redundant_efforts_scale_with_mass_and_duration():
    """Scaling every mass and inertia by k scales the efforts and shaking force by k; halving the
    duration multiplies them by 4 (no gravity)."""
    data, spec, model = regular_random(11)
    t = registry.time_grid(spec)
    an = analyse(model, t)
    heavy = copy.deepcopy(data)
    k = 2.5
    heavy["mechanism"]["platform"]["mass"] *= k
    heavy["mechanism"]["platform"]["inertia"] *= k
    for leg in heavy["mechanism"]["legs"].values():
        for key in ("proximal", "distal"):
            leg[key]["mass"] *= k
            leg[key]["inertia"] *= k
    fast = copy.deepcopy(data)
    fast["motion"]["duration"] /= 2
    an_k = analyse(registry.unbalanced_model(spec_of(heavy)), t)
    fspec = spec_of(fast)
    an_f = analyse(registry.unbalanced_model(fspec), registry.time_grid(fspec))
    for name in an.efforts:
        scale = np.abs(an.efforts[name]).max()
        assert np.abs(an_k.efforts[name] - k * an.efforts[name]).max() <= 1e-9 * k * scale
        assert np.abs(an_f.efforts[name] - 4 * an.efforts[name]).max() <= 1e-8 * 4 * scale
    assert np.abs(an_k.force - k * an.force).max() <= 1e-9 * k * an.max_force
    assert np.abs(an_f.force - 4 * an.force).max() <= 1e-8 * 4 * an.max_force


def test_independent_distal_link_gives_fig2b_and_two_need_a_special_platform():
    """Sec. II.B: with l22 as built, mu52 = -m22 p22 / l22 (eq. 11) and l22 needs no counter-mass;
    the leg-by-leg design still balances. Two independent links (Fig. 2c) need the combined
    centre of mass on a line, which this platform does not have: a located error."""
    data = paper_data()
    data["balancing"]["independent"] = [22]
    data["analysis"] = {"samples": 101}
    st = study.run(spec_of(data))
    assert st.ok, st.problems
    lbl = st.stages[1]
    assert "Fig. 2b" in lbl.stage.label
    assert lbl.stage.model.body("link22").attachments == ()
    p = {x.name: x.value for x in st.balance.parameters}
    assert p["mu52"] == pytest.approx(-0.6 * 0.15 / 0.3)
    assert sum(p[f"mu5{i}"] for i in (1, 2, 3, 4)) == pytest.approx(1.0)
    assert lbl.analysis.max_inertial_force <= 1e-9 * st.stages[0].analysis.max_inertial_force
    assert p["eq17_residual_leg_by_leg"] < 1e-12
    data["balancing"]["independent"] = [22, 42]
    with pytest.raises(SpecFieldError, match="cannot be met") as exc:
        study.run(spec_of(data))
    assert exc.value.path == ("balancing", "independent")


def test_a_leg_turning_half_a_revolution_is_a_located_error():
    """A 1-RRR whose pivot is inside the circle of C3: a full platform turn sweeps the leg around."""
    data = drop_legs(paper_data(), (3,))
    leg = data["mechanism"]["legs"][3]
    leg["pivot"] = ["0 m", "0 m"]
    leg["proximal"]["length"], leg["distal"]["length"] = "0.3 m", "0.25 m"
    data["mechanism"]["actuators"] = ["A3", "B3", "C3"]
    data["motion"]["drive"]["platform"] = {"from": [0.0, 0.0, "0 deg"], "to": [0.0, 0.0, "360 deg"]}
    with pytest.raises(SpecFieldError, match="turns by 180 deg or more") as exc:
        registry.unbalanced_model(spec_of(data))
    assert exc.value.path == ("motion", "drive", "platform", "to")
