"""Newton-Raphson and velocity/acceleration solves for the continuation of closed loops
(:func:`.positions.follow_motion`) on the constraints evaluated by type (:mod:`.vectorised`).

The same iteration as the general path (:func:`.positions.newton_raphson`, :func:`.kinematics._vel_acc`:
Haug, ch. 3 and 6): q <- q - Phi_q^-1 Phi until max |Phi| < 1e-12, then Phi_q q' = nu and
Phi_q q'' = gamma. Only the evaluation differs: Phi and the Jacobian's non-zero entries come from
:mod:`.vectorised` (a few numpy operations per primitive type instead of a Python loop over
primitives), and the linear systems are solved

* for a few samples (the continuation's coarse steps, one sample each): on the dense Jacobian
  scattered from those entries, by LAPACK (one call);
* for many samples (the batched refinement): block by block (:func:`.structure.solve`), without
  forming N dense matrices.

A step that is not finite (an exactly singular Jacobian) is taken again by the general path's
dense solve for those samples (least squares where LAPACK refuses), and velocities that are not
finite come from :func:`.kinematics._vel_acc` (which raises where the general path raises), so
that the continuation behaves as on the general path: same branch, substeps and located errors.
"""

from __future__ import annotations

import numpy as np

from .compile import Compiled
from .constraints import GridLaws, with_frame, jacobian
from .kinematics import _solve_rect, _vel_acc
from .structure import Decomposition, invert_blocks, solve
from .vectorised import (State, Vectorised, acceleration_rhs, jacobian_values, law_table, residual, table_row,
                         velocity_rhs)

_TOL = 1e-12  # as :data:`.positions._TOL`
_CONVERGED = 1e-9  # as :func:`.positions.newton_raphson`'s convergence test
_DENSE_ENTRIES = 20_000  # samples x n^2 up to which the dense scattered Jacobian is used
_POLISH = 1e-14  # closed loops: one more Newton step where the residual exceeds this (:func:`polish`)


