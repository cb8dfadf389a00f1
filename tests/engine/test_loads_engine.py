"""Loads in the engine against an independent Newton-Euler computation written here.

A crank-rocker four-bar (random masses and centres of mass) carries a spring-damper from the
frame to the coupler, a torsional spring at the rocker's frame pivot, a tabulated force on the
rocker with rising and falling branches against a point's stroke, viscous friction at one pin and
Coulomb friction in two (one of them a frame bearing). The test writes each body's Newton-Euler
equations with the pin forces and the motor torque as unknowns, solves them per sample and finds
the Coulomb friction by its own fixed point (plain iteration, not the engine's Newton); efforts,
reactions and frame loads must agree to 1e-9 of their peaks.
"""

import dataclasses
import math

import numpy as np
import pytest

from balpipe.engine import AnalysisError, analyse
from balpipe.mechanics.loads import Anchor, AppliedLoad, ForceElement, JointFriction, LoadTable, TorsionElement
from balpipe.model import FRAME
from test_engine import four_bar

T = 0.4
GRID = np.linspace(0.0, T, 241)
GRAVITY = (0.0, -9.81)


def _table(rng):
    x = np.linspace(-0.2, 0.2, 9)
    up = 40.0 + 30.0 * rng.uniform(size=9)
    down = -10.0 + 20.0 * rng.uniform(size=9)
    return LoadTable(("stroke", "rocker", (0.3, 0.0), (0.0, 1.0), 0.05), (x, up), (x, down))


def loaded(rng, coulomb=(0.2, 0.15), external=True):
    base = four_bar(rng, sweep=1.0, T=T)
    loads = (
        ForceElement("spring", Anchor(FRAME, (0.1, 0.3)), Anchor("coupler", (0.2, 0.0)), stiffness=800.0,
                     free_length=0.15, preload=5.0, damping=12.0),
        TorsionElement("torsion", "D", stiffness=20.0, free_angle=1.0, preload=1.0, damping=0.3),
        AppliedLoad("rod", Anchor("rocker", (0.3, 0.0)), force=(0.3, -1.0), torque=0.02, axes="body",
                    law=_table(rng), source="external" if external else "internal"),
        JointFriction("fB", "B", viscous=0.05),
        JointFriction("fA", "A", viscous=0.02, coefficient=coulomb[0], pin_radius=0.01),
        JointFriction("fC", "C", coefficient=coulomb[1], pin_radius=0.012),
    )
    return dataclasses.replace(base, loads=loads)


def cross(u, w):
    return u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]


def perp(u):
    return np.stack([-u[..., 1], u[..., 0]], axis=-1)


def rot(th, p):
    c, s = np.cos(th), np.sin(th)
    return np.stack([c * p[0] - s * p[1], s * p[0] + c * p[1]], axis=-1)


