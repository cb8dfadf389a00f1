"""Gear meshes with pitch radii pass tooth forces to their bearings (issue 7, item 5).

The invariants: the shaking loads, the efforts and the mesh torques are those of the couple-only
formulation (the tooth-force row is a combination of the old rows); every gear body obeys
Newton's law with its bearing force and the tooth forces; the five-bar's bearing loads at O5,
A1-6 and A2-7 equal a hand calculation from the mesh torques and pitch radii.
"""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load, load_text
from balpipe.mechanics.meshes import mesh_geometry
from balpipe.model import FRAME, Body, Driver, Gear, Model, Revolute
from balpipe.motion import PROFILES, PointToPoint
from balpipe.report.results import joint_load_table, timeseries_csv
from balpipe.spec_parts import SpecFieldError
from _edits import replaced

SPEC = Path(__file__).resolve().parents[2] / "specs" / "paper004_five_bar.yaml"
TAN20 = math.tan(math.radians(20.0))


def couple_only(model: Model) -> Model:
    """The same model with every gear pair's pitch radii removed: today's couple formulation."""
    return replace(model, joints=tuple(
        replace(j, radius_a=None, radius_b=None) if isinstance(j, Gear) else j for j in model.joints
    ))


def assert_same_dynamics(a, b, F0: float, M0: float) -> None:
    assert np.max(np.abs(a.force - b.force)) <= 1e-9 * F0
    assert np.max(np.abs(a.moment - b.moment)) <= 1e-9 * M0
    for d in a.efforts:
        scale = max(1.0, float(np.max(np.abs(b.efforts[d]))))
        assert np.max(np.abs(a.efforts[d] - b.efforts[d])) <= 1e-9 * scale
    df, dm = a.route_difference()
    assert df <= 1e-9 * F0 and dm <= 1e-9 * M0


@pytest.fixture(scope="module")
def paper():
    spec = load(SPEC).spec
    result = registry.balance(spec)
    t = registry.time_grid(spec)
    stages = {s.name: s for s in result.stages}
    return spec, stages, {n: analyse(s.model, t) for n, s in stages.items()}, t


# --------------------------------------------------------------------------------------------
# the five-bar of paper 004


def test_tooth_forces_leave_the_five_bar_shaking_loads_efforts_and_torques_unchanged(paper):
    _, stages, an, t = paper
    F0, M0 = an["unbalanced"].max_force, an["unbalanced"].max_moment
    for name, st in stages.items():
        old = analyse(couple_only(st.model), t)
        assert_same_dynamics(an[name], old, F0, M0)
        for j, comps in an[name].reactions.items():
            if "T" in comps:
                scale = float(np.max(np.abs(old.reactions[j]["T"])))
                assert np.max(np.abs(comps["T"] - old.reactions[j]["T"])) <= 1e-9 * scale


def _centre(an, body: str) -> np.ndarray:
    """Global position (N, 2) of a body frame's origin (every gear's centre in the five-bar)."""
    return an.frame_pose[:, an.names.index(body), :2]


def _tooth_force_on_b(an, mesh: str, a: str, b: str, r_b: float) -> np.ndarray:
    """By hand: the tooth force on gear b (N, 2) from the mesh torque T on b and b's pitch radius.
    It acts at the pitch point, on the line of centres r_b from b's centre towards a's: the
    tangential part T / r_b perpendicular to that line (so that its moment about b's centre is
    T), the radial part |T / r_b| tan 20 deg towards b's centre."""
    T = an.reactions[mesh]["T"]
    d = _centre(an, a) - _centre(an, b)
    e = d / np.linalg.norm(d, axis=1)[:, None]
    perp = np.stack([-e[:, 1], e[:, 0]], axis=1)
    ft = T / r_b
    return ft[:, None] * perp - (np.abs(ft) * TAN20)[:, None] * e


