"""The block-triangular path of :func:`balpipe.engine.analyse`: kinematics and multipliers by
substitution on the decomposed Jacobian (:mod:`.structure`), the constraints evaluated by type
(:mod:`.vectorised`).

* Positions: when every block is 1 x 1 and linear in its unknown (open chains with driven
  joints, guides fixed to the frame, ...) Phi(q, t) = 0 is solved level by level, each unknown
  by one division, with no Newton iteration, continuation or branch to follow (the solution is
  unique); the residual is checked at the end. Otherwise (closed loops) the motion of the
  bodies' frames is solved on the frame model (every centre of mass at its frame's origin, so
  that it depends on the geometry alone) by the general continuation and batched
  Newton-Raphson of :mod:`.positions`, followed by one Newton step by blocks (its residual
  1e-12 becomes ~1e-16); it is kept and reused by every model with the same joints, drivers,
  points, initial poses and grid (a balancing stage, a mass design: no continuation), which
  places its centres of mass in it. Within :func:`.warmstart.warm_start` a new geometry of the
  same structure (a sweep's next design) starts from the nearest anchor instead
  (:mod:`.warmstart`).
* Velocities Phi_q q' = nu, accelerations Phi_q q'' = gamma: forward substitution.
* Multipliers Phi_q^T lambda = Q - M q'': backward substitution on the same values.
* Long grids: after the positions, everything runs :func:`chunk_size` samples at a time
  (:func:`dynamics_by_chunks`; the same values), so that the Jacobian's values and the
  trigonometry of one chunk are alive at a time and stay in the caches.
* Regularity: cond(Phi_q) >= max|entry| / sigma_min(block) for every diagonal block; samples
  where this bound passes 1e-4 of the limit get the exact (SVD) condition number, and a sample
  beyond the limit is reported by :func:`.positions._check_regular`, with the same message as
  the general path. The full condition numbers (``Analysis.condition``) are computed
  when first read.

Anything this path does not cover (redundant actuation, structurally singular patterns, a
non-finite or non-converged explicit solution) raises :class:`Fallback`, and the caller takes
the general dense path.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..model import Model
from . import warmstart
from .compile import Compiled, compile_model
from .positions import _COND_LIMIT, _TOL, _check_regular, _condition, follow_motion, redundancy, solve_positions
from .constraints import with_frame, jacobian
from .newton_blocks import BlockOps, polish
from .structure import Decomposition, block_sigma_min, decompose, invert_blocks, solve
from .vectorised import State, Vectorised, acceleration_rhs, jacobian_values, law_table, residual, residual_rows, velocity_rhs, vectorise

_SCREEN = 1e-4  # exact condition numbers where the lower bound exceeds this fraction of the limit
_RESIDUAL = 1e-9  # the general path's convergence test (:func:`.positions.newton_raphson`)


class Fallback(Exception):
    """The block path does not apply; take the general path."""


@dataclass
class Prepared:
    """What the block path keeps per compiled model."""

    vz: Vectorised
    dec: Decomposition | None
    free_slots: np.ndarray  # Jacobian entries on free coordinates
    frame_slots: list[tuple[np.ndarray, np.ndarray]]  # per frame coordinate: (slots, rows)
    static_bound: float | None = None  # a bound of :func:`_screen`'s bound valid at every sample


def prepare(c: Compiled) -> Prepared:
    vz = vectorise(c)
    dec = decompose(vz) if redundancy(c) == 0 else None
    frame = [(np.flatnonzero(vz.cols == k), vz.rows[vz.cols == k]) for k in range(3)]
    free = np.flatnonzero(vz.cols >= 3)
    return Prepared(vz, dec, free, frame, _static_bound(vz, dec, free))


def _static_bound(vz: Vectorised, dec: Decomposition | None, free: np.ndarray) -> float | None:
    """max|entry| / min|pivot| over every configuration, where it holds for all: every block 1 x 1
    with a constant pivot and no projection (the varying entries are then the components of
    rotated local vectors A s, at most |s| in size). None elsewhere."""
    if dec is None or not dec.explicit or not dec.pivots_constant or len(vz.pi):
        return None
    const = vz.const[free]
    fixed = np.abs(const[~np.isnan(const)])
    local = np.hypot(np.concatenate([vz.csi, vz.csj])[:, 0], np.concatenate([vz.csi, vz.csj])[:, 1])
    largest = float(max(fixed.max(initial=0.0), local.max(initial=0.0)))
    pivots = [np.abs(vz.const[st.diag]).min() for st in dec.forward.steps if not st.square]
    if not pivots or min(pivots) <= 0.0:
        return None
    return largest / float(min(pivots)) * (1.0 + 1e-9)  # the rotations' round-off

@dataclass
class Kinematics:
    X: np.ndarray  # (3 nb + 3 + 1, N): frame rows first, a zero row last
    V: np.ndarray
    A: np.ndarray
    vals: np.ndarray  # Jacobian values at X
    state: State
    inverses: dict[int, np.ndarray]  # of the k x k diagonal blocks


def _decomposed(p: Prepared) -> Decomposition:
    """``p``'s decomposition; :class:`Fallback` when the block path does not apply (no
    decomposition: :func:`kinematics` refuses such a model first)."""
    if p.dec is None:
        raise Fallback
    return p.dec


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


CHUNK: int | None = None  # samples per chunk of :func:`dynamics_by_chunks` (None: :func:`chunk_size`)
_CHUNK_VALUES = 1 << 20  # the float rows x samples of one chunk: a few MB, in the caches


def chunk_size(vz: Vectorised) -> int:
    """Samples per chunk: about :data:`_CHUNK_VALUES` values over the Jacobian's entries and the
    coordinates' rows (X, V, A and the trigonometry), 1024 to 16384 samples (a small model's
    chunk is long: each chunk costs a fixed few hundred numpy calls)."""
    rows = vz.nnz + 4 * vz.ncol
    return int(min(16384, max(1024, _CHUNK_VALUES // max(1, rows))))


@dataclass
class Motion:
    """What :func:`dynamics_by_chunks` returns: positions, velocities and accelerations,
    coordinate-major as in :class:`Kinematics` (without the transients of the solves), the
    multipliers (m, N) and the load on the frame (N, 3)."""

    X: np.ndarray
    V: np.ndarray
    A: np.ndarray
    lamT: np.ndarray
    frame: np.ndarray


def dynamics_by_chunks(c: Compiled, p: Prepared, t: np.ndarray, Mdiag: np.ndarray, g: np.ndarray,
                       chunk: int | None = None) -> Motion:
    """:func:`kinematics`, then the multipliers of Phi_q^T lambda = Q - M q'' (gravity ``g``,
    ``Mdiag`` the diagonal of M, (1, 3 nb)) and the frame load, ``chunk`` samples at a time
    (default :data:`CHUNK`, else :func:`chunk_size`):
    the same operations sample by sample as the whole grid at once (the same values), with the
    Jacobian's values, its blocks' inverses and the trigonometry of one chunk alive at a time
    (a fifth of the memory of 20,000 samples of a 21-body ladder; the chunks' arrays stay in the
    caches, so that throughput does not fall past 10^4 samples). The checks are those of
    :func:`kinematics` chunk by chunk: an explicit solution off its equations falls back, a
    singular configuration is reported at its first sample (the earlier chunks are regular)."""
    dec, vz = p.dec, p.vz
    if dec is None:
        raise Fallback
    N = len(t)
    chunk = max(1, chunk if chunk is not None else CHUNK if CHUNK is not None else chunk_size(vz))
    gx, gy = (c.mass * g[0])[:, None], (c.mass * g[1])[:, None]
    if N <= chunk:  # one chunk: the arrays of the solves are the results
        kin = kinematics(c, p, t)
        rhsT = -Mdiag.T * kin.A[3:-1]
        rhsT[0::3] += gx
        rhsT[1::3] += gy
        lamT1 = multipliers(p, kin, rhsT)
        return Motion(kin.X, kin.V, kin.A, lamT1, frame_load(p, kin.vals, lamT1))
    f, fd, fdd = law_table(vz, t)  # the whole grid: a law may depend on it
    X = np.zeros((vz.ncol + 1, N))
    if not dec.explicit:
        X[3:-1] = _closed_loop_positions(c, vz, dec, t, f).T
    V, A = np.zeros(X.shape), np.zeros(X.shape)
    lamT = np.zeros((vz.m + 1, N))  # a padding row last, as solve() lays it out
    frame = np.empty((N, 3))
    for a in range(0, N, chunk):
        b = min(N, a + chunk)
        n, fa = b - a, f[:, a:b]
        if dec.explicit:
            Xc, state = _explicit_positions(vz, dec, fa, n)
            phi = residual(vz, state, fa)
            if not np.all(np.abs(phi) < _RESIDUAL):
                raise Fallback
            X[:, a:b] = Xc
        else:
            Xc = X[:, a:b]
            state = State(vz, Xc[:-1])
        vals = jacobian_values(vz, state)
        inverses = invert_blocks(dec, vals)
        _screen(c, p, vals, inverses, Xc, t[a:b])
        Vc = solve(dec.forward, vals, velocity_rhs(vz, fd[:, a:b], n), inverses, offset=3, out=V[:, a:b])
        Ac = solve(dec.forward, vals, acceleration_rhs(vz, state, Vc, fdd[:, a:b]), inverses, offset=3,
                   out=A[:, a:b])
        rhsT = -Mdiag.T * Ac[3:-1]
        rhsT[0::3] += gx
        rhsT[1::3] += gy
        lc = solve(dec.backward, vals, rhsT, inverses, out=lamT[:, a:b])[:-1]
        frame[a:b] = frame_load(p, vals, lc)
    return Motion(X, V, A, lamT[:-1], frame)


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
        koef = vz.akoef[eq]
        used = np.flatnonzero(np.any(koef != 0.0, axis=0))  # the angles these rows read: a few, not all
        X[unk + 3] = -(koef[:, used] @ th[used] + fa[eq]) / vz.const[piv][:, None]
    s = State(vz, X[:-1])
    for eq, unk, piv in dec.position_steps:
        phi = residual_rows(vz, s, f, eq)
        p = vz.const[piv][:, None] if dec.pivots_constant else jacobian_values(vz, s)[piv]
        X[unk + 3] = -phi / p
    if not np.all(np.isfinite(X)):
        raise Fallback
    return X, s


_MOTIONS: dict[tuple, tuple[list, np.ndarray]] = {}


def _closed_loop_positions(c: Compiled, vz: Vectorised, dec: Decomposition, t: np.ndarray, f: np.ndarray) -> np.ndarray:
    """Positions (N, 3 nb) of a closed loop: the centres of mass placed in the frame motion of its
    geometry (:func:`frame_motion`), the residual checked; where that motion cannot be solved on
    the frame model (its pattern has no block form), the continuation on ``c`` itself."""
    frame = frame_motion(c, t, f)
    if frame is not None and not np.any(c.com_local):  # c is its own frame model
        return frame
    if frame is not None:
        q = _place(frame, c.com_local)
        X = np.zeros((vz.ncol, len(t)))
        X[3:] = q.T
        if np.all(np.abs(residual(vz, State(vz, X), f)) < _TOL):
            return q
    return polish(vz, dec, follow_motion(c, t), f)


def frame_motion(c: Compiled, t: np.ndarray, f: np.ndarray) -> np.ndarray | None:
    """The motion (N, 3 nb) of the bodies' own frames along ``t``, solved on the frame model
    (:func:`frame_model`) so that it depends on the geometry alone, not on the mass properties
    (every balancing stage and mass design of a mechanism shares it, whatever ran first):

    1. known: solved before in this process for the same joints, drivers, points, initial poses
       and grid (:func:`.warmstart.motion_key`), or warm-started before from the active anchors;
    2. within :func:`.warmstart.warm_start`: from the nearest anchor, if accepted;
    3. the continuation (:func:`.positions.follow_motion`) and one Newton step by blocks.

    None when the frame model's pattern has no block form (the caller solves ``c`` itself)."""
    key = warmstart.motion_key(c, t)
    hit = _MOTIONS.get(key)
    frame = hit[1] if hit is not None else warmstart.solved(key)
    if frame is not None:
        warmstart.STATS["reused"] += 1
    else:
        fc = _frame_compiled(c)
        fp = fc.fast
        if fp.dec is None:
            return None
        frame = warmstart.start(fc, fp.vz, fp.dec, t, f, key)
        if frame is None:
            warmstart.STATS["continuation"] += 1
            frame = polish(fp.vz, fp.dec, follow_motion(fc, t), f)
            if len(_MOTIONS) >= 16:
                _MOTIONS.clear()
            _MOTIONS[key] = ([d.law for d in c.model.drivers], frame)
    warmstart.note(c, t, frame)
    return frame


