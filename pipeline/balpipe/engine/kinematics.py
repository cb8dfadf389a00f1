"""Velocities and accelerations: Phi_q q' = nu and Phi_q q'' = gamma (Haug, eqs. 3.4.x, 6.x)."""

from __future__ import annotations

import numpy as np

from .compile import Compiled
from .constraints import with_frame, acceleration_rhs, jacobian, velocity_rhs
from .normal import Normal, factor
from .vectorised import State, Vectorised, jacobian_values
from .vectorised import acceleration_rhs as by_type_acceleration_rhs, velocity_rhs as by_type_velocity_rhs


def _solve_rect(J: np.ndarray, b: np.ndarray, qr: tuple[np.ndarray, np.ndarray] | None = None) -> np.ndarray:
    """Solve J x = b for stacks (N, m, n) of full-column-rank J: exact when square, the least-
    squares solution of a consistent over-determined system (redundant drivers) otherwise, by
    the reduced QR factors of J (``qr``: :func:`_factors` of this J, computed here if None)."""
    if J.shape[-2] == J.shape[-1]:
        return np.linalg.solve(J, b[..., None])[..., 0]
    Q, R = qr if qr is not None else np.linalg.qr(J)  # reduced: J = Q R, R (n, n) upper triangular
    return np.linalg.solve(R, np.einsum("nji,nj->ni", Q, b)[..., None])[..., 0]


def _factors(J: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The reduced QR factors that :func:`_solve_rect` uses for J (None for a square J, solved
    directly): for several right-hand sides with the same J, one factorisation."""
    return None if J.shape[-2] == J.shape[-1] else np.linalg.qr(J)


class Consistent:
    """Solves of J x = b for one stack J (N, m, n) of full column rank and consistent right-hand
    sides: LU where square; with redundant drivers (m > n) the normal equations, refined
    (:mod:`.normal`: one inverse of J^T J for every right-hand side), and where they do
    not hold (:func:`.normal.factor` or a refinement gives None), the reduced QR factors of
    :func:`_solve_rect`, made once. ``G``: J^T J when the caller has it. ``normal``: the
    factorisation, for other solves with this J (the multipliers of
    :func:`.dynamics.solve_multipliers`), or None."""

    def __init__(self, J: np.ndarray, G: np.ndarray | None = None):
        self.J = J
        self.normal: Normal | None = factor(J, G) if J.shape[-2] > J.shape[-1] else None
        self._qr: tuple[np.ndarray, np.ndarray] | None = None

    def solve(self, b: np.ndarray) -> np.ndarray:
        """x (N, n)."""
        if self.normal is not None:
            x = self.normal.solve(b)
            if x is not None:
                return x
        if self._qr is None:
            self._qr = _factors(self.J)
        return _solve_rect(self.J, b, self._qr)


def rates(c: Compiled, q: np.ndarray, t: np.ndarray, laws: list | None = None,
          J: np.ndarray | None = None, G: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, Consistent]:
    """Velocities and accelerations (N, n) at positions q, and the solves of their Jacobian
    Phi_q (:class:`Consistent`: one factorisation for both). ``laws``:
    :func:`.constraints.law_triples` at ``t`` (evaluated when not given); ``J``: the whole
    Jacobian at q, frame columns included (formed when not given); ``G``: the Gram matrix of its
    free columns, when the caller has it."""
    qx = with_frame(q)
    solver = Consistent((jacobian(c, qx) if J is None else J)[:, :, 3:], G)
    v = solver.solve(velocity_rhs(c, t, laws))
    a = solver.solve(acceleration_rhs(c, qx, with_frame(v), t, laws))
    return v, a, solver


def jacobian_by_type(vz: Vectorised, q: np.ndarray) -> tuple[State, np.ndarray]:
    """The state (:class:`.vectorised.State`) and the whole Phi_q (N, m, 3 nb + 3), frame columns
    included, at positions q (N, 3 nb), evaluated by primitive type (``vz``: the model's
    :func:`.vectorised.vectorise`): :func:`.constraints.jacobian`'s values with fewer numpy calls."""
    N = q.shape[0]
    X = np.zeros((vz.ncol, N))
    X[3:] = q.T
    s = State(vz, X)
    J = np.zeros((N, vz.m, vz.ncol))
    J[:, vz.rows, vz.cols] = jacobian_values(vz, s)[:-1].T
    return s, J


def rates_by_type(vz: Vectorised, q: np.ndarray, table: tuple[np.ndarray, np.ndarray, np.ndarray],
                  at: tuple[State, np.ndarray] | None = None, G: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray, Consistent]:
    """:func:`rates` with Phi_q, nu and gamma evaluated by primitive type (:mod:`.vectorised`,
    ``vz``: the model's; ``table``: its :func:`.vectorised.law_table` at the samples): the same
    values (on paper 001's 4-RRR bit for bit) with fewer numpy calls. ``at``:
    :func:`jacobian_by_type` at q, and ``G`` the Gram matrix of its free columns, when the caller
    has them."""
    N = q.shape[0]
    s, J = jacobian_by_type(vz, q) if at is None else at
    solver = Consistent(J[:, :, 3:], G)
    v = solver.solve(by_type_velocity_rhs(vz, table[1], N).T)
    V = np.zeros((vz.ncol, N))
    V[3:] = v.T
    a = solver.solve(by_type_acceleration_rhs(vz, s, V, table[2]).T)
    return v, a, solver


def _vel_acc(c: Compiled, q: np.ndarray, t: np.ndarray, laws: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations (N, n) at positions q (:func:`rates`)."""
    v, a, _ = rates(c, q, t, laws)
    return v, a
