"""A model's loads (:mod:`balpipe.mechanics.loads`) in the inverse dynamics.

:func:`terms` evaluates every load along a motion as generalized forces Q on the bodies' centre
of mass coordinates (a force F at a point P of body k adds F to its (x, y) and (P - r_k) x F to
its angle), the reactions that internal loads put on the frame, and the external loads on the
links (force and moment about O). Viscous friction is a known generalized force too. Coulomb
friction is not: its magnitude mu r |R| depends on the joint's reaction R, which depends on the
friction. :func:`solve` solves both together, exactly: the multipliers are affine in the
friction magnitudes phi (lambda = lambda_0 + sum_j phi_j lambda_j, each lambda_j the multipliers
of joint j's unit friction, its sign that of the joint's relative velocity), so per sample
phi_j = mu_j r_j |R_j(lambda(phi))| is a small nonlinear system, solved by Newton's method to
round-off (not lagged by a sample).

The frame load is everything the frame feels: -Phi_q0^T lambda (bearings, slideways, the motors'
reactions) plus the frame-side reactions of internal loads. By Newton-Euler on the moving links
it equals the shaking load (weight - dP/dt, the moment likewise) plus the external loads, so the
shaking force and moment, computed from the frame load less the external loads, stay the
inertial ones whatever the loads (DESIGN.md, "Loads, and what the frame feels").
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Callable, TypeVar, cast

import numpy as np

from ..mechanics.loads import Anchor, AppliedLoad, ForceElement, JointFriction, LoadTable, TorsionElement
from ..mechanics.planar import cross, rotate
from ..model import Driver, Model, Prismatic, Revolute
from .compile import Compiled, _perp
from .errors import AnalysisError

Solver = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
#: a load's value: a float (one state, :mod:`.step_loads`) or an array (along a motion)
Num = TypeVar("Num", float, np.ndarray)

#: Newton iterations of the Coulomb friction before it is declared self-locking
MAX_ITERATIONS = 60


@dataclass
class _Coulomb:
    """One joint's Coulomb friction: its unit generalized force (sign of the relative velocity),
    the unit reaction it puts on the frame, how its reaction is read from the multipliers, and
    mu r (revolute) or mu (prismatic)."""

    name: str
    Q: np.ndarray  # (N, n)
    frame: np.ndarray  # (N, 3)
    rows: list[int]
    sign: float  # +1: R = lambda[rows] (revolute force on b); -1: N = -lambda[row] (prismatic)
    gain: float
    rate: np.ndarray  # (N,) signed relative speed
    on_b: str  # "torque" or "force"
    direction: np.ndarray  # (N,) unit friction on b (or the slider): -sgn(rate)


@dataclass
class LoadTerms:
    """The loads of one model along one motion (N samples, n = 3 nb coordinates)."""

    Q: np.ndarray  # (N, n) generalized forces of every load except Coulomb friction
    frame: np.ndarray  # (N, 3) their reactions on the frame (Fx, Fy, M about O)
    external: np.ndarray  # (N, 3) external loads on the links (Fx, Fy, M about O)
    series: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    coulomb: list[_Coulomb] = field(default_factory=list)
    t: np.ndarray = field(default_factory=lambda: np.zeros(0))  # the motion's times


class _Acc:
    """Accumulates forces and torques on bodies (into Q) or on the frame."""

    def __init__(self, N: int, nb: int, q: np.ndarray):
        self.Q = np.zeros((N, 3 * nb))
        self.frame = np.zeros((N, 3))
        self.external = np.zeros((N, 3))
        self.q = q

    def force(self, k: int | None, P: np.ndarray, F: np.ndarray, Q: np.ndarray | None = None,
              frame: np.ndarray | None = None) -> None:
        Q = self.Q if Q is None else Q
        frame = self.frame if frame is None else frame
        if k is None:
            frame[:, :2] += F
            frame[:, 2] += cross(P, F)
        else:
            Q[:, 3 * k: 3 * k + 2] += F
            Q[:, 3 * k + 2] += cross(P - self.q[:, 3 * k: 3 * k + 2], F)

    def torque(self, k: int | None, T: np.ndarray, Q: np.ndarray | None = None,
               frame: np.ndarray | None = None) -> None:
        Q = self.Q if Q is None else Q
        frame = self.frame if frame is None else frame
        if k is None:
            frame[:, 2] += T
        else:
            Q[:, 3 * k + 2] += T

    def outside(self, P: np.ndarray | None, F: np.ndarray | None, T: np.ndarray | None = None) -> None:
        if F is not None:
            if P is None:
                raise ValueError("an external force needs its point of application")
            self.external[:, :2] += F
            self.external[:, 2] += cross(P, F)
        if T is not None:
            self.external[:, 2] += T


class _Motion:
    """Points, angles and rates of a model's bodies along a motion."""

    def __init__(self, model: Model, c: Compiled, t: np.ndarray, q: np.ndarray, v: np.ndarray):
        self.model, self.c, self.t, self.q, self.v = model, c, t, q, v
        self.index = {n: k for k, n in enumerate(c.names)}

    def body(self, name: str) -> int | None:
        if name == "frame":
            return None
        try:
            return self.index[name]
        except KeyError:
            raise ValueError(f"a load refers to unknown body {name!r}") from None

    def angle(self, k: int | None) -> tuple[np.ndarray, np.ndarray]:
        if k is None:
            z = np.zeros(len(self.t))
            return z, z
        return self.q[:, 3 * k + 2], self.v[:, 3 * k + 2]

    def point(self, a: Anchor) -> tuple[int | None, np.ndarray, np.ndarray]:
        """(body index or None, P (N, 2), velocity (N, 2)) of an anchor."""
        k = self.body(a.body)
        p = np.asarray(a.point, dtype=float)
        N = len(self.t)
        if k is None:
            return None, np.broadcast_to(p, (N, 2)).copy(), np.zeros((N, 2))
        th, w = self.angle(k)
        arm = rotate(th, p - self.c.com_local[k])
        return k, self.q[:, 3 * k: 3 * k + 2] + arm, self.v[:, 3 * k: 3 * k + 2] + w[:, None] * _perp(arm)

    def coincident_velocity(self, k: int | None, P: np.ndarray) -> np.ndarray:
        """Velocity of the point of body k (the frame: zero) that is at P."""
        if k is None:
            return np.zeros_like(P)
        _, w = self.angle(k)
        return self.v[:, 3 * k: 3 * k + 2] + w[:, None] * _perp(P - self.q[:, 3 * k: 3 * k + 2])

    def argument(self, law: LoadTable, own: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray]:
        """(x, rate) of a table's argument."""
        kind = law.argument[0]
        if kind == "time":
            return self.t, np.ones_like(self.t)
        if kind == "driver":
            x, xd, _ = driver(self.model, law.argument[1]).law(self.t)
            return np.broadcast_to(np.asarray(x, dtype=float), self.t.shape), np.broadcast_to(np.asarray(xd, dtype=float), self.t.shape)
        if kind == "stroke":
            _, body, p, direction, origin = law.argument
            _, P, V = self.point(Anchor(body, p))
            return stroke(P[:, 0], P[:, 1], V[:, 0], V[:, 1], direction, origin)
        if kind == "deflection" and own is not None:
            return own
        raise unknown_argument(law)


