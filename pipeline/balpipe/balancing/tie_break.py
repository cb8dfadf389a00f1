"""The stated tie-break among least-mass designs: the same spec always gets the same design.

The least-mass programme (:mod:`.least_mass`) is a linear programme: its optimum is often a
whole face of designs of the same total mass (a symmetric mechanism has its mirror images, and
every blend of them). The solver returns one vertex of that face, an arbitrary choice. The rule
here: among all designs of least total mass, take the one whose counterweights' parameters
d_k = (m_k, m_k x_k / L, m_k y_k / L[, J_k / L^2]) (mass, first moments and, with the moment
balanced, inertias about the body origin; L the mechanism's size) have the least sum of squares.
It is unique (a strictly convex function of the design over a convex set), so a design that the
mechanism's symmetry maps onto another of the same mass is replaced by the symmetric one.

    min |W D z|^2 + eps |z|^2   s.t.   A z = b,  z >= 0,  z_i = 0 where c_i - A_i^T y > 0

The optimal face is found by complementary slackness: with the programme's duals y, a variable
of positive reduced cost is zero in every optimal design, and every feasible z on the others
has the least mass (c . z = b . y). The small multiple of |z|^2 (:data:`REGULARISATION`, the
same for every generator, so the objective stays as symmetric as the mechanism) makes the
solution unique in z as well; it is found by SLSQP with exact gradients from the solver's
vertex, and kept only if it meets the conditions and the least mass. Whether the optimum was unique in the
design is decided by two more linear programmes over the optimal face, minimising and
maximising a fixed generic combination of the design parameters.
"""

from __future__ import annotations

import numpy as np

MASS_SLACK = 1e-9  # relative: the tie-broken design's mass may exceed the least mass by this
UNIQUE_TOLERANCE = 1e-5
REGULARISATION = 1e-6  # x |D|^2: weight of |z|^2 beside |D z|^2

RULE = ("among all designs of least total mass, the one whose counterweights' masses, first moments "
        "(divided by the mechanism's size) and inertias have the least sum of squares")


def least_norm(A: np.ndarray, b: np.ndarray, cost: np.ndarray, D: np.ndarray, z0: np.ndarray
               ) -> tuple[np.ndarray, bool]:
    """The tie-broken design on the face of least ``cost . z`` (``z0``: an optimal vertex) and
    whether the least-mass design was unique already. ``D`` maps z to the weighted design
    parameters."""
    from scipy.optimize import linprog  # scipy only when a tie is broken

    if D.shape[0] == 0 or z0.size == 0:
        return z0, True
    lp = linprog(cost, A_eq=A, b_eq=b, bounds=(0, None), method="highs")
    if lp.status != 0:
        return z0, True
    # complementary slackness: a variable of positive reduced cost is zero on the whole optimal face
    reduced = cost - A.T @ lp.eqlin.marginals
    keep = np.flatnonzero(reduced <= 1e-9 * max(float(np.max(np.abs(cost))), 1e-300))
    Ak, Dk = A[:, keep], D[:, keep]
    rng = np.random.default_rng(12345)
    r = Dk.T @ rng.standard_normal(D.shape[0])
    spread = []
    for sign in (1.0, -1.0):
        res = linprog(sign * r, A_eq=Ak, b_eq=b, bounds=(0, None), method="highs")
        spread.append(float(r @ res.x) if res.x is not None else float(r @ z0[keep]))
    scale = float(np.linalg.norm(D @ z0)) * float(np.linalg.norm(r)) / max(float(np.linalg.norm(Dk, 2)), 1e-300)
    if abs(spread[0] - spread[1]) <= UNIQUE_TOLERANCE * max(scale, 1e-300):
        return z0, True
    zk = _least_distance(Ak, b, Dk, z0[keep])
    z = np.zeros_like(z0)
    z[keep] = zk
    ok = (np.all(np.isfinite(z)) and np.max(np.abs(A @ z - b)) <= 1e-8 * max(float(np.max(np.abs(b))), 1e-300)
          and cost @ z <= (cost @ z0) * (1 + MASS_SLACK) + 1e-12)
    return (z if ok else z0), False


def _least_distance(Aeq: np.ndarray, beq: np.ndarray, D: np.ndarray, z0: np.ndarray) -> np.ndarray:
    """min |D z|^2 + eps |z|^2 s.t. Aeq z = beq, z >= 0 (SLSQP with exact gradients, scaled, from
    the feasible z0; a few variables once the face is pruned)."""
    from scipy.optimize import minimize  # scipy only when a tie is broken

    U, sv, _ = np.linalg.svd(Aeq, full_matrices=False)  # independent rows only (SLSQP needs them)
    rank = int(np.sum(sv > 1e-9 * sv[0])) if sv.size and sv[0] > 0 else 0
    Aeq, beq = U[:, :rank].T @ Aeq, U[:, :rank].T @ beq
    s = max(float(np.max(z0)), 1e-300)
    eps = REGULARISATION * float(np.linalg.norm(D, 2)) ** 2
    H = (D.T @ D + eps * np.eye(z0.size)) * s * s
    As = Aeq * s
    res = minimize(lambda x: float(x @ H @ x), z0 / s, jac=lambda x: 2 * H @ x, method="SLSQP",
                   bounds=[(0, None)] * z0.size,
                   constraints=[{"type": "eq", "fun": lambda x: As @ x - beq, "jac": lambda x: As}],
                   options={"maxiter": 1000, "ftol": 1e-15})
    return np.maximum(res.x * s, 0.0)
