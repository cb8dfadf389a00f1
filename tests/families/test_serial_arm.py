"""The serial nR arm template: inverse kinematics (paper 003, eqs. 8-10), exact task-space laws,
and the explicit serial dynamics against the engine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from balpipe import registry
from balpipe.engine import analyse

from balpipe.families.serial_arm.template import (
    ArmGeometry,
    TaskMotion,
    JointSolution,
    arm_state,
    com_chain,
    joint_torques,
    shaking_loads,
    tip_chain,
)
from balpipe.motion import PointToPoint, quintic
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError


def arm_spec(rng: np.random.Generator, n: int = 3, drive: dict | None = None, gravity: bool = False,
             payload: float | None = None, offsets: bool = True, duration: float = 0.5, **balancing) -> Spec:
    links = []
    for _ in range(n):
        L = float(rng.uniform(0.2, 0.6))
        m = float(rng.uniform(0.5, 5.0))
        links.append({"length": L, "mass": m, "com": float(rng.uniform(0.1, 0.7) * L),
                      "com_offset": float(rng.uniform(-0.1, 0.1) * L) if offsets else 0.0,
                      "inertia": m * L * L * float(rng.uniform(0.03, 0.1))})
    if drive is None:
        drive = {f"q{k + 1}": {"from": float(rng.uniform(-1, 1)), "to": float(rng.uniform(-1, 1))} for k in range(n)}
    data = {
        "name": "random arm",
        "mechanism": {"template": "serial_arm", "links": links},
        "motion": {"law": "quintic", "duration": duration, "drive": drive},
        "analysis": {"samples": 121, "gravity": gravity},
    }
    if payload:
        data["mechanism"]["payload"] = {"mass": payload}
    if balancing:
        data["balancing"] = balancing
    return Spec.model_validate(data)


def eq8_q1(chain, P, phi, sign: int) -> float:
    """Paper 003's eq. 8 as read: a cos q1 + b sin q1 + c = 0 with a = -2 l1 (x - l3 cos phi),
    b = -2 l1 (y - l3 sin phi), c = |W|^2 + l1^2 - l2^2, q1 = 2 atan((-b +- sqrt(b^2 - c^2 + a^2)) / (c - a))."""
    l1, l2, l3 = (v[0] for v in chain.vectors)
    wx, wy = P[0] - l3 * math.cos(phi), P[1] - l3 * math.sin(phi)
    a, b = -2 * l1 * wx, -2 * l1 * wy
    c = wx * wx + wy * wy + l1 * l1 - l2 * l2
    return 2 * math.atan((-b + sign * math.sqrt(b * b - c * c + a * a)) / (c - a))


def test_working_mode_plus_is_the_plus_root_of_eq_8(rng):
    for _ in range(20):
        model = registry.unbalanced_model(arm_spec(rng, offsets=False))
        arm = ArmGeometry.of(model)
        for chain in (tip_chain(arm), com_chain(arm)):
            q = np.array([rng.uniform(0, math.pi), -rng.uniform(0.3, 2.5), rng.uniform(-1, 1)])
            P = chain.point(q[None])[0]
            phi = q.sum()
            for mode, sign in ((1, 1), (-1, -1)):
                sol, margin = chain.inverse(P[None], np.array([phi]), mode)
                expect = eq8_q1(chain, P, phi, sign)
                assert math.remainder(sol[0, 0] - expect, 2 * math.pi) == pytest.approx(0, abs=1e-9)
                assert np.allclose(chain.point(sol), P, atol=1e-12) and margin[0] > 0
                assert np.cumsum(sol[0])[-1] == pytest.approx(phi)
            # the '+' mode is the configuration with q2 < 0 (centres of mass on the axes)
            sol, _ = chain.inverse(P[None], np.array([phi]), 1)
            assert np.allclose(sol[0], q, atol=1e-9)


def test_task_space_laws_are_exact(rng):
    """The arm driven by its tip follows the straight line: positions, velocities and
    accelerations of the tip from the engine equal the law's to round-off."""
    for n in (2, 3):
        spec = arm_spec(rng, n=n, drive={"tip": {"from": [0.3, 0.2] + ([0.1] if n == 3 else []),
                                                  "to": [0.1, 0.45] + ([1.0] if n == 3 else [])}})
        spec = _reachable(spec, rng)
        model = registry.unbalanced_model(spec)
        t = registry.time_grid(spec)
        an = analyse(model, t)
        k = an.names.index(f"link{n}")
        L = model.body(f"link{n}").point("tip")[0]
        pose = an.frame_pose[:, k]
        tip = pose[:, :2] + L * np.stack([np.cos(pose[:, 2]), np.sin(pose[:, 2])], axis=1)
        law = quintic(t / t[-1])[0]
        start, end = np.array(spec.motion.drive["tip"].start[:2]), np.array(spec.motion.drive["tip"].end[:2])
        assert np.allclose(tip, start + law[:, None] * (end - start), atol=1e-10)
        # accelerations: the tip's from the engine's body accelerations
        th, w, al = an.q[:, k, 2], an.v[:, k, 2], an.a[:, k, 2]
        cl = np.array(model.body(f"link{n}").mass_properties()[1])
        rel = np.array([L, 0.0]) - cl
        c, s = np.cos(th), np.sin(th)
        u = np.stack([c * rel[0] - s * rel[1], s * rel[0] + c * rel[1]], axis=1)
        acc = an.a[:, k, :2] + al[:, None] * np.stack([-u[:, 1], u[:, 0]], axis=1) - (w**2)[:, None] * u
        T = t[-1]
        expect = (end - start)[None, :] * quintic(t / T)[2][:, None] / T**2
        assert np.allclose(acc, expect, atol=1e-8 * np.abs(expect).max())


