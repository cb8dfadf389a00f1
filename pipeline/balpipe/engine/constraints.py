"""The constraint equations Phi(q, t) = 0, their Jacobian Phi_q and the right-hand sides of the
velocity (nu) and acceleration (gamma) equations, vectorised over samples (Haug, ch. 3)."""

from __future__ import annotations

import numpy as np

from .compile import Compiled, _Angle, _Coincident, _perp, rotate


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
            out.append(ri + rotate(thi, p.si) - rj - rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            f = _law_values(p, t)[0]
            val = sum(v * qx[:, 3 * k + 2] for k, v in p.coeffs) - p.const - f
            out.append(val[:, None])
        else:
            f = _law_values(p, t)[0]
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            e = rotate(thi, p.a)
            d = rj + rotate(thj, p.sj) - ri - rotate(thi, p.si)
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
            J[:, row : row + 2, 3 * p.i + 2] += _perp(rotate(thi, p.si))
            J[:, row : row + 2, 3 * p.j + 2] -= _perp(rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            for k, v in p.coeffs:
                J[:, row, 3 * k + 2] += v
        else:
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            e = rotate(thi, p.a)
            Asi, Asj = rotate(thi, p.si), rotate(thj, p.sj)
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
            out.append((wi**2)[:, None] * rotate(thi, p.si) - (wj**2)[:, None] * rotate(thj, p.sj))
        elif isinstance(p, _Angle):
            out.append(_law_values(p, t)[2][:, None])
        else:
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            vi, wi = _split(vx, p.i)
            vj, wj = _split(vx, p.j)
            e = rotate(thi, p.a)
            Asi, Asj = rotate(thi, p.si), rotate(thj, p.sj)
            d = rj + Asj - ri - Asi
            dd = vj + wj[:, None] * _perp(Asj) - vi - wi[:, None] * _perp(Asi)
            quad = (
                -(wi**2) * np.sum(e * d, axis=1)
                + 2 * wi * np.sum(_perp(e) * dd, axis=1)
                + np.sum(e * (-(wj**2)[:, None] * Asj + (wi**2)[:, None] * Asi), axis=1)
            )
            out.append((_law_values(p, t)[2] - quad)[:, None])
    return np.concatenate(out, axis=1)


def with_frame(q: np.ndarray) -> np.ndarray:
    """The moving bodies' coordinates ``q`` (N, 3n) with the frame's q_0 = 0 put first (N, 3 + 3n):
    the coordinates that :func:`residual` and :func:`jacobian` take."""
    return np.concatenate([np.zeros((q.shape[0], 3)), q], axis=1)