def test_five_bar_bearing_loads_equal_the_hand_calculation(paper):
    spec, stages, an, _ = paper
    params = {p.name: p.value for p in registry.balance(spec).parameters}
    r1p, r2p, r5, r3p, r6 = params["r1p"], params["r2p"], params["r5"], params["r3p"], params["r6"]
    for name in ("unbalanced", "counterweights", "full", "full_point_masses"):
        a = an[name]
        F15 = _tooth_force_on_b(a, "1'-5", "link1", "gear5", r5)
        F52 = _tooth_force_on_b(a, "5-2'", "gear5", "link2", r2p)
        # gear 5 is massless on a fixed axis: its bearing O5 (force on gear 5 from the frame)
        # balances the tooth forces of its two meshes (on 5 as gear b of 1'-5, as gear a of 5-2')
        O5 = np.stack([a.reactions["O5"]["Fx"], a.reactions["O5"]["Fy"]], axis=1)
        hand = -(F15 - F52)
        peak = float(np.max(np.linalg.norm(hand, axis=1)))
        assert peak > 1.0, name  # a real load, not 0 N
        assert np.max(np.linalg.norm(O5 - hand, axis=1)) <= 1e-9 * peak, name
        for mesh, rb in (("1'-5", r5), ("5-2'", r2p)):
            comps = a.reactions[mesh]
            assert np.allclose(comps["Ft"], comps["T"] / rb, rtol=0, atol=1e-12 * peak)
            assert np.allclose(comps["Fr"], np.abs(comps["Ft"]) * TAN20, rtol=0, atol=1e-12 * peak)
    full = an["full"]
    # the issue's figure: mesh 1'-5 carries 10.4 N m on r5 = 0.0789 m, ~130 N of tooth force
    assert abs(np.max(np.abs(full.reactions["1'-5"]["T"])) - 10.4) < 0.05
    assert 125 < np.max(np.abs(full.reactions["1'-5"]["Ft"])) < 135
    for j, dist, planet in ((1, "link3", "gear6"), (2, "link4", "gear7")):
        # the massless planet j+5 on axis A_j: its bearing on the input link balances the mesh
        hand = -_tooth_force_on_b(full, f"{j + 2}'-{j + 5}", dist, planet, r6)
        bearing = np.stack([full.reactions[f"A{j}-{j + 5}"]["Fx"], full.reactions[f"A{j}-{j + 5}"]["Fy"]], axis=1)
        peak = float(np.max(np.linalg.norm(hand, axis=1)))
        assert peak > 1.0
        assert np.max(np.linalg.norm(bearing - hand, axis=1)) <= 1e-9 * peak
    assert abs(r3p - r6) < 1e-12  # U63 = 1


def test_couple_only_gears_leave_the_bearings_unloaded(paper):
    """Today's formulation, kept for gear pairs without pitch radii (a belt)."""
    _, stages, _, t = paper
    old = analyse(couple_only(stages["full"].model), t)
    assert np.max(np.abs(old.reactions["O5"]["Fx"])) < 1e-9
    assert set(old.reactions["1'-5"]) == {"T"}
    # and the joint-load table says that such a pair is a couple only
    from types import SimpleNamespace

    study = SimpleNamespace(stages=[SimpleNamespace(stage=SimpleNamespace(name="full"), analysis=old)])
    kinds = {r["kind"] for r in joint_load_table(study) if r["joint"] == "1'-5"}
    assert kinds == {"gear pair without pitch radii, a couple only: |T| (torque on the driven gear)"}


def test_pressure_angle_is_read_from_the_spec():
    text = replaced(SPEC.read_text(), "    r1p: 0.14 m\n", "    r1p: 0.14 m\n    pressure_angle: 25 deg\n")
    text = replaced(text, "    planet_mass: 0 kg\n", "    planet_mass: 0 kg\n    pressure_angle: 14.5 deg\n")
    spec, _ = load_text(text, "five_bar.yaml")
    stages = {s.name: s for s in registry.balance(spec).stages}
    t = registry.time_grid(spec)
    a = analyse(stages["full"].model, t)
    for mesh, deg in (("1'-5", 25.0), ("5-2'", 25.0), ("3'-6", 14.5), ("4'-7", 14.5)):
        c = a.reactions[mesh]
        assert np.allclose(c["Fr"], np.abs(c["Ft"]) * math.tan(math.radians(deg)), atol=1e-12 * np.max(np.abs(c["Ft"])))


def test_joint_load_table_and_csv_have_the_mesh_forces(paper):
    from balpipe import study as study_mod

    spec = paper[0]
    s = study_mod.run(spec)
    rows = {(r["joint"], r["kind"].split(":")[1].strip().split(" ")[0]): r for r in joint_load_table(s)}
    assert rows[("1'-5", "|Ft|")]["unit"] == "N" and rows[("1'-5", "Fr")]["unit"] == "N"
    assert rows[("1'-5", "|T|")]["unit"] == "N m"
    for joint in ("O5", "A1-6", "A2-7"):
        assert rows[(joint, "|F|")]["peaks"]["full"] > 1.0
    head = timeseries_csv(s).splitlines()[0].split(",")
    for col in ("full.reaction.1'-5.Ft_N", "full.reaction.1'-5.Fr_N", "full.reaction.3'-6.Ft_N", "full.reaction.O5.Fx_N"):
        assert col in head


# --------------------------------------------------------------------------------------------
# random geared models


def law(a: float, b: float, T: float = 0.5) -> PointToPoint:
    return PointToPoint(a, b, T, PROFILES["quintic"])


