"""Position analysis: assembly, continuation along a coarse grid and batched Newton-Raphson on
Phi(q, t) = 0, with the regularity (singularity) check."""

from __future__ import annotations

import functools
from typing import Any, Protocol

import numpy as np

from ..mechanics.sampling import spread_indices
from .compile import Compiled
from .constraints import GridLaws, with_frame, jacobian, law_positions, law_triples, residual
from .errors import AnalysisError
from .kinematics import _solve_rect, _vel_acc, rates_by_type
from .normal import factor, gram
from .vectorised import State, Vectorised, jacobian_values, law_table, residual as vresidual, table_row, vectorised_of


class Ops(Protocol):
    """The continuation's solves (:class:`DenseOps`, :class:`.newton_blocks.BlockOps`)."""

    def newton(self, q: np.ndarray, t: np.ndarray, max_iter: int = ...) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Batched Newton-Raphson from q (N, n) at t (N,): (q, converged mask, residual norms)."""
        ...

    def vel_acc(self, q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Velocities and accelerations (N, n) at positions q and times t."""
        ...

_TOL = 1e-12
_MAX_ITER = 25
_COND_LIMIT = 1e11
_COARSE = 17  # samples followed by continuation before the batched refinement
_GAP = 3.0  # a continuation step longer than this many 1/16 of the grid's span gets times between
_JUMP = 0.2  # rad: a refined angle this far from its interpolated guess may be another branch


def _check_square(c: Compiled) -> None:
    """Fewer equations than coordinates is an error; more are allowed when only drivers are
    redundant (redundant actuation, checked by :func:`_check_redundancy` once assembled)."""
    m, n = len(c.row_owner), 3 * c.nb
    if m < n:
        raise AnalysisError(
            f"the model has {n} coordinates but {m} constraint equations: add drivers or joints "
            "(it can move freely)"
        )
    if m > n and m - len(c.driver_rows) > n:
        raise AnalysisError(
            f"the model has {n} coordinates but its joints alone give {m - len(c.driver_rows)} "
            "constraint equations: it is over-constrained (only actuators may be redundant)"
        )


def redundancy(c: Compiled) -> int:
    """Number of redundant actuators: constraint rows beyond the coordinates (0 when square)."""
    return len(c.row_owner) - 3 * c.nb


def _check_redundancy(c: Compiled, q: np.ndarray, t: float) -> None:
    """With redundant actuation the joints' own rows must be independent (else the multipliers,
    hence the reactions, are not determined by the minimum-norm efforts)."""
    if redundancy(c) == 0:
        return
    J = jacobian(c, with_frame(q[None, :]))[0, :, 3:]
    drv = set(c.driver_rows.values())
    rows = [r for r in range(J.shape[0]) if r not in drv]
    s = np.linalg.svd(J[rows], compute_uv=False)
    if s[-1] <= 1e-10 * s[0]:
        raise AnalysisError(
            f"at t = {t:.6g} s the joints' constraint equations are dependent (condition "
            f"{s[0] / max(s[-1], 1e-300):.2g}): the mechanism is over-constrained by its joints, "
            "not only by redundant actuators", t,
        )


class _ByPrimitive:
    """Phi (N, m) and the free columns of Phi_q (k, m, n) of ``c`` at times ``t`` by
    :mod:`.constraints` (a loop over the primitives); ``laws``: :func:`.constraints.law_positions`
    at ``t``."""

    def __init__(self, c: Compiled, t: np.ndarray, laws: list):
        self.c, self.t, self.laws = c, t, laws
        self._qx = np.zeros((0, 0))

    def residual(self, q: np.ndarray) -> np.ndarray:
        self._qx = with_frame(q)
        return residual(self.c, self._qx, self.t, self.laws)

    def jacobian(self, todo: np.ndarray) -> np.ndarray:
        """At the positions of the last :meth:`residual`, for the samples ``todo`` (a mask)."""
        return jacobian(self.c, self._qx[todo])[:, :, 3:]

    def subset(self, idx: np.ndarray) -> _ByPrimitive:
        return _ByPrimitive(self.c, self.t[idx], [None if f is None else np.broadcast_to(f, self.t.shape)[idx] for f in self.laws])