def driver(model: Model, name: str) -> Driver:
    """The driver a table's argument names."""
    for d in model.drivers:
        if d.name == name:
            return d
    raise ValueError(f"a load table refers to unknown driver {name!r}")


def unknown_argument(law: LoadTable) -> ValueError:
    """The error of a table whose argument is none this module knows (a deflection off a force element)."""
    return ValueError(f"unknown load table argument {law.argument!r}")


def terms(model: Model, c: Compiled, t: np.ndarray, q: np.ndarray, v: np.ndarray) -> LoadTerms:
    """Every load of ``model`` along the motion (q, v: (N, 3 nb) centre of mass coordinates)."""
    mo = _Motion(model, c, t, q, v)
    acc = _Acc(len(t), c.nb, q)
    out = LoadTerms(acc.Q, acc.frame, acc.external, t=t)
    for load in model.loads:
        if isinstance(load, ForceElement):
            out.series[load.name] = _element(mo, acc, load)
        elif isinstance(load, TorsionElement):
            out.series[load.name] = _torsion(mo, acc, load)
        elif isinstance(load, AppliedLoad):
            out.series[load.name] = _applied(mo, acc, load)
        elif isinstance(load, JointFriction):
            out.series[load.name], coulomb = _friction(mo, acc, load)
            if coulomb is not None:
                out.coulomb.append(coulomb)
        else:  # pragma: no cover - the Load union is closed
            raise TypeError(load)
    return out


