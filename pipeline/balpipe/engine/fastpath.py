"""The block-triangular path of :func:`balpipe.engine.analyse`: kinematics and multipliers by
substitution on the decomposed Jacobian (:mod:`.structure`), the constraints evaluated by type
(:mod:`.vectorised`).

* Positions: when every block is 1 x 1 and linear in its unknown (open chains with driven
  joints, guides fixed to the frame, ...) Phi(q, t) = 0 is solved level by level, each unknown
  by one division, with no Newton iteration, continuation or branch to follow (the solution is
  unique); the residual is checked at the end. Otherwise (closed loops) the general
  continuation and batched Newton-Raphson of :mod:`.positions`, followed by one Newton step
  by blocks (its residual 1e-12 becomes ~1e-16); the motion of the bodies' frames is kept and
  reused by the next model with the same joints, drivers, initial poses and grid (a balancing
  stage, a mass design), which then needs no continuation. A new geometry of the same structure
  (a sweep's next design: other lengths, the same joints, drivers, point names and grid) starts
  a Newton-Raphson by blocks on all samples at once from the motion of the nearest design solved
  before, accepted when it converges everywhere on the branch of its own initial pose, else the
  continuation runs (:func:`_warm_start`; counts in :data:`STATS`). Opt-in, within
  :func:`warm_designs` (the last digits would otherwise depend on the history).
* Velocities Phi_q q' = nu, accelerations Phi_q q'' = gamma: forward substitution.
* Multipliers Phi_q^T lambda = Q - M q'': backward substitution on the same values.
* Regularity: cond(Phi_q) >= max|entry| / sigma_min(block) for every diagonal block; samples
  where this bound passes 1e-4 of the limit get the exact (SVD) condition number, and a sample
  beyond the limit is reported by :func:`.positions._check_regular`, with the same message as
  the general path. The full condition numbers (``Analysis.extra["condition"]``) are computed
  when first read.

Anything this path does not cover (redundant actuation, structurally singular patterns, a
non-finite or non-converged explicit solution) raises :class:`Fallback`, and the caller takes
the general dense path.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass

import numpy as np

from .compile import Compiled
from .positions import _COND_LIMIT, _JUMP, _MAX_ITER, _TOL, _check_regular, _condition, follow_motion, redundancy
from .constraints import _extend, jacobian
from .structure import Decomposition, block_sigma_min, decompose, invert_blocks, solve
from .vectorised import State, Vectorised, acceleration_rhs, jacobian_values, law_table, residual, velocity_rhs, vectorise

_SCREEN = 1e-4  # exact condition numbers where the lower bound exceeds this fraction of the limit
_RESIDUAL = 1e-9  # the general path's convergence test (:func:`.positions._newton`)
_POLISH = 1e-14  # closed loops: one more Newton step where the residual exceeds this


class Fallback(Exception):
    """The block path does not apply; take the general path."""


@dataclass
class Prepared:
    """What the block path keeps per compiled model."""

    vz: Vectorised
    dec: Decomposition | None
    free_slots: np.ndarray  # Jacobian entries on free coordinates
    frame_slots: list[tuple[np.ndarray, np.ndarray]]  # per frame coordinate: (slots, rows)


def prepare(c: Compiled) -> Prepared:
    vz = vectorise(c)
    dec = decompose(vz) if redundancy(c) == 0 else None
    frame = [(np.flatnonzero(vz.cols == k), vz.rows[vz.cols == k]) for k in range(3)]
    return Prepared(vz, dec, np.flatnonzero(vz.cols >= 3), frame)


@dataclass
class Kinematics:
    X: np.ndarray  # (3 nb + 3 + 1, N): frame rows first, a zero row last
    V: np.ndarray
    A: np.ndarray
    vals: np.ndarray  # Jacobian values at X
    state: State
    inverses: dict[int, np.ndarray]  # of the k x k diagonal blocks


def kinematics(c: Compiled, p: Prepared, t: np.ndarray) -> Kinematics:
    """Positions, velocities and accelerations, coordinate-major, with the Jacobian's values."""
    dec, vz = p.dec, p.vz
    if dec is None:
        raise Fallback
    N = len(t)
    f, fd, fdd = law_table(vz, t)
    if dec.explicit:
        X, state = _explicit_positions(vz, dec, f, N)
    else:
        X = np.zeros((vz.ncol + 1, N))
        X[3:-1] = _closed_loop_positions(c, vz, dec, t, f).T
        state = State(vz, X[:-1])
    vals = jacobian_values(vz, state)
    if dec.explicit:
        phi = residual(vz, state, f)
        if not np.all(np.abs(phi) < _RESIDUAL):
            raise Fallback
    inverses = invert_blocks(dec, vals)
    _screen(c, p, vals, inverses, X, t)
    V = solve(dec.forward, vals, velocity_rhs(vz, fd, N), inverses, offset=3)
    A = solve(dec.forward, vals, acceleration_rhs(vz, state, V, fdd), inverses, offset=3)
    return Kinematics(X, V, A, vals, state, inverses)