def newton_euler(model, an):
    """Efforts, pin forces and frame load (F, M about O) by Newton-Euler per body, Coulomb by
    plain fixed-point iteration."""
    names = an.names
    N = len(an.t)
    com = {b.name: np.array(b.mass_properties()[1]) for b in model.bodies}
    mass = {b.name: b.mass_properties()[0] for b in model.bodies}
    inertia = {b.name: b.mass_properties()[2] for b in model.bodies}
    r = {n: an.q[:, k, :2] for k, n in enumerate(names)}
    v = {n: an.v[:, k, :2] for k, n in enumerate(names)}
    th = {n: an.q[:, k, 2] for k, n in enumerate(names)}
    w = {n: an.v[:, k, 2] for k, n in enumerate(names)}
    th[FRAME] = w[FRAME] = np.zeros(N)

    def point(body, p):
        if body == FRAME:
            return np.broadcast_to(np.array(p, float), (N, 2)), np.zeros((N, 2))
        arm = rot(th[body], np.array(p, float) - com[body])
        return r[body] + arm, v[body] + w[body][:, None] * perp(arm)

    # known loads: (body, point P or None, F or None, torque) lists; frame-side and external kept apart
    applied = []  # (body, P, F, M)
    frame_F, frame_M = np.zeros((N, 2)), np.zeros(N)
    ext_F, ext_M = np.zeros((N, 2)), np.zeros(N)
    lds = {ld.name: ld for ld in model.loads}
    s = lds["spring"]
    Pa, Va = point(s.a.body, s.a.point)
    Pb, Vb = point(s.b.body, s.b.point)
    d = Pb - Pa
    L = np.linalg.norm(d, axis=1)
    u = d / L[:, None]
    ten = s.preload + s.stiffness * (L - s.free_length) + s.damping * np.einsum("nk,nk->n", Vb - Va, u)
    applied.append((s.b.body, Pb, -ten[:, None] * u, 0.0))
    frame_F += ten[:, None] * u
    frame_M += cross(Pa, ten[:, None] * u)
    tz = lds["torsion"]
    jD = model.joint("D")
    phi = th[jD.b] - th[jD.a]
    torque = tz.preload + tz.stiffness * (phi - tz.free_angle) + tz.damping * (w[jD.b] - w[jD.a])
    applied.append((jD.b, None, None, -torque))
    frame_M += torque
    rod = lds["rod"]
    P, V = point(rod.at.body, rod.at.point)
    _, body, p_s, dirn, origin = rod.law.argument
    Ps, Vs = point(body, p_s)
    x, xd = Ps @ np.array(dirn) - origin, Vs @ np.array(dirn)
    val = np.where(xd < 0, np.interp(x, *rod.law.falling), np.interp(x, *rod.law.rising))
    F = rot(th[rod.at.body], np.array(rod.force)) * val[:, None]
    applied.append((rod.at.body, P, F, rod.torque * val))
    if rod.source == "external":
        ext_F += F
        ext_M += cross(P, F) + rod.torque * val
    else:
        frame_F -= F
        frame_M -= cross(P, F) + rod.torque * val
    fric = {ld.joint: ld for ld in model.loads if isinstance(ld, JointFriction)}

    joints = [j.name for j in model.joints]
    bodies = [b.name for b in model.bodies]
    nun = 2 * len(joints) + 1  # pin forces (on b from a), motor torque on the crank

    def solve(k, coulomb_torque):
        """Unknowns at sample k, given the Coulomb torques on b of every joint."""
        A = np.zeros((3 * len(bodies), nun))
        rhs = np.zeros(3 * len(bodies))
        bi = {n: i for i, n in enumerate(bodies)}
        for n in bodies:
            i = 3 * bi[n]
            a_lin = an.a[k, names.index(n), :2]
            alpha = an.a[k, names.index(n), 2]
            rhs[i:i + 2] = mass[n] * a_lin - mass[n] * np.array(GRAVITY)
            rhs[i + 2] = inertia[n] * alpha
        for jn, jt in enumerate(model.joints):
            Pj = point(jt.b, jt.point_b)[0][k]
            for body, sign in ((jt.b, 1.0), (jt.a, -1.0)):
                if body == FRAME:
                    continue
                i = 3 * bi[body]
                A[i:i + 2, 2 * jn:2 * jn + 2] += sign * np.eye(2)
                arm = Pj - r[body][k]
                A[i + 2, 2 * jn] += sign * -arm[1]
                A[i + 2, 2 * jn + 1] += sign * arm[0]
            f = fric.get(jt.name)
            wr = w[jt.b][k] - w[jt.a][k]
            tq = (-(f.viscous * wr) if f else 0.0) + coulomb_torque.get(jt.name, 0.0)
            for body, sign in ((jt.b, 1.0), (jt.a, -1.0)):
                if body != FRAME:
                    rhs[3 * bi[body] + 2] -= sign * tq
        A[3 * bi["crank"] + 2, -1] = 1.0  # motor torque on the crank (driver of joint A, a = frame)
        for body, Pp, Fp, Mp in applied:
            i = 3 * bi[body]
            Mk = Mp[k] if np.ndim(Mp) else Mp
            if Fp is not None:
                rhs[i:i + 2] -= Fp[k]
                rhs[i + 2] -= cross(Pp[k] - r[body][k], Fp[k])
            rhs[i + 2] -= Mk
        return np.linalg.solve(A, rhs)

    efforts = np.zeros(N)
    pins = {j: np.zeros((N, 2)) for j in joints}
    fF, fM = frame_F.copy(), frame_M.copy()
    for k in range(N):
        ct: dict[str, float] = {}
        for _ in range(400):
            x = solve(k, ct)
            new = {}
            for jn, jt in enumerate(model.joints):
                f = fric.get(jt.name)
                if f is not None and f.coefficient:
                    wr = w[jt.b][k] - w[jt.a][k]
                    new[jt.name] = -np.sign(wr) * f.coefficient * f.pin_radius * np.linalg.norm(x[2 * jn:2 * jn + 2])
            if all(abs(new[j] - ct.get(j, 0.0)) <= 1e-16 * max(1.0, abs(new[j])) for j in new):
                break
            ct = new
        x = solve(k, new)
        efforts[k] = x[-1]
        for jn, jt in enumerate(model.joints):
            pins[jt.name][k] = x[2 * jn:2 * jn + 2]
            if jt.a == FRAME:  # the frame feels minus the pin force, the friction and the motor reactions
                Pj = point(jt.b, jt.point_b)[0][k]
                fF[k] -= x[2 * jn:2 * jn + 2]
                fM[k] -= cross(Pj, x[2 * jn:2 * jn + 2])
                f = fric.get(jt.name)
                wr = w[jt.b][k] - w[jt.a][k]
                fM[k] -= (-(f.viscous * wr) if f else 0.0) + new.get(jt.name, 0.0)
        fM[k] -= efforts[k]
    return efforts, pins, fF, fM, ext_F, ext_M