def tension(e: ForceElement, T0: Num, L: Num, Ld: Num, law: Num | None) -> Num:
    """A force element's tension T0 + k (L - L_ref) + c dL/dt + scale * law (``T0``: its preload;
    ``law``: its table's value, None without one), only the terms it has, in that order: the same
    operations on floats as on arrays (the engine's and the simulation's values are equal)."""
    T = T0
    if e.stiffness:
        T = T + e.stiffness * (L - cast(float, e.free_length))
    if e.damping:
        T = T + e.damping * Ld
    if law is not None:
        T = T + e.scale * law
    return T


def deflection(e: ForceElement, L: Num, Ld: Num) -> tuple[Num, Num]:
    """A force element's deflection argument (L - L_free, dL/dt) for its table."""
    return L - (e.free_length or 0.0), Ld


def torsion(e: TorsionElement, T0: Num, phi: Num, w: Num) -> Num:
    """A torsion element's torque T0 + k (phi - phi_ref) + c dphi/dt (``T0``: its preload), only
    the terms it has, in that order: the same operations on floats as on arrays."""
    T = T0
    if e.stiffness:
        T = T + e.stiffness * (phi - cast(float, e.free_angle))
    if e.damping:
        T = T + e.damping * w
    return T


def stroke(px: Num, py: Num, vx: Num, vy: Num, direction: tuple[float, float], origin: float) -> tuple[Num, Num]:
    """A stroke table's argument: the point's displacement along ``direction`` from ``origin``
    and its rate (written out, not a matrix product, so that floats and arrays agree)."""
    dx, dy = float(direction[0]), float(direction[1])
    return px * dx + py * dy - origin, vx * dx + vy * dy


def _element(mo: _Motion, acc: _Acc, e: ForceElement) -> dict[str, np.ndarray]:
    ka, Pa, Va = mo.point(e.a)
    kb, Pb, Vb = mo.point(e.b)
    d = Pb - Pa
    L = np.linalg.norm(d, axis=1)
    if np.any(L <= 0.0):
        raise ValueError(f"force element {e.name!r}: its two points coincide, its direction is undefined")
    u = d / L[:, None]
    Ld = np.einsum("nk,nk->n", Vb - Va, u)
    law = None if e.law is None else e.law(*mo.argument(e.law, deflection(e, L, Ld)))
    T = tension(e, np.full(len(L), float(e.preload)), L, Ld, law)
    Fa, Fb = T[:, None] * u, -T[:, None] * u
    for k, P, F in ((ka, Pa, Fa), (kb, Pb, Fb)):
        if k is None and e.source == "external":
            continue  # its outside end: not on the machine's frame
        acc.force(k, P, F)
        if k is not None and e.source == "external":
            acc.outside(P, F)
    return {"tension": T, "length": L, "power": -T * Ld}


