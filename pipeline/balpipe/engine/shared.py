"""Motions of the general (dense) path, shared by every model of one geometry.

The block path (:mod:`.fastpath`) solves a closed loop's motion once per geometry, on the frame
model, and places every model's centres of mass in it. The general path (redundant actuation,
patterns with no block form) does the same here: the balancing stages and mass designs of a
mechanism differ only in their mass properties, so the motion of the bodies' own frames is
solved once by the continuation of :mod:`.positions` on the **frame model**
(:func:`.fastpath.frame_model`: every centre of mass at its frame's origin, so that the motion
depends on the geometry alone, not on which model of it came first) and kept by
:func:`.warmstart.motion_key` (joints, drivers by identity, points, initial poses, time grid).
Each model's centres of mass are placed in it and refined by the batched Newton-Raphson of the
continuation (no iteration where the residual is already below its 1e-12): accepted when every
sample converges and no angle moves by the continuation's branch guard; otherwise, or when the
frame model cannot be followed, the continuation runs on the model itself, which raises the
model's own located error. The regularity check (a singular configuration is an error) runs on
the model's own Jacobian either way, so the same specs fail, with the same messages.

A model whose centres of mass are at its frames' origins is its own frame model: its positions
are the continuation's, bit for bit. The others' agree with their own continuation to the Newton
tolerance (the position solve of a 4-RRR stage moved its results by < 1e-12 relative), and
depend only on the geometry and on their own mass properties. Counts of what happened are in
:data:`STATS`.
"""

from __future__ import annotations

import numpy as np

from .compile import Compiled, compile_model
from .errors import AnalysisError
from .fastpath import _place as place, frame_model
from .positions import _JUMP, DenseOps, _check_regular, follow_motion, newton_raphson, solve_positions
from .warmstart import motion_key

STATS = {"shared": 0, "solved": 0, "rejected": 0}
_MOTIONS: dict[tuple, tuple[list, np.ndarray | None]] = {}  # motion key -> (laws kept alive, frame motion or None)
_KEPT = 16


def positions(c: Compiled, t: np.ndarray) -> np.ndarray:
    """:func:`.positions.solve_positions` of ``c`` along ``t`` (``c.condition`` set, or None), its centres
    of mass placed in the frame motion of its geometry (see the module)."""
    if not np.any(c.com_local):
        return solve_positions(c, t)  # its own frame model: the continuation itself
    frame = frame_motion(c, t)
    if frame is not None:
        q = _from_shared(c, t, frame)
        if q is not None:
            STATS["shared"] += 1
            c.condition = _check_regular(c, q, t, screen=True)
            return q
        STATS["rejected"] += 1
    return solve_positions(c, t)


def frame_motion(c: Compiled, t: np.ndarray) -> np.ndarray | None:
    """The motion (N, 3 nb) of ``c``'s bodies' frames along ``t`` by the continuation on its frame
    model, solved once per :func:`.warmstart.motion_key`; None where the frame model cannot be
    followed (the caller's continuation then reports the model's own error)."""
    key = motion_key(c, t)
    hit = _MOTIONS.get(key)
    if hit is not None:
        return hit[1]
    if c.frame is None:
        c.frame = compile_model(frame_model(c.model))
    fc = c.frame
    try:
        frame = follow_motion(fc, t, DenseOps(fc))
        STATS["solved"] += 1
    except (AnalysisError, np.linalg.LinAlgError):
        frame = None
    if len(_MOTIONS) >= _KEPT:
        _MOTIONS.clear()
    _MOTIONS[key] = ([d.law for d in c.model.drivers], frame)  # the laws kept alive: their ids key
    return frame


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