def _peak(x):
    return float(np.max(np.abs(x)))


@pytest.mark.parametrize("seed", range(3))
def test_efforts_reactions_and_frame_load_equal_newton_euler(seed):
    rng = np.random.default_rng(seed)
    model = loaded(rng)
    an = analyse(model, GRID, gravity=GRAVITY)
    efforts, pins, fF, fM, eF, eM = newton_euler(model, an)
    e = an.efforts["crank"]
    assert _peak(e - efforts) <= 1e-9 * _peak(efforts)
    for j, F in pins.items():
        got = np.stack([an.reactions[j]["Fx"], an.reactions[j]["Fy"]], axis=1)
        assert _peak(got - F) <= 1e-9 * _peak(F), j
    FF, FM = an.frame_load
    assert _peak(FF - fF) <= 1e-9 * _peak(fF)
    assert _peak(FM - fM) <= 1e-9 * _peak(fM)
    # the frame load of the external rod load is the shaking load plus that load
    assert _peak(FF - (an.force + eF)) <= 1e-9 * _peak(FF)
    assert _peak(FM - (an.moment + eM)) <= 1e-9 * _peak(FM)
    # the friction does work against the motion: its loss is positive where its joint moves
    assert np.all(an.loads["fA"]["loss"] >= 0) and np.max(an.loads["fA"]["loss"]) > 0


@pytest.mark.parametrize("seed", range(3))
def test_internal_loads_leave_the_shaking_loads_unchanged(seed):
    rng = np.random.default_rng(seed)
    model = loaded(rng, external=False)
    bare = analyse(dataclasses.replace(model, loads=()), GRID, gravity=GRAVITY)
    an = analyse(model, GRID, gravity=GRAVITY)
    assert _peak(an.force - bare.force) <= 1e-12 * _peak(bare.force)
    assert _peak(an.moment - bare.moment) <= 1e-12 * _peak(bare.moment)
    # and the frame feels the shaking load alone (every load internal)
    FF, FM = an.frame_load
    assert _peak(FF - an.force) <= 1e-9 * _peak(FF)
    assert _peak(FM - an.moment) <= 1e-9 * _peak(FM)
    # the efforts do change
    assert _peak(an.efforts["crank"] - bare.efforts["crank"]) > 0.1 * _peak(bare.efforts["crank"])


