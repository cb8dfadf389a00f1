"""The largest condition number of Phi_q along a motion, and where it is, with SVDs only where the
peak can be.

A page reports the largest condition number over its stages' motions and where it occurs
(:func:`balpipe.study.near_singular_note`, :func:`balpipe.diagnose.dead_centres.find`): the peak of
:func:`.positions.condition_numbers`, an SVD per sample. :func:`peak` finds the same sample and
the same value, bit for bit, from SVDs of a subset: every :data:`STRIDE`-th sample first, then
every sample whose condition number these do not show to be below the largest found.

The bound is Weyl's inequality for singular values, |sigma_k(A) - sigma_k(B)| <= ||A - B||_2 <=
||A - B||_F (Golub and Van Loan, *Matrix Computations*, 4th ed., Cor. 8.6.2): with J_j a sample
whose SVD is known and d >= ||J_i - J_j||_F, sigma_max(J_i) <= sigma_max(J_j) + d and
sigma_min(J_i) >= sigma_min(J_j) - d; d is the sum of the steps ||J_k+1 - J_k||_F between the
two samples (the triangle inequality: one difference of consecutive samples, not one per pair). The SVD computed in floating point is the exact one of a
matrix within a small multiple of eps ||J|| (backward stability), so the computed values of both
samples are within :data:`ROUNDING` ||J||_F of the exact ones; the bound adds that for both. A
sample is skipped only when the bound from its nearer known neighbour on either side, with a
relative margin of 1e-9 for the rounding of the bound itself, is below the largest computed
value: its computed condition number could not have reached it, so the first sample of the
largest value is the one :func:`numpy.argmax` finds among all of them. (On the specs of specs/
the SVDs of a build fall from 55698 to about 22000: a motion whose condition number barely
varies, as many do, needs most of its samples.)
"""

from __future__ import annotations

from collections.abc import Callable

import numpy as np

from .compile import Compiled
from .constraints import jacobian, with_frame
from .positions import _condition, condition_of

#: the samples whose SVD is computed first: every STRIDE-th one and the last
STRIDE = 8
#: a bound on the distance of a computed singular value from the exact one, per unit of ||J||_F
#: (a generous multiple of LAPACK's backward error, p(m, n) eps with p a low-degree polynomial)
ROUNDING = 1e-9
#: below this many samples every SVD is computed
SMALL = 4 * STRIDE
#: samples whose Jacobians are held at once
CHUNK = 512


#: the Jacobians (k, m, n) of the samples idx (k,)
Jacobians = Callable[[np.ndarray], np.ndarray]

def peak(J: np.ndarray) -> tuple[int, float]:
    """The first sample k of the largest 2-norm condition number of J (N, m, n), m >= n, and that
    number: ``k = argmax(cond)``, ``cond[k]`` with ``cond = positions._condition(J)``, the same
    floats."""
    norm, steps = _norms_and_steps(J)
    return _peak(len(J), lambda idx: J[idx], norm, steps)


def _norms_and_steps(J: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """||J_k||_F (N,) and ||J_k+1 - J_k||_F (N - 1,)."""
    D = np.diff(J, axis=0)
    return np.sqrt(np.einsum("nij,nij->n", J, J)), np.sqrt(np.einsum("nij,nij->n", D, D))


def _condition_of(get: Jacobians, idx: np.ndarray) -> np.ndarray:
    """Condition numbers of the samples ``idx``, :data:`CHUNK` at a time (``get(idx)``: their J)."""
    return np.concatenate([_condition(get(idx[a : a + CHUNK])) for a in range(0, len(idx), CHUNK)] or [np.zeros(0)])


def _singular(get: Jacobians, idx: np.ndarray) -> np.ndarray:
    """Singular values of the samples ``idx``, :data:`CHUNK` at a time."""
    return np.concatenate([np.linalg.svd(get(idx[a : a + CHUNK]), compute_uv=False) for a in range(0, len(idx), CHUNK)])


def _peak(N: int, get: Jacobians, norm: np.ndarray, steps: np.ndarray) -> tuple[int, float]:
    """:func:`peak` from ``get(idx)`` (the Jacobians of the samples idx), their Frobenius norms
    and the norms of the steps between consecutive samples. A Jacobian is finite exactly when
    its norm is."""
    every = np.arange(N)
    if N < SMALL or not np.all(np.isfinite(norm)):
        cond = _condition_of(get, every)
        k = int(np.argmax(cond))
        return k, float(cond[k])
    known = np.unique(np.r_[np.arange(0, N, STRIDE), N - 1])
    s = _singular(get, known)
    smax, smin = np.full(N, np.nan), np.full(N, np.nan)
    smax[known], smin[known] = s[:, 0], s[:, -1]
    cond = np.full(N, -np.inf)
    cond[known] = condition_of(s)
    best = float(np.max(cond[known]))
    path = np.concatenate([[0.0], np.cumsum(steps)])  # arc length in ||.||_F
    slack = N * np.finfo(float).eps * path[-1]  # the rounding of the sums
    after = np.searchsorted(known, every)  # known[after] >= i
    upper = np.full(N, np.inf)
    for side in (known[np.maximum(after - 1, 0)], known[np.minimum(after, len(known) - 1)]):
        # ||J_i - J_j|| <= the path's length between them (the triangle inequality, step by step)
        d = np.abs(path - path[side]) * (1 + 1e-9) + slack + ROUNDING * (norm + norm[side])
        low = smin[side] - d
        with np.errstate(divide="ignore", invalid="ignore"):
            bound = np.where(low > 0, (smax[side] + d) / low, np.inf)
        upper = np.minimum(upper, bound)
    upper[known] = -np.inf
    rest = np.flatnonzero(~(upper * (1 + 1e-9) < best))
    if rest.size:
        cond[rest] = _condition_of(get, rest)
    k = int(np.argmax(cond))
    return k, float(cond[k])


def motion_peak(c: Compiled, q: np.ndarray) -> tuple[int, float]:
    """:func:`peak` of Phi_q at positions q (N, 3 nb): the peak of
    :func:`.positions.condition_numbers` ``(c, q)``. The Jacobians are formed :data:`CHUNK`
    samples at a time (each sample's entries, norms and SVD do not depend on the others: the
    same floats), so that the memory does not grow with the number of samples."""
    def get(idx: np.ndarray | slice) -> np.ndarray:
        return jacobian(c, with_frame(q[idx]))[:, :, 3:]

    N = len(q)
    norms, steps = [], []
    for a in range(0, N, CHUNK):
        lo = max(a - 1, 0)  # one sample of overlap: the step into this chunk
        n_, s_ = _norms_and_steps(get(slice(lo, min(a + CHUNK, N))))
        norms.append(n_[a - lo :])
        steps.append(s_)
    return _peak(N, get, np.concatenate(norms), np.concatenate(steps))