def disc(name: str, rng) -> Body:
    return Body(name, float(rng.uniform(0.1, 1.0)), (float(rng.uniform(-0.01, 0.01)), 0.0),
                float(rng.uniform(1e-4, 1e-2)), {"O": (0.0, 0.0)}, radius=0.03, kind="gear")


def arm(name: str, L: float, rng) -> Body:
    m = float(rng.uniform(0.5, 2.0))
    return Body(name, m, (float(rng.uniform(0.2, 0.8)) * L, float(rng.uniform(-0.02, 0.02))),
                float(rng.uniform(0.02, 0.1)) * m * L * L, {"P": (0.0, 0.0), "Q": (L, 0.0)}, outline=("P", "Q"))


def random_planetary(rng) -> Model:
    """Two driven arms; a disc on arm1 meshes externally with a gear fixed on arm2 (carrier
    arm1); a sun fixed to the frame meshes with a planet on arm1 (gear a is the frame); a ring
    pivoted on arm1 at the frame pivot meshes internally with a second planet, the ring's angle
    driven."""
    L1, L2 = float(rng.uniform(0.25, 0.4)), float(rng.uniform(0.15, 0.3))
    k = float(rng.uniform(0.5, 3.0))
    dD = float(rng.uniform(0.08, 0.15))  # disc axis from B, towards A, on arm1
    rs = float(rng.uniform(0.03, 0.08))  # sun
    rp = float(rng.uniform(0.02, 0.05))  # planet on the sun
    R = float(rng.uniform(0.12, 0.2))  # ring
    rq = float(rng.uniform(0.02, 0.05))  # planet in the ring
    a1 = arm("arm1", L1, rng)
    a1 = replace(a1, points={**a1.points, "D": (L1 - dD, 0.0), "S": (0.0, rs + rp), "Rq": (0.0, -(R - rq))})
    bodies = (a1, arm("arm2", L2, rng), disc("disc", rng), disc("planet", rng), disc("planetq", rng),
              replace(disc("ring", rng), radius=R))
    pa = float(rng.uniform(0.0, 0.5))
    joints = (
        Revolute("A", FRAME, "arm1", (0.0, 0.0), (0.0, 0.0)),
        Revolute("B", "arm1", "arm2", (L1, 0.0), (0.0, 0.0)),
        Revolute("D", "arm1", "disc", (L1 - dD, 0.0), (0.0, 0.0)),
        Revolute("S", "planet", "arm1", (0.0, 0.0), (0.0, rs + rp)),  # gear is joint body a
        Revolute("Q", "arm1", "planetq", (0.0, -(R - rq)), (0.0, 0.0)),
        Revolute("R", "arm1", "ring", (0.0, 0.0), (0.0, 0.0)),
        Gear("arm2-disc", "arm2", "disc", "arm1", -k, None, dD * k / (1 + k), dD / (1 + k), pa),
        Gear("sun-planet", FRAME, "planet", "arm1", -rs / rp, None, rs, rp, pa),
        Gear("ring-planetq", "ring", "planetq", "arm1", R / rq, None, R, rq, pa),
    )
    drivers = (Driver("q1", ("joint", "A"), law(0.0, float(rng.uniform(1.0, 2.5)))),
               Driver("q2", ("joint", "B"), law(0.2, float(rng.uniform(-1.5, 1.0)))),
               Driver("ring", ("angle", "ring"), law(0.0, float(rng.uniform(-2.0, 2.0)))))
    initial = {"arm1": (0, 0, 0.0), "arm2": (L1, 0, 0.2), "disc": (L1 - dD, 0.0, 0.0),
               "planet": (0.0, rs + rp, 0.0), "planetq": (0.0, -(R - rq), 0.0), "ring": (0.0, 0.0, 0.0)}
    return Model("random planetary", bodies, joints, drivers, initial)


