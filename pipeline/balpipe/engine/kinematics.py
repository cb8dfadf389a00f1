"""Velocities and accelerations: Phi_q q' = nu and Phi_q q'' = gamma (Haug, eqs. 3.4.x, 6.x)."""

from __future__ import annotations

import numpy as np

from .compile import Compiled
from .constraints import with_frame, acceleration_rhs, jacobian, velocity_rhs


def _solve_rect(J: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Solve J x = b for stacks (N, m, n) of full-column-rank J: exact when square, the least-
    squares solution of a consistent over-determined system (redundant drivers) otherwise."""
    if J.shape[-2] == J.shape[-1]:
        return np.linalg.solve(J, b[..., None])[..., 0]
    Q, R = np.linalg.qr(J)  # reduced: J = Q R, R (n, n) upper triangular
    return np.linalg.solve(R, np.einsum("nji,nj->ni", Q, b)[..., None])[..., 0]


def _vel_acc(c: Compiled, q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    qx = with_frame(q)
    J = jacobian(c, qx)[:, :, 3:]
    v = _solve_rect(J, velocity_rhs(c, t))
    a = _solve_rect(J, acceleration_rhs(c, qx, with_frame(v), t))
    return v, a
