"""The generic planar multibody engine: kinematics, inverse dynamics and shaking loads.

Coordinates are absolute: body k has q_k = (x, y, theta) of its centre of mass (attachments
included). The frame is body 0 with q_0 = 0; it takes part in the constraint Jacobian so that
``-J_0^T lambda`` is directly the load the mechanism puts on the frame (force, and moment about
the origin O).

Every joint and driver reduces to three constraint primitives, each vectorised over the N time
samples:

* ``coincident``: r_i + A_i s_i - r_j - A_j s_j = 0 (2 rows; revolute joints);
* ``angle``: sum_k c_k theta_k - c0 - f(t) = 0 (relative angles, gears, angle drivers,
  the rotation lock of a prismatic pair);
* ``projection``: (A_i a)^T (r_j + A_j s_j - r_i - A_i s_i) - c0 - f(t) = 0 (the guide of a
  prismatic pair, prismatic drivers, point-coordinate drivers).

Position analysis is Newton-Raphson on Phi(q, t) = 0; velocities solve Phi_q q' = nu and
accelerations Phi_q q'' = gamma (Haug, Computer-Aided Kinematics and Dynamics, ch. 3 and 6).
Inverse dynamics solves Phi_q^T lambda = Q - M q'' (M q'' + Phi_q^T lambda = Q).

Redundant actuation (more drivers than degrees of freedom, e.g. a 4-RRR with four base motors):
the consistent over-determined position, velocity and acceleration equations are solved in least
squares (Gauss-Newton, least squares by QR, exact for consistent drivers), and the
multipliers are those whose actuator efforts have the least norm (:func:`_multipliers`). The
joints alone must not be over-constrained. The shaking
loads are computed twice, independently:

(a) reactions: F_sh, M_sh = -Phi_{q0}^T lambda (all frame joints, actuator reactions and gear
    mesh couples on the frame); a gear pair with pitch radii has its row rewritten as tooth
    forces at the pitch point for the dynamics (:func:`_tooth_rows`, :mod:`balpipe.meshes`), so
    that its bearings carry the tooth force;
(b) momentum: F_sh = sum m g - dP/dt, M_O = sum r x m g - dH_O/dt.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from .meshes import mesh_geometry
from .model import FRAME, Driver, Gear, Model, Prismatic, Revolute, pose_of_com


class AnalysisError(Exception):
    """The mechanism cannot follow the motion: non-convergence or a singular configuration."""

    def __init__(self, message: str, time: float | None = None, joint: str | None = None):
        super().__init__(message)
        self.time = time
        self.joint = joint


def _perp(v: np.ndarray) -> np.ndarray:
    """Rotate vectors (..., 2) by +90 degrees."""
    out = np.empty_like(v)
    out[..., 0] = -v[..., 1]
    out[..., 1] = v[..., 0]
    return out


def _rotate(theta: np.ndarray, s: np.ndarray) -> np.ndarray:
    """A(theta) s for theta (N,), s (2,) -> (N, 2)."""
    c, si = np.cos(theta), np.sin(theta)
    out = np.empty(theta.shape + (2,))
    out[..., 0] = c * s[0] - si * s[1]
    out[..., 1] = si * s[0] + c * s[1]
    return out


@dataclass
class _Coincident:
    owner: str
    i: int
    si: np.ndarray
    j: int
    sj: np.ndarray
    rows: int = 2


@dataclass
class _Angle:
    owner: str
    coeffs: list[tuple[int, float]]
    const: float = 0.0
    law: object = None
    rows: int = 1


@dataclass
class _Projection:
    owner: str
    i: int
    a: np.ndarray
    si: np.ndarray
    j: int
    sj: np.ndarray
    const: float = 0.0
    law: object = None
    rows: int = 1


@dataclass
class Compiled:
    """A model prepared for vectorised evaluation."""

    model: Model
    names: list[str]  # body names, index k+1 for body k (0 is the frame)
    mass: np.ndarray  # (nb,)
    inertia: np.ndarray  # (nb,)
    prims: list
    row_owner: list[str]  # joint/driver name per constraint row
    driver_rows: dict[str, int]
    joint_rows: dict[str, list[int]]
    q0: np.ndarray  # (3 nb,) initial guess
    condition: np.ndarray | None = None  # condition numbers of Phi_q along the last motion solved
    meshes: list = field(default_factory=list)  # _Mesh: gear pairs that pass tooth forces

    @property
    def nb(self) -> int:
        return len(self.names)


def compile_model(model: Model) -> Compiled:
    """Index bodies, express joint points relative to each body's centre of mass and reduce
    joints and drivers to primitives."""
    names = [b.name for b in model.bodies]
    if FRAME in names:
        raise ValueError(f"'{FRAME}' is reserved for the fixed frame")
    if len(set(names)) != len(names):
        raise ValueError("body names must be unique")
    index = {FRAME: 0, **{n: k + 1 for k, n in enumerate(names)}}
    com = {FRAME: np.zeros(2)}
    mass, inertia = [], []
    for b in model.bodies:
        m, c, i = b.mass_properties()
        if m < 0 or i < 0:
            raise ValueError(f"body {b.name!r} has a negative mass or inertia")
        mass.append(m)
        inertia.append(i)
        com[b.name] = np.array(c, dtype=float)

    def idx(name: str, where: str) -> int:
        try:
            return index[name]
        except KeyError:
            raise ValueError(f"{where} refers to unknown body {name!r}") from None

    def local(name: str, p) -> np.ndarray:
        return np.asarray(p, dtype=float) - com[name]

    init = {FRAME: (0.0, 0.0, 0.0)}
    for b in model.bodies:
        if b.name not in model.initial:
            raise ValueError(f"body {b.name!r} has no initial pose")
        init[b.name] = pose_of_com(b, model.initial[b.name])

    prims: list = []
    joints_by_name = {}
    for jt in model.joints:
        if jt.name in joints_by_name:
            raise ValueError(f"joint name {jt.name!r} is used twice")
        joints_by_name[jt.name] = jt
        if isinstance(jt, Revolute):
            prims.append(
                _Coincident(jt.name, idx(jt.a, jt.name), local(jt.a, jt.point_a), idx(jt.b, jt.name), local(jt.b, jt.point_b))
            )
        elif isinstance(jt, Prismatic):
            g, s = idx(jt.guide, jt.name), idx(jt.slider, jt.name)
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            prims.append(_Angle(jt.name, [(s, 1.0), (g, -1.0)], jt.angle))
            prims.append(
                _Projection(jt.name, g, _perp(ax), local(jt.guide, jt.point_guide), s, local(jt.slider, jt.point_slider))
            )
        elif isinstance(jt, Gear):
            a, b, c = idx(jt.a, jt.name), idx(jt.b, jt.name), idx(jt.carrier, jt.name)
            coeffs: dict[int, float] = {}
            for k, v in ((b, 1.0), (c, -1.0), (a, -jt.ratio), (c, jt.ratio)):
                coeffs[k] = coeffs.get(k, 0.0) + v
            if jt.phase is None:
                th = {n: init[n][2] for n in (jt.a, jt.b, jt.carrier)}
                phase = (th[jt.b] - th[jt.carrier]) - jt.ratio * (th[jt.a] - th[jt.carrier])
            else:
                phase = jt.phase
            prims.append(_Angle(jt.name, [(k, v) for k, v in coeffs.items() if v != 0.0], phase))
        else:  # pragma: no cover - the Joint union is closed
            raise TypeError(jt)

    driver_rows: dict[str, int] = {}
    for d in model.drivers:
        start = len(prims)
        prims.append(_driver_primitive(d, joints_by_name, idx, local, model))
        driver_rows[d.name] = start

    row_owner: list[str] = []
    joint_rows: dict[str, list[int]] = {}
    prim_first_row = []
    for p in prims:
        prim_first_row.append(len(row_owner))
        joint_rows.setdefault(p.owner, []).extend(range(len(row_owner), len(row_owner) + p.rows))
        row_owner.extend([p.owner] * p.rows)
    driver_rows = {n: prim_first_row[k] for n, k in driver_rows.items()}

    q0 = np.array([v for n in names for v in init[n]], dtype=float)
    compiled = Compiled(
        model, names, np.array(mass), np.array(inertia), prims, row_owner, driver_rows, joint_rows, q0
    )
    compiled.meshes = _compile_meshes(model, idx, local, joint_rows)
    return compiled


@dataclass
class _Mesh:
    """A gear pair with pitch radii (see :mod:`balpipe.meshes`), indexed for the engine."""

    name: str
    row: int  # the gear's constraint row
    ia: int
    ib: int
    ic: int
    sca: np.ndarray  # bearing centres O_a, O_b on the carrier (relative to its centre of mass)
    scb: np.ndarray
    pitch_a: float
    pitch_b: float
    side: float
    external: bool
    tan_alpha: float
    rows_a: list[int]  # rows of the bearings' revolute joints
    rows_b: list[int]
    sign_a: float  # +1 when the gear is body b of its bearing (its reaction is the force on the gear)
    sign_b: float


def _compile_meshes(model: Model, idx, local, joint_rows: dict[str, list[int]]) -> list[_Mesh]:
    out = []
    for jt in model.joints:
        if not isinstance(jt, Gear):
            continue
        geo = mesh_geometry(model, jt)
        if geo is None:
            continue
        ba, bb = geo.bearing_a, geo.bearing_b
        out.append(_Mesh(
            jt.name, joint_rows[jt.name][0], idx(jt.a, jt.name), idx(jt.b, jt.name), idx(jt.carrier, jt.name),
            local(jt.carrier, ba.centre_carrier), local(jt.carrier, bb.centre_carrier),
            geo.pitch_a, geo.pitch_b, geo.side, geo.external, float(np.tan(geo.pressure_angle)),
            joint_rows[ba.joint], joint_rows[bb.joint],
            1.0 if ba.gear_is_b else -1.0, 1.0 if bb.gear_is_b else -1.0,
        ))
    return out


def _driver_primitive(d: Driver, joints: dict, idx, local, model: Model):
    kind = d.target[0]
    if kind == "joint":
        jt = joints.get(d.target[1])
        if jt is None:
            raise ValueError(f"driver {d.name!r} refers to unknown joint {d.target[1]!r}")
        if isinstance(jt, Revolute):
            return _Angle(d.name, [(idx(jt.b, d.name), 1.0), (idx(jt.a, d.name), -1.0)], 0.0, d.law)
        if isinstance(jt, Prismatic):
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            return _Projection(
                d.name, idx(jt.guide, d.name), ax, local(jt.guide, jt.point_guide),
                idx(jt.slider, d.name), local(jt.slider, jt.point_slider), 0.0, d.law,
            )
        raise ValueError(f"driver {d.name!r}: a gear pair cannot be driven, drive one of its bodies")
    body = d.target[1]
    b = idx(body, d.name)
    if kind == "angle":  # absolute angle: theta_b - theta_frame, so the reaction lands on the frame
        return _Angle(d.name, [(b, 1.0), (0, -1.0)], 0.0, d.law)
    if kind in ("x", "y"):
        point = model.body(body).point(d.target[2]) if len(d.target) > 2 else (0.0, 0.0)
        axis = np.array([1.0, 0.0]) if kind == "x" else np.array([0.0, 1.0])
        return _Projection(d.name, 0, axis, np.zeros(2), b, local(body, point), 0.0, d.law)
    raise ValueError(f"driver {d.name!r}: unknown target {d.target!r}")


# --------------------------------------------------------------------------------------------
# Evaluation of the primitives, vectorised over samples


def _split(q: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Position (N, 2) and angle (N,) of body k from the extended coordinates (N, 3 nb + 3)."""
    return q[:, 3 * k : 3 * k + 2], q[:, 3 * k + 2]