def test_power_balance_of_the_motor():
    """The motor's power equals the rate of kinetic and potential energy plus the power that
    the loads absorb (friction losses, element powers, minus the rod load's power)."""
    rng = np.random.default_rng(7)
    model = loaded(rng)
    an = analyse(model, GRID, gravity=GRAVITY)
    m = np.array([b.mass_properties()[0] for b in model.bodies])
    I = np.array([b.mass_properties()[2] for b in model.bodies])
    dKE = np.einsum("k,nkd,nkd->n", m, an.v[:, :, :2], an.a[:, :, :2]) + np.einsum("k,nk,nk->n", I, an.v[:, :, 2], an.a[:, :, 2])
    dPE = -np.einsum("k,nkd,d->n", m, an.v[:, :, :2], np.array(GRAVITY))
    absorbed = sum(an.loads[n]["loss"] for n in ("fA", "fB", "fC")) - an.loads["spring"]["power"] - an.loads["torsion"]["power"]
    k = an.names.index("rocker")
    arm = rot(an.q[:, k, 2], np.array([0.3, 0.0]) - np.array(model.body("rocker").mass_properties()[1]))
    vP = an.v[:, k, :2] + an.v[:, k, 2][:, None] * perp(arm)
    rod = an.loads["rod"]
    rod_power = rod["Fx"] * vP[:, 0] + rod["Fy"] * vP[:, 1] + rod["torque"] * an.v[:, k, 2]
    motor = an.efforts["crank"] * an.v[:, an.names.index("crank"), 2]
    expected = dKE + dPE + absorbed - rod_power
    assert _peak(motor - expected) <= 1e-9 * _peak(motor)


def test_every_engine_path_gives_the_same_loads():
    rng = np.random.default_rng(3)
    model = loaded(rng)
    fast = analyse(model, GRID, gravity=GRAVITY)
    dense = analyse(model, GRID, gravity=GRAVITY, method="dense")
    for a, b in ((fast.efforts["crank"], dense.efforts["crank"]), (fast.frame_load[1], dense.frame_load[1]),
                 (fast.reactions["C"]["Fx"], dense.reactions["C"]["Fx"])):
        assert _peak(a - b) <= 1e-10 * _peak(a)


def test_self_locking_friction_is_a_located_error():
    rng = np.random.default_rng(1)
    model = loaded(rng, coulomb=(80.0, 60.0))
    with pytest.raises(AnalysisError, match="locks itself"):
        analyse(model, GRID, gravity=GRAVITY)


def test_masses_times_k_without_loads_still_scale():
    """The loads' own terms do not depend on the masses: the efforts of a model with loads are
    those of its inertia and weight plus the loads', so doubling every mass adds exactly the
    bare efforts once more (friction off, where it is linear)."""
    rng = np.random.default_rng(5)
    model = loaded(rng, coulomb=(0.0, 0.0))
    heavy = dataclasses.replace(model, bodies=tuple(dataclasses.replace(b, mass=2 * b.mass, inertia=2 * b.inertia)
                                                    for b in model.bodies))
    bare = analyse(dataclasses.replace(model, loads=()), GRID, gravity=GRAVITY).efforts["crank"]
    one = analyse(model, GRID, gravity=GRAVITY).efforts["crank"]
    two = analyse(heavy, GRID, gravity=GRAVITY).efforts["crank"]
    assert _peak(two - one - bare) <= 1e-9 * _peak(two)
    assert not math.isclose(_peak(one), _peak(bare))