def frame_model(model: Model) -> Model:
    """``model`` with every body's centre of mass at its frame origin (mass 1 kg, inertia
    1 kg m^2, attachments massless): the same geometry, whose coordinates are the bodies' frames."""
    bodies = tuple(dataclasses.replace(b, mass=1.0, com=(0.0, 0.0), inertia=1.0,
                                       attachments=tuple(dataclasses.replace(a, mass=0.0, inertia=0.0)
                                                         for a in b.attachments))
                   for b in model.bodies)
    return dataclasses.replace(model, bodies=bodies)


def _frame_compiled(c: Compiled) -> Compiled:
    """The compiled frame model of ``c`` (``c`` itself when its centres of mass are at the
    frames' origins), prepared for the block path; kept on ``c`` (the general path may have
    compiled it first, unprepared: :func:`.shared.kinematics`)."""
    if c.frame is None:
        if not np.any(c.com_local):
            c.frame = c
        else:
            c.frame = compile_model(frame_model(c.model))
    if c.frame.fast is None:
        c.frame.fast = prepare(c.frame)
    return c.frame


def _place(frame: np.ndarray, com: np.ndarray) -> np.ndarray:
    """Coordinates (N, 3 nb) of the points at ``com`` (nb, 2) in the bodies' frames ``frame``."""
    rx, ry = _arms(frame, com)
    q = frame.copy()
    q[:, 0::3] += rx
    q[:, 1::3] += ry
    return q