def _explicit_positions(vz: Vectorised, dec: Decomposition, f: np.ndarray, N: int) -> tuple[np.ndarray, State]:
    """Every block 1 x 1 and linear: unknown = -phi(unknown = 0) / pivot, level by level. The
    angles come first (angle rows involve angles only), then the trigonometry once, then the
    positions (their rows are linear in the positions at fixed angles)."""
    X = np.zeros((vz.ncol + 1, N))
    th = X[2:-1:3]
    fa = np.zeros((len(vz.arow), N))
    fa[:] = -vz.aconst[:, None]
    at = np.searchsorted(vz.arow, vz.law_rows)
    is_angle = (at < len(vz.arow)) & (vz.arow[np.minimum(at, len(vz.arow) - 1)] == vz.law_rows)
    fa[at[is_angle]] -= f[is_angle]
    for eq, unk, piv in dec.angle_steps:
        X[unk + 3] = -(vz.akoef[eq] @ th + fa[eq]) / vz.const[piv][:, None]
    s = State(vz, X[:-1])
    for eq, unk, piv in dec.position_steps:
        phi = residual(vz, s, f)
        p = vz.const[piv][:, None] if dec.pivots_constant else jacobian_values(vz, s)[piv]
        X[unk + 3] = -phi[eq] / p
    if not np.all(np.isfinite(X)):
        raise Fallback
    return X, s


_MOTIONS: dict[tuple, tuple[list, np.ndarray]] = {}


def _motion_key(c: Compiled, t: np.ndarray) -> tuple:
    """Everything the motion of the bodies' own frames depends on: the joints, the drivers (their
    laws by identity, kept alive by the cache), the bodies' named points, the initial poses
    (the branch) and the time grid; not the mass properties, which move only the centres of
    mass within the bodies (a balancing stage, a mass design). Numbers enter exactly."""
    m = c.model
    joints = tuple((type(j).__name__, *(_exact(getattr(j, f.name)) for f in dataclasses.fields(j))) for j in m.joints)
    return (joints, tuple((d.name, _exact(d.target), id(d.law)) for d in m.drivers),
            tuple((b.name, _exact(sorted(b.points.items()))) for b in m.bodies),
            _exact(sorted(m.initial.items())), t.tobytes())


def _exact(v):
    """A hashable, exact image of nested tuples, lists, arrays and numbers."""
    if isinstance(v, (str, type(None))):
        return v
    if isinstance(v, (tuple, list, np.ndarray)):
        return tuple(_exact(x) for x in v)
    return float(v).hex()