#: a slider-crank against a constant gas pressure with Coulomb friction on the slideway and in the crank pin
SLIDER_CRANK = """
name: x
mechanism:
  template: slider_crank
  offset: 20 mm
  crank:   {length: 50 mm, mass: 1.0 kg, com: 20 mm, inertia: 0.0003 kg m^2}
  coupler: {length: 200 mm, mass: 0.6 kg, com: 80 mm, inertia: 0.0025 kg m^2}
  slider:  {mass: 1.2 kg}
motion:
  law: quintic
  duration: 0.15 s
  drive:
    crank: {from: 10 deg, to: 370 deg}
analysis: {samples: 151, gravity: true}
loads:
  - {type: pressure, name: gas, piston: {body: slider, point: C}, head: {body: frame, point: [0.3, 0.02]}, area: 20 cm^2, pressure: 3 bar}
  - {type: friction, name: rings, joint: guide, coefficient: 0.12}
  - {type: friction, name: pin, joint: B, coefficient: 0.2, pin_radius: 8 mm}
"""


def test_prismatic_coulomb_friction_and_pressure_equal_newton_euler():
    """A slider-crank (gravity on, offset guide) against a constant gas pressure, Coulomb friction
    on the slideway (mu |N|) and in the crank pin (mu r |R|): Newton-Euler per body with the pin
    forces, the slideway's normal force and lock moment and the motor torque as unknowns, the
    friction by plain fixed-point iteration."""
    from balpipe.loader import load_text
    spec = load_text(SLIDER_CRANK, "x.yaml")[0]
    from balpipe import registry
    from balpipe.mechanics.sampling import gravity_vector
    model, t = registry.unbalanced_model(spec), registry.time_grid(spec)
    g = np.asarray(gravity_vector(spec))
    an = analyse(model, t, tuple(g))
    names = an.names
    N = len(t)
    com = {b.name: np.array(b.mass_properties()[1]) for b in model.bodies}
    mass = {b.name: b.mass_properties()[0] for b in model.bodies}
    inert = {b.name: b.mass_properties()[2] for b in model.bodies}

    def pt(body, p, k):
        i = names.index(body)
        return an.q[k, i, :2] + rot(an.q[k, i, 2], np.array(p, float) - com[body])

    jA, jB, jC, guide = (model.joint(n) for n in ("A", "B", "C", "guide"))
    head = np.array([0.3, 0.02])
    area, p = 20e-4, 3e5
    eff = np.zeros(N)
    Ng = np.zeros(N)
    RB = np.zeros((N, 2))
    bi = {"crank": 0, "coupler": 1, "slider": 2}
    for k in range(N):
        w = {n: an.v[k, names.index(n), 2] for n in bi}
        Pc = pt("slider", guide.point_slider, k)
        u = np.array(guide.axis, float) / np.linalg.norm(guide.axis)
        n_ = np.array([-u[1], u[0]])
        sdot = an.v[k, names.index("slider"), :2] @ u  # the slider does not turn
        wB = w["coupler"] - w["crank"]
        d = Pc - head
        gas = p * area * d / np.linalg.norm(d)  # pushes the piston away from the head

        def solve(f_rings, t_pin):
            A = np.zeros((9, 9))
            rhs = np.zeros(9)
            for n, i in bi.items():
                a = an.a[k, names.index(n)]
                rhs[3 * i: 3 * i + 2] = mass[n] * (a[:2] - g)
                rhs[3 * i + 2] = inert[n] * a[2]
            r = {n: an.q[k, names.index(n), :2] for n in bi}
            # unknowns: F_A (0,1) on crank; F_B (2,3) on coupler from crank; F_C (4,5) on slider from coupler; N (6); M (7); tau (8)
            for col, jt in ((0, jA), (2, jB), (4, jC)):
                P = pt(jt.b, jt.point_b, k)
                for body, s in ((jt.b, 1.0), (jt.a, -1.0)):
                    if body == "frame":
                        continue
                    i = bi[body]
                    A[3 * i: 3 * i + 2, col: col + 2] += s * np.eye(2)
                    arm = P - r[body]
                    A[3 * i + 2, col] += -s * arm[1]
                    A[3 * i + 2, col + 1] += s * arm[0]
            i = bi["slider"]
            A[3 * i: 3 * i + 2, 6] = n_
            A[3 * i + 2, 6] = cross(Pc - r["slider"], n_)
            A[3 * i + 2, 7] = 1.0
            A[3 * bi["crank"] + 2, 8] = 1.0
            F = gas + f_rings * u
            rhs[3 * i: 3 * i + 2] -= F
            rhs[3 * i + 2] -= cross(Pc - r["slider"], F)
            rhs[3 * bi["coupler"] + 2] -= t_pin
            rhs[3 * bi["crank"] + 2] += t_pin
            return np.linalg.solve(A, rhs)

        fr, tp = 0.0, 0.0
        for _ in range(500):
            x = solve(fr, tp)
            fr2 = -np.sign(sdot) * 0.12 * abs(x[6])
            tp2 = -np.sign(wB) * 0.2 * 0.008 * np.linalg.norm(x[2:4])
            if abs(fr2 - fr) <= 1e-15 * max(1.0, abs(fr2)) and abs(tp2 - tp) <= 1e-16 * max(1.0, abs(tp2)):
                break
            fr, tp = fr2, tp2
        x = solve(fr2, tp2)
        eff[k], Ng[k], RB[k] = x[8], x[6], x[2:4]
    assert _peak(an.efforts["crank"] - eff) <= 1e-9 * _peak(eff)
    assert _peak(an.reactions["guide"]["N"] - Ng) <= 1e-9 * _peak(Ng)
    got = np.stack([an.reactions["B"]["Fx"], an.reactions["B"]["Fy"]], axis=1)
    assert _peak(got - RB) <= 1e-9 * _peak(RB)


