"""Consistent over-determined systems J x = b (stacks (N, m, n), m > n: redundant drivers) and the
least-norm-efforts multipliers of J^T lambda = rhs, by the normal equations: G = J^T J per
sample, batched, and one factorisation of G (a Newton step by an LU solve of G; the refined
solves by G's inverse, made once) instead of a QR factorisation.

numpy's QR of a stack (LAPACK's geqrf and orgqr, and triangular copies) costs about three times
G and its factorisation (a 4-RRR's 28 x 27 Jacobians at 1,000 samples: 15 ms against 5 ms),
and one factorisation serves every right-hand side (velocities and accelerations, the multipliers
of every model of one geometry) without a QR's Q.

Accuracy. Through G a solution loses up to cond(J)^2 eps instead of QR's cond(J) eps, so every
solution of velocities, accelerations and multipliers takes one step of iterative refinement in
floating point, its residual recomputed from J, not G (Higham, *Accuracy and Stability of
Numerical Algorithms*, sec. 12.1 and 20.5): the step contracts the error by about cond(J)^2 eps,
and the error after it is within a small multiple of cond(J) eps, as by QR. The correction the
step makes measures the first solution's error; where it exceeds :data:`REFINED` of the
solution in some sample (cond(J) near 1e4 or beyond: ill conditioned for the normal equations),
or the factorisation fails, the caller solves by QR as before (None): near-singular motions keep
the general path's QR solves, and its checks (regularity, actuation condition, their errors)
are untouched. The 4-RRR's Jacobians have cond(J) <= 200: corrections below 1e-13.

A Newton-Raphson step needs no refinement (the iteration corrects the step's error: the same
converged positions); :func:`.positions.newton_raphson` repeats by QR what does not converge.
"""

from __future__ import annotations

import numpy as np

#: largest correction of the refinement step, relative to the solution's largest entry
REFINED = 1e-8


class Normal:
    """G = J^T J for a stack of J (N, m, n), m > n (:func:`factor`), and the solves through it:
    a Newton step by one LU solve of G, the refined solves by G's inverse (made once, when first
    needed: 16 ms at 1,000 28 x 27 Jacobians, and then a product per solve, where a forward and
    back substitution in numpy costs 2 ms per right-hand side)."""

    def __init__(self, J: np.ndarray, G: np.ndarray):
        self.J = J
        self._JT = J.transpose(0, 2, 1)
        self._G: np.ndarray | None = G  # dropped once its inverse is made (a shared entry keeps the inverse)
        self._Ginv: np.ndarray | None = None
        self._null: dict[tuple[int, ...], np.ndarray | None] = {}

    def gram_solve(self, B: np.ndarray) -> np.ndarray:
        """G^-1 B for B (N, n, k)."""
        if self._Ginv is None:
            assert self._G is not None
            self._Ginv, self._G = np.linalg.inv(self._G), None
        return self._Ginv @ B

    def step(self, b: np.ndarray) -> np.ndarray:
        """x (N, n) with G x = J^T b (N, m): the least-squares solution, unrefined (a Newton step)."""
        if self._G is None:
            return self.gram_solve(self._JT @ b[..., None])[..., 0]
        return np.linalg.solve(self._G, self._JT @ b[..., None])[..., 0]

    def solve(self, b: np.ndarray) -> np.ndarray | None:
        """x (N, n) with J x = b (N, m) consistent, refined once; None where the refinement's
        correction exceeds :data:`REFINED` of x (solve by QR)."""
        J, JT = self.J, self._JT
        x = self.gram_solve(JT @ b[..., None])
        dx = self.gram_solve(JT @ (b[..., None] - J @ x))
        if not _small(dx, x):
            return None
        return (x + dx)[..., 0]

    def least_norm(self, rhs: np.ndarray) -> np.ndarray | None:
        """A solution lambda (N, m, k) of J^T lambda = rhs (N, n, k): the least-norm one J G^-1
        rhs, refined once (the residual rhs - J^T lambda solved again); None as :meth:`solve`."""
        J = self.J
        lam = J @ self.gram_solve(rhs)
        d = J @ self.gram_solve(rhs - self._JT @ lam)
        return lam + d if _small(d, lam) else None

    def null_space(self, rows: list[int], r: int) -> np.ndarray | None:
        """M = N (S N)^+ (N, m, d) for the rows S of ``rows`` (the drivers', d of them) and an
        orthonormal basis N (N, m, r) of the null space of J^T (r = m - n), or None as
        :meth:`solve`: lambda - M S lambda is the solution of J^T lambda = rhs whose ``rows``
        have the least norm (:func:`.dynamics.solve_multipliers`). N is made of the projections
        W = P S^T of the rows' unit vectors, P = I - J G^-1 J^T applied twice (the second
        application corrects the first's rounding, and is its check), and the r leading
        eigenvectors of W^T W (one redundant driver, r = 1: W = n (S n)^T for the unit null vector
        n, so M = W / trace(S W) without them). They span the null space when the rows' multipliers determine its
        component (S N of rank r: the joints' own rows independent,
        :func:`.positions._check_redundancy`). Made once per ``rows``."""
        key = tuple(rows)
        if key not in self._null:
            J, JT = self.J, self._JT
            N, m, _ = J.shape
            W = np.zeros((N, m, len(rows)))
            W[:, rows, np.arange(len(rows))] = 1.0
            W -= J @ self.gram_solve(JT @ W)
            d = J @ self.gram_solve(JT @ W)
            M = None
            if _small(d, W) and r == 1:
                # P = n n^T, W = n (S n)^T: M = n (S n)^T / |S n|^2 = W / trace(S W)
                W -= d
                M = W / np.einsum("nii->n", W[:, rows, :])[:, None, None]
            elif _small(d, W):
                W -= d
                w, V = np.linalg.eigh(W.transpose(0, 2, 1) @ W)  # ascending
                basis = (W @ V[:, :, -r:]) / np.sqrt(w[:, -r:])[:, None, :]
                M = basis @ np.linalg.pinv(basis[:, rows, :])
            self._null[key] = M
        return self._null[key]


def _small(d: np.ndarray, x: np.ndarray) -> bool:
    """Whether every sample's correction ``d`` is within :data:`REFINED` of its ``x``'s largest
    entry (and finite)."""
    N = len(x)
    dm = np.abs(d.reshape(N, -1)).max(axis=1)
    xm = np.abs(x.reshape(N, -1)).max(axis=1)
    return bool(np.all(dm <= REFINED * xm))


def gram(J: np.ndarray) -> np.ndarray:
    """G = J^T J per sample, (N, n, n)."""
    return np.matmul(J.transpose(0, 2, 1), J)


def factor(J: np.ndarray, G: np.ndarray | None = None) -> Normal | None:
    """The normal equations of a stack J (N, m, n), m > n, or None (square, empty or not finite:
    the caller takes QR). ``G``: :func:`gram` of J when the caller has it."""
    N, m, n = J.shape
    if m <= n or N == 0 or not np.all(np.isfinite(J)):
        return None
    return Normal(J, gram(J) if G is None else G)
