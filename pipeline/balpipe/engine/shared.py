"""Motions shared on the general (dense) path, for ``balpipe check`` only.

The block path (:mod:`.fastpath`) already solves a closed loop's motion once per geometry and
places every model's centres of mass in it. The general path (redundant actuation, patterns with
no block form) solves each model by the continuation of :mod:`.positions`, although the
balancing stages and mass designs of a mechanism differ only in their mass properties. Within
:func:`shared_motions`, a model whose joints, drivers (their laws by identity), points, initial
poses and time grid are those of a model solved before in the block
(:func:`.warmstart.motion_key`) starts from that motion, its centres of mass placed in the
bodies' frames, and is refined by the batched Newton-Raphson of the continuation (no iteration
where the residual is already below its 1e-12): accepted only when every sample converges and
no angle moves by the continuation's branch guard; otherwise the continuation runs, as outside
the block. The regularity check (a singular configuration is an error) runs on the model's own
Jacobian either way, so the same specs fail, with the same messages.

The positions reached this way agree with the continuation's to the Newton tolerance, not to
the last bit: :func:`balpipe.study.run` opens the block only without ``page`` (``balpipe
check``, which writes no numbers); ``balpipe build`` never shares and its output is unchanged.
Counts of what happened are in :data:`STATS`.
"""

from __future__ import annotations

import contextlib
from collections.abc import Iterator

import numpy as np

from .compile import Compiled
from .fastpath import _place as place
from .positions import _JUMP, _check_regular, newton_raphson, solve_positions
from .warmstart import motion_key

STATS = {"shared": 0, "solved": 0, "rejected": 0}
_ACTIVE: list[dict] = []


@contextlib.contextmanager
def shared_motions() -> Iterator[None]:
    """Within this block the general path's models of one geometry share its motion (see the
    module); the motions are forgotten when it ends."""
    store: dict = {}
    _ACTIVE.append(store)
    try:
        yield
    finally:
        _ACTIVE.remove(store)


def positions(c: Compiled, t: np.ndarray) -> np.ndarray:
    """:func:`.positions.solve_positions` of ``c`` along ``t`` (``c.condition`` set), from a
    shared motion within :func:`shared_motions`."""
    if not _ACTIVE:
        return solve_positions(c, t)
    store = _ACTIVE[-1]
    key = motion_key(c, t)
    hit = store.get(key)
    if hit is not None:
        q = _from_shared(c, t, hit[1])
        if q is not None:
            STATS["shared"] += 1
            c.condition = _check_regular(c, q, t)
            return q
        STATS["rejected"] += 1
    q = solve_positions(c, t)
    STATS["solved"] += 1
    store[key] = ([d.law for d in c.model.drivers], place(q, -c.com_local))  # the laws kept alive: their ids key
    return q


def _from_shared(c: Compiled, t: np.ndarray, frame: np.ndarray) -> np.ndarray | None:
    """``c``'s positions refined from the shared frame motion, or None (rejected)."""
    guess = place(frame, c.com_local)
    q, ok, _ = newton_raphson(c, guess, t)
    if not ok.all() or not np.all(np.isfinite(q)):
        return None
    if np.abs(q[:, 2::3] - guess[:, 2::3]).max(initial=0.0) > _JUMP:
        return None
    return q