class _ByType:
    """The same as :class:`_ByPrimitive` by :mod:`.vectorised` (a few numpy operations per
    primitive type: on paper 001's 4-RRR the same floats, bit for bit, in a third of the time);
    ``f``: the driven rows' law values at the samples, :func:`.vectorised.law_table`'s first."""

    def __init__(self, vz: Vectorised, f: np.ndarray):
        self.vz, self.f = vz, f
        free = np.flatnonzero(vz.cols >= 3)
        self._free, self._frow, self._fcol = free, vz.rows[free], vz.cols[free] - 3
        self._state: State | None = None

    def residual(self, q: np.ndarray) -> np.ndarray:
        X = np.zeros((self.vz.ncol, q.shape[0]))
        X[3:] = q.T
        self._state = State(self.vz, X)
        return vresidual(self.vz, self._state, self.f).T

    def jacobian(self, todo: np.ndarray) -> np.ndarray:
        """At the positions of the last :meth:`residual`, for the samples ``todo`` (a mask)."""
        assert self._state is not None
        vals = jacobian_values(self.vz, self._state)[self._free][:, todo]
        J = np.zeros((vals.shape[1], self.vz.m, self.vz.ncol - 3))
        J[:, self._frow, self._fcol] = vals.T
        return J

    def subset(self, idx: np.ndarray) -> _ByType:
        return _ByType(self.vz, self.f[:, idx])


