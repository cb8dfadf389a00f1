"""The generic engine on hand-built models: closed loops, gears with moving carriers, errors."""

import math

import numpy as np
import pytest

from balpipe.engine import AnalysisError, analyse
from balpipe.model import FRAME, Body, Driver, Gear, Model, Revolute
from balpipe.motion import PROFILES, PointToPoint
from balpipe.spec import Spec
from balpipe import registry


def bar(name, L, m, rng):
    return Body(name, m, (float(rng.uniform(0.2, 0.8)) * L, float(rng.uniform(-0.05, 0.05))),
                float(rng.uniform(0.01, 0.1)) * m * L * L, {"P": (0.0, 0.0), "Q": (L, 0.0)}, outline=("P", "Q"))


def four_bar(rng, sweep=1.0, T=0.4):
    """Crank-rocker: ground 0.4, crank 0.1, coupler 0.35, rocker 0.3."""
    g, a, b, c = 0.4, 0.1, 0.35, 0.3
    th = 0.7
    B = np.array([a * math.cos(th), a * math.sin(th)])
    D = np.array([g, 0.0])
    d = np.linalg.norm(D - B)
    ang = math.atan2(D[1] - B[1], D[0] - B[0]) + math.acos((b * b + d * d - c * c) / (2 * b * d))
    C = B + b * np.array([math.cos(ang), math.sin(ang)])
    phi3 = math.atan2(C[1] - D[1], C[0] - D[0])
    bodies = (bar("crank", a, 1.0, rng), bar("coupler", b, 2.0, rng), bar("rocker", c, 1.5, rng))
    joints = (
        Revolute("A", FRAME, "crank", (0.0, 0.0), (0.0, 0.0)),
        Revolute("B", "crank", "coupler", (a, 0.0), (0.0, 0.0)),
        Revolute("C", "coupler", "rocker", (b, 0.0), (c, 0.0)),
        Revolute("D", FRAME, "rocker", (g, 0.0), (0.0, 0.0)),
    )
    law = PointToPoint(th, th + sweep * 2 * math.pi, T, PROFILES["cycloidal"])
    return Model("four-bar", bodies, joints, (Driver("crank", ("joint", "A"), law),),
                 {"crank": (0, 0, th), "coupler": (B[0], B[1], ang), "rocker": (g, 0, phi3)})


@pytest.mark.parametrize("seed", range(5))
def test_closed_loop_reactions_agree_with_momentum(seed):
    rng = np.random.default_rng(seed)
    t = np.linspace(0, 0.4, 401)
    an = analyse(four_bar(rng), t, gravity=(0.0, -9.81), moment_point=(0.1, 0.05))
    df, dm = an.route_difference()
    assert df <= 1e-9 * an.max_force and dm <= 1e-9 * an.max_moment
    # the loop closes at every sample: C computed from the coupler and from the rocker agree
    k = an.names.index("coupler")
    assert np.isfinite(an.q).all() and an.q.shape == (401, 3, 3) and k == 1


def test_geared_disc_on_a_moving_carrier_conserves_angular_momentum():
    """A planetary disc on an arm, geared (ratio -2) to a gear fixed on a second arm; both arms
    driven. The mesh couple lands on the carrier, so the routes agree."""
    rng = np.random.default_rng(4)
    arm1, arm2 = bar("arm1", 0.3, 1.0, rng), bar("arm2", 0.2, 0.7, rng)
    disc = Body("disc", 0.3, (0.0, 0.0), 0.002, {"O": (0.0, 0.0)}, radius=0.04, kind="gear")
    model = Model(
        "planetary", (arm1, arm2, disc),
        (Revolute("A", FRAME, "arm1", (0.0, 0.0), (0.0, 0.0)),
         Revolute("B", "arm1", "arm2", (0.3, 0.0), (0.0, 0.0)),
         Revolute("D", "arm1", "disc", (0.15, 0.0), (0.0, 0.0)),
         Gear("mesh", "arm2", "disc", "arm1", -2.0)),
        (Driver("q1", ("joint", "A"), PointToPoint(0.0, 1.5, 0.5, PROFILES["quintic"])),
         Driver("q2", ("joint", "B"), PointToPoint(0.2, -1.0, 0.5, PROFILES["quintic"]))),
        {"arm1": (0, 0, 0.0), "arm2": (0.3, 0, 0.2), "disc": (0.15, 0.0, 0.0)},
    )
    an = analyse(model, np.linspace(0, 0.5, 301))
    df, dm = an.route_difference()
    assert dm <= 1e-9 * an.max_moment and df <= 1e-9 * an.max_force
    # the disc turns relative to its carrier at -2 times arm2's relative rate
    i1, i2, i3 = (an.names.index(n) for n in ("arm1", "arm2", "disc"))
    w = an.v[:, :, 2]
    assert np.allclose(w[:, i3] - w[:, i1], -2.0 * (w[:, i2] - w[:, i1]), atol=1e-9)