class BlockOps:
    """The continuation's solves for a model with a square, structurally regular Jacobian."""

    def __init__(self, c: Compiled, vz: Vectorised, dec: Decomposition, t: np.ndarray | None = None):
        """``t``: the time grid of the motion, whose law values are then evaluated once."""
        self.c, self.vz, self.dec = c, vz, dec
        self._grid = None if t is None else GridLaws(t, lambda grid: law_table(vz, grid), table_row)
        free = np.flatnonzero(vz.cols >= 3)
        self._free, self._frow, self._fcol = free, vz.rows[free], vz.cols[free] - 3
        self.n = vz.ncol - 3
        self._last_state: tuple[np.ndarray, State] | None = None  # (q, State) where the last single-sample Newton stopped

    def _X(self, q: np.ndarray) -> np.ndarray:
        X = np.zeros((self.vz.ncol + 1, q.shape[0]))
        X[3:-1] = q.T
        return X

    def _dense(self, vals: np.ndarray) -> np.ndarray:
        """Phi_q over the free coordinates, (N, m, n), from the entries' values."""
        J = np.zeros((vals.shape[1], self.vz.m, self.n))
        J[:, self._frow, self._fcol] = vals[self._free].T
        return J

    def _small(self, N: int) -> bool:
        return N * self.n * self.n <= _DENSE_ENTRIES

    def _laws(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """:func:`.vectorised.law_table` at times t: taken from the table of the whole grid
        (made once) for the grid itself and for single times on it (the coarse steps)."""
        found = None if self._grid is None else self._grid.at(t)
        return law_table(self.vz, t) if found is None else found

    def newton(self, q: np.ndarray, t: np.ndarray, max_iter: int = 25) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Batched Newton-Raphson from q (N, n) at times t (N,). Returns (q, converged mask,
        residual norms), as :func:`.positions.newton_raphson`."""
        vz = self.vz
        f = self._laws(t)[0]
        X = self._X(q)
        for it in range(max_iter + 1):
            s = State(vz, X[:-1])
            phi = residual(vz, s, f)
            norms = np.abs(phi).max(axis=0)
            todo = ~(norms < _TOL)
            if it == max_iter or not todo.any():
                break
            vals = jacobian_values(vz, s)
            dq = self._step(X, vals, phi, todo)
            X[3:-1, todo] += dq
        q = X[3:-1].T.copy()
        self._last_state = (q, s) if len(t) == 1 else None
        return q, norms < _CONVERGED, norms

    def _step(self, X: np.ndarray, vals: np.ndarray, phi: np.ndarray, todo: np.ndarray) -> np.ndarray:
        """-Phi_q^-1 Phi for the samples ``todo``, (n, k)."""
        if self._small(int(todo.sum())):
            J = self._dense(vals[:, todo])
            try:
                return np.linalg.solve(J, -phi[:, todo].T[..., None])[..., 0].T
            except np.linalg.LinAlgError:
                return self._general(X[3:-1, todo], phi[:, todo])
        every = bool(todo.all())  # no copies of the values when every sample takes the step
        v = vals if every else vals[:, todo]
        with np.errstate(all="ignore"):
            dq = solve(self.dec.forward, v, -(phi if every else phi[:, todo]), invert_blocks(self.dec, v),
                       offset=3)[3:-1]
        del v
        bad = ~np.isfinite(dq).all(axis=0)
        if bad.any():
            dq[:, bad] = self._general(X[3:-1, todo][:, bad], phi[:, todo][:, bad])
        return dq

    def _general(self, q: np.ndarray, phi: np.ndarray) -> np.ndarray:
        """The general path's step (least squares where the Jacobian is singular), (n, k)."""
        J = jacobian(self.c, with_frame(q.T))[:, :, 3:]
        try:
            dq = _solve_rect(J, -phi.T)
        except np.linalg.LinAlgError:
            dq = np.stack([np.linalg.lstsq(Jk, -pk, rcond=None)[0] for Jk, pk in zip(J, phi.T)])
        return dq.T

    def vel_acc(self, q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Velocities and accelerations (N, n) at positions q (N, n), as :func:`.kinematics._vel_acc`."""
        vz = self.vz
        N = len(t)
        _, fd, fdd = self._laws(t)
        last = self._last_state
        if last is not None and N == 1 and np.array_equal(last[0], q):
            s = last[1]  # the state where Newton-Raphson stopped: the same positions
        else:
            s = State(vz, self._X(q)[:-1])
        vals = jacobian_values(vz, s)
        nu = velocity_rhs(vz, fd, N)
        if self._small(N):
            J = self._dense(vals)
            V = np.zeros((vz.ncol + 1, N))
            try:
                V[3:-1] = np.linalg.solve(J, nu.T[..., None])[..., 0].T
                A = np.linalg.solve(J, acceleration_rhs(vz, s, V, fdd).T[..., None])[..., 0]
            except np.linalg.LinAlgError:
                return _vel_acc(self.c, q, t)
            return V[3:-1].T, A
        with np.errstate(all="ignore"):
            inv = invert_blocks(self.dec, vals)
            V = solve(self.dec.forward, vals, nu, inv, offset=3)
            A = solve(self.dec.forward, vals, acceleration_rhs(vz, s, V, fdd), inv, offset=3)
        if not (np.isfinite(V).all() and np.isfinite(A).all()):
            return _vel_acc(self.c, q, t)
        return V[3:-1].T, A[3:-1].T


def polish(vz: Vectorised, dec: Decomposition, q: np.ndarray, f: np.ndarray) -> np.ndarray:
    """One more Newton step, block by block, where the residual exceeds 1e-14: the continuation
    stops at a residual of 1e-12, where joint points still miss each other by up to ~1e-12 and
    the two routes to the shaking moment (reactions, momentum) disagree by that times the
    forces."""
    X = np.zeros((vz.ncol + 1, q.shape[0]))
    X[3:-1] = q.T
    state = State(vz, X[:-1])
    phi = residual(vz, state, f)
    if np.all(np.abs(phi) <= _POLISH):
        return q
    vals = jacobian_values(vz, state)
    X += solve(dec.forward, vals, -phi, invert_blocks(dec, vals), offset=3)
    return X[3:-1].T.copy()