def _law_values(prim, t: np.ndarray):
    if prim.law is None:
        z = np.zeros_like(t)
        return z, z, z
    return prim.law(t)


def residual(c: Compiled, qx: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Phi(q, t), shape (N, m)."""
    out = []
    for p in c.prims:
        if isinstance(p, _Coincident):
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            out.append(ri + _rotate(thi, p.si) - rj - _rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            f = _law_values(p, t)[0]
            val = sum(v * qx[:, 3 * k + 2] for k, v in p.coeffs) - p.const - f
            out.append(val[:, None])
        else:
            f = _law_values(p, t)[0]
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            e = _rotate(thi, p.a)
            d = rj + _rotate(thj, p.sj) - ri - _rotate(thi, p.si)
            out.append((np.sum(e * d, axis=1) - p.const - f)[:, None])
    return np.concatenate(out, axis=1)


def jacobian(c: Compiled, qx: np.ndarray) -> np.ndarray:
    """Phi_q over the extended coordinates (frame included), shape (N, m, 3 nb + 3)."""
    N = qx.shape[0]
    m = len(c.row_owner)
    J = np.zeros((N, m, qx.shape[1]))
    row = 0
    for p in c.prims:
        if isinstance(p, _Coincident):
            _, thi = _split(qx, p.i)
            _, thj = _split(qx, p.j)
            for a in range(2):
                J[:, row + a, 3 * p.i + a] += 1.0
                J[:, row + a, 3 * p.j + a] -= 1.0
            J[:, row : row + 2, 3 * p.i + 2] += _perp(_rotate(thi, p.si))
            J[:, row : row + 2, 3 * p.j + 2] -= _perp(_rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            for k, v in p.coeffs:
                J[:, row, 3 * k + 2] += v
        else:
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            e = _rotate(thi, p.a)
            Asi, Asj = _rotate(thi, p.si), _rotate(thj, p.sj)
            d = rj + Asj - ri - Asi
            J[:, row, 3 * p.i : 3 * p.i + 2] -= e
            J[:, row, 3 * p.j : 3 * p.j + 2] += e
            J[:, row, 3 * p.i + 2] += np.sum(_perp(e) * d, axis=1) - np.sum(e * _perp(Asi), axis=1)
            J[:, row, 3 * p.j + 2] += np.sum(e * _perp(Asj), axis=1)
        row += p.rows
    return J


def velocity_rhs(c: Compiled, t: np.ndarray) -> np.ndarray:
    """nu = -Phi_t, shape (N, m)."""
    out = []
    for p in c.prims:
        if p.rows == 2:
            out.append(np.zeros((len(t), 2)))
        else:
            out.append(_law_values(p, t)[1][:, None])
    return np.concatenate(out, axis=1)


def acceleration_rhs(c: Compiled, qx: np.ndarray, vx: np.ndarray, t: np.ndarray) -> np.ndarray:
    """gamma = Phi_q q'' (everything in Phi'' but the q'' terms, moved to the right), (N, m)."""
    out = []
    for p in c.prims:
        if isinstance(p, _Coincident):
            _, thi = _split(qx, p.i)
            _, thj = _split(qx, p.j)
            wi, wj = vx[:, 3 * p.i + 2], vx[:, 3 * p.j + 2]
            out.append((wi**2)[:, None] * _rotate(thi, p.si) - (wj**2)[:, None] * _rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            out.append(_law_values(p, t)[2][:, None])
        else:
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            vi, wi = _split(vx, p.i)
            vj, wj = _split(vx, p.j)
            e = _rotate(thi, p.a)
            Asi, Asj = _rotate(thi, p.si), _rotate(thj, p.sj)
            d = rj + Asj - ri - Asi
            dd = vj + wj[:, None] * _perp(Asj) - vi - wi[:, None] * _perp(Asi)
            quad = (
                -(wi**2) * np.sum(e * d, axis=1)
                + 2 * wi * np.sum(_perp(e) * dd, axis=1)
                + np.sum(e * (-(wj**2)[:, None] * Asj + (wi**2)[:, None] * Asi), axis=1)
            )
            out.append((_law_values(p, t)[2] - quad)[:, None])
    return np.concatenate(out, axis=1)


# --------------------------------------------------------------------------------------------
# Position analysis

_TOL = 1e-12
_MAX_ITER = 25
_COND_LIMIT = 1e11
_COARSE = 17  # samples followed by continuation before the batched refinement
_JUMP = 0.2  # rad: a refined angle this far from its interpolated guess may be another branch


def _extend(q: np.ndarray) -> np.ndarray:
    return np.concatenate([np.zeros((q.shape[0], 3)), q], axis=1)


def _check_square(c: Compiled) -> None:
    """Fewer equations than coordinates is an error; more are allowed when only drivers are
    redundant (redundant actuation, checked by :func:`_check_redundancy` once assembled)."""
    m, n = len(c.row_owner), 3 * c.nb
    if m < n:
        raise AnalysisError(
            f"the model has {n} coordinates but {m} constraint equations: add drivers or joints "
            "(it can move freely)"
        )
    if m > n and m - len(c.driver_rows) > n:
        raise AnalysisError(
            f"the model has {n} coordinates but its joints alone give {m - len(c.driver_rows)} "
            "constraint equations: it is over-constrained (only actuators may be redundant)"
        )


def redundancy(c: Compiled) -> int:
    """Number of redundant actuators: constraint rows beyond the coordinates (0 when square)."""
    return len(c.row_owner) - 3 * c.nb


def _check_redundancy(c: Compiled, q: np.ndarray, t: float) -> None:
    """With redundant actuation the joints' own rows must be independent (else the multipliers,
    hence the reactions, are not determined by the minimum-norm efforts)."""
    if redundancy(c) == 0:
        return
    J = jacobian(c, _extend(q[None, :]))[0, :, 3:]
    drv = set(c.driver_rows.values())
    rows = [r for r in range(J.shape[0]) if r not in drv]
    s = np.linalg.svd(J[rows], compute_uv=False)
    if s[-1] <= 1e-10 * s[0]:
        raise AnalysisError(
            f"at t = {t:.6g} s the joints' constraint equations are dependent (condition "
            f"{s[0] / max(s[-1], 1e-300):.2g}): the mechanism is over-constrained by its joints, "
            "not only by redundant actuators", t,
        )


def _solve_rect(J: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve J x = b for stacks (N, m, n) of full-column-rank J: exact when square, the least-
    squares solution of a consistent over-determined system (redundant drivers) otherwise."""
    if J.shape[-2] == J.shape[-1]:
        return np.linalg.solve(J, b[..., None])[..., 0]
    Q, R = np.linalg.qr(J)  # reduced: J = Q R, R (n, n) upper triangular
    return np.linalg.solve(R, np.einsum("nji,nj->ni", Q, b)[..., None])[..., 0]


