"""Dynamics in the drivers' coordinates for any model: the joint-space mass matrix.

With the drivers' coordinates u as generalised coordinates (the mechanism's degrees of freedom),
the body velocities are v = V(q) u', where V solves Phi_q V = E (E: unit rates on the drivers'
rows, zero on the joints'). The kinetic energy is T = 1/2 u'^T M(q) u' with
M = V^T diag(m, m, I) V (Haug, ch. 6). Used to show and check decoupled dynamics (paper 002):
a decoupled arm has a constant, diagonal M.
"""

from __future__ import annotations

import numpy as np

from .compile import compile_model
from .constraints import with_frame, jacobian
from .positions import solve_positions
from ..model import Model


def mass_matrix(model: Model, t: np.ndarray) -> tuple[list[str], np.ndarray]:
    """Driver names and M(q(t)) (N, nd, nd) along the model's motion at times ``t``."""
    c = compile_model(model)
    t = np.asarray(t, dtype=float)
    q = solve_positions(c, t)
    J = jacobian(c, with_frame(q))[:, :, 3:]
    names = list(c.driver_rows)
    E = np.zeros((len(t), J.shape[1], len(names)))
    for k, n in enumerate(names):
        E[:, c.driver_rows[n], k] = 1.0
    V = np.linalg.solve(J, E)  # (N, 3 nb, nd)
    w = np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(-1)
    return names, np.einsum("nik,i,nil->nkl", V, w, V)