def newton_raphson(c: Compiled, q: np.ndarray, t: np.ndarray, max_iter: int = _MAX_ITER,
                   laws: list | None = None, normal: bool = True,
                   by_type: tuple[Vectorised, np.ndarray] | None = None) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Batched Newton-Raphson. Returns (q, converged mask, residual norms). ``laws``: the
    drivers' f(t), :func:`.constraints.law_positions` (evaluated here when not given);
    ``by_type``: (the model's :func:`.vectorised.vectorise`, its :func:`.vectorised.law_table`'s
    values at ``t``), to evaluate Phi and Phi_q by primitive type (:class:`_ByType`) instead
    (``laws`` not read).

    With redundant drivers a step is the least-squares one (Gauss-Newton), through the normal
    equations (:mod:`.normal`) where their factorisation holds, else by QR; with ``normal``, the
    samples that do not converge so are iterated again from ``q`` by QR alone (what they did
    before the normal equations: an ill-conditioned step never fails where QR's converges)."""
    if by_type is not None:
        ev: _ByPrimitive | _ByType = _ByType(*by_type)
    else:
        ev = _ByPrimitive(c, t, law_positions(c, t) if laws is None else laws)  # f(t): the same at every iteration
    return _newton(q, ev, max_iter, normal)


def _newton(q: np.ndarray, ev: _ByPrimitive | _ByType, max_iter: int, normal: bool) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`newton_raphson` with the evaluation ``ev``."""
    q0 = q
    q = q.copy()
    norms = np.full(len(q), np.inf)
    used = False
    for _ in range(max_iter):
        phi = ev.residual(q)
        norms = np.abs(phi).max(axis=1)
        todo = ~(norms < _TOL)
        if not todo.any():
            break
        J = ev.jacobian(todo)
        ne = factor(J) if normal else None
        if ne is not None:
            used = True
            dq = ne.step(-phi[todo])
        else:
            try:
                dq = _solve_rect(J, -phi[todo])
            except np.linalg.LinAlgError:
                dq = np.stack([np.linalg.lstsq(Jk, -pk, rcond=None)[0] for Jk, pk in zip(J, phi[todo])])
        q[todo] += dq
    else:  # the last step's residual (after a break, norms are those of q as it is)
        norms = np.abs(ev.residual(q)).max(axis=1)
    ok = norms < 1e-9
    if used and not ok.all():
        again = np.flatnonzero(~ok)
        q[again], ok[again], norms[again] = _newton(q0[again], ev.subset(again), max_iter, normal=False)
    return q, ok, norms


def _worst_rows(c: Compiled, values: np.ndarray) -> str:
    order = np.argsort(-np.abs(values))
    names: list[str] = []
    for r in order:
        if abs(values[r]) < 0.2 * abs(values[order[0]]):
            break
        if c.row_owner[r] not in names:
            names.append(c.row_owner[r])
    return ", ".join(repr(n) for n in names[:3])


def _fail_position(c: Compiled, q: np.ndarray, t: float) -> AnalysisError:
    qx = with_frame(q[None, :])
    phi = residual(c, qx, np.array([t]))[0]
    worst = int(np.argmax(np.abs(phi)))
    err = AnalysisError(
        f"position analysis did not converge at t = {t:.6g} s: joint {c.row_owner[worst]!r} cannot "
        f"be closed (residual {abs(phi[worst]):.3g}); the motion leaves the mechanism's workspace",
        t,
        c.row_owner[worst],
    )
    err.q = q  # the configuration reached, for a diagnosis of the loop (balpipe.diagnose.loop_closure)
    return err


def condition_numbers(c: Compiled, q: np.ndarray, chunk: int = 512) -> np.ndarray:
    """2-norm condition numbers of Phi_q (N,) at positions q (N, 3 nb), ``chunk`` samples'
    Jacobians at a time (each sample's number does not depend on the others)."""
    if len(q) <= chunk:
        return _condition(jacobian(c, with_frame(q))[:, :, 3:])
    return np.concatenate([_condition(jacobian(c, with_frame(q[a : a + chunk]))[:, :, 3:]) for a in range(0, len(q), chunk)])


def _condition(J: np.ndarray) -> np.ndarray:
    return condition_of(np.linalg.svd(J, compute_uv=False))


def condition_of(s: np.ndarray) -> np.ndarray:
    """Condition numbers from singular values (N, n) in decreasing order."""
    return s[:, 0] / np.maximum(s[:, -1], 1e-300)


def _proven_regular(J: np.ndarray, G: np.ndarray | None = None) -> bool:
    """Whether every sample's Phi_q (N, m, n), m >= n, is shown far from singular without an SVD
    (a Cholesky factorisation, a quarter of the SVD's time on the 4-RRR's 28 x 27). ``G``: J^T J
    when the caller has it (:func:`.normal.gram`; not modified), else formed here.

    With G = J^T J and delta = d ||J||_F^2, a factorisation of G - delta I that succeeds in
    floating point shows that J^T J - delta I + E is positive semi-definite, E the rounding of G
    (||E|| <= m eps ||J||_F^2) and of the factorisation (<= n (n + 1) eps ||G||) (Higham,
    *Accuracy and Stability of Numerical Algorithms*, Thms 3.5 and 10.3). With d at least 100
    times those, lambda_min(J^T J) >= 0.99 delta, so sigma_min(J) >= 0.99 sqrt(d) ||J||_F and
    cond(J) = sigma_max / sigma_min <= 1 / (0.99 sqrt(d)): below 1.1e5 for every model of up to
    60 columns (d = 1e-10), far below :data:`_COND_LIMIT`. A batch where one sample does not
    pass, or whose entries are not finite, is not shown regular: the caller computes the exact
    condition numbers (:func:`_condition`), which decide."""
    N, m, n = J.shape
    if m < n or N == 0 or not np.all(np.isfinite(J)):
        return False
    eps = np.finfo(float).eps
    d = max(1e-10, 100.0 * (m + n * (n + 1)) * eps)
    G = gram(J) if G is None else G.copy()
    scale = np.einsum("nij,nij->n", J, J)  # ||J||_F^2 per sample
    G[:, np.arange(n), np.arange(n)] -= (d * scale)[:, None]
    try:
        L = np.linalg.cholesky(G)
    except np.linalg.LinAlgError:
        return False
    return bool(np.all(np.isfinite(L)) and np.all(scale > 0))


def _check_regular(c: Compiled, q: np.ndarray, t: np.ndarray, screen: bool = False) -> np.ndarray | None:
    """Condition numbers of Phi_q along the motion; a singular configuration is an error. With
    ``screen``, None where :func:`_proven_regular` shows the whole motion regular (the numbers
    are then computed only when read: :func:`condition_numbers`, the same values)."""
    J = jacobian(c, with_frame(q))[:, :, 3:]
    if screen and _proven_regular(J):
        return None
    cond = _condition(J)
    bad = np.flatnonzero(cond > _COND_LIMIT)
    if bad.size:
        k = int(bad[0])
        u, _, _ = np.linalg.svd(J[k])
        weak = u[:, J.shape[2] - 1]  # left vector of the smallest of the n singular values
        raise AnalysisError(
            f"singular configuration at t = {t[k]:.6g} s (condition number {cond[k]:.2g}): "
            f"joints {_worst_rows(c, weak)} lose their rank (a dead point, a limit of the "
            f"workspace or a branch change)",
            float(t[k]),
            c.row_owner[int(np.argmax(np.abs(weak)))],
        )
    return cond


class DenseOps:
    """The general path's solves: :func:`newton_raphson` and :func:`.kinematics._vel_acc` on every
    sample's full Jacobian (:func:`.constraints.jacobian`).

    ``t``: the motion's time grid, whose drivers' values are then evaluated once and taken for
    the grid itself and for single times on it (the continuation's steps: a 4-RRR's driver laws
    solve the legs' inverse kinematics, 60 % of a step when evaluated one time at a time), as
    :class:`.newton_blocks.BlockOps` does. ``by_type``: Phi, Phi_q, nu and gamma evaluated by
    primitive type instead (:mod:`.vectorised`: :func:`newton_raphson`'s ``by_type``,
    :func:`.kinematics.rates_by_type`), in a third of the time: the continuation's single-sample
    steps are mostly these evaluations. The same values to round-off (gear rows' sums in another
    order), on paper 001's 4-RRR bit for bit: taken for the frame motions of the general path's
    models (:mod:`.shared`), not where it is the block path's reference or the balancing's
    states (:func:`solve_positions`)."""

    def __init__(self, c: Compiled, t: np.ndarray | None = None, by_type: bool = False):
        self.c = c
        self._vz = vectorised_of(c) if by_type else None
        vz = self._vz
        if t is None:
            self._grid = None
        elif vz is None:
            self._grid = GridLaws(t, functools.partial(law_triples, c), _triples_row)
        else:
            self._grid = GridLaws(t, lambda grid: law_table(vz, grid), table_row)

    @property
    def vectorised(self) -> Vectorised | None:
        """The model's :func:`.vectorised.vectorise` with ``by_type``, else None."""
        return self._vz

    def table(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """With ``by_type``: :func:`.vectorised.law_table` at ``t``, from the grid's table where
        it has them."""
        assert self._vz is not None
        laws = self._laws(t)
        return law_table(self._vz, t) if laws is None else laws

    def _laws(self, t: np.ndarray) -> Any:
        """The drivers' values at ``t`` (:func:`.constraints.law_triples`, or by type
        :func:`.vectorised.law_table`) from the grid's table (the grid itself, or a single time
        on it), else None (evaluated by the callee)."""
        return None if self._grid is None else self._grid.at(t)

    def newton(self, q: np.ndarray, t: np.ndarray, max_iter: int = _MAX_ITER) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        if self._vz is not None:
            return newton_raphson(self.c, q, t, max_iter, by_type=(self._vz, self.table(t)[0]))
        laws = self._laws(t)
        return newton_raphson(self.c, q, t, max_iter, None if laws is None else [None if f is None else f[0] for f in laws])

    def vel_acc(self, q: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        if self._vz is not None:
            return rates_by_type(self._vz, q, self.table(t))[:2]
        return _vel_acc(self.c, q, t, self._laws(t))


def _triples_row(table: list, k: int) -> list:
    """Sample k of :func:`.constraints.law_triples`' table, as the table of that time alone."""
    return [None if f is None else (f[0][k : k + 1], f[1][k : k + 1], f[2][k : k + 1]) for f in table]


def _ops(c: Compiled, t: np.ndarray) -> Ops:
    """The solves for the continuation of ``c``: by the constraints evaluated by type
    (:class:`.newton_blocks.BlockOps`) when the block path has decomposed its Jacobian
    (``c.fast``, :func:`.fastpath.prepare`), else the general path's."""
    p = c.fast
    if p is not None and getattr(p, "dec", None) is not None and redundancy(c) == 0:
        from .newton_blocks import BlockOps

        return BlockOps(c, p.vz, p.dec, t)
    return DenseOps(c, t)


def solve_positions(c: Compiled, t: np.ndarray) -> np.ndarray:
    """Positions (N, 3 nb) along the motion.

    The first sample is assembled from the model's initial pose; a coarse grid is then followed
    by continuation (second-order predictor), and all samples are refined at once by batched
    Newton-Raphson from a cubic Hermite interpolation of the coarse solution. A singular
    configuration on the way is an error (:func:`_check_regular`); ``c.condition`` is set to the
    condition numbers along the motion, or to None where the screen showed it regular (then
    :func:`condition_numbers` gives them, as the block path does). Always the general path's
    dense solves (:class:`DenseOps`): the reference the block path is tested against.
    """
    qall = follow_motion(c, t, DenseOps(c, t))
    c.condition = _check_regular(c, qall, t, screen=True)
    return qall


def follow_motion(c: Compiled, t: np.ndarray, ops: Ops | None = None) -> np.ndarray:
    """:func:`solve_positions` without the regularity check (the caller makes it). ``ops``: the
    Newton-Raphson and velocity solves (:class:`DenseOps`, or
    :class:`.newton_blocks.BlockOps`); by default the block ones where ``c`` has been decomposed
    (:func:`_ops`). Either gives the same motion (same branch, to the Newton tolerance).

    The model's initial pose is its pose at t = 0 (:class:`balpipe.model.Model`): a grid that
    starts later (a few samples inside the motion) is reached from t = 0 by continuation
    (:func:`_lead`), so that it lies on the branch of the whole motion. Assembled at t[0] from
    the initial pose instead, an offset slider-crank at 293 deg of its crank put the slider on
    the other side of the crank (the torque-driven run's efforts at a law's jump came from
    that mirror image)."""
    if ops is None:
        ops = _ops(c, t)
    _check_square(c)
    N = len(t)
    start = min(float(t[0]), 0.0)
    q, ok, _ = ops.newton(c.q0[None, :], np.array([start]), max_iter=50)
    if not ok[0]:
        err = AnalysisError(
            f"cannot assemble the mechanism at t = {start:g}: " + str(_fail_position(c, q[0], start)).split(": ", 1)[1],
            start,
        )
        err.q = q[0]
        raise err
    _check_redundancy(c, q[0], start)
    if start != t[0]:
        q = _lead(c, q[0], np.linspace(start, float(t[0]), _COARSE), ops)[None, :]
    tc = _coarse_times(t)
    qc, vc = _continue(c, q[0], tc, ops)
    # Hermite interpolation to the full grid
    seg = np.clip(np.searchsorted(tc, t, side="right") - 1, 0, len(tc) - 2) if len(tc) > 1 else np.zeros(N, int)
    if len(tc) > 1:
        t0, t1 = tc[seg], tc[seg + 1]
        h = (t1 - t0)[:, None]
        s = ((t - t0) / (t1 - t0))[:, None]
        h00, h10, h01, h11 = 2 * s**3 - 3 * s**2 + 1, s**3 - 2 * s**2 + s, -2 * s**3 + 3 * s**2, s**3 - s**2
        guess = h00 * qc[seg] + h10 * h * vc[seg] + h01 * qc[seg + 1] + h11 * h * vc[seg + 1]
    else:
        guess = np.repeat(qc[:1], N, axis=0)
    qall, ok, _ = ops.newton(guess, t)
    jumped = np.abs(qall[:, 2::3] - guess[:, 2::3]).max(axis=1) > _JUMP
    for k in np.flatnonzero(~ok | jumped):  # rare: refine sequentially from the previous sample
        prev = k - 1
        qall[k] = _substep(c, qall[prev], t[prev], t[k], ops=ops)[0]
    return qall


def _coarse_times(t: np.ndarray) -> np.ndarray:
    """The times the continuation follows: :data:`_COARSE` samples of ``t`` spread over it, and
    where two of them are more than :data:`_GAP` times the even spacing (span / 16) apart (a
    sparse grid: a few times far inside the motion), times between them at that spacing. An
    evenly spread grid of 9 or more samples (every analysis of a motion; the balancing
    regressors' 9 states along it) has no such gap: its continuation is unchanged."""
    tc = t[spread_indices(len(t), _COARSE)]
    if len(tc) < 2:
        return tc
    step = float(tc[-1] - tc[0]) / (_COARSE - 1)
    gaps = np.diff(tc)
    if step <= 0 or not np.any(gaps > _GAP * step):
        return tc
    parts = [tc[:1]]
    for a, b, g in zip(tc[:-1], tc[1:], gaps):
        if g > _GAP * step:
            parts.append(np.linspace(a, b, int(np.ceil(g / step)) + 1)[1:-1])
        parts.append(np.array([b]))
    return np.concatenate(parts)


def _continue(c: Compiled, q0: np.ndarray, tc: np.ndarray, ops: Ops) -> tuple[np.ndarray, np.ndarray]:
    """Positions and velocities at the times ``tc`` followed from ``q0`` (the pose at tc[0]) by
    a second-order predictor and Newton-Raphson, substepped where a step does not converge."""
    qc = np.zeros((len(tc), q0.shape[0]))
    vc = np.zeros_like(qc)
    ac = np.zeros(qc.shape[1])
    qc[0] = q0
    for k in range(len(tc)):
        if k > 0:
            h = tc[k] - tc[k - 1]
            guess = qc[k - 1] + vc[k - 1] * h + 0.5 * ac * h * h
            sol, ok_k, _ = ops.newton(guess[None, :], tc[k : k + 1])
            if not ok_k[0]:
                # substep the continuation before giving up
                sol = _substep(c, qc[k - 1], tc[k - 1], tc[k], ops=ops)
            qc[k] = sol[0]
        v, ac = ops.vel_acc(qc[k : k + 1], tc[k : k + 1])
        vc[k], ac = v[0], ac[0]
    return qc, vc


def _lead(c: Compiled, q0: np.ndarray, times: np.ndarray, ops: Ops) -> np.ndarray:
    """The pose at ``times[-1]`` followed from ``q0`` (the pose at ``times[0]``) along ``times``."""
    return _continue(c, q0, times, ops)[0][-1]


def _substep(c: Compiled, q: np.ndarray, ta: float, tb: float, depth: int = 0, ops: Ops | None = None) -> np.ndarray:
    ops = ops if ops is not None else DenseOps(c)
    for n in (4, 16, 64):
        cur = q.copy()
        good = True
        for tt in np.linspace(ta, tb, n + 1)[1:]:
            try:
                v, a = ops.vel_acc(cur[None, :], np.array([tt]))
                v, a = v[0], a[0]
            except np.linalg.LinAlgError:
                v, a = np.zeros_like(cur), np.zeros_like(cur)
            h = (tb - ta) / n
            sol, ok, _ = ops.newton((cur + v * h + 0.5 * a * h * h)[None, :], np.array([tt]))
            if not ok[0]:
                good = False
                break
            cur = sol[0]
        if good:
            return cur[None, :]
    raise _fail_position(c, cur, float(tt))