def test_motion_outside_the_workspace_names_time_and_joint():
    """Driving the rocker of a crank-rocker through a full turn is impossible."""
    rng = np.random.default_rng(0)
    m = four_bar(rng)
    # from the assembled rocker angle, swing it by 3 rad
    phi = m.initial["rocker"][2]
    rocker_driven = Model(m.name, m.bodies, m.joints,
                          (Driver("rocker", ("joint", "D"), PointToPoint(phi, phi + 3.0, 0.4, PROFILES["quintic"])),),
                          m.initial)
    with pytest.raises(AnalysisError) as exc:
        analyse(rocker_driven, np.linspace(0, 0.4, 201))
    msg = str(exc.value)
    assert "t = " in msg and exc.value.time is not None and 0 < exc.value.time < 0.4
    assert exc.value.joint in {"A", "B", "C", "D", "rocker"}


def test_custom_template_matches_the_slider_crank_template():
    """The same slider-crank written as a custom body/joint list gives the same loads."""
    sc = {
        "name": "sc", "validation": {"enabled": False},
        "mechanism": {"template": "slider_crank",
                      "crank": {"length": 0.2, "mass": 1.0, "com": 0.08, "inertia": 0.004},
                      "coupler": {"length": 0.3, "mass": 0.8, "com": 0.1, "inertia": 0.006},
                      "slider": {"mass": 0.5}},
        "motion": {"duration": 0.3, "drive": {"crank": {"from": 0.3, "to": 2.0}}},
    }
    B = (0.2 * math.cos(0.3), 0.2 * math.sin(0.3))
    phi = -math.asin(B[1] / 0.3)
    C = (B[0] + 0.3 * math.cos(phi), 0.0)
    custom = {
        "name": "custom", "validation": {"enabled": False},
        "mechanism": {"template": "custom", "frame_points": {"A": [0, 0]},
                      "bodies": [
                          {"name": "crank", "mass": 1.0, "com": [0.08, 0], "inertia": 0.004,
                           "points": {"A": [0, 0], "B": [0.2, 0]}, "pose": [0, 0, 0.3]},
                          {"name": "coupler", "mass": 0.8, "com": [0.1, 0], "inertia": 0.006,
                           "points": {"B": [0, 0], "C": [0.3, 0]}, "pose": [B[0], B[1], phi]},
                          {"name": "slider", "mass": 0.5, "pose": [C[0], C[1], 0], "kind": "slider"}],
                      "joints": [
                          {"type": "revolute", "name": "A", "a": "frame", "b": "crank", "point_a": "A", "point_b": "A"},
                          {"type": "revolute", "name": "B", "a": "crank", "b": "coupler", "point_a": "B", "point_b": "B"},
                          {"type": "revolute", "name": "C", "a": "coupler", "b": "slider", "point_a": "C"},
                          {"type": "prismatic", "name": "guide", "guide": "frame", "slider": "slider",
                           "point_guide": [0, 0], "axis": [1, 0]}],
                      "drivers": [{"name": "crank", "joint": "A"}]},
        "motion": {"duration": 0.3, "drive": {"crank": {"from": 0.3, "to": 2.0}}},
    }
    t = np.linspace(0, 0.3, 101)
    a = analyse(registry.balance(Spec.model_validate(sc)).stages[0].model, t)
    b = analyse(registry.balance(Spec.model_validate(custom)).stages[0].model, t)
    assert np.allclose(a.force, b.force, atol=1e-9 * a.max_force)
    assert np.allclose(a.moment, b.moment, atol=1e-9 * a.max_moment)
    assert np.allclose(a.efforts["crank"], b.efforts["crank"], atol=1e-9)


