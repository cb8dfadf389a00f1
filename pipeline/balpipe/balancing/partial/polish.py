"""A cone programme's optimum polished to round-off on its active set: Newton's method on the
Karush-Kuhn-Tucker equations of the constraints an interior-point answer holds active.

An interior-point solver stops when the duality gap is below its tolerance. Where the optimum is a
vertex that leaves the design exact to about the tolerance; where the objective is smooth at the
optimum (an RMS: a Euclidean norm, flat to first order there) a gap of eps leaves the design off
by about sqrt(eps), 1e-5 at a gap of 1e-10. The optimum is however the solution of a small system
of equations once it is known which constraints hold with equality:

    q - sum_i mu_i grad c_i(x) = 0,      c_i(x) = 0 (i active),

with c_i a linear row of a zero or nonnegative cone, ``s0 - |s1|`` for a second-order cone whose
slack ``s = b - A x`` lies on its boundary (both its slack and its dual nonzero), and every row of
a cone whose slack is at its apex. Newton's method on those equations (the Hessian of the
Lagrangian from the cones' curvature, a least-squares step where the optimum is not unique, so
that the free directions keep the solver's values) converges quadratically from the solver's
answer. The polished point is accepted only if every constraint of the programme holds to
round-off, the multipliers of the active inequalities are not negative (the active set was right),
and its objective is not above the solver's; otherwise the solver's answer stands.
"""

from __future__ import annotations

import numpy as np

#: a slack below this (the programme's variables and rows are scaled to about 1) is at its bound
AT_BOUND = 1e-8
#: the polished point must meet every constraint to this (scaled): round-off, not a tolerance
FEASIBLE = 1e-12
ITERATIONS = 12


def _active(cones: list[tuple[str, int]], s: np.ndarray, y: np.ndarray) -> tuple[list[int], list[np.ndarray], list[int]]:
    """(rows held as linear equations, second-order cones on their boundary (their row indices),
    rows of inequalities among the linear ones), by the solver's slacks ``s`` and duals ``y``."""
    linear, curved, inequal = [], [], []
    i = 0
    for kind, size in cones:
        rows = np.arange(i, i + size)
        i += size
        if kind == "zero":
            linear += list(rows)
        elif kind == "nonneg":
            for r in rows:
                if s[r] <= max(y[r], AT_BOUND):
                    linear.append(r)
                    inequal.append(r)
        else:
            s0, s1 = s[rows[0]], np.linalg.norm(s[rows[1:]])
            y0, y1 = y[rows[0]], np.linalg.norm(y[rows[1:]])
            inside = s0 - s1
            if inside > max(y0, AT_BOUND):  # strictly inside, its dual negligible: inactive
                continue
            if s0 <= max(y0 - y1, AT_BOUND):  # at the apex: every row an equation
                linear += list(rows)
            else:
                curved.append(rows)
    return linear, curved, inequal


def _feasible(cones: list[tuple[str, int]], s: np.ndarray) -> bool:
    i = 0
    for kind, size in cones:
        v = s[i : i + size]
        i += size
        tol = FEASIBLE * max(1.0, float(np.max(np.abs(v))))
        if kind == "zero" and np.max(np.abs(v)) > tol:
            return False
        if kind == "nonneg" and np.min(v) < -tol:
            return False
        if kind == "soc" and v[0] - np.linalg.norm(v[1:]) < -tol:
            return False
    return True


def polish(q: np.ndarray, A: np.ndarray, b: np.ndarray, cones: list[tuple[str, int]], x: np.ndarray,
           s: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, float] | None:
    """The optimum of min q'x s.t. b - A x in ``cones`` (unmerged, in order) polished from the
    solver's answer (x, its slacks s and duals y) on its active set, and a bound on its relative
    error; None when the polish is not sure (a negative multiplier, a violated constraint, no
    convergence)."""
    A = np.asarray(A.todense() if hasattr(A, "todense") else A, dtype=float)
    linear, curved, inequal = _active(cones, s, y)
    if not curved and not linear:
        return None
    x = np.asarray(x, dtype=float).copy()
    n = len(x)
    lin = np.asarray(linear, dtype=int)
    n_c = len(lin) + len(curved)

    def equations(x):
        """c(x), its Jacobian (rows), the curved constraints' (A1, u, |s1|) for the Hessian."""
        sl = b - A @ x
        c = [sl[lin]]
        J = [-A[lin]]
        parts = []
        for rows in curved:
            s1 = sl[rows[1:]]
            r = float(np.linalg.norm(s1))
            u = s1 / r
            c.append(np.array([sl[rows[0]] - r]))
            J.append((-A[rows[0]] + u @ A[rows[1:]])[None, :])
            parts.append((A[rows[1:]], u, r))
        return np.concatenate(c), np.vstack(J), parts

    c, J, parts = equations(x)
    if any(r <= 0 for _, _, r in parts):
        return None
    mu = np.linalg.lstsq(J.T, q, rcond=None)[0]  # q = J' mu at the optimum
    last = np.inf
    for _ in range(ITERATIONS):
        H = np.zeros((n, n))
        for k, (A1, u, r) in enumerate(parts):
            # the Hessian of s0 - |s1| in x is -A1' (I - u u') A1 / |s1|; the Lagrangian's is minus mu times it
            P = np.eye(len(u)) - np.outer(u, u)
            H += mu[len(lin) + k] * (A1.T @ P @ A1) / r
        K = np.block([[H, -J.T], [J, np.zeros((n_c, n_c))]])
        rhs = -np.concatenate([q - J.T @ mu, c])
        step = np.linalg.lstsq(K, rhs, rcond=None)[0]
        x = x + step[:n]
        mu = mu + step[n:]
        c, J, parts = equations(x)
        if any(r <= 0 for _, _, r in parts):
            return None
        size = float(np.linalg.norm(step))
        # converged: a step at round-off, one that no longer shrinks (round-off reached), or the
        # one step that solves equations that are all linear
        if size <= 1e-14 * max(1.0, float(np.linalg.norm(x))) or size >= 0.5 * last or not curved:
            break
        last = size
    scale = max(1.0, float(np.max(np.abs(q))))
    if np.max(np.abs(q - J.T @ mu), initial=0.0) > 1e-10 * scale or np.max(np.abs(c), initial=0.0) > FEASIBLE:
        return None
    signs = np.r_[np.isin(lin, inequal), np.ones(len(curved), dtype=bool)]
    if np.any(mu[signs] < -1e-9 * scale):  # an inequality pulling the wrong way: the active set was not right
        return None
    if not _feasible(cones, b - A @ x):
        return None
    return x, _error(K, np.concatenate([q - J.T @ mu, c]), x)


def _error(K: np.ndarray, residual: np.ndarray, x: np.ndarray) -> float:
    """A first-order bound on the polished point's relative error in the directions its equations
    determine: |K^+| |residual| plus round-off, |K^+| |K| machine epsilon (K the Newton matrix)."""
    sv = np.linalg.svd(K, compute_uv=False)
    live = sv[sv > 1e-13 * sv[0]]
    inv = 1.0 / live[-1]
    eps = np.finfo(float).eps
    return float((inv * np.linalg.norm(residual) + inv * sv[0] * eps * max(1.0, float(np.linalg.norm(x))))
                 / max(1.0, float(np.linalg.norm(x))))