def _newton(c: Compiled, q: np.ndarray, t: np.ndarray, max_iter: int = _MAX_ITER):
    """Batched Newton-Raphson. Returns (q, converged mask, residual norms)."""
    q = q.copy()
    norms = np.full(len(t), np.inf)
    for _ in range(max_iter):
        qx = _extend(q)
        phi = residual(c, qx, t)
        norms = np.abs(phi).max(axis=1)
        todo = ~(norms < _TOL)
        if not todo.any():
            break
        J = jacobian(c, qx[todo])[:, :, 3:]
        try:
            dq = _solve_rect(J, -phi[todo])
        except np.linalg.LinAlgError:
            dq = np.stack([np.linalg.lstsq(Jk, -pk, rcond=None)[0] for Jk, pk in zip(J, phi[todo])])
        q[todo] += dq
    qx = _extend(q)
    norms = np.abs(residual(c, qx, t)).max(axis=1)
    return q, norms < 1e-9, norms


def _worst_rows(c: Compiled, values: np.ndarray) -> str:
    order = np.argsort(-np.abs(values))
    names: list[str] = []
    for r in order:
        if abs(values[r]) < 0.2 * abs(values[order[0]]):
            break
        if c.row_owner[r] not in names:
            names.append(c.row_owner[r])
    return ", ".join(repr(n) for n in names[:3])