def test_absolute_angle_drivers_put_their_reaction_on_the_frame():
    rng = np.random.default_rng(9)
    a1, a2 = bar("l1", 0.3, 1.2, rng), bar("l2", 0.25, 0.8, rng)
    model = Model("2R", (a1, a2),
                  (Revolute("A", FRAME, "l1", (0.0, 0.0), (0.0, 0.0)), Revolute("B", "l1", "l2", (0.3, 0.0), (0.0, 0.0))),
                  (Driver("t1", ("angle", "l1"), PointToPoint(0.1, 1.2, 0.5, PROFILES["quintic"])),
                   Driver("t2", ("angle", "l2"), PointToPoint(0.5, -0.7, 0.5, PROFILES["quintic"]))),
                  {"l1": (0, 0, 0.1), "l2": (0.3 * math.cos(0.1), 0.3 * math.sin(0.1), 0.5)})
    an = analyse(model, np.linspace(0, 0.5, 201))
    df, dm = an.route_difference()
    assert an.max_moment > 0.1 and dm <= 1e-9 * an.max_moment and df <= 1e-9 * an.max_force


def test_joint_reactions_balance_each_body():
    """Named reactions: the frame pivot of a four-bar crank carries minus the force on the frame
    from that joint, and Newton's law holds for the slider of a slider-crank."""
    spec = Spec.model_validate({
        "name": "sc", "validation": {"enabled": False},
        "mechanism": {"template": "slider_crank", "offset": 0.02,
                      "crank": {"length": 0.2, "mass": 1.0, "com": 0.08, "inertia": 0.004},
                      "coupler": {"length": 0.3, "mass": 0.8, "com": 0.1, "inertia": 0.006},
                      "slider": {"mass": 0.5}},
        "motion": {"duration": 0.3, "drive": {"crank": {"from": 0.3, "to": 2.0}}},
    })
    model = registry.balance(spec).stages[0].model
    an = analyse(model, np.linspace(0, 0.3, 101))
    k = an.names.index("slider")
    m3 = model.body("slider").mass_properties()[0]
    RC = np.stack([an.reactions["C"]["Fx"], an.reactions["C"]["Fy"]], axis=1)  # on the slider
    N = an.reactions["guide"]["N"]  # along the guide's left normal, +y here
    assert np.allclose(m3 * an.a[:, k, 0], RC[:, 0], atol=1e-9 * np.abs(RC).max())
    assert np.allclose(0.0, RC[:, 1] + N, atol=1e-9 * np.abs(RC).max())
    # the frame takes minus the pivot force at A and minus the guide's normal force
    frame_load = -np.stack([an.reactions["A"]["Fx"], an.reactions["A"]["Fy"] + N], axis=1)
    assert np.allclose(frame_load, an.force, atol=1e-9 * an.max_force)


@pytest.mark.parametrize("seed", [None, 0, 1, 2, 3])
def test_a_grid_inside_the_motion_lies_on_the_branch_of_the_whole_motion(seed):
    """Model.initial is the pose at t = 0: a few samples far inside the motion (the torque-driven
    run's efforts at a law's jump) are reached from there by continuation, not assembled on
    their own. Assembled at t[0] from the initial pose, the offset slider-crank at 293 deg of its
    crank (seed None) put the slider on the other side of the crank, where a mechanism that
    never changes branch cannot be. Random slider-cranks (seeded): every random sparse grid
    agrees with the whole motion's samples."""
    from conftest import slider_crank_spec

    if seed is None:
        spec = slider_crank_spec(law="trapezoidal", duration=0.5)
        data = spec.model_dump(mode="json", exclude_none=True)
        data["mechanism"].update(offset=0.03, crank={"length": 0.2, "mass": 1.2, "com": 0.1, "inertia": 0.004},
                                 coupler={"length": 0.3, "mass": 0.9, "com": 0.15, "inertia": 0.00675},
                                 slider={"mass": 0.6})
        data["motion"]["drive"] = {"crank": {"from": 0.0, "to": 2 * math.pi}}
        spec = Spec.model_validate(data)
        t = np.linspace(0.0, 0.5, 1001)
        grids = [t[[730]], t[[729, 731]], t[[270, 730]], t[500:]]
    else:
        rng = np.random.default_rng(300 + seed)
        spec = slider_crank_spec(rng, law="trapezoidal")
        t = np.linspace(0.0, spec.motion.duration, 601)
        grids = [np.sort(rng.choice(np.arange(1, 601), size=n, replace=False)) for n in (1, 2, 3, 5)]
        grids = [t[g] for g in grids] + [t[300:]]
    model = registry.balance(spec).stages[0].model
    whole = analyse(model, t)
    for sub in grids:
        part = analyse(model, sub)
        idx = np.searchsorted(t, sub)
        assert np.allclose(part.q, whole.q[idx], atol=1e-9), (seed, sub)
        assert np.allclose(part.efforts["crank"], whole.efforts["crank"][idx], atol=1e-9 * np.max(np.abs(whole.efforts["crank"])))
