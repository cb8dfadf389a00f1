"""Velocities and accelerations: Phi_q q' = nu and Phi_q q'' = gamma (Haug, eqs. 3.4.x, 6.x)."""

from __future__ import annotations

import numpy as np

from .compile import Compiled
from .constraints import with_frame, acceleration_rhs, jacobian, velocity_rhs


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


def _vel_acc(c: Compiled, q: np.ndarray, t: np.ndarray, laws: list | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations (N, n) at positions q: one Jacobian and, with redundant
    drivers, one QR factorisation for both solves (the same numbers as factorising it twice).
    ``laws``: :func:`.constraints.law_triples` at ``t`` (evaluated when not given)."""
    qx = with_frame(q)
    J = jacobian(c, qx)[:, :, 3:]
    qr = _factors(J)
    v = _solve_rect(J, velocity_rhs(c, t, laws), qr)
    a = _solve_rect(J, acceleration_rhs(c, qx, with_frame(v), t, laws), qr)
    return v, a