@pytest.mark.parametrize("seed", range(6))
def test_random_geared_models_keep_their_dynamics_and_every_gear_obeys_newton(seed):
    rng = np.random.default_rng(seed)
    model = random_planetary(rng)
    t = np.linspace(0.0, 0.5, 201)
    g = (0.0, -9.81) if seed % 2 else (0.0, 0.0)
    P = (float(rng.uniform(-0.1, 0.1)), float(rng.uniform(-0.1, 0.1)))
    new = analyse(model, t, gravity=g, moment_point=P)
    old = analyse(couple_only(model), t, gravity=g, moment_point=P)
    assert_same_dynamics(new, old, new.max_force, new.max_moment)
    # each planet has one bearing and one mesh: m a = m g + bearing force + tooth force
    for body, bearing, mesh, sign in (("disc", "D", "arm2-disc", 1.0), ("planet", "S", "sun-planet", -1.0),
                                      ("planetq", "Q", "ring-planetq", 1.0)):
        k = new.names.index(body)
        m = model.body(body).mass_properties()[0]
        geo = mesh_geometry(model, model.joint(mesh))
        c = new.reactions[mesh]
        # the tooth force on b by the engine's own components: Ft along the direction that turns
        # b counter-clockwise at the pitch point, Fr towards b's centre (external) or away (internal)
        Ob = _point(new, model, "arm1", model.joint(bearing).point_a if sign > 0 else model.joint(bearing).point_b)
        Oa = _point(new, model, "arm1", (0.0, 0.0)) if mesh != "arm2-disc" else _point(new, model, "arm1", model.joint("B").point_a)
        u = (Ob - Oa) / np.linalg.norm(Ob - Oa, axis=1)[:, None]
        Ppitch = Oa + geo.side * geo.pitch_a * u
        e = (Ppitch - Ob) / np.linalg.norm(Ppitch - Ob, axis=1)[:, None]
        tooth = c["Ft"][:, None] * np.stack([-e[:, 1], e[:, 0]], axis=1) + (
            (1.0 if geo.external else -1.0) * c["Fr"])[:, None] * u
        bear = sign * np.stack([new.reactions[bearing]["Fx"], new.reactions[bearing]["Fy"]], axis=1)
        lhs = m * new.a[:, k, :2]
        rhs = m * np.asarray(g) + bear + tooth
        scale = float(np.max(np.abs(rhs))) + float(np.max(np.abs(lhs))) + 1.0
        assert np.max(np.abs(lhs - rhs)) <= 1e-9 * scale, body
        assert np.max(np.abs(c["Ft"])) > 1e-3


def _point(an, model: Model, body: str, p) -> np.ndarray:
    pose = an.frame_pose[:, an.names.index(body)]
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.stack([pose[:, 0] + c * p[0] - s * p[1], pose[:, 1] + s * p[0] + c * p[1]], axis=1)


# --------------------------------------------------------------------------------------------
# bad input


def _custom_gear_spec(**gear) -> str:
    g = ", ".join(f"{k}: {v}" for k, v in gear.items())
    return f"""
name: geared arm
mechanism:
  template: custom
  bodies:
    - {{name: arm, mass: 1 kg, com: [0.1 m, 0 m], inertia: 0.01 kg m^2, points: {{A: [0, 0], D: [0.15 m, 0]}}, pose: [0, 0, 0]}}
    - {{name: disc, mass: 0.2 kg, inertia: 0.001 kg m^2, pose: [0.15 m, 0, 0], kind: gear}}
  joints:
    - {{type: revolute, name: A, a: frame, b: arm, point_a: [0, 0]}}
    - {{type: revolute, name: D, a: arm, b: disc, point_a: D}}
    - {{type: gear, name: G, a: frame, b: disc, carrier: arm, ratio: -2{', ' + g if g else ''}}}
  drivers:
    - {{name: q, joint: A}}
motion:
  duration: 0.5 s
  drive:
    q: {{from: 0 deg, to: 90 deg}}
validation: {{enabled: false}}
"""


def test_custom_gear_with_consistent_radii_passes_tooth_forces():
    spec, _ = load_text(_custom_gear_spec(radius_a="0.1 m", radius_b="50 mm", pressure_angle="25 deg"), "g.yaml")
    model = registry.unbalanced_model(spec)
    an = analyse(model, registry.time_grid(spec))
    assert {"T", "Ft", "Fr"} <= set(an.reactions["G"])
    assert np.max(np.abs(an.reactions["G"]["Fr"])) > 0
    spec, _ = load_text(_custom_gear_spec(), "g.yaml")  # no radii: a couple, as before
    assert set(analyse(registry.unbalanced_model(spec), registry.time_grid(spec)).reactions["G"]) == {"T"}


@pytest.mark.parametrize("gear, field, words", [
    ({"radius_a": "0.1 m"}, "radius_b", "both pitch radii"),
    ({"radius_a": "0.1 m", "radius_b": "0.06 m"}, "radius_a", "does not match the pitch radii"),
    ({"radius_a": "0.2 m", "radius_b": "0.1 m"}, "radius_a", "0.15 m apart"),
])
def test_inconsistent_pitch_radii_are_located_spec_errors(gear, field, words):
    spec, _ = load_text(_custom_gear_spec(**gear), "g.yaml")
    with pytest.raises(SpecFieldError) as exc:
        registry.unbalanced_model(spec)
    assert exc.value.path == ("mechanism", "joints", 2, field)
    assert words in str(exc.value)


def test_pressure_angle_out_of_range_is_rejected():
    from balpipe.loader import SpecErrors

    with pytest.raises(SpecErrors) as exc:
        load_text(_custom_gear_spec(radius_a="0.1 m", radius_b="0.05 m", pressure_angle="95 deg"), "g.yaml")
    assert "pressure_angle" in str(exc.value)
