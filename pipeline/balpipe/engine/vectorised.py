"""The constraint equations evaluated all at once, primitive type by primitive type.

The same Phi, Phi_q, nu and gamma as :mod:`.constraints` (Haug, ch. 3 and 6), laid out for
speed: coordinates are stored coordinate-major, ``X`` of shape (3 nb + 3, N) with the frame's
three zero rows first, so that every operation runs on contiguous rows of N samples; each
primitive type is evaluated for all its instances in a few numpy operations (no loop over
joints); the Jacobian is kept sparse, as the values ``(nnz, N)`` of a fixed list of entries
(row, column) whose constant entries (the +-1 of revolutes, the coefficients of angle rows)
are written once. The driver laws are evaluated once per call (:func:`law_table`).
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from .compile import Compiled, _Angle, _Coincident


@dataclass
class Vectorised:
    """Index arrays of a compiled model, grouped by primitive type."""

    m: int  # constraint rows
    ncol: int  # 3 nb + 3 (frame included)
    # revolutes: bodies, local points, first rows
    ci: np.ndarray
    cj: np.ndarray
    csi: np.ndarray  # (nc, 2)
    csj: np.ndarray
    crow: np.ndarray
    # angle rows: dense coefficients over the bodies' angles, constants, rows
    akoef: np.ndarray  # (na, nb + 1)
    aconst: np.ndarray
    arow: np.ndarray
    # projections
    pi: np.ndarray
    pj: np.ndarray
    pa: np.ndarray  # (np, 2)
    psi: np.ndarray
    psj: np.ndarray
    pconst: np.ndarray
    prow: np.ndarray
    # driven rows (a law), and the laws
    law_rows: np.ndarray
    laws: list
    # sparse Jacobian: entries (row, col), constant values (nan where they vary), structural mask
    rows: np.ndarray
    cols: np.ndarray
    const: np.ndarray
    structural: np.ndarray  # False for entries that are zero whatever the configuration
    c_base: int  # slot of the first revolute entry (8 kinds x nc)
    p_base: int  # slot of the first projection entry (6 kinds x np)

    @property
    def nnz(self) -> int:
        return len(self.rows)

    def __post_init__(self) -> None:
        self.aux = _Aux(self)  # derived index arrays and stacks, made once (not a field)


def vectorise(c: Compiled) -> Vectorised:
    """Group the primitives of ``c`` by type and lay out the sparse Jacobian's entries."""
    nbx = c.nb + 1
    coinc, angle, proj = [], [], []
    row = 0
    law_rows, laws = [], []
    for p in c.prims:
        if isinstance(p, _Coincident):
            coinc.append((p, row))
        elif isinstance(p, _Angle):
            angle.append((p, row))
        else:
            proj.append((p, row))
        if getattr(p, "law", None) is not None:
            law_rows.append(row)
            laws.append(p.law)
        row += p.rows
    def ia(xs: Sequence[Any]) -> np.ndarray:
        return np.array(xs, dtype=np.intp)

    def fa(xs: Sequence[Any], shape: tuple[int, ...] = (0,)) -> np.ndarray:
        return np.array(xs, dtype=float).reshape((-1,) + shape[1:]) if xs else np.zeros(shape)

    ci, cj = ia([p.i for p, _ in coinc]), ia([p.j for p, _ in coinc])
    csi, csj = fa([p.si for p, _ in coinc], (0, 2)), fa([p.sj for p, _ in coinc], (0, 2))
    crow = ia([r for _, r in coinc])
    akoef = np.zeros((len(angle), nbx))
    for k, (p, _) in enumerate(angle):
        for b, v in p.coeffs:
            akoef[k, b] += v
    pi, pj = ia([p.i for p, _ in proj]), ia([p.j for p, _ in proj])
    pa = fa([p.a for p, _ in proj], (0, 2))
    psi, psj = fa([p.si for p, _ in proj], (0, 2)), fa([p.sj for p, _ in proj], (0, 2))

    rows: list[int] = []
    cols: list[int] = []
    const: list[float] = []
    struct: list[bool] = []

    def add(r: int, col: int, value: float, nonzero: Any = True) -> None:
        rows.append(r)
        cols.append(col)
        const.append(value)
        struct.append(bool(nonzero))

    # angle rows first (constant), then revolutes in 8 kinds, then projections in 6 kinds
    for k, (p, r) in enumerate(angle):
        for b in range(nbx):
            if akoef[k, b] != 0.0:
                add(r, 3 * b + 2, akoef[k, b])
    c_base = len(rows)
    nc = len(coinc)
    kinds = [(0, 0, 1.0), (1, 1, 1.0), (0, 0, -1.0), (1, 1, -1.0)]
    for kk, (dr, dc, val) in enumerate(kinds):
        body = ci if kk < 2 else cj
        for k in range(nc):
            add(crow[k] + dr, 3 * body[k] + dc, val)
    for kk in range(4):  # theta entries: rows r, r+1 of body i, then of body j
        body, s = (ci, csi) if kk < 2 else (cj, csj)
        for k in range(nc):
            add(crow[k] + kk % 2, 3 * body[k] + 2, np.nan, np.any(s[k] != 0.0))
    p_base = len(rows)
    prow = ia([r for _, r in proj])
    for kk in range(6):  # x_i, y_i, x_j, y_j, theta_i, theta_j
        for k in range(len(proj)):
            body = pi[k] if kk in (0, 1, 4) else pj[k]
            col = 3 * body + (kk % 2 if kk < 4 else 2)
            add(prow[k], col, np.nan, kk != 5 or np.any(psj[k] != 0.0))
    return Vectorised(
        m=row, ncol=3 * nbx, ci=ci, cj=cj, csi=csi, csj=csj, crow=crow,
        akoef=akoef, aconst=np.array([p.const for p, _ in angle], dtype=float), arow=ia([r for _, r in angle]),
        pi=pi, pj=pj, pa=pa, psi=psi, psj=psj, pconst=np.array([p.const for p, _ in proj], dtype=float), prow=prow,
        law_rows=ia(law_rows), laws=laws,
        rows=ia(rows), cols=ia(cols), const=np.array(const, dtype=float), structural=np.array(struct, dtype=bool),
        c_base=c_base, p_base=p_base,
    )


