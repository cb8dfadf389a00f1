"""Inverse dynamics: Lagrange multipliers (least-norm efforts under redundant actuation), gear
tooth forces and joint reactions."""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from ..model import Model, Prismatic, Revolute
from ..mechanics.planar import cross, rotate
from .compile import Compiled, _perp
from .constraints import _split
from .errors import AnalysisError
from .normal import Normal, factor


def tooth_rows(c: Compiled, qx: np.ndarray, J: np.ndarray) -> list[dict[str, np.ndarray]]:
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
        Oa = rc + rotate(thc, m.sca)
        Ob = rc + rotate(thc, m.scb)
        d = Ob - Oa
        u = d / np.linalg.norm(d, axis=1)[:, None]
        t = _perp(u)
        P = Oa + (m.side * m.pitch_a) * u
        J[:, m.row, :] = 0.0
        for k, sign in ((m.ib, 1.0), (m.ia, -1.0)):
            rk, _ = _split(qx, k)
            arm = P - rk
            J[:, m.row, 3 * k : 3 * k + 2] += sign * t
            J[:, m.row, 3 * k + 2] += sign * cross(arm, t)
        geo.append({"u": u, "t": t, "P": P, "Ob": Ob})
    return geo


def radial_tooth_loads(
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
                on_frame[:, 2] += cross(P, f)
    return lam, on_frame


def joint_reactions(
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
            T = cross(arm, F)
            out[jt.name] = {"T": T, "Ft": T / m.pitch_b, "Fr": np.abs(lam[:, rows[0]]) * m.tan_alpha}
        else:
            out[jt.name] = {"T": -lam[:, rows[0]]}
    return out


ACTUATION_LIMIT = 1e11  # condition number of the actuated system beyond which the efforts are lost


def actuation_condition(c: Compiled, Jf: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Condition numbers (N,) of the actuated system [Phi_joints; B^T] (``Jf``: its free
    columns) along the motion, checked: fewer rows than coordinates (fewer actuators than
    degrees of freedom), or a configuration where the actuators lose control of the mechanism
    (condition above :data:`ACTUATION_LIMIT`: an effort there would be infinite), is an
    :class:`AnalysisError` naming the actuators. ``c``: the system of :func:`.compile._actuated`."""
    m, n = Jf.shape[1], Jf.shape[2]
    names = ", ".join(repr(a) for a in c.driver_rows)
    if m < n:
        dof = n - (m - len(c.driver_rows))
        raise AnalysisError(
            f"not realisable: the mechanism has {dof} degree{'s' if dof != 1 else ''} of freedom but "
            f"{len(c.driver_rows)} actuator{'s are' if len(c.driver_rows) != 1 else ' is'} named ({names}): "
            f"name at least {dof} actuated joints", float(t[0]), joint=None,
        )
    s = np.linalg.svd(Jf, compute_uv=False)
    cond = s[:, 0] / np.maximum(s[:, -1], 1e-300)
    bad = np.flatnonzero(~(cond <= ACTUATION_LIMIT))
    if bad.size:
        k = int(bad[0])
        always = bad.size == len(t)
        raise AnalysisError(
            f"not realisable: the actuators {names} cannot produce the prescribed motion "
            + ("anywhere on it (their joint coordinates leave the mechanism free to move; choose other "
               "actuated joints)" if always else
               f"at t = {t[k]:.6g} s (condition number {cond[k]:.2g}: they lose control of the mechanism "
               "there, a dead centre of the actuation; keep the motion away from it or actuate other joints)"),
            float(t[k]),
        )
    return cond


def multiplier_map(c: Compiled, Jf: np.ndarray) -> np.ndarray:
    """K (N, m, n) with lambda = K rhs the multipliers of :func:`solve_multipliers` for every
    right-hand side: that solve applied to the n unit right-hand sides at once. For models that
    share one factorisation (:func:`.shared.multipliers`)."""
    n = Jf.shape[2]
    return solve_multipliers(c, Jf, np.broadcast_to(np.eye(n), (len(Jf), n, n)))


def multiplier_solver(c: Compiled, Jf: np.ndarray, normal: Normal | None = None) -> Callable[[np.ndarray], np.ndarray]:
    """rhs (N, n) -> the multipliers (N, m) of :func:`solve_multipliers`, for many right-hand
    sides with one ``Jf`` (the models of one geometry, :func:`.shared.multipliers`): with
    redundant actuation the normal equations' factorisation (``normal``: :mod:`.normal`, of this
    ``Jf``; made here if None) and its null space, kept, where they hold; else the map
    :func:`multiplier_map`, made once."""
    if Jf.shape[1] > Jf.shape[2]:
        ne = normal if normal is not None else factor(Jf)
        if ne is not None and ne.null_space(sorted(c.driver_rows.values()), Jf.shape[1] - Jf.shape[2]) is not None:
            return lambda rhs: solve_multipliers(c, Jf, rhs, ne)
    K = multiplier_map(c, Jf)
    return lambda rhs: np.einsum("nmk,nk->nm", K, rhs)


def solve_multipliers(c: Compiled, Jf: np.ndarray, rhs: np.ndarray, normal: Normal | None = None) -> np.ndarray:
    """Lagrange multipliers from Phi_q^T lambda = Q - M q'' (N samples): ``rhs`` (N, n) gives
    (N, m); (N, n, k), k right-hand sides at once (a regressor's columns), gives (N, m, k).

    Square Jacobian: the unique solution. Redundant actuation (r more rows than coordinates):
    Phi_q^T has an r-dimensional null space, the internal (antagonistic) loads that the
    actuators can add without moving anything. Of all solutions, lambda_p + N z, the one whose
    driver rows (the actuator efforts) have the least Euclidean norm is taken: z minimises
    |S (lambda_p + N z)| with S the driver rows. The joint multipliers follow from the same
    lambda, so every reaction is consistent with the efforts; the frame load -Phi_q0^T lambda
    still equals minus the momentum rate, whatever the split (the null space loads every body
    with zero net force). This is the pseudo-inverse solution tau = (G^T)^+ f of the reduced
    dynamics G^T tau = f, G the Jacobian of the actuated coordinates.

    lambda_p and N come from the normal equations (:mod:`.normal`: ``normal``, the
    factorisation of this ``Jf``, or made here) where they hold, refined to QR's accuracy;
    else from the complete QR factorisation of Jf (the same solution to round-off).
    """
    A = np.transpose(Jf, (0, 2, 1))  # (N, n, m)
    n, m = A.shape[1], A.shape[2]
    B = rhs[..., None] if rhs.ndim == 2 else rhs  # (N, n, k)
    lam = None
    if m == n:
        lam = np.linalg.solve(A, B)
    else:
        drv = sorted(c.driver_rows.values())
        ne = normal if normal is not None else factor(Jf)
        M = None if ne is None else ne.null_space(drv, m - n)
        lam_p = None if M is None or ne is None else ne.least_norm(B)
        if M is not None and lam_p is not None:
            lam = lam_p - M @ lam_p[:, drv]  # the null space's component that minimises the efforts
        else:
            Q, R = np.linalg.qr(Jf, mode="complete")  # Jf = [Q1 Q2] [R1; 0]: Q2 spans the null space of A
            y = np.linalg.solve(np.transpose(R[:, :n, :], (0, 2, 1)), B)  # R1^T y = rhs
            lam_p = Q[:, :, :n] @ y  # the least-norm solution, Q1 R1^-T rhs
            null = Q[:, :, n:]  # (N, m, r)
            z = -np.linalg.pinv(null[:, drv, :]) @ lam_p[:, drv]  # (N, r, k)
            lam = lam_p + null @ z
    return lam[..., 0] if rhs.ndim == 2 else lam
