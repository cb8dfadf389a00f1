"""The state sampler's work per state by blocks (:func:`.regressor.sample_states`), for a
mechanism of one degree of freedom: O(bodies) per state where the dense route is O(bodies^3).

The dense route takes, for every trial state, Newton-Raphson on the full Jacobian, then the SVD
of the joints' Jacobian J (m x n, m = n - 1 rows): its rank, the test s_m > MIN_CONDITION s_1
and the null vector. Here, with K = [J; driver row] square and structurally regular (its
block-triangular form, :mod:`balpipe.engine.structure`):

* Newton-Raphson: the same iteration by blocks (:class:`balpipe.engine.newton_blocks.BlockOps`);
  the same states to round-off.
* The test: s_1(J) <= sqrt(||J||_1 ||J||_inf) (Higham, *Accuracy and Stability of Numerical
  Algorithms*, 2002, eq. 6.12; a few units for a sparse J, where ||J||_F grows with its size), and
  s_m(J) >= s_n(K) (deleting a row interlaces the singular
  values: s_i(K) >= s_i(J) >= s_{i+1}(K)), s_n(K) = 1 / ||K^-1||_2. ||K^-1||_2^2, the largest
  eigenvalue of B = K^-T K^-1, is estimated by :data:`POWER_STEPS` steps of the power method
  (two triangular solves each) from a fixed random start x0: the estimate e is the largest
  growth ||B x|| / ||x|| of the k steps. Each is at most lambda_max(B), and their product is
  ||B^k x0|| / ||x0|| >= lambda_max(B)^k |c_1| / ||x0|| (c_1 the start's component along the top
  eigenvector), so lambda_max(B) (|c_1| / ||x0||)^(1/k) <= e <= lambda_max(B). A state whose
  1 / (sqrt(e ||J||_1 ||J||_inf)) exceeds MIN_CONDITION x :data:`MARGIN` passes the test for
  certain unless |c_1| / ||x0|| < MARGIN^(-2k) (for a Gaussian start in n dimensions, a
  probability below MARGIN^(-2k) sqrt(n) = 2e-18 sqrt(n) per state). Every other state (near a singular
  configuration, a driver nearly tangent to the motion, a failed Newton-Raphson) takes the
  dense route's SVD, which decides as before.
* The rank (the median over the states, as the dense route counts it) is then m for every
  certified state, the SVD's count for the others.
* The null vector of J: x = K^-1 e_d (e_d: one on the driver's row), normalised; the SVD's is
  the same up to its sign, which does not change the regressor's row space nor its singular
  values (a sample's rows change sign).

The sampled states, the conditions and every singular value above the rank are therefore the
dense route's to round-off; the singular values at round-off level (below the rank tolerance)
are round-off of either route.
"""

from __future__ import annotations

import numpy as np

from ..engine.compile import Compiled
from ..engine.newton_blocks import BlockOps
from ..engine.structure import Decomposition, decompose, invert_blocks, solve
from ..engine.vectorised import State, Vectorised, jacobian_values, vectorise

POWER_STEPS = 6  # power-method steps on K^-T K^-1 per state
MARGIN = 30.0  # certified states: the bound of s_m / s_1 above MIN_CONDITION times this
_START_SEED = 20261204  # the power method's start vectors (its own generator: the sampler's draws are unchanged)


class BlockRound:
    """One round of trial states solved by blocks: positions, the certified regularity test and
    the null vectors. Build with :meth:`of`, which returns None where this route does not apply
    (more than one degree of freedom, a structurally singular or non-square system)."""

    def __init__(self, trial: Compiled, vz: Vectorised, dec: Decomposition, joint_rows: int):
        self.trial, self.vz, self.dec, self.m = trial, vz, dec, joint_rows
        free = vz.cols >= 3
        self._joint_slots = np.flatnonzero(free & (vz.rows < joint_rows))
        self._slot_rows = vz.rows[self._joint_slots]
        self._slot_cols = vz.cols[self._joint_slots] - 3
        self.n = vz.ncol - 3

    @classmethod
    def of(cls, trial: Compiled, joint_rows: int) -> "BlockRound | None":
        """The block route for ``trial`` (joints then one driver row), or None."""
        n = 3 * trial.nb
        if len(trial.row_owner) != n or joint_rows != n - 1:
            return None
        vz = vectorise(trial)
        dec = decompose(vz)
        return None if dec is None else cls(trial, vz, dec, joint_rows)

    def newton(self, q0: np.ndarray, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Positions (S, n) from the guesses q0 at the trial's 'times' (its states' indices), and
        the converged mask: :func:`balpipe.engine.positions.newton_raphson`'s iteration, by
        blocks."""
        q, ok, _ = BlockOps(self.trial, self.vz, self.dec).newton(q0, times)
        return q, ok

    def certify(self, q: np.ndarray, min_condition: float) -> tuple[np.ndarray, np.ndarray]:
        """(certified mask (S,), null vectors (S, n) of the certified states, unit length): a
        certified state passes the test s_m > ``min_condition`` s_1 of its joint Jacobian, with
        rank m (see the module's docstring); the others' rows of the null vectors are undefined."""
        S, n = q.shape
        X = np.zeros((self.vz.ncol + 1, S))
        X[3:-1] = q.T
        vals = jacobian_values(self.vz, State(self.vz, X[:-1]))
        entries = np.abs(vals[self._joint_slots])
        row_sums, col_sums = np.zeros((self.m, S)), np.zeros((n, S))
        np.add.at(row_sums, self._slot_rows, entries)
        np.add.at(col_sums, self._slot_cols, entries)
        s_max = np.sqrt(row_sums.max(axis=0) * col_sums.max(axis=0))  # >= s_1(J)
        with np.errstate(all="ignore"):
            inv = invert_blocks(self.dec, vals)
            x = np.random.default_rng(_START_SEED).normal(size=(n, S))
            x /= np.linalg.norm(x, axis=0)
            growth = np.zeros(S)
            for _ in range(POWER_STEPS):
                y = solve(self.dec.forward, vals, x, inv)[:-1]
                x = solve(self.dec.backward, vals, y, inv)[:-1]
                g = np.linalg.norm(x, axis=0)
                growth = np.maximum(growth, g)
                x /= g
            e = np.zeros((self.vz.m, S))
            e[self.m] = 1.0
            null = solve(self.dec.forward, vals, e, inv)[:-1]
            null /= np.linalg.norm(null, axis=0)
            bound = 1.0 / (np.sqrt(growth) * s_max)
        ok = np.isfinite(bound) & (bound > min_condition * MARGIN) & np.isfinite(null).all(axis=0)
        return ok, null.T
