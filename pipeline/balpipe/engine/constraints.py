"""The constraint equations Phi(q, t) = 0, their Jacobian Phi_q and the right-hand sides of the
velocity (nu) and acceleration (gamma) equations, vectorised over samples (Haug, ch. 3)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from ..mechanics.planar import rotate
from .compile import Compiled, _Angle, _Coincident, _Projection, _perp


def _split(q: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
    """Position (N, 2) and angle (N,) of body k from the extended coordinates (N, 3 nb + 3)."""
    return q[:, 3 * k : 3 * k + 2], q[:, 3 * k + 2]


def _law_values(prim: _Angle | _Projection, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    if prim.law is None:
        z = np.zeros_like(t)
        return z, z, z
    return prim.law(t)


def law_positions(c: Compiled, t: np.ndarray) -> list[np.ndarray | None]:
    """Each primitive's driving law f(t) (None for a coincidence): what :func:`residual` subtracts,
    evaluated once for the iterations of a Newton-Raphson solve at the same times."""
    return [None if isinstance(p, _Coincident) else _law_values(p, t)[0] for p in c.prims]


def law_triples(c: Compiled, t: np.ndarray) -> list[tuple[np.ndarray, np.ndarray, np.ndarray] | None]:
    """Each primitive's (f, f', f'') at times t (None for a coincidence): :func:`law_positions`
    with the derivatives that :func:`velocity_rhs` and :func:`acceleration_rhs` take."""
    return [None if isinstance(p, _Coincident) else _law_values(p, t) for p in c.prims]


class GridLaws:
    """The drivers' values on a motion's time grid, made once when first needed
    (``evaluate(grid)``): the whole table for the grid itself, its row for a single time on it
    (``row(table, k)``: the continuation's steps), None for any other times (the caller
    evaluates those). Shared by the general path's and the block path's solves
    (:class:`.positions.DenseOps`, :class:`.newton_blocks.BlockOps`), whose tables differ."""

    def __init__(self, grid: np.ndarray, evaluate: Callable[[np.ndarray], Any], row: Callable[[Any, int], Any]):
        self.grid, self._evaluate, self._row = grid, evaluate, row
        self._where = {x: k for k, x in enumerate(grid.tolist())}
        self._table: Any = None

    def at(self, t: np.ndarray) -> Any:
        k = self._where.get(float(t[0])) if len(t) == 1 else None
        if t is not self.grid and k is None:
            return None
        if self._table is None:
            self._table = self._evaluate(self.grid)
        if t is self.grid or k is None:  # k is None only for the grid itself (returned above otherwise)
            return self._table
        return self._row(self._table, k)


def residual(c: Compiled, qx: np.ndarray, t: np.ndarray, laws: list | None = None) -> np.ndarray:
    """Phi(q, t), shape (N, m). The revolute rows of every joint at once (:func:`revolute_rows`),
    the same arithmetic as one joint at a time, so the same bits; ``laws``: :func:`law_positions`
    at ``t`` (the same values, not evaluated again)."""
    if laws is None:
        laws = law_positions(c, t)
    rev = revolute_rows(c)
    out = np.empty((qx.shape[0], len(c.row_owner)))
    if rev is not None:
        ri, rj = qx[:, rev.xi], qx[:, rev.xj]
        Ai, Aj = rotate(qx[:, rev.ti], rev.si), rotate(qx[:, rev.tj], rev.sj)
        out[:, rev.rows] = ri + Ai - rj - Aj
    row = 0
    for p, f in zip(c.prims, laws):
        if isinstance(p, _Coincident):
            if rev is None:
                ri, thi = _split(qx, p.i)
                rj, thj = _split(qx, p.j)
                out[:, row : row + 2] = ri + rotate(thi, p.si) - rj - rotate(thj, p.sj)
        elif isinstance(p, _Angle):
            val = sum(v * qx[:, 3 * k + 2] for k, v in p.coeffs) - p.const - f
            out[:, row] = val
        else:
            ri, thi = _split(qx, p.i)
            rj, thj = _split(qx, p.j)
            e = rotate(thi, p.a)
            d = rj + rotate(thj, p.sj) - ri - rotate(thi, p.si)
            out[:, row] = np.sum(e * d, axis=1) - p.const - f
        row += p.rows
    return out


def jacobian(c: Compiled, qx: np.ndarray) -> np.ndarray:
    """Phi_q over the extended coordinates (frame included), shape (N, m, 3 nb + 3). Every entry
    of a revolute joint's rows has that joint alone as its source: they are written for every
    joint at once (``0.0 + x``, ``0.0 - x``: the signed zeros of the accumulation)."""
    N = qx.shape[0]
    m = len(c.row_owner)
    J = np.zeros((N, m, qx.shape[1]))
    rev = revolute_rows(c)
    if rev is not None:
        r0, r1 = rev.rows[:, 0], rev.rows[:, 1]
        for a, r in ((0, r0), (1, r1)):
            J[:, r, rev.xi[:, a]] = 0.0 + 1.0
            J[:, r, rev.xj[:, a]] = 0.0 - 1.0
        Pi = _perp(rotate(qx[:, rev.ti], rev.si))
        Pj = _perp(rotate(qx[:, rev.tj], rev.sj))
        J[:, r0, rev.ti] = 0.0 + Pi[..., 0]
        J[:, r1, rev.ti] = 0.0 + Pi[..., 1]
        J[:, r0, rev.tj] = 0.0 - Pj[..., 0]
        J[:, r1, rev.tj] = 0.0 - Pj[..., 1]
    row = 0
    for p in c.prims:
        if isinstance(p, _Coincident):
            if rev is None:
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


@dataclass(frozen=True)
class RevoluteRows:
    """Indices of every revolute joint (``_Coincident``) of a compiled model, in prim order:
    ``rows`` (K, 2) its two constraint rows, ``xi``/``xj`` (K, 2) the position columns of bodies
    i and j in the extended coordinates, ``ti``/``tj`` (K,) their angle columns, ``si``/``sj``
    (K, 2) the joint point relative to each centre of mass."""

    rows: np.ndarray
    xi: np.ndarray
    xj: np.ndarray
    ti: np.ndarray
    tj: np.ndarray
    si: np.ndarray
    sj: np.ndarray


def revolute_rows(c: Compiled) -> RevoluteRows | None:
    """The :class:`RevoluteRows` of ``c``, made once (kept in ``c.revolutes``); None when ``c``
    has none or a joint joins a body to itself (then the joints are evaluated one at a time)."""
    if c.revolutes is None:
        c.revolutes = _revolute_rows(c.prims) or False
    rows: RevoluteRows | None = c.revolutes or None
    return rows


def _revolute_rows(prims: list) -> RevoluteRows | None:
    rows, idx = [], []
    row = 0
    for p in prims:
        if isinstance(p, _Coincident):
            rows.append((row, row + 1))
            idx.append(p)
        row += p.rows
    if not idx or any(p.i == p.j for p in idx):
        return None
    i = np.array([p.i for p in idx])
    j = np.array([p.j for p in idx])
    return RevoluteRows(np.array(rows), np.stack([3 * i, 3 * i + 1], axis=1), np.stack([3 * j, 3 * j + 1], axis=1),
                        3 * i + 2, 3 * j + 2, np.array([p.si for p in idx], dtype=float),
                        np.array([p.sj for p in idx], dtype=float))


def velocity_rhs(c: Compiled, t: np.ndarray, laws: list | None = None) -> np.ndarray:
    """nu = -Phi_t, shape (N, m). ``laws``: :func:`law_triples` at ``t`` (evaluated when not given)."""
    out = []
    for k, p in enumerate(c.prims):
        if p.rows == 2:
            out.append(np.zeros((len(t), 2)))
        else:
            out.append((_law_values(p, t) if laws is None else laws[k])[1][:, None])
    return np.concatenate(out, axis=1)


def acceleration_rhs(c: Compiled, qx: np.ndarray, vx: np.ndarray, t: np.ndarray, laws: list | None = None) -> np.ndarray:
    """gamma = Phi_q q'' (everything in Phi'' but the q'' terms, moved to the right), (N, m);
    the revolute rows for every joint at once, as in :func:`residual`. ``laws``: :func:`law_triples`
    at ``t`` (evaluated when not given)."""
    rev = revolute_rows(c)
    out = np.empty((qx.shape[0], len(c.row_owner)))
    if rev is not None:
        wi, wj = vx[:, rev.ti], vx[:, rev.tj]
        Ai, Aj = rotate(qx[:, rev.ti], rev.si), rotate(qx[:, rev.tj], rev.sj)
        out[:, rev.rows] = (wi**2)[..., None] * Ai - (wj**2)[..., None] * Aj
    row = 0
    for k, p in enumerate(c.prims):
        if isinstance(p, _Coincident):
            if rev is None:
                _, thi = _split(qx, p.i)
                _, thj = _split(qx, p.j)
                wi, wj = vx[:, 3 * p.i + 2], vx[:, 3 * p.j + 2]
                out[:, row : row + 2] = (wi**2)[:, None] * rotate(thi, p.si) - (wj**2)[:, None] * rotate(thj, p.sj)
        elif isinstance(p, _Angle):
            out[:, row] = (_law_values(p, t) if laws is None else laws[k])[2]
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
            out[:, row] = (_law_values(p, t) if laws is None else laws[k])[2] - quad
        row += p.rows
    return out


def with_frame(q: np.ndarray) -> np.ndarray:
    """The moving bodies' coordinates ``q`` (N, 3n) with the frame's q_0 = 0 put first (N, 3 + 3n):
    the coordinates that :func:`residual` and :func:`jacobian` take."""
    return np.concatenate([np.zeros((q.shape[0], 3)), q], axis=1)
