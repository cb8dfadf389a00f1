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
  stage, a mass design), which then needs no continuation.
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

import dataclasses
from dataclasses import dataclass

import numpy as np

from .compile import Compiled
from .positions import _COND_LIMIT, _TOL, _check_regular, _condition, follow_motion, redundancy
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
    of mass are placed in the bodies' frames, and the residual is checked."""
    key = _motion_key(c, t)
    hit = _MOTIONS.get(key)
    com = c.com_local
    if hit is not None:
        frame = hit[1]
        th = frame[:, 2::3]
        cos, sin = np.cos(th), np.sin(th)
        q = frame.copy()
        q[:, 0::3] += cos * com[:, 0] - sin * com[:, 1]
        q[:, 1::3] += sin * com[:, 0] + cos * com[:, 1]
        X = np.zeros((vz.ncol, len(t)))
        X[3:] = q.T
        if np.all(np.abs(residual(vz, State(vz, X), f)) < _TOL):
            return q
    q = _polish(vz, dec, follow_motion(c, t), f)
    th = q[:, 2::3]
    cos, sin = np.cos(th), np.sin(th)
    frame = q.copy()
    frame[:, 0::3] -= cos * com[:, 0] - sin * com[:, 1]
    frame[:, 1::3] -= sin * com[:, 0] + cos * com[:, 1]
    if len(_MOTIONS) >= 16:
        _MOTIONS.clear()
    _MOTIONS[key] = ([d.law for d in c.model.drivers], frame)
    return q


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
