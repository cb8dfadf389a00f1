"""Motions of the general (dense) path, shared by every model of one geometry.

The block path (:mod:`.fastpath`) solves a closed loop's motion once per geometry, on the frame
model, and places every model's centres of mass in it. The general path (redundant actuation,
patterns with no block form) does the same here: the balancing stages and mass designs of a
mechanism differ only in their mass properties, so the motion of the bodies' own frames is
solved once by the continuation of :mod:`.positions` (its constraints evaluated by primitive
type, :class:`.positions.DenseOps`' ``by_type``) on the **frame model**
(:func:`.fastpath.frame_model`: every centre of mass at its frame's origin, so that the motion
depends on the geometry alone, not on which model of it came first) and kept by
:func:`.warmstart.motion_key` (joints, drivers by identity, points, initial poses, time grid).
Each model's centres of mass are placed in it and refined by the batched Newton-Raphson of the
continuation (no iteration where the residual is already below its 1e-12): accepted when every
sample converges and no angle moves by the continuation's branch guard; otherwise, or when the
frame model cannot be followed, the continuation runs on the model itself, which raises the
model's own located error. The regularity check (a singular configuration is an error) runs on
the model's own Jacobian either way, unless the frame motion's, screened once, shows it regular
(:func:`_shown_regular`: then it could not fail), so the same specs fail, with the same messages. The
velocities and accelerations of an accepted model are placed too (:func:`kinematics`): the
frames' are solved once per geometry (one factorisation per sample of the frame model's
Jacobian instead of one per model; with redundant drivers its normal equations, :mod:`.normal`,
which the multipliers' solve reuses), and a centre of mass at c in its body's frame moves with
r' = r_f' + w perp(R c), r'' = r_f'' + alpha perp(R c) - w^2 R c, exact kinematics; and so are
their Lagrange multipliers where the model has no gear meshes or named actuators
(:func:`multipliers`: the frame model's solve, the generalised forces moved to the frames' origins).

A model whose centres of mass are at its frames' origins is its own frame model: its positions
are the continuation's, and its rates its own solves, bit for bit. The others' agree with their
own continuation and solves to round-off (a 4-RRR stage's loads to < 1e-12 of their peaks), and
depend only on the geometry and on their own mass properties. Counts of what happened are in
:data:`STATS`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from .compile import Compiled, compile_model
from .errors import AnalysisError
from .fastpath import _arms, _place as place, frame_model
from .constraints import jacobian, with_frame
from .dynamics import multiplier_solver
from .kinematics import _vel_acc, jacobian_by_type, rates_by_type
from .vectorised import State
from .normal import Normal, gram
from .positions import _JUMP, DenseOps, _check_regular, _proven_regular, follow_motion, newton_raphson, solve_positions
from .warmstart import motion_key

STATS = {"shared": 0, "solved": 0, "rejected": 0}
_KEPT = 16


@dataclass
class _Shared:
    """What the models of one geometry and grid share: the frame model ``fc``, its motion
    (None where it cannot be followed), and, made when first needed, its rates and its
    multipliers' solve with the frame's Jacobian columns. ``laws``: the drivers' laws, kept alive
    (their ids are part of the key); ``normal``: the normal equations of the rates' Jacobian
    (redundant drivers, :mod:`.normal`), and ``jacobian``, the rates' whole Jacobian, for the
    multipliers' solve; ``regular``: whether the frame motion's Phi_q is shown regular
    (:func:`_shown_regular`), with ``gram`` (its free columns' J^T J, for the rates) made there.
    ``ops``: the solves that followed the motion (the constraints by primitive type and the
    drivers' table on the grid, :class:`.positions.DenseOps`), for its rates; ``state``: its
    :class:`.vectorised.State` at the frame motion, with ``jacobian``."""

    laws: list
    fc: Compiled
    frame: np.ndarray | None
    ops: DenseOps | None = None
    rates: tuple[np.ndarray, np.ndarray] | None = None
    normal: Normal | None = None
    jacobian: np.ndarray | None = None
    state: State | None = None
    gram: np.ndarray | None = None
    regular: bool | None = None
    dynamics: tuple[Callable[[np.ndarray], np.ndarray], np.ndarray] | None = None


_MOTIONS: dict[tuple, _Shared] = {}  # motion key -> what its models share


def kinematics(c: Compiled, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray, _Shared | None]:
    """Positions, velocities and accelerations (N, 3 nb) of ``c`` along ``t``: the positions of
    :func:`.positions.solve_positions` (``c.condition`` set, or None) with the centres of mass
    placed in the frame motion of its geometry where that motion is accepted (see the module),
    and the rates placed from the frame motion's where the positions were, else solved on
    ``c``'s own Jacobian (:func:`.kinematics._vel_acc`); and the shared entry they were placed
    from (for :func:`multipliers`), or None."""
    q, entry = _positions(c, t)
    if entry is None:
        return (q, *_vel_acc(c, q, t), None)
    frame = _motion(entry)
    if entry.rates is None:  # once per geometry and grid
        at = _frame_jacobian(entry) if entry.state is None or entry.jacobian is None else (entry.state, entry.jacobian)
        ops = entry.ops
        assert ops is not None and ops.vectorised is not None  # the entry's motion was followed by type
        v, a, solver = rates_by_type(ops.vectorised, frame, ops.table(t), at, entry.gram)
        entry.rates, entry.normal, entry.jacobian, entry.gram, entry.state = (v, a), solver.normal, at[1], None, None
    return (q, *_place_rates(frame, *entry.rates, c.com_local), entry)


def _motion(entry: _Shared) -> np.ndarray:
    """The frame motion of an entry that positions were placed from (:func:`_positions` returns
    only those whose motion was followed)."""
    if entry.frame is None:
        raise RuntimeError("a shared entry without its frame motion placed a model's positions")
    return entry.frame


def multipliers(c: Compiled, entry: _Shared | None, rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray] | None:
    """The multipliers (N, m) of Phi_q^T lambda = ``rhs`` for a model placed in the frame motion
    of ``entry`` (:func:`kinematics`), and the frame's columns J0 (N, m, 3) of Phi_q, from the
    frame model's solve (:func:`.dynamics.multiplier_solver`, made once per geometry and grid): the
    model's Jacobian is the frame model's times T^-1 (a centre of mass at R c from its frame's
    origin: dr = dr_f + dphi perp(R c)), so Phi_q^T lambda = rhs is J_f^T lambda = T^T rhs, the
    generalised forces moved to the frames' origins (the moment gains r x F). None where the
    model has gear meshes or named actuators (their own rows and tooth forces), or no entry."""
    if entry is None or c.meshes or c.dynamics is not None:
        return None
    fc = entry.fc
    if fc.meshes or fc.dynamics is not None or fc.row_owner != c.row_owner or fc.driver_rows != c.driver_rows:
        return None
    if entry.dynamics is None:
        J = entry.jacobian if entry.jacobian is not None else jacobian(fc, with_frame(_motion(entry)))
        entry.dynamics = (multiplier_solver(fc, J[:, :, 3:], entry.normal), J[:, :, :3])  # once per geometry and grid
        entry.normal = entry.jacobian = None
    solve, J0 = entry.dynamics
    rx, ry = _arms(_motion(entry), c.com_local)
    moved = rhs.copy()
    moved[:, 2::3] += rx * rhs[:, 1::3] - ry * rhs[:, 0::3]
    return solve(moved), J0


def _positions(c: Compiled, t: np.ndarray) -> tuple[np.ndarray, _Shared | None]:
    """:func:`kinematics`' positions and the shared entry they were placed from (None: solved on
    ``c``)."""
    if not np.any(c.com_local):
        return solve_positions(c, t), None  # its own frame model: the continuation itself
    entry = _frame_entry(c, t)
    if entry.frame is not None:
        q = _from_shared(c, t, entry.frame)
        if q is not None:
            STATS["shared"] += 1
            c.condition = None if _shown_regular(c, entry, q) else _check_regular(c, q, t, screen=True)
            return q, entry
        STATS["rejected"] += 1
    return solve_positions(c, t), None


#: the largest cond(T)^2 (:func:`_shown_regular`) for which the frame motion's proof is taken
_TRANSFER = 10.0
#: the largest move of the refined positions from the placed ones (relative) for which it is taken
_PLACED = 1e-9


def _shown_regular(c: Compiled, entry: _Shared, q: np.ndarray) -> bool:
    """Whether ``c``'s Phi_q along its positions ``q``, placed in ``entry``'s frame motion, is
    shown regular by the frame motion's (made once per geometry and grid), instead of screening
    ``c``'s own (:func:`.positions._check_regular`, what it does otherwise).

    The model's Jacobian is the frame model's times T^-1 (:func:`multipliers`), T block
    diagonal with, per body, [[1, 0, -r_y], [0, 1, r_x], [0, 0, 1]], r = R c its centre of mass
    from its frame's origin: singular values 1, s and 1/s, s = (|c| + sqrt(|c|^2 + 4)) / 2. So
    cond(Phi_q) <= cond(Phi_q of the frame) s_max^2 at the placed positions, and where the frame
    motion's is shown below 1.1e5 (:func:`.positions._proven_regular`) and s_max^2 <=
    :data:`_TRANSFER`, the model's is below 1.1e6, far below the singular limit 1e11; ``q`` (the
    placed positions refined by Newton-Raphson, :func:`_from_shared`) must be within
    :data:`_PLACED` of them (Phi_q moves by as little: Weyl's inequality). No configuration of
    the motion is then singular, as the model's own screen would show, and its condition numbers
    are computed when read (``c.condition`` None), the same values."""
    rho = float(np.hypot(c.com_local[:, 0], c.com_local[:, 1]).max(initial=0.0))
    if ((rho + np.sqrt(rho * rho + 4.0)) / 2.0) ** 2 > _TRANSFER:
        return False
    placed = place(_motion(entry), c.com_local)
    if not np.abs(q - placed).max(initial=0.0) <= _PLACED * max(1.0, float(np.abs(placed).max(initial=0.0))):
        return False
    if entry.regular is None:
        s, J = _frame_jacobian(entry)
        G = gram(J[:, :, 3:])
        if entry.rates is None:
            entry.state, entry.jacobian, entry.gram = s, J, G  # for the rates and the multipliers
        entry.regular = _proven_regular(J[:, :, 3:], G)
    return entry.regular


def _frame_jacobian(entry: _Shared) -> tuple[State, np.ndarray]:
    """The state and whole Phi_q of the frame model at the frame motion, by primitive type."""
    ops = entry.ops
    assert ops is not None and ops.vectorised is not None
    return jacobian_by_type(ops.vectorised, _motion(entry))


def _frame_entry(c: Compiled, t: np.ndarray) -> _Shared:
    key = motion_key(c, t)
    hit = _MOTIONS.get(key)
    if hit is not None:
        return hit
    if c.frame is None:
        c.frame = compile_model(frame_model(c.model))
    fc = c.frame
    ops = DenseOps(fc, t, by_type=True)
    try:
        frame = follow_motion(fc, t, ops)
        STATS["solved"] += 1
    except (AnalysisError, np.linalg.LinAlgError):
        frame = None
    if len(_MOTIONS) >= _KEPT:
        _MOTIONS.clear()
    entry = _MOTIONS[key] = _Shared([d.law for d in c.model.drivers], fc, frame, ops)
    return entry


def _place_rates(frame: np.ndarray, vf: np.ndarray, af: np.ndarray, com: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Velocities and accelerations (N, 3 nb) of the points at ``com`` (nb, 2) of bodies whose
    frames move with ``frame``, ``vf``, ``af``: r' = r_f' + w perp(R c),
    r'' = r_f'' + alpha perp(R c) - w^2 R c; the angles' rates are the frames'."""
    w, al = vf[:, 2::3], af[:, 2::3]
    rx, ry = _arms(frame, com)
    v, a = vf.copy(), af.copy()
    w2 = w * w
    v[:, 0::3] -= w * ry
    v[:, 1::3] += w * rx
    a[:, 0::3] -= al * ry + w2 * rx
    a[:, 1::3] += al * rx - w2 * ry
    return v, a


def clear() -> None:
    """Forget the frame motions (:func:`.analysis.clear_cache`)."""
    _MOTIONS.clear()


def _from_shared(c: Compiled, t: np.ndarray, frame: np.ndarray) -> np.ndarray | None:
    """``c``'s positions refined from the shared frame motion, or None (rejected)."""
    guess = place(frame, c.com_local)
    q, ok, _ = newton_raphson(c, guess, t)
    if not ok.all() or not np.all(np.isfinite(q)):
        return None
    if np.abs(q[:, 2::3] - guess[:, 2::3]).max(initial=0.0) > _JUMP:
        return None
    return q
