"""Motors distinct from the prescribed coordinates (issue 20, item 2; DESIGN.md "Real machines").

The motors' efforts of a 3-RRR (platform pose prescribed, motors at the base joints) and of a
plain five-bar (gripper prescribed, motors at A1, A2) are checked against the principle of
virtual work written here from scratch: each leg's inverse kinematics (positions, rates,
accelerations of a dyad from its pivot to its end point), the generalized inertial force
f = sum_k J_k^T (M_k a_k - Q_k) in the prescribed coordinates X, and the actuators' rates
G = d(actuated joint coordinates)/dX, so that G^T tau = f. Redundant actuation: the engine's
efforts are the minimum-norm solution, np.linalg.lstsq of the same equations.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
import yaml

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import SpecErrors, load, load_text

ROOT = Path(__file__).resolve().parents[2]
G0 = 9.80665


def _si(v) -> float:
    """A spec number with an optional unit (kg, kg m^2, m, s, deg) in SI."""
    if not isinstance(v, str):
        return float(v)
    x = float(v.split()[0])
    return math.radians(x) if v.endswith("deg") else x


def _perp(v):
    return np.stack([-v[..., 1], v[..., 0]], axis=-1)


def _e(th):
    return np.stack([np.cos(th), np.sin(th)], axis=-1)


def _rot(th, s):
    s = np.asarray(s, float)
    return _e(th) * s[0] + _perp(_e(th)) * s[1]


def _quintic(t, T, a, b):
    """3-4-5 law from a to b in T: value, rate, acceleration (N, ...)."""
    u = np.clip(t / T, 0, 1)[:, None]
    a, b = np.asarray(a, float), np.asarray(b, float)
    s = 10 * u**3 - 15 * u**4 + 6 * u**5
    ds = (30 * u**2 - 60 * u**3 + 30 * u**4) / T
    dds = (60 * u - 180 * u**2 + 120 * u**3) / T**2
    return a + (b - a) * s, (b - a) * ds, (b - a) * dds


def _leg(A, l1, l2, sigma, C, dC, ddC):
    """Dyad A -(l1)- B -(l2)- C: absolute angles th1, th2 with rates and accelerations."""
    d = C - np.asarray(A, float)
    dist = np.hypot(d[:, 0], d[:, 1])
    beta = np.arccos((l1**2 + dist**2 - l2**2) / (2 * l1 * dist))
    th1 = np.arctan2(d[:, 1], d[:, 0]) + sigma * beta
    B = np.asarray(A, float) + l1 * _e(th1)
    th2 = np.arctan2(*(C - B).T[::-1])
    M = np.stack([l1 * _perp(_e(th1)), l2 * _perp(_e(th2))], axis=-1)  # (N, 2, 2): C' = M [w1, w2]
    w = np.linalg.solve(M, dC[..., None])[..., 0]
    rhs = ddC + l1 * _e(th1) * w[:, :1] ** 2 + l2 * _e(th2) * w[:, 1:] ** 2
    al = np.linalg.solve(M, rhs[..., None])[..., 0]
    return (th1, th2), w, al, M


def _bar_motion(origin, dorigin, ddorigin, th, w, al, s):
    """Centre of mass of a bar whose frame origin moves as given: position, velocity, acceleration."""
    r = _rot(th, s)
    return origin + r, dorigin + w[:, None] * _perp(r), ddorigin + al[:, None] * _perp(r) - (w**2)[:, None] * r


def virtual_work_efforts(bodies, rates_per_dof, act_rates, g):
    """tau from G^T tau = f, f_i = sum_k (m_k (a_k - g) . dr_k/dX_i + I_k alpha_k dth_k/dX_i); the
    minimum-norm solution when G has more rows than columns. ``bodies``: {name: (m, I, a (N,2),
    alpha (N,))}; ``rates_per_dof``: per unit rate of X_i, {name: (v (N,2), w (N,))};
    ``act_rates``: per unit rate of X_i, (N, na) actuated-coordinate rates."""
    nd = len(rates_per_dof)
    N = next(iter(bodies.values()))[2].shape[0]
    f = np.zeros((N, nd))
    for i, rates in enumerate(rates_per_dof):
        for name, (m, I, a, alpha) in bodies.items():
            v, w = rates[name]
            f[:, i] += m * np.sum((a - np.asarray(g)) * v, axis=1) + I * alpha * w
    G = np.stack(act_rates, axis=-1)  # (N, na, nd)
    return np.stack([np.linalg.lstsq(G[k].T, f[k], rcond=None)[0] for k in range(N)])


# --------------------------------------------------------------------------------------------
# 3-RRR


def rrr3_spec(rng=None, actuators=("A1", "A2", "A3"), gravity=False) -> dict:
    """A 3-RRR custom spec (the shipped one when rng is None, random masses, inertias, centres
    of mass, link lengths and platform motion otherwise)."""
    base = yaml.safe_load((ROOT / "specs/custom_3rrr_motors.yaml").read_text())
    spec = base
    mech = spec["mechanism"]
    mech["actuators"] = list(actuators)
    spec["analysis"] = {"samples": 201, "gravity": gravity}
    if rng is None:
        return spec
    R, r = 0.5, float(rng.uniform(0.08, 0.12))
    l1, l2 = float(rng.uniform(0.32, 0.38)), float(rng.uniform(0.32, 0.38))
    bodies = {b["name"]: b for b in mech["bodies"]}
    for i, ang in enumerate((90, 210, 330), start=1):
        t = math.radians(ang)
        A = R * np.array([math.cos(t), math.sin(t)])
        C = r * np.array([math.cos(t), math.sin(t)])
        mech["frame_points"][f"A{i}"] = A.tolist()
        bodies["platform"]["points"][f"C{i}"] = C.tolist()
        d = np.linalg.norm(C - A)
        th1 = math.atan2(*(C - A)[::-1]) + math.acos((l1**2 + d**2 - l2**2) / (2 * l1 * d))
        B = A + l1 * np.array([math.cos(th1), math.sin(th1)])
        for name, L, pose in ((f"prox{i}", l1, (A, th1)), (f"dist{i}", l2, (B, math.atan2(*(C - B)[::-1])))):
            b = bodies[name]
            m = float(rng.uniform(0.3, 2.0))
            b.update(mass=m, com=[float(rng.uniform(0.2, 0.8) * L), float(rng.uniform(-0.1, 0.1) * L)],
                     inertia=m * L * L * float(rng.uniform(0.05, 0.12)),
                     pose=[float(pose[0][0]), float(pose[0][1]), float(pose[1])])
            b["points"][list(b["points"])[1]] = [L, 0.0]
    p = bodies["platform"]
    p.update(mass=float(rng.uniform(0.5, 3)), com=[float(rng.uniform(-0.02, 0.02)), float(rng.uniform(-0.02, 0.02))],
             inertia=float(rng.uniform(0.002, 0.01)))
    drive = spec["motion"]["drive"]
    drive["x"]["to"] = float(rng.uniform(-0.05, 0.05))
    drive["y"]["to"] = float(rng.uniform(-0.05, 0.05))
    drive["phi"]["to"] = float(rng.uniform(-0.3, 0.3))
    spec["motion"]["duration"] = float(rng.uniform(0.2, 0.6))
    return spec


def model_of(spec: dict):
    s, _ = load_text(yaml.safe_dump(spec), "test.yaml")
    return s, registry.unbalanced_model(s)


def rrr3_reference(spec: dict, t: np.ndarray, actuators) -> dict[str, np.ndarray]:
    """The motors' efforts of the 3-RRR by virtual work, from the spec's numbers alone."""
    mech, motion = spec["mechanism"], spec["motion"]
    bodies = {b["name"]: b for b in mech["bodies"]}
    T, num = _si(motion["duration"]), _si
    d = motion["drive"]
    X, dX, ddX = _quintic(t, T, [num(d[k]["from"]) for k in ("x", "y", "phi")], [num(d[k]["to"]) for k in ("x", "y", "phi")])
    g = (0.0, -G0) if spec["analysis"].get("gravity") else (0.0, 0.0)
    plat = bodies["platform"]
    N = len(t)
    dyn, legs = {}, {}
    for i in (1, 2, 3):
        c = np.asarray(plat["points"][f"C{i}"], float)
        C, dC, ddC = _bar_motion(X[:, :2], dX[:, :2], ddX[:, :2], X[:, 2], dX[:, 2], ddX[:, 2], c)
        pr, di = bodies[f"prox{i}"], bodies[f"dist{i}"]
        l1, l2 = pr["points"]["B"][0], di["points"]["C"][0]
        A = np.asarray(mech["frame_points"][f"A{i}"], float)
        (th1, th2), w, al, M = _leg(A, l1, l2, 1, C, dC, ddC)
        legs[i] = (A, l1, th1, th2, M, c)
        z = np.zeros((N, 2))
        _, _, a1 = _bar_motion(A + z, z, z, th1, w[:, 0], al[:, 0], pr["com"])
        B, dB, ddB = _bar_motion(A + z, z, z, th1, w[:, 0], al[:, 0], (l1, 0.0))
        _, _, a2 = _bar_motion(B, dB, ddB, th2, w[:, 1], al[:, 1], di["com"])
        dyn[f"prox{i}"] = (_si(pr["mass"]), _si(pr["inertia"]), a1, al[:, 0])
        dyn[f"dist{i}"] = (_si(di["mass"]), _si(di["inertia"]), a2, al[:, 1])
    _, _, ap = _bar_motion(X[:, :2], dX[:, :2], ddX[:, :2], X[:, 2], dX[:, 2], ddX[:, 2], plat["com"])
    dyn["platform"] = (_si(plat["mass"]), _si(plat["inertia"]), ap, ddX[:, 2])
    rates_per_dof, act_rates = [], []
    for k in range(3):  # unit rate of x, y, phi
        u = np.zeros((N, 3))
        u[:, k] = 1.0
        rates, leg_w = {}, {}
        for i, (A, l1, th1, th2, M, c) in legs.items():
            dC = u[:, :2] + u[:, 2:3] * _perp(_rot(X[:, 2], c))
            w = np.linalg.solve(M, dC[..., None])[..., 0]
            leg_w[i] = w
            pr, di = bodies[f"prox{i}"], bodies[f"dist{i}"]
            rates[f"prox{i}"] = (w[:, :1] * _perp(_rot(th1, pr["com"])), w[:, 0])
            rates[f"dist{i}"] = (w[:, :1] * _perp(l1 * _e(th1)) + w[:, 1:] * _perp(_rot(th2, di["com"])), w[:, 1])
        rates["platform"] = (u[:, :2] + u[:, 2:3] * _perp(_rot(X[:, 2], plat["com"])), u[:, 2])
        rates_per_dof.append(rates)
        col = []
        for a in actuators:  # joint coordinate theta_b - theta_a of A_i (frame-prox) or B_i (prox-dist)
            i = int(a[1])
            col.append(leg_w[i][:, 0] if a[0] == "A" else leg_w[i][:, 1] - leg_w[i][:, 0])
        act_rates.append(np.stack(col, axis=1))
    tau = virtual_work_efforts(dyn, rates_per_dof, act_rates, g)
    return {a: tau[:, k] for k, a in enumerate(actuators)}


def _agree(efforts: dict, ref: dict) -> float:
    peak = max(float(np.max(np.abs(v))) for v in ref.values())
    return max(float(np.max(np.abs(efforts[k] - ref[k]))) for k in ref) / peak


@pytest.mark.parametrize("seed", [None, 1, 2, 3])
def test_3rrr_motor_torques_equal_virtual_work(seed):
    rng = None if seed is None else np.random.default_rng(seed)
    spec = rrr3_spec(rng, gravity=seed == 2)
    s, model = model_of(spec)
    t = registry.time_grid(s)
    an = analyse(model, t, (0.0, -G0) if seed == 2 else (0.0, 0.0))
    assert sorted(an.efforts) == ["A1", "A2", "A3"]  # the motors, not the platform's x, y, phi
    ref = rrr3_reference(spec, t, ("A1", "A2", "A3"))
    assert _agree(an.efforts, ref) < 1e-9
    # the frame loads still equal minus the momentum rate: the motors' reactions land on the frame
    df, dm = an.route_difference()
    assert df < 1e-9 * max(an.max_force, 1e-9) and dm < 1e-9 * max(an.max_moment, 1e-9)


@pytest.mark.parametrize("seed", [None, 4])
def test_3rrr_redundant_actuation_is_minimum_norm(seed):
    rng = None if seed is None else np.random.default_rng(seed)
    acts = ("A1", "A2", "A3", "B1")
    spec = rrr3_spec(rng, actuators=acts)
    s, model = model_of(spec)
    t = registry.time_grid(s)
    an = analyse(model, t)
    assert an.redundant_actuators == 1
    ref = rrr3_reference(spec, t, acts)  # np.linalg.lstsq of G^T tau = f: the minimum-norm tau
    assert _agree(an.efforts, ref) < 1e-9
    # and it is not the non-redundant solution: B1 takes a share
    assert float(np.max(np.abs(an.efforts["B1"]))) > 1e-3 * float(np.max(np.abs(an.efforts["A1"])))


def test_efforts_scale_with_masses_and_time():
    """masses x k => efforts x k; half the duration => 4x the efforts (no gravity)."""
    spec = rrr3_spec(np.random.default_rng(7))
    s, model = model_of(spec)
    base = analyse(model, registry.time_grid(s)).efforts
    heavy = dict(spec)
    heavy["mechanism"] = dict(spec["mechanism"])
    heavy["mechanism"]["bodies"] = [dict(b, mass=3 * _si(b["mass"]), inertia=3 * _si(b["inertia"])) for b in spec["mechanism"]["bodies"]]
    s2, m2 = model_of(heavy)
    e2 = analyse(m2, registry.time_grid(s2)).efforts
    fast = dict(spec, motion=dict(spec["motion"], duration=_si(spec["motion"]["duration"]) / 2))
    s3, m3 = model_of(fast)
    e3 = analyse(m3, registry.time_grid(s3)).efforts
    for k in base:
        assert np.allclose(e2[k], 3 * base[k], rtol=1e-9, atol=1e-12)
        assert np.allclose(e3[k], 4 * base[k], rtol=1e-9, atol=1e-12)


# --------------------------------------------------------------------------------------------
# five-bar


def five_bar_spec(rng=None) -> dict:
    spec = {
        "name": "plain five-bar, two motors",
        "mechanism": {
            "template": "five_bar", "pivots": {"A1": [-0.24, 0], "A2": [0.24, 0]},
            "links": {"proximal": {"length": 0.36, "mass": 1.2, "com": 0.18, "inertia": 0.012},
                      "distal": {"length": 0.30, "mass": 1.0, "com": 0.15, "inertia": 0.010}},
            "working_modes": [1, -1],
        },
        "motion": {"law": "quintic", "duration": 1.0, "drive": {"gripper": {"from": [-0.06, 0.45], "to": [0.1364, 0.4878]}}},
        "analysis": {"samples": 201},
    }
    if rng is not None:
        lk = spec["mechanism"]["links"]
        for key, L in (("proximal", 0.36), ("distal", 0.30), ("proximal_2", 0.36), ("distal_2", 0.30)):
            m = float(rng.uniform(0.3, 2))
            lk[key] = {"length": L, "mass": m, "com": float(rng.uniform(-0.1, 0.9) * L),
                       "com_offset": float(rng.uniform(-0.05, 0.05)), "inertia": m * L * L * float(rng.uniform(0.05, 0.12))}
        spec["motion"]["duration"] = float(rng.uniform(0.3, 1.5))
        spec["analysis"]["gravity"] = True
    return spec


def five_bar_reference(spec: dict, t: np.ndarray) -> dict[str, np.ndarray]:
    mech, motion = spec["mechanism"], spec["motion"]
    lk = mech["links"]
    legs = ((lk["proximal"], lk["distal"]), (lk.get("proximal_2", lk["proximal"]), lk.get("distal_2", lk["distal"])))
    d = motion["drive"]["gripper"]
    C, dC, ddC = _quintic(t, motion["duration"], d["from"], d["to"])
    g = (0.0, -G0) if spec["analysis"].get("gravity") else (0.0, 0.0)
    N = len(t)
    z = np.zeros((N, 2))
    dyn, geo = {}, {}
    for j, ((p, q), sigma) in enumerate(zip(legs, mech["working_modes"]), start=1):
        A = np.asarray(mech["pivots"][f"A{j}"], float)
        (th1, th2), w, al, M = _leg(A, p["length"], q["length"], sigma, C, dC, ddC)
        sp, sq = (p["com"], p.get("com_offset", 0.0)), (q["com"], q.get("com_offset", 0.0))
        _, _, a1 = _bar_motion(A + z, z, z, th1, w[:, 0], al[:, 0], sp)
        B, dB, ddB = _bar_motion(A + z, z, z, th1, w[:, 0], al[:, 0], (p["length"], 0.0))
        _, _, a2 = _bar_motion(B, dB, ddB, th2, w[:, 1], al[:, 1], sq)
        dyn[f"link{j}"] = (p["mass"], p["inertia"], a1, al[:, 0])
        dyn[f"link{j + 2}"] = (q["mass"], q["inertia"], a2, al[:, 1])
        geo[j] = (th1, th2, M, sp, sq, p["length"])
    rates_per_dof, act_rates = [], []
    for k in range(2):
        u = np.zeros((N, 2))
        u[:, k] = 1.0
        rates, col = {}, []
        for j, (th1, th2, M, sp, sq, l1) in geo.items():
            w = np.linalg.solve(M, u[..., None])[..., 0]
            rates[f"link{j}"] = (w[:, :1] * _perp(_rot(th1, sp)), w[:, 0])
            rates[f"link{j + 2}"] = (w[:, :1] * _perp(l1 * _e(th1)) + w[:, 1:] * _perp(_rot(th2, sq)), w[:, 1])
            col.append(w[:, 0])
        rates_per_dof.append(rates)
        act_rates.append(np.stack(col, axis=1))
    tau = virtual_work_efforts(dyn, rates_per_dof, act_rates, g)
    return {"A1": tau[:, 0], "A2": tau[:, 1]}


@pytest.mark.parametrize("seed", [None, 5, 6])
def test_five_bar_reports_its_two_motor_torques(seed):
    spec = five_bar_spec(None if seed is None else np.random.default_rng(seed))
    s, model = model_of(spec)
    t = registry.time_grid(s)
    an = analyse(model, t, (0.0, -G0) if s.analysis.gravity else (0.0, 0.0))
    assert sorted(an.efforts) == ["A1", "A2"]
    assert _agree(an.efforts, five_bar_reference(spec, t)) < 1e-9


def test_five_bar_virtual_gripper_forces_only_when_asked():
    spec = five_bar_spec()
    spec["mechanism"]["actuators"] = []
    s, model = model_of(spec)
    assert not model.actuators
    an = analyse(model, registry.time_grid(s))
    assert sorted(an.efforts) == ["gripper_x", "gripper_y"]
    from balpipe.diagnose import actuation

    assert "Virtual efforts" in actuation.virtual_note(model)
    assert actuation.virtual_note(model_of(five_bar_spec())[1]) is None


# --------------------------------------------------------------------------------------------
# errors


def _write(tmp_path, spec, name="bad.yaml") -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(spec, sort_keys=False))
    return p


@pytest.mark.parametrize("acts, expect", [
    (["A1", "A2"], "not realisable: the mechanism has 3 degrees of freedom but only 2"),
    (["A1", "Z9", "A3"], "unknown joint 'Z9'"),
    (["A1", "A1", "A3"], "named twice"),
])
def test_actuator_errors_are_located(tmp_path, acts, expect):
    from balpipe.runner import analyse as build_analyse

    spec = rrr3_spec(actuators=acts)
    path = _write(tmp_path, spec)
    loaded = load(path)
    with pytest.raises(SpecErrors) as err:
        build_analyse(loaded, simulate=False)
    msg = str(err.value)
    assert expect in msg
    text = path.read_text().splitlines()
    line = int(msg.split(":")[1])
    assert "actuators" in text[line - 1] or "- A" in text[line - 1] or "- Z9" in text[line - 1]


def test_prismatic_motor_force_in_newtons_by_power_balance():
    """A slider-crank whose crank angle is prescribed and whose motor pushes the slider: the
    motor's force F (N) satisfies F x' = sum_k (m_k (a_k - g) . v_k + I_k alpha_k w_k) (power)."""
    spec = {
        "name": "slider-crank, crank prescribed, linear motor on the slider",
        "mechanism": {
            "template": "custom",
            "bodies": [
                {"name": "crank", "mass": 1.3, "com": [0.04, 0.01], "inertia": 0.002, "pose": [0, 0, 0.3],
                 "points": {"A": [0, 0], "B": [0.1, 0]}},
                {"name": "coupler", "mass": 0.9, "com": [0.12, -0.005], "inertia": 0.006, "pose": [0.0955, 0.0296, -0.1],
                 "points": {"B": [0, 0], "C": [0.3, 0]}},
                {"name": "slider", "mass": 0.7, "com": [0.01, 0.0], "inertia": 0.001, "pose": [0.394, 0, 0], "points": {"C": [0, 0]}},
            ],
            "joints": [
                {"type": "revolute", "name": "A", "a": "frame", "b": "crank", "point_a": [0, 0], "point_b": "A"},
                {"type": "revolute", "name": "B", "a": "crank", "b": "coupler", "point_a": "B", "point_b": "B"},
                {"type": "revolute", "name": "C", "a": "coupler", "b": "slider", "point_a": "C", "point_b": "C"},
                {"type": "prismatic", "name": "guide", "guide": "frame", "slider": "slider", "point_guide": [0, 0], "axis": [1, 0]},
            ],
            "drivers": [{"name": "crank", "joint": "A"}],
            "actuators": ["guide"],
        },
        "motion": {"law": "quintic", "duration": 0.3, "drive": {"crank": {"from": 0.3, "to": 2.5}}},
        "analysis": {"samples": 301, "gravity": True},
    }
    s, model = model_of(spec)
    t = registry.time_grid(s)
    an = analyse(model, t, (0.0, -G0))
    F = an.efforts["guide"]
    power = np.zeros(len(t))
    for k, b in enumerate(model.bodies):
        m, _, inertia = b.mass_properties()
        power += m * np.sum((an.a[:, k, :2] - np.array([0.0, -G0])) * an.v[:, k, :2], axis=1) + inertia * an.a[:, k, 2] * an.v[:, k, 2]
    xdot = an.v[:, an.names.index("slider"), 0]
    assert np.max(np.abs(F * xdot - power)) < 1e-9 * np.max(np.abs(power))
    from balpipe.report.present import driver_unit

    assert driver_unit(model, "guide") == "N"