def _closed_loop_positions(c: Compiled, vz: Vectorised, dec: Decomposition, t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Positions (N, 3 nb) by the general continuation, or from the motion of the bodies' frames
    solved before for the same mechanism and grid (another stage or mass design): the centres
    of mass are placed in the bodies' frames, and the residual is checked. A new geometry of a
    mechanism solved before (same structure, other lengths or poses) starts from that motion
    (:func:`_warm_start`); the continuation runs when it is rejected."""
    key = _motion_key(c, t)
    hit = _MOTIONS.get(key)
    com = c.com_local
    if hit is not None:
        q = _place(hit[1], com)
        X = np.zeros((vz.ncol, len(t)))
        X[3:] = q.T
        if np.all(np.abs(residual(vz, State(vz, X), f)) < _TOL):
            STATS["reused"] += 1
            return q
    skey, numbers = _structure_key(c, t) if _WARM_ENABLED else (None, None)
    q = _warm_start(c, vz, dec, f, skey, numbers) if _WARM_ENABLED else None
    if q is None:
        STATS["continuation"] += 1
        q = _polish(vz, dec, follow_motion(c, t), f)
    frame = _place(q, -com)
    if len(_MOTIONS) >= 16:
        _MOTIONS.clear()
    _MOTIONS[key] = ([d.law for d in c.model.drivers], frame)
    if skey is None:
        return q
    designs = _WARM.setdefault(skey, [])
    if len(designs) >= 8:
        del designs[0]
    designs.append((numbers, frame))
    if len(_WARM) >= 16:
        _WARM.clear()
        _WARM[skey] = designs
    return q


def _place(frame: np.ndarray, com: np.ndarray) -> np.ndarray:
    """Coordinates (N, 3 nb) of the points at ``com`` (nb, 2) in the bodies' frames ``frame``."""
    th = frame[:, 2::3]
    cos, sin = np.cos(th), np.sin(th)
    q = frame.copy()
    q[:, 0::3] += cos * com[:, 0] - sin * com[:, 1]
    q[:, 1::3] += sin * com[:, 0] + cos * com[:, 1]
    return q


# Warm start across geometry: per structure (:func:`_structure_key`), the frame motions of the
# designs solved last, with their numbers; on within :func:`warm_designs` only.
_WARM: dict[tuple, list[tuple[np.ndarray, np.ndarray]]] = {}
_WARM_ENABLED = False
STATS = {"reused": 0, "warm": 0, "warm_rejected": 0, "continuation": 0}
_SAME_POSE = 1e-8  # warm start: the first sample against the assembled initial pose (relative)
_STEP_CHANGE = 0.5  # warm start: a step's angle change against the start's, in its largest step
_CHORD = 0.1  # warm start: a new Jacobian after a step that reduced the residual less than this factor


@contextlib.contextmanager
def warm_designs() -> Iterator[None]:
    """Within this block, :func:`balpipe.engine.analyse` of a closed loop with a new geometry
    (other lengths or poses; the same joints, drivers, point names and time grid) starts from the
    motion of the nearest design analysed before in the block's process instead of the
    sequential continuation (:func:`_warm_start`).

    Off by default: a warm-started motion equals the continuation's only to round-off (~1e-15 of
    each quantity's peak), so with it a design's numbers would depend, in their last digits, on
    which designs ran before in the same process (a build must give the same bytes for the same
    spec; a sweep the same table for any chunking). A caller that accepts that (an optimiser, an
    interactive sweep) opts in here."""
    global _WARM_ENABLED
    previous = _WARM_ENABLED
    _WARM_ENABLED = True
    try:
        yield
    finally:
        _WARM_ENABLED = previous


def _structure_key(c: Compiled, t: np.ndarray) -> tuple[tuple, np.ndarray]:
    """:func:`_motion_key` with the numbers taken out: the names and types of the joints,
    drivers (the laws by type), bodies' points and initial poses, and the time grid exactly;
    the numbers (lengths, offsets, poses) separately, to pick the nearest design."""
    m = c.model
    numbers: list[float] = []
    joints = tuple((type(j).__name__, *(_shape(getattr(j, f.name), numbers) for f in dataclasses.fields(j)))
                   for j in m.joints)
    drivers = tuple((d.name, _shape(d.target, numbers), type(d.law).__name__) for d in m.drivers)
    bodies = tuple((b.name, _shape(sorted(b.points.items()), numbers)) for b in m.bodies)
    initial = _shape(sorted(m.initial.items()), numbers)
    return (joints, drivers, bodies, initial, t.tobytes()), np.array(numbers, dtype=float)


def _shape(v, numbers: list[float]):
    """:func:`_exact` with every number replaced by "#" and appended to ``numbers``."""
    if isinstance(v, (str, type(None))):
        return v
    if isinstance(v, (tuple, list, np.ndarray)):
        return tuple(_shape(x, numbers) for x in v)
    numbers.append(float(v))
    return "#"


def _warm_start(c: Compiled, vz: Vectorised, dec: Decomposition, f: np.ndarray, skey: tuple,
                numbers: np.ndarray) -> np.ndarray | None:
    """Positions (N, 3 nb) by Newton-Raphson on all samples at once (block by block) from the
    motion of the nearest design with the same structure, or None (take the continuation).

    Accepted only when every sample converges (residual below 1e-14, or no longer decreasing
    below 1e-12) and the motion stays on the branch of the model's own initial pose: the first
    sample is the pose assembled from ``model.initial`` by Newton's method (as the continuation
    starts; by blocks here), no angle is more than 0.2 rad from its start (the continuation's
    branch guard, :data:`.positions._JUMP`) and no step between samples changes its angles by
    more than half the start's largest step (no jump between samples)."""
    designs = _WARM.get(skey)
    if not designs:
        return None
    start = _place(min(designs, key=lambda d: float(np.abs(d[0] - numbers).max()))[1], c.com_local)
    q = _block_newton(vz, dec, start, f)
    if q is None or not _same_branch(c, vz, dec, f, q, start):
        STATS["warm_rejected"] += 1
        return None
    STATS["warm"] += 1
    return q


def _block_newton(vz: Vectorised, dec: Decomposition, q: np.ndarray, f: np.ndarray, max_iter: int = _MAX_ITER,
                  chord: bool = True) -> np.ndarray | None:
    """Newton-Raphson by blocks on all samples from ``q`` (N, 3 nb); None if it does not converge.

    ``chord``: the Jacobian (its values and block inverses) is evaluated again only when the
    last step reduced the residual less than tenfold (:data:`_CHORD`; from a nearby start the first one serves
    several steps); the iteration stops at the same residual as Newton's method. ``chord=False``:
    Newton's method itself (the assembly of the first sample, as :func:`.positions._newton`)."""
    X = np.zeros((vz.ncol + 1, q.shape[0]))
    X[3:-1] = q.T
    last, fresh, jac = np.inf, False, None
    with np.errstate(all="ignore"):
        for _ in range(max_iter):
            state = State(vz, X[:-1])
            phi = residual(vz, state, f)
            err = float(np.abs(phi).max())
            if not np.isfinite(err) or err <= _POLISH or (err < _TOL and err > 0.1 * last and fresh):
                break
            if jac is None or not chord or err > _CHORD * last:
                vals = jacobian_values(vz, state)
                try:
                    jac = (vals, invert_blocks(dec, vals))
                except np.linalg.LinAlgError:
                    return None
                fresh = True
            else:
                fresh = False
            last = err
            X += solve(dec.forward, jac[0], -phi, jac[1], offset=3)
    if not err < _TOL or not np.all(np.isfinite(X)):
        return None
    return X[3:-1].T.copy()


def _same_branch(c: Compiled, vz: Vectorised, dec: Decomposition, f: np.ndarray, q: np.ndarray,
                 start: np.ndarray) -> bool:
    """The branch guard of the warm start (see :func:`_warm_start`)."""
    q0 = _block_newton(vz, dec, c.q0[None, :], f[:, :1], max_iter=50, chord=False)
    if q0 is None or np.abs(q[0] - q0[0]).max() > _SAME_POSE * max(1.0, float(np.abs(q0[0]).max())):
        return False
    th, th0 = q[:, 2::3], start[:, 2::3]
    if np.abs(th - th0).max() > _JUMP:
        return False
    if len(q) > 1:
        step, step0 = np.diff(th, axis=0), np.diff(th0, axis=0)
        if np.abs(step - step0).max() > _STEP_CHANGE * float(np.abs(step0).max()):
            return False
    return True


def _polish(vz: Vectorised, dec: Decomposition, q: np.ndarray, f: np.ndarray) -> np.ndarray:
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


def _screen(c: Compiled, p: Prepared, vals: np.ndarray, inverses: dict, X: np.ndarray, t: np.ndarray) -> None:
    """Singular configurations: the block bound, then the exact check where it is close."""
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.abs(vals[p.free_slots]).max(axis=0) / block_sigma_min(p.dec, vals, inverses)
    close = ~(bound <= _COND_LIMIT * _SCREEN)
    if close.any():
        q = X[3:-1, close].T
        if not np.all(_condition(jacobian(c, _extend(q))[:, :, 3:]) <= _COND_LIMIT):
            _check_regular(c, X[3:-1].T, t)  # raises, naming the first singular sample
            raise Fallback  # pragma: no cover - the exact check disagreed with itself


def multipliers(p: Prepared, k: Kinematics, rhs: np.ndarray) -> np.ndarray:
    """lambda (m, N) from Phi_q^T lambda = rhs (n, N), square Phi_q."""
    return solve(p.dec.backward, k.vals, rhs, k.inverses)[:-1]


def frame_load(p: Prepared, vals: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """-Phi_q0^T lambda (N, 3): the load on the frame (Fx, Fy, moment about O)."""
    out = np.empty((lam.shape[1], 3))
    for col, (slots, rows) in enumerate(p.frame_slots):
        out[:, col] = -np.einsum("kn,kn->n", vals[slots], lam[rows]) if len(slots) else 0.0
    return out