def vectorised_of(c: Compiled) -> Vectorised:
    """``c``'s :func:`vectorise`, made once: the block path's (:func:`.fastpath.prepare`) where
    it has been prepared, else kept on ``c``."""
    if c.fast is not None:
        return c.fast.vz
    if c.vectorised is None:
        c.vectorised = vectorise(c)
    return c.vectorised


def law_table(vz: Vectorised, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """f, f', f'' of every driven row, (len(law_rows), N) each: each law called once."""
    N = len(t)
    F = np.empty((3, len(vz.laws), N))
    for k, law in enumerate(vz.laws):
        f = law(t)
        F[0, k], F[1, k], F[2, k] = f[0], f[1], f[2]
    return F[0], F[1], F[2]


def table_row(table: tuple[np.ndarray, np.ndarray, np.ndarray], k: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Sample k of :func:`law_table`'s table, as the table of that time alone."""
    return table[0][:, k : k + 1], table[1][:, k : k + 1], table[2][:, k : k + 1]


def _rot(C: np.ndarray, S: np.ndarray, b: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A(theta_b) s for arrays of bodies b and local vectors s (k, 2): x and y, (k, N) each."""
    cb, sb = C[b], S[b]
    return cb * s[:, :1] - sb * s[:, 1:], sb * s[:, :1] + cb * s[:, 1:]


class _Aux:
    """Index arrays and stacks derived from a :class:`Vectorised`, made once with it: the rows of
    the coordinates each primitive reads, and every local vector :class:`State` rotates (the
    revolutes' s_i, s_j, then the projections' a, s_i, s_j) with its body."""

    def __init__(self, vz: Vectorised):
        self.cix, self.ciy, self.cjx, self.cjy = 3 * vz.ci, 3 * vz.ci + 1, 3 * vz.cj, 3 * vz.cj + 1
        self.pix, self.piy, self.pjx, self.pjy = 3 * vz.pi, 3 * vz.pi + 1, 3 * vz.pj, 3 * vz.pj + 1
        self.crow1 = vz.crow + 1
        self.aconst, self.pconst = vz.aconst[:, None], vz.pconst[:, None]
        self.const = np.append(vz.const, 0.0)[:, None]
        self.bodies = np.concatenate([vz.ci, vz.cj, vz.pi, vz.pi, vz.pj]).astype(np.intp)
        self.local = np.concatenate([vz.csi, vz.csj, vz.pa, vz.psi, vz.psj]).reshape(-1, 2)
        # per constraint row: its kind (0, 1: a revolute's x, y; 2: an angle row; 3: a projection),
        # its primitive's index within the kind, and its law's index (-1: no law)
        self.kind = np.full(vz.m, -1, dtype=np.intp)
        self.index = np.zeros(vz.m, dtype=np.intp)
        self.law = np.full(vz.m, -1, dtype=np.intp)
        for kind, rows in ((0, vz.crow), (1, vz.crow + 1), (2, vz.arow), (3, vz.prow)):
            self.kind[rows] = kind
            self.index[rows] = np.arange(len(rows))
        self.law[vz.law_rows] = np.arange(len(vz.law_rows))


class State:
    """Trigonometry and rotated local vectors at the angles of X (3 nb + 3, N). They depend on
    the angles only: the positions in X may change afterwards (:func:`residual` and the others
    read them from X each time)."""

    def __init__(self, vz: Vectorised, X: np.ndarray):
        th = X[2::3]
        self.vz = vz
        self.X = X
        self.C, self.S = np.cos(th), np.sin(th)
        # every rotated local vector at once (fewer numpy calls; the same operations per entry)
        self.aux = aux = vz.aux
        x, y = _rot(self.C, self.S, aux.bodies, aux.local)
        nc, npj = len(vz.ci), len(vz.pi)
        self.AIx, self.AIy = x[:nc], y[:nc]
        self.AJx, self.AJy = x[nc : 2 * nc], y[nc : 2 * nc]
        if npj:
            b = 2 * nc
            self.ex, self.ey = x[b : b + npj], y[b : b + npj]
            self.PIx, self.PIy = x[b + npj : b + 2 * npj], y[b + npj : b + 2 * npj]
            self.PJx, self.PJy = x[b + 2 * npj :], y[b + 2 * npj :]

    def d(self) -> tuple[np.ndarray, np.ndarray]:
        """The projections' vectors d = r_j + A_j s_j - r_i - A_i s_i, x and y (np, N)."""
        X, ax = self.X, self.aux
        return (X[ax.pjx] + self.PJx - X[ax.pix] - self.PIx,
                X[ax.pjy] + self.PJy - X[ax.piy] - self.PIy)


def residual(vz: Vectorised, s: State, f: np.ndarray) -> np.ndarray:
    """Phi (m, N) at the state ``s``; ``f`` the law values of the driven rows."""
    X, ax = s.X, s.aux
    out = np.empty((vz.m, X.shape[1]))
    if len(vz.ci):
        out[vz.crow] = X[ax.cix] + s.AIx - X[ax.cjx] - s.AJx
        out[ax.crow1] = X[ax.ciy] + s.AIy - X[ax.cjy] - s.AJy
    if len(vz.arow):
        out[vz.arow] = vz.akoef @ X[2::3] - ax.aconst
    if len(vz.prow):
        dx, dy = s.d()
        out[vz.prow] = s.ex * dx + s.ey * dy - ax.pconst
    if len(vz.law_rows):
        out[vz.law_rows] -= f
    return out


def residual_rows(vz: Vectorised, s: State, f: np.ndarray, eq: np.ndarray) -> np.ndarray:
    """The rows ``eq`` of :func:`residual` (len(eq), N), each by the same operations as there (the
    same values), the others not evaluated: what an explicit solve level by level needs (the
    whole residual at every level is O(levels x rows): quadratic in a serial chain's length)."""
    X, ax = s.X, s.aux
    out = np.empty((len(eq), X.shape[1]))
    kind, index = ax.kind[eq], ax.index[eq]
    for kd in (0, 1, 2, 3):
        at = np.flatnonzero(kind == kd)
        if not len(at):
            continue
        k = index[at]
        if kd == 0:
            out[at] = X[ax.cix[k]] + s.AIx[k] - X[ax.cjx[k]] - s.AJx[k]
        elif kd == 1:
            out[at] = X[ax.ciy[k]] + s.AIy[k] - X[ax.cjy[k]] - s.AJy[k]
        elif kd == 2:
            out[at] = vz.akoef[k] @ X[2::3] - ax.aconst[k]
        else:
            xi, yi, xj, yj = ax.pix[k], ax.piy[k], ax.pjx[k], ax.pjy[k]
            dx = X[xj] + s.PJx[k] - X[xi] - s.PIx[k]
            dy = X[yj] + s.PJy[k] - X[yi] - s.PIy[k]
            out[at] = s.ex[k] * dx + s.ey[k] * dy - ax.pconst[k]
    law = ax.law[eq]
    driven = np.flatnonzero(law >= 0)
    if len(driven):
        out[driven] -= f[law[driven]]
    return out


def jacobian_values(vz: Vectorised, s: State) -> np.ndarray:
    """Values (nnz + 1, N) of the Jacobian's entries (frame columns included); the extra last
    row is zero (a padding slot for the triangular solves)."""
    N = s.X.shape[1]
    J = np.empty((vz.nnz + 1, N))
    J[:] = s.aux.const
    nc, npj = len(vz.ci), len(vz.pi)
    if nc:
        b = vz.c_base + 4 * nc
        J[b : b + nc] = -s.AIy
        J[b + nc : b + 2 * nc] = s.AIx
        J[b + 2 * nc : b + 3 * nc] = s.AJy
        J[b + 3 * nc : b + 4 * nc] = -s.AJx
    if npj:
        b = vz.p_base
        J[b : b + npj] = -s.ex
        J[b + npj : b + 2 * npj] = -s.ey
        J[b + 2 * npj : b + 3 * npj] = s.ex
        J[b + 3 * npj : b + 4 * npj] = s.ey
        # d/dtheta_i: perp(e) . d - e . perp(A_i s_i);  d/dtheta_j: e . perp(A_j s_j)
        dx, dy = s.d()
        J[b + 4 * npj : b + 5 * npj] = (-s.ey * dx + s.ex * dy) - (-s.ex * s.PIy + s.ey * s.PIx)
        J[b + 5 * npj : b + 6 * npj] = -s.ex * s.PJy + s.ey * s.PJx
    return J


def velocity_rhs(vz: Vectorised, fd: np.ndarray, N: int) -> np.ndarray:
    """nu = -Phi_t (m, N): the laws' rates on the driven rows, zero elsewhere."""
    out = np.zeros((vz.m, N))
    if len(vz.law_rows):
        out[vz.law_rows] = fd
    return out


def acceleration_rhs(vz: Vectorised, s: State, V: np.ndarray, fdd: np.ndarray) -> np.ndarray:
    """gamma (m, N) at state ``s`` with velocities V (3 nb + 3, N) (see
    :func:`.constraints.acceleration_rhs`)."""
    out = np.zeros((vz.m, V.shape[1]))
    W = V[2::3]
    if len(vz.ci):
        wi2, wj2 = W[vz.ci] ** 2, W[vz.cj] ** 2
        out[vz.crow] = wi2 * s.AIx - wj2 * s.AJx
        out[s.aux.crow1] = wi2 * s.AIy - wj2 * s.AJy
    if len(vz.prow):
        wi, wj = W[vz.pi], W[vz.pj]
        dx, dy = s.d()
        ax = s.aux
        ddx = V[ax.pjx] - wj * s.PJy - V[ax.pix] + wi * s.PIy
        ddy = V[ax.pjy] + wj * s.PJx - V[ax.piy] - wi * s.PIx
        wi2, wj2 = wi**2, wj**2
        quad = (
            -wi2 * (s.ex * dx + s.ey * dy)
            + 2 * wi * (-s.ey * ddx + s.ex * ddy)
            + s.ex * (-wj2 * s.PJx + wi2 * s.PIx) + s.ey * (-wj2 * s.PJy + wi2 * s.PIy)
        )
        out[vz.prow] = -quad
    if len(vz.law_rows):
        out[vz.law_rows] += fdd
    return out