def _torsion(mo: _Motion, acc: _Acc, e: TorsionElement) -> dict[str, np.ndarray]:
    jt = mo.model.joint(e.joint)
    if isinstance(jt, Prismatic):
        raise ValueError(f"torsion element on {e.joint!r}: a prismatic joint has no relative angle")
    ka, kb = mo.body(jt.a), mo.body(jt.b)
    (tha, wa), (thb, wb) = mo.angle(ka), mo.angle(kb)
    phi, w = thb - tha, wb - wa
    T = torsion(e, np.full(len(phi), float(e.preload)), phi, w)
    for k, s in ((kb, -1.0), (ka, 1.0)):
        if k is None and e.source == "external":
            continue
        acc.torque(k, s * T)
        if k is not None and e.source == "external":
            acc.outside(None, None, s * T)
    return {"torque": T, "angle": phi, "power": -T * w}


def _applied(mo: _Motion, acc: _Acc, e: AppliedLoad) -> dict[str, np.ndarray]:
    k, P, _ = mo.point(e.at)
    value = np.ones(len(mo.t)) if e.law is None else e.law(*mo.argument(e.law))
    f = np.broadcast_to(np.asarray(e.force, dtype=float), P.shape)
    if e.axes == "body":
        th, _ = mo.angle(k)
        f = rotate(th, np.asarray(e.force, dtype=float))
    F = f * value[:, None]
    T = e.torque * value
    acc.force(k, P, F)
    acc.torque(k, T)
    if e.source == "internal":
        acc.force(None, P, -F)
        acc.torque(None, -T)
    else:
        acc.outside(P, F, T)
    return {"Fx": F[:, 0], "Fy": F[:, 1], "torque": T}


def _friction(mo: _Motion, acc: _Acc, e: JointFriction) -> tuple[dict[str, np.ndarray], _Coulomb | None]:
    jt = mo.model.joint(e.joint)
    N = len(mo.t)
    Qu, frame_u = np.zeros_like(acc.Q), np.zeros((N, 3))
    if isinstance(jt, Revolute):
        ka, kb = mo.body(jt.a), mo.body(jt.b)
        rate = mo.angle(kb)[1] - mo.angle(ka)[1]
        direction = -np.sign(rate)
        for k, s in ((kb, 1.0), (ka, -1.0)):
            acc.torque(k, -s * e.viscous * rate)
            acc.torque(k, s * direction, Qu, frame_u)
        rows, sign, gain, what = mo.c.joint_rows[jt.name][:2], 1.0, e.coefficient * e.pin_radius, "torque"
    elif isinstance(jt, Prismatic):
        kg, ks = mo.body(jt.guide), mo.body(jt.slider)
        _, Ps, Vs = mo.point(Anchor(jt.slider, jt.point_slider))
        ax = np.asarray(jt.axis, dtype=float)
        ax = ax / np.linalg.norm(ax)
        u = rotate(mo.angle(kg)[0], ax)
        rate = np.einsum("nk,nk->n", Vs - mo.coincident_velocity(kg, Ps), u)
        direction = -np.sign(rate)
        for k, s in ((ks, 1.0), (kg, -1.0)):
            acc.force(k, Ps, (-s * e.viscous * rate)[:, None] * u)
            acc.force(k, Ps, (s * direction)[:, None] * u, Qu, frame_u)
        rows, sign, gain, what = [mo.c.joint_rows[jt.name][1]], -1.0, e.coefficient, "force"
    else:
        raise ValueError(f"friction {e.name!r}: joint {e.joint!r} is a gear pair, not a revolute or prismatic joint")
    series = {what: -e.viscous * rate, "loss": e.viscous * rate * rate, "rate": rate}
    if gain == 0.0:
        return series, None
    return series, _Coulomb(e.name, Qu, frame_u, list(rows), sign, gain, rate, what, direction)


def _reaction(cf: _Coulomb, lam: np.ndarray) -> np.ndarray:
    """The joint's reaction (N, 1 or 2) from multipliers (N, m)."""
    return cf.sign * lam[:, cf.rows]