def test_mass_sweep_and_partial_maps_count_the_loads():
    """The loads add the same multipliers to every mass design: the mass sweep's efforts and
    reactions, and the partial-balancing maps' constant terms, equal the engine's with the loads,
    for this model and for another mass distribution of it."""
    from balpipe.balancing.mass_sweep import MassSweep
    from balpipe.balancing.partial import maps
    from balpipe.balancing.regressor import parameters
    rng = np.random.default_rng(11)
    model = loaded(rng, coulomb=(0.0, 0.0))
    sweep = MassSweep.build(model, GRID, GRAVITY)
    other = dataclasses.replace(model, bodies=tuple(dataclasses.replace(b, mass=1.7 * b.mass, com=(b.com[0] * 0.8, 0.01))
                                                    for b in model.bodies))
    for m in (model, other):
        an = analyse(m, GRID, gravity=GRAVITY)
        p = parameters(m, angular=True)
        e = sweep.loads(p)[2][:, 0]
        assert _peak(e - an.efforts["crank"]) <= 1e-9 * _peak(an.efforts["crank"])
        R = sweep.reactions(p)["C"]["Fx"]
        assert _peak(R - an.reactions["C"]["Fx"]) <= 1e-9 * _peak(an.reactions["C"]["Fx"])
        peak = sweep.peaks(p[None, :])["max_actuator_effort"][0]
        assert peak == pytest.approx(_peak(an.efforts["crank"]), rel=1e-9)
    mp = maps.build(model, model, GRID, [], [], GRAVITY)
    an = analyse(model, GRID, gravity=GRAVITY)
    assert _peak(mp.loads["effort:crank"].b[:, 0] - an.efforts["crank"]) <= 1e-9 * _peak(an.efforts["crank"])
    with pytest.raises(ValueError, match="Coulomb"):
        MassSweep.build(loaded(rng), GRID, GRAVITY)