def place_rows(X: np.ndarray, com: np.ndarray) -> np.ndarray:
    """:func:`_place` on coordinate-major coordinates ``X`` (3 nb, N) (the block path's layout),
    returned in the same layout: the same values, without transposing the grid in memory."""
    th = X[2::3]
    cos, sin = np.cos(th), np.sin(th)
    cx, cy = com[:, :1], com[:, 1:]
    out = X.copy()
    out[0::3] += cos * cx - sin * cy
    out[1::3] += sin * cx + cos * cy
    return out


def _arms(frame: np.ndarray, com: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """R(phi) c (N, nb), x and y: the points at ``com`` (nb, 2) from their frames' origins."""
    th = frame[:, 2::3]
    cos, sin = np.cos(th), np.sin(th)
    return cos * com[:, 0] - sin * com[:, 1], sin * com[:, 0] + cos * com[:, 1]


def _screen(c: Compiled, p: Prepared, vals: np.ndarray, inverses: dict, X: np.ndarray, t: np.ndarray) -> None:
    """Singular configurations: the block bound, then the exact check where it is close (none
    where the bound of every configuration is far from the limit: :func:`_static_bound`)."""
    if p.static_bound is not None and p.static_bound <= _COND_LIMIT * _SCREEN:
        return
    with np.errstate(divide="ignore", invalid="ignore"):
        bound = np.abs(vals[p.free_slots]).max(axis=0) / block_sigma_min(_decomposed(p), vals, inverses)
    close = ~(bound <= _COND_LIMIT * _SCREEN)
    if close.any():
        q = X[3:-1, close].T
        if not np.all(_condition(jacobian(c, with_frame(q))[:, :, 3:]) <= _COND_LIMIT):
            _check_regular(c, X[3:-1].T, t)  # raises, naming the first singular sample
            raise Fallback  # pragma: no cover - the exact check disagreed with itself


def solve_positions_by_blocks(c: Compiled, t: np.ndarray) -> np.ndarray:
    """:func:`.positions.solve_positions` with the block path's solves where ``c``'s Jacobian
    decomposes (the continuation's Newton-Raphson by blocks, :class:`.newton_blocks.BlockOps`;
    the regularity by the block bound, exact where it comes close, with the same error at a
    singular configuration): the same motion to the Newton tolerance, O(bodies) per sample
    instead of O(bodies^3). ``c`` is not changed (no ``fast`` or ``condition`` set on it)."""
    p = prepare(c)
    if p.dec is None:
        return solve_positions(c, t)
    q = follow_motion(c, t, BlockOps(c, p.vz, p.dec, t))
    X = np.zeros((p.vz.ncol + 1, len(t)))
    X[3:-1] = q.T
    vals = jacobian_values(p.vz, State(p.vz, X[:-1]))
    with np.errstate(all="ignore"):
        inverses = invert_blocks(p.dec, vals)
    _screen(c, p, vals, inverses, X, t)
    return q


def multipliers(p: Prepared, k: Kinematics, rhs: np.ndarray) -> np.ndarray:
    """lambda (m, N) from Phi_q^T lambda = rhs (n, N), square Phi_q."""
    return solve(_decomposed(p).backward, k.vals, rhs, k.inverses)[:-1]


def frame_load(p: Prepared, vals: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """-Phi_q0^T lambda (N, 3): the load on the frame (Fx, Fy, moment about O)."""
    out = np.empty((lam.shape[1], 3))
    for col, (slots, rows) in enumerate(p.frame_slots):
        out[:, col] = -np.einsum("kn,kn->n", vals[slots], lam[rows]) if len(slots) else 0.0
    return out