def solve(lt: LoadTerms, rhs: np.ndarray, solver: Solver) -> tuple[np.ndarray, np.ndarray]:
    """Multipliers (N, m) and frame load (N, 3: Fx, Fy, M about O) of Phi_q^T lambda = rhs + Q
    with every load, Coulomb friction included (module docstring); ``solver(rhs)`` gives the
    multipliers and -Phi_q0^T lambda of a right-hand side, linearly. Adds each Coulomb joint's
    friction (signed, on body b or the slider), its magnitude ``coulomb`` and its power loss to
    ``lt.series``."""
    lam, frame = solver(rhs + lt.Q)
    frame = frame + lt.frame
    if not lt.coulomb:
        return lam, frame
    units = [solver(cf.Q) for cf in lt.coulomb]
    Lu = np.stack([u[0] for u in units], axis=2)  # (N, m, nf)
    Fu = np.stack([u[1] + cf.frame for u, cf in zip(units, lt.coulomb)], axis=2)  # (N, 3, nf)
    phi = _friction_magnitudes(lt.coulomb, lam, Lu, lt.t)
    lam = lam + np.einsum("nmf,nf->nm", Lu, phi)
    frame = frame + np.einsum("nkf,nf->nk", Fu, phi)
    for j, cf in enumerate(lt.coulomb):
        s = lt.series[cf.name]
        s[cf.on_b] = s[cf.on_b] + cf.direction * phi[:, j]
        s["loss"] = s["loss"] + phi[:, j] * np.abs(cf.rate)
        s["coulomb"] = phi[:, j]
        s["normal" if cf.on_b == "force" else "reaction"] = np.linalg.norm(_reaction(cf, lam), axis=1)
    return lam, frame


def _friction_magnitudes(cs: list[_Coulomb], lam0: np.ndarray, Lu: np.ndarray, t: np.ndarray) -> np.ndarray:
    """phi (N, nf) with phi_j = gain_j |R_j(lam0 + Lu phi)| for every sample, by Newton's method
    from phi = gain |R(lam0)|, to round-off."""
    N, nf = lam0.shape[0], len(cs)
    phi = np.stack([c.gain * np.linalg.norm(_reaction(c, lam0), axis=1) for c in cs], axis=1)
    eye = np.eye(nf)
    for _ in range(MAX_ITERATIONS):
        lam = lam0 + np.einsum("nmf,nf->nm", Lu, phi)
        g = np.empty((N, nf))
        Jg = np.broadcast_to(eye, (N, nf, nf)).copy()
        for j, c in enumerate(cs):
            R = _reaction(c, lam)
            r = np.linalg.norm(R, axis=1)
            g[:, j] = phi[:, j] - c.gain * r
            unit = np.divide(R, r[:, None], out=np.zeros_like(R), where=r[:, None] > 0)
            dR = c.sign * Lu[:, c.rows, :]  # (N, 1 or 2, nf)
            Jg[:, j, :] -= c.gain * np.einsum("nk,nkf->nf", unit, dR)
        try:
            step = np.linalg.solve(Jg, g[..., None])[..., 0]
        except np.linalg.LinAlgError:
            step = np.full_like(g, np.nan)
        phi = phi - step
        if not np.all(np.isfinite(phi)):
            break
        size = np.abs(phi).max(axis=1, keepdims=True)
        if np.all(np.abs(step) <= 1e-14 * size):
            return phi
    bad = np.flatnonzero(~np.isfinite(phi).all(axis=1))
    k = int(bad[0]) if bad.size else 0
    raise AnalysisError(
        "the Coulomb friction in " + ", ".join(repr(c.name) for c in cs) + " has no solution here: the friction "
        "is too large for the mechanism's geometry (it locks itself); reduce the coefficient or the pin radius",
        float(t[k]), joint=None)