def _reachable(spec: Spec, rng) -> Spec:
    """Scale the tip drive into the arm's reach."""
    L = sum(lk.length for lk in spec.mechanism.links)
    d = spec.motion.drive["tip"]
    k = 0.6 * L / 0.55
    start = [d.start[0] * k, d.start[1] * k] + list(d.start[2:])
    end = [d.end[0] * k, d.end[1] * k] + list(d.end[2:])
    data = spec.model_dump(by_alias=True)
    data["motion"]["drive"]["tip"] = {"from": start, "to": end}
    return Spec.model_validate(data)


@pytest.mark.parametrize("gravity", [False, True])
def test_explicit_dynamics_equal_the_engine(rng, gravity):
    for _ in range(4):
        spec = arm_spec(rng, n=int(rng.integers(2, 5)), gravity=gravity, payload=float(rng.uniform(0, 3)))
        model = registry.unbalanced_model(spec)
        t = registry.time_grid(spec)
        g = (0.0, -9.80665) if gravity else (0.0, 0.0)
        P = (float(rng.uniform(-0.2, 0.2)), float(rng.uniform(-0.2, 0.2)))
        an = analyse(model, t, g, P)
        arm = ArmGeometry.of(model)
        laws = [d.law(t) for d in model.drivers]
        q, qd, qdd = (np.stack([v[k] for v in laws], axis=1) for k in range(3))
        st = arm_state(arm, q, qd, qdd)
        F, M = shaking_loads(arm, st, g, P)
        assert np.max(np.abs(F - an.force)) <= 1e-9 * an.max_force
        assert np.max(np.abs(M - an.moment)) <= 1e-9 * an.max_moment
        tau = joint_torques(arm, st, g)
        for j in range(arm.n):
            e = an.efforts[f"q{j + 1}"]
            assert np.max(np.abs(tau[:, j] - e)) <= 1e-9 * np.max(np.abs(e))


def test_com_motion_moves_the_total_centre_of_mass_on_its_law(rng):
    spec = arm_spec(rng, n=3, payload=2.0)
    model = registry.unbalanced_model(spec)
    arm = ArmGeometry.of(model)
    chain = com_chain(arm)
    q0 = np.array([1.2, -1.0, 0.4])
    q1 = np.array([1.7, -0.7, 1.2])
    c0, c1 = chain.point(q0[None])[0], chain.point(q1[None])[0]
    T = 0.4
    from balpipe.families.serial_arm.template import joint_laws, with_joint_laws
    from balpipe.motion import bang_bang

    motion = TaskMotion((PointToPoint(c0[0], c1[0], T, bang_bang), PointToPoint(c0[1], c1[1], T, bang_bang),
                         PointToPoint(q0.sum(), q1.sum(), T, quintic)), "com")
    t = np.linspace(0, T, 201)
    driven = with_joint_laws(model, joint_laws(chain, motion, 1))
    an = analyse(driven, t)
    s = bang_bang(t / T)[0]
    assert np.allclose(an.com, c0 + s[:, None] * (c1 - c0), atol=1e-10)
    d = float(np.hypot(*(c1 - c0)))
    assert an.max_force == pytest.approx(4 * arm.total_mass * d / T**2, rel=1e-9)


def check(tmp_path, text: str):
    import subprocess
    import sys

    f = tmp_path / "arm.yaml"
    f.write_text(text, encoding="utf-8")
    return subprocess.run([sys.executable, "-m", "balpipe", "check", str(f)], capture_output=True, text=True)


def test_out_of_reach_tip_is_a_located_error(tmp_path):
    text = """name: arm
mechanism:
  template: serial_arm
  links:
    - {length: 0.5 m, mass: 1 kg, com: 0.25 m, inertia: 0.02 kg m^2}
    - {length: 0.3 m, mass: 1 kg, com: 0.15 m, inertia: 0.01 kg m^2}
motion:
  duration: 1 s
  drive:
    tip: {from: [0.5 m, 0.2 m], to: [0.9 m, 0.3 m]}
"""
    out = check(tmp_path, text)
    assert out.returncode == 2, out.stderr
    assert "arm.yaml:10:10: motion.drive.tip: trajectory tip: at t = " in out.stderr
    assert "out of reach" in out.stderr and "Traceback" not in out.stderr