def _fail_position(c: Compiled, q: np.ndarray, t: float) -> AnalysisError:
    qx = _extend(q[None, :])
    phi = residual(c, qx, np.array([t]))[0]
    worst = int(np.argmax(np.abs(phi)))
    return AnalysisError(
        f"position analysis did not converge at t = {t:.6g} s: joint {c.row_owner[worst]!r} cannot "
        f"be closed (residual {abs(phi[worst]):.3g}); the motion leaves the mechanism's workspace",
        t,
        c.row_owner[worst],
    )


def _check_regular(c: Compiled, q: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Condition numbers of Phi_q along the motion; a singular configuration is an error."""
    J = jacobian(c, _extend(q))[:, :, 3:]
    s = np.linalg.svd(J, compute_uv=False)
    cond = s[:, 0] / np.maximum(s[:, -1], 1e-300)
    bad = np.flatnonzero(cond > _COND_LIMIT)
    if bad.size:
        k = int(bad[0])
        u, _, _ = np.linalg.svd(J[k])
        weak = u[:, J.shape[2] - 1]  # left vector of the smallest of the n singular values
        raise AnalysisError(
            f"singular configuration at t = {t[k]:.6g} s (condition number {cond[k]:.2g}): "
            f"joints {_worst_rows(c, weak)} lose their rank (a dead point, a limit of the "
            f"workspace or a branch change)",
            float(t[k]),
            c.row_owner[int(np.argmax(np.abs(weak)))],
        )
    return cond


def solve_positions(c: Compiled, t: np.ndarray) -> np.ndarray:
    """Positions (N, 3 nb) along the motion.

    The first sample is assembled from the model's initial pose; a coarse grid is then followed
    by continuation (second-order predictor), and all samples are refined at once by batched
    Newton-Raphson from a cubic Hermite interpolation of the coarse solution.
    """
    _check_square(c)
    N = len(t)
    q, ok, _ = _newton(c, c.q0[None, :], t[:1], max_iter=50)
    if not ok[0]:
        raise AnalysisError(
            "cannot assemble the mechanism at t = 0: " + str(_fail_position(c, q[0], float(t[0]))).split(": ", 1)[1],
            float(t[0]),
        )
    _check_redundancy(c, q[0], float(t[0]))
    coarse_idx = np.unique(np.linspace(0, N - 1, min(N, _COARSE)).round().astype(int))
    tc = t[coarse_idx]
    qc = np.zeros((len(tc), q.shape[1]))
    vc = np.zeros_like(qc)
    ac = np.zeros(qc.shape[1])
    qc[0] = q[0]
    for k in range(len(tc)):
        if k > 0:
            h = tc[k] - tc[k - 1]
            guess = qc[k - 1] + vc[k - 1] * h + 0.5 * ac * h * h
            sol, ok_k, _ = _newton(c, guess[None, :], tc[k : k + 1])
            if not ok_k[0]:
                # substep the continuation before giving up
                sol = _substep(c, qc[k - 1], tc[k - 1], tc[k])
            qc[k] = sol[0]
        v, ac = _vel_acc(c, qc[k : k + 1], tc[k : k + 1])
        vc[k], ac = v[0], ac[0]
    # Hermite interpolation to the full grid
    seg = np.clip(np.searchsorted(tc, t, side="right") - 1, 0, len(tc) - 2) if len(tc) > 1 else np.zeros(N, int)
    if len(tc) > 1:
        t0, t1 = tc[seg], tc[seg + 1]
        h = (t1 - t0)[:, None]
        s = ((t - t0) / (t1 - t0))[:, None]
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        guess = h00 * qc[seg] + h10 * h * vc[seg] + h01 * qc[seg + 1] + h11 * h * vc[seg + 1]
    else:
        guess = np.repeat(qc[:1], N, axis=0)
    qall, ok, _ = _newton(c, guess, t)
    jumped = np.abs(qall[:, 2::3] - guess[:, 2::3]).max(axis=1) > _JUMP
    for k in np.flatnonzero(~ok | jumped):  # rare: refine sequentially from the previous sample
        prev = k - 1
        qall[k] = _substep(c, qall[prev], t[prev], t[k])[0]
    c.condition = _check_regular(c, qall, t)
    return qall


def _substep(c: Compiled, q: np.ndarray, ta: float, tb: float, depth: int = 0) -> np.ndarray:
    for n in (4, 16, 64):
        cur = q.copy()
        good = True
        for tt in np.linspace(ta, tb, n + 1)[1:]:
            v, a = _vel_acc_safe(c, cur, tt)
            h = (tb - ta) / n
            sol, ok, _ = _newton(c, (cur + v * h + 0.5 * a * h * h)[None, :], np.array([tt]))
            if not ok[0]:
                good = False
                break
            cur = sol[0]
        if good:
            return cur[None, :]
    raise _fail_position(c, cur, float(tt))


def _vel_acc_safe(c: Compiled, q: np.ndarray, t: float):
    try:
        v, a = _vel_acc(c, q[None, :], np.array([t]))
        return v[0], a[0]
    except np.linalg.LinAlgError:
        return np.zeros_like(q), np.zeros_like(q)


def _vel_acc(c: Compiled, q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    qx = _extend(q)
    J = jacobian(c, qx)[:, :, 3:]
    v = _solve_rect(J, velocity_rhs(c, t))
    a = _solve_rect(J, acceleration_rhs(c, qx, _extend(v), t))
    return v, a


# --------------------------------------------------------------------------------------------
# Dynamics and results


@dataclass
class Analysis:
    """Everything the engine computes for one model along one motion (SI units).

    ``q``, ``v``, ``a``: (N, nb, 3) centre-of-mass coordinates and their derivatives.
    ``force``/``moment``: shaking force (N, 2) and moment (N,) on the frame from the reactions
    (route a), about ``moment_point``; ``force_momentum``/``moment_momentum`` the same from the
    momentum derivative (route b). ``efforts``: actuator torque or force per driver, applied by
    the actuator to the driven body. ``reactions``: constraint loads per joint (the generalized
    forces of the joint's multipliers, see :func:`_joint_reactions`), for revolutes the force
    exerted on body b by body a.
    """

    t: np.ndarray
    names: list[str]
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    force_momentum: np.ndarray
    moment_momentum: np.ndarray
    efforts: dict[str, np.ndarray]
    reactions: dict[str, dict[str, np.ndarray]]
    com: np.ndarray
    momentum: np.ndarray
    angular_momentum: np.ndarray
    moment_point: tuple[float, float]
    gravity: tuple[float, float]
    extra: dict = field(default_factory=dict)

    @property
    def max_force(self) -> float:
        return float(np.max(np.linalg.norm(self.force, axis=1)))

    @property
    def max_moment(self) -> float:
        return float(np.max(np.abs(self.moment)))

    def static_load(self) -> tuple[np.ndarray, np.ndarray]:
        """The part of the shaking loads due to the moving links' weight: the force m g (2,)
        and its moment (N,) about the moment point, (r_com - P) x m g. Zero without gravity."""
        W = self.extra["total_mass"] * np.asarray(self.gravity)
        r = self.com - np.asarray(self.moment_point)
        return W, r[:, 0] * W[1] - r[:, 1] * W[0]

    @property
    def inertial_force(self) -> np.ndarray:
        """Shaking force minus the links' weight: -dP/dt (N, 2)."""
        return self.force - self.static_load()[0]

    @property
    def inertial_moment(self) -> np.ndarray:
        """Shaking moment minus the weight's moment: -dH_P/dt (N,)."""
        return self.moment - self.static_load()[1]

    @property
    def max_inertial_force(self) -> float:
        return float(np.max(np.linalg.norm(self.inertial_force, axis=1)))

    @property
    def max_inertial_moment(self) -> float:
        return float(np.max(np.abs(self.inertial_moment)))

    def route_difference(self) -> tuple[float, float]:
        """Absolute max |reactions - momentum| of the force (N) and of the moment (N m); the
        study divides them by the unbalanced stage's peaks."""
        df = float(np.max(np.linalg.norm(self.force - self.force_momentum, axis=1)))
        dm = float(np.max(np.abs(self.moment - self.moment_momentum)))
        return df, dm

    def pose(self, k: int, body: str) -> tuple[float, float, float]:
        """Pose of a body's own frame (not its centre of mass) at sample k."""
        i = self.names.index(body)
        return self.extra["frame_pose"][k, i].tolist()


def _tooth_rows(c: Compiled, qx: np.ndarray, J: np.ndarray) -> list[dict[str, np.ndarray]]:
    """Write each mesh's generalized force as tooth forces at its pitch point (in place in J).

    The gear's angle row is replaced by the rolling condition t . (v_P(b) - v_P(a)) = 0 at the
    pitch point P = O_a + s r_a u of the bearings' centres O_a, O_b on the carrier (u from O_a
    to O_b, t = perp(u)): on b the row is (t, (P - r_b) x t), on a (-t, -(P - r_a) x t). Where
    the bearings are closed it equals -r_b times the angle row plus a combination of the
    bearings' rows, so the motion, the efforts and the frame loads are unchanged, the mesh's
    multiplier becomes the tangential tooth force (-lambda t on b) and the bearings' multipliers
    carry it (Haug, ch. 6: a constraint's reaction is -Phi_q^T lambda for any equivalent
    choice of rows). Returns the geometry (u, t, P, O_b) per mesh for the reactions.
    """
    geo = []
    for m in c.meshes:
        rc, thc = _split(qx, m.ic)
        Oa = rc + _rotate(thc, m.sca)
        Ob = rc + _rotate(thc, m.scb)
        d = Ob - Oa
        u = d / np.linalg.norm(d, axis=1)[:, None]
        t = _perp(u)
        P = Oa + (m.side * m.pitch_a) * u
        J[:, m.row, :] = 0.0
        for k, sign in ((m.ib, 1.0), (m.ia, -1.0)):
            rk, _ = _split(qx, k)
            arm = P - rk
            J[:, m.row, 3 * k : 3 * k + 2] += sign * t
            J[:, m.row, 3 * k + 2] += sign * (arm[:, 0] * t[:, 1] - arm[:, 1] * t[:, 0])
        geo.append({"u": u, "t": t, "P": P, "Ob": Ob})
    return geo


def _radial_tooth_loads(
    c: Compiled, geo: list[dict[str, np.ndarray]], lam: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Add each mesh's radial tooth force, |F_t| tan(pressure angle), to its bearings.

    The radial pair (on b: +F_r u for an external mesh, which it pushes apart, -F_r u for an
    internal one; the opposite on a) acts at P on the line of centres, so it has no moment about
    either bearing and its forces on the carrier, at O_a and O_b, cancel: the increments of the
    two bearings' multipliers below are the exact solution of Phi_q^T dlambda = Q_radial, every
    other multiplier (and so the efforts) unchanged. When a gear is the frame itself (a fixed
    sun), the radial force its teeth take is an applied load on the frame, not a multiplier:
    it is returned as (Fx, Fy, M_O) per sample, to add to the frame's load -Phi_q0^T lambda.
    """
    on_frame = np.zeros((lam.shape[0], 3))
    for m, g in zip(c.meshes, geo):
        Fr = np.abs(lam[:, m.row]) * m.tan_alpha
        on_b = (Fr if m.external else -Fr)[:, None] * g["u"]  # radial tooth force on gear b
        lam[:, m.rows_b] -= m.sign_b * on_b  # the bearing of b takes it back ...
        lam[:, m.rows_a] += m.sign_a * on_b  # ... and that of a the opposite one
        for k, f in ((m.ia, -on_b), (m.ib, on_b)):
            if k == 0:
                P = g["P"]
                on_frame[:, :2] += f
                on_frame[:, 2] += P[:, 0] * f[:, 1] - P[:, 1] * f[:, 0]
    return lam, on_frame


def _joint_reactions(
    model: Model, c: Compiled, lam: np.ndarray, geo: list[dict[str, np.ndarray]] | None = None
) -> dict[str, dict[str, np.ndarray]]:
    """Loads that each joint transmits, from its multipliers (constraint force = -Phi_q^T lam).

    Revolute: force (Fx, Fy) exerted on body b by body a (Phi = P_a - P_b, so it is +lam); a
    gear's bearing includes the tooth force. Prismatic: N, the force on the slider along the
    guide's left normal (-lam of the guide row), and M, the moment on the slider (-lam of the
    rotation lock). Gear: T, the torque on gear b relative to the carrier (-lam of the angle
    row; with pitch radii the moment of the tooth force about b's centre), and with pitch radii
    Ft = T / r_b, the tangential tooth force on b (positive when it turns b counter-clockwise)
    and Fr >= 0, the radial one (|Ft| tan(pressure angle)).
    """
    out: dict[str, dict[str, np.ndarray]] = {}
    tooth = {m.name: (m, g) for m, g in zip(c.meshes, geo or [])}
    for jt in model.joints:
        rows = c.joint_rows[jt.name]
        if isinstance(jt, Revolute):
            out[jt.name] = {"Fx": lam[:, rows[0]], "Fy": lam[:, rows[1]]}
        elif isinstance(jt, Prismatic):
            out[jt.name] = {"N": -lam[:, rows[1]], "M": -lam[:, rows[0]]}
        elif jt.name in tooth:
            m, g = tooth[jt.name]
            F = -lam[:, rows[0]][:, None] * g["t"]  # tangential tooth force on b
            arm = g["P"] - g["Ob"]
            T = arm[:, 0] * F[:, 1] - arm[:, 1] * F[:, 0]
            out[jt.name] = {"T": T, "Ft": T / m.pitch_b, "Fr": np.abs(lam[:, rows[0]]) * m.tan_alpha}
        else:
            out[jt.name] = {"T": -lam[:, rows[0]]}
    return out


def _multipliers(c: Compiled, Jf: np.ndarray, rhs: np.ndarray) -> np.ndarray:
    """Lagrange multipliers from Phi_q^T lambda = Q - M q'' (N samples).

    Square Jacobian: the unique solution. Redundant actuation (r more rows than coordinates):
    Phi_q^T has an r-dimensional null space, the internal (antagonistic) loads that the
    actuators can add without moving anything. Of all solutions, lambda_p + N z, the one whose
    driver rows (the actuator efforts) have the least Euclidean norm is taken: z minimises
    |S (lambda_p + N z)| with S the driver rows. The joint multipliers follow from the same
    lambda, so every reaction is consistent with the efforts; the frame load -Phi_q0^T lambda
    still equals minus the momentum rate, whatever the split (the null space loads every body
    with zero net force). This is the pseudo-inverse solution tau = (G^T)^+ f of the reduced
    dynamics G^T tau = f, G the Jacobian of the actuated coordinates.
    """
    A = np.transpose(Jf, (0, 2, 1))  # (N, n, m)
    n, m = A.shape[1], A.shape[2]
    if m == n:
        return np.linalg.solve(A, rhs[..., None])[..., 0]
    Q, R = np.linalg.qr(Jf, mode="complete")  # Jf = [Q1 Q2] [R1; 0]: Q2 spans the null space of A
    y = np.linalg.solve(np.transpose(R[:, :n, :], (0, 2, 1)), rhs[..., None])[..., 0]  # R1^T y = rhs
    lam_p = np.einsum("nmk,nk->nm", Q[:, :, :n], y)  # the least-norm solution, Q1 R1^-T rhs
    null = Q[:, :, n:]  # (N, m, r)
    drv = sorted(c.driver_rows.values())
    S_null = null[:, drv, :]  # (N, d, r)
    z = -np.einsum("nij,nj->ni", np.linalg.pinv(S_null), lam_p[:, drv])
    return lam_p + np.einsum("nmr,nr->nm", null, z)


def analyse(
    model: Model,
    t: np.ndarray,
    gravity: tuple[float, float] = (0.0, 0.0),
    moment_point: tuple[float, float] = (0.0, 0.0),
) -> Analysis:
    """Kinematics, inverse dynamics and shaking loads of ``model`` at times ``t``."""
    c = compile_model(model)
    t = np.asarray(t, dtype=float)
    q = solve_positions(c, t)
    v, a = _vel_acc(c, q, t)
    qx = _extend(q)
    J = jacobian(c, qx)
    mesh_geo = _tooth_rows(c, qx, J)  # gear meshes with pitch radii act by tooth forces
    Jf, J0 = J[:, :, 3:], J[:, :, :3]
    nb = c.nb
    g = np.asarray(gravity, dtype=float)
    Mdiag = np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(1, -1)
    Q = np.zeros_like(q)
    Q[:, 0::3] = c.mass * g[0]
    Q[:, 1::3] = c.mass * g[1]
    rhs = Q - Mdiag * a
    lam = _multipliers(c, Jf, rhs)
    lam, radial_on_frame = _radial_tooth_loads(c, mesh_geo, lam)
    gen0 = -np.einsum("nmk,nm->nk", J0, lam) + radial_on_frame  # load on the frame: Fx, Fy, M_O
    P = np.asarray(moment_point, dtype=float)
    force = gen0[:, :2]
    moment_O = gen0[:, 2]

    qb, vb, ab = q.reshape(-1, nb, 3), v.reshape(-1, nb, 3), a.reshape(-1, nb, 3)
    m, I = c.mass, c.inertia
    r, rd, rdd = qb[:, :, :2], vb[:, :, :2], ab[:, :, :2]
    cross = lambda u, w: u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]  # noqa: E731
    dP = np.einsum("k,nkd->nd", m, rdd)
    dH = np.einsum("k,nk->n", m, cross(r, rdd)) + ab[:, :, 2] @ I
    weight = m.sum() * g
    force_mom = weight[None, :] - dP
    moment_mom = np.einsum("k,nk->n", m, cross(r, np.broadcast_to(g, r.shape))) - dH
    momentum = np.einsum("k,nkd->nd", m, rd)
    ang = np.einsum("k,nk->n", m, cross(r, rd)) + vb[:, :, 2] @ I
    com = np.einsum("k,nkd->nd", m, r) / m.sum() if m.sum() > 0 else np.zeros((len(t), 2))

    def about_P(M: np.ndarray, F: np.ndarray) -> np.ndarray:
        return M - (P[0] * F[:, 1] - P[1] * F[:, 0])

    efforts = {name: -lam[:, row] for name, row in c.driver_rows.items()}
    reactions = _joint_reactions(model, c, lam, mesh_geo)
    # frame poses for drawing: frame origin = com - A(theta) com_local
    frame_pose = np.zeros_like(qb)
    for k, b in enumerate(model.bodies):
        _, cl, _ = b.mass_properties()
        frame_pose[:, k, :2] = qb[:, k, :2] - _rotate(qb[:, k, 2], np.asarray(cl))
        frame_pose[:, k, 2] = qb[:, k, 2]
    return Analysis(
        t=t, names=c.names, q=qb, v=vb, a=ab,
        force=force, moment=about_P(moment_O, force),
        force_momentum=force_mom, moment_momentum=about_P(moment_mom, force_mom),
        efforts=efforts, reactions=reactions, com=com, momentum=momentum, angular_momentum=ang,
        moment_point=(float(P[0]), float(P[1])), gravity=(float(g[0]), float(g[1])),
        extra={"frame_pose": frame_pose, "condition": c.condition, "total_mass": float(m.sum()),
               "redundant_actuators": redundancy(c)},
    )