def test_joint_solution_reports_singular_configurations(rng):
    spec = arm_spec(rng, n=2, offsets=False, drive={"q1": {"from": 0, "to": 1}, "q2": {"from": 0.5, "to": 1}})
    arm = ArmGeometry.of(registry.unbalanced_model(spec))
    L = sum(arm.lengths)
    # a straight line through the stretched configuration (|P| = l1 + l2 at t = T/2)
    motion = TaskMotion((PointToPoint(0.9 * L, L, 1.0, quintic), PointToPoint(0.0, 0.0, 1.0, quintic)), "tip",
                        ("motion", "drive", "tip"), "stretch")
    with pytest.raises(SpecFieldError) as exc:
        JointSolution(tip_chain(arm), motion, 1, np.linspace(0, 1, 101))
    assert "trajectory stretch: singular configuration at t = 1 s" in str(exc.value)


@pytest.mark.parametrize("drive,where,message", [
    ({"q1": {"from": 0, "to": 1}}, ("motion", "drive"), "drive every joint (missing: q2, q3)"),
    ({"q4": {"from": 0, "to": 1}}, ("motion", "drive", "q4"), "unknown drive 'q4'"),
    ({"tip": {"from": [0.3, 0.3, 0], "to": [0.3, 0.4, 0]}, "q1": {"from": 0, "to": 1}},
     ("motion", "drive", "tip"), "drive either the tip or the joints"),
    ({"tip": {"from": [0.3, 0.3], "to": [0.3, 0.4, 0]}}, ("motion", "drive", "tip", "from"), "expected the tip pose [x, y, phi]"),
    ({"tip": {"from": [0.3, 0.3, "2 kg"], "to": [0.3, 0.4, 0]}}, ("motion", "drive", "tip", "from"), "kg"),
])
def test_bad_drives_are_located(rng, drive, where, message):
    spec = arm_spec(rng, n=3, drive=drive)
    with pytest.raises(SpecFieldError) as exc:
        registry.unbalanced_model(spec)
    assert exc.value.path == where and message in exc.value.message


def test_decoupling_and_planning_need_their_arms(rng):
    two = arm_spec(rng, n=2, method="com_motion_planning")
    with pytest.raises(SpecFieldError, match="plans a 3R arm"):
        registry.balance(two)
    three = arm_spec(rng, n=3, method="gear_decoupling", gear_1p={"position": 0.1, "mass": 1},
                     counterweights={"link1": {"distance": 0.1}, "link2": {"distance": 0.1}},
                     counter_rotation={"position": [0, -0.2]})
    with pytest.raises(SpecFieldError, match="balances a 2R arm"):
        registry.balance(three)


@pytest.mark.parametrize("n", [1, 2, 3, 5])
def test_absolute_state_positions_by_the_chain_and_its_layout(rng, n):
    """Centres of mass and proximal joints by the chain written sample by sample (point = base +
    sum of R(theta_i) (l_i, 0) over the previous links + R(theta_k) c_k), and accelerations by
    central differences of those positions; every field an (N, n) C-ordered array."""
    from balpipe.families.serial_arm.template import absolute_state

    arm = ArmGeometry((0.1, -0.2), tuple(rng.uniform(0.2, 0.6, n)), tuple(rng.uniform(0.5, 5, n)),
                      tuple(tuple(c) for c in rng.uniform(-0.1, 0.3, (n, 2))), tuple(rng.uniform(0.01, 0.2, n)))
    w0, w1, w2 = rng.uniform(-2, 2, (3, n))
    th = lambda t: w0 + w1 * t[:, None] + w2 * np.sin(3 * t)[:, None]  # noqa: E731
    thd = lambda t: w1 + 3 * w2 * np.cos(3 * t)[:, None]  # noqa: E731
    thdd = lambda t: -9 * w2 * np.sin(3 * t)[:, None]  # noqa: E731
    t, h = np.linspace(0.0, 1.0, 41), 1e-4
    st = absolute_state(arm, th(t), thd(t), thdd(t))
    for f in ("rx", "ry", "ax", "ay", "ox", "oy"):
        a = getattr(st, f)
        assert a.shape == (len(t), n) and a.flags.c_contiguous
    for i, tk in enumerate(t):
        a = th(np.array([tk]))[0]
        o = np.array(arm.base, dtype=float)
        for k in range(n):
            R = np.array([[math.cos(a[k]), -math.sin(a[k])], [math.sin(a[k]), math.cos(a[k])]])
            assert np.allclose([st.ox[i, k], st.oy[i, k]], o, atol=1e-14)
            assert np.allclose([st.rx[i, k], st.ry[i, k]], o + R @ np.asarray(arm.coms[k]), atol=1e-14)
            o = o + R @ np.array([arm.lengths[k], 0.0])
    p, m = absolute_state(arm, th(t + h), thd(t + h), thdd(t + h)), absolute_state(arm, th(t - h), thd(t - h), thdd(t - h))
    assert np.allclose(st.ax, (p.rx - 2 * st.rx + m.rx) / h**2, atol=1e-5)
    assert np.allclose(st.ay, (p.ry - 2 * st.ry + m.ry) / h**2, atol=1e-5)
