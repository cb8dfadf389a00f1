"""Warm start across geometry: a closed loop of a new geometry (a sweep's next design: other
lengths, offsets, poses or duration; the same joints, drivers, point names and number of time
samples) is solved by
Newton-Raphson on all samples at once from the motion of an **anchor**, instead of the sequential
continuation of :func:`.positions.follow_motion`.

Anchors are fixed in advance, so a design's numbers depend only on the anchors and on the design,
never on which designs ran before in the process (a sweep gives the same table for any chunking,
order or number of workers; a build never warm-starts):

* ``with record() as anchors:`` keeps the frame motion of every closed loop the engine solves or
  reuses inside the block (a sweep: its base spec's stages);
* ``with warm_start(anchors):`` a closed loop whose motion is not known starts from the anchor of
  the same structure nearest in its numbers (the max-norm of the differences of its lengths,
  offsets and poses; ties go to the first recorded), and is accepted only on the branch of its own
  initial pose (:func:`start`); otherwise, or with no anchor of its structure, the continuation
  runs, as outside the block.

Motions are frame motions, solved on the model with every centre of mass at its body's frame
origin (:func:`balpipe.engine.fastpath.frame_model`), so that they depend on the geometry alone.
Counts of what happened are in :data:`STATS`.
"""

from __future__ import annotations

import contextlib
import dataclasses
from collections.abc import Iterator
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from .compile import Compiled
from .positions import _JUMP, _TOL
from .newton_blocks import BlockOps, polish
from .structure import Decomposition
from .vectorised import Vectorised

STATS = {"reused": 0, "warm": 0, "warm_rejected": 0, "continuation": 0}
_MAX_ITER = 50  # the assembly's iteration limit (:func:`.positions.follow_motion`)
_SAME_POSE = 1e-8  # the first sample against the assembled initial pose (relative)
_STEP_CHANGE = 0.5  # a step's angle change against the anchor's, in the anchor's largest step
_SOLVED = 64  # warm-started motions kept per block (the design's other stages reuse them)


@dataclass
class Anchors:
    """Frame motions (N, 3 nb) of closed loops by structure key (:func:`structure_key`), each
    with its numbers, in the order recorded. Picklable (a sweep ships them to its workers); the
    motions warm-started from them in a process are kept in ``solved`` (not pickled)."""

    designs: dict[tuple, list[tuple[np.ndarray, np.ndarray]]] = field(default_factory=dict)
    solved: dict[tuple, tuple[list, np.ndarray]] = field(default_factory=dict, repr=False)  # and the laws, kept alive

    def __len__(self) -> int:
        return sum(len(v) for v in self.designs.values())

    def __getstate__(self) -> dict:
        return {"designs": self.designs, "solved": {}}

    def add(self, c: Compiled, t: np.ndarray, frame: np.ndarray) -> None:
        skey, numbers = structure_key(c, t)
        designs = self.designs.setdefault(skey, [])
        if not any(np.array_equal(n, numbers) for n, _ in designs):
            designs.append((numbers, frame))


_RECORDING: list[Anchors] = []
_ACTIVE: list[Anchors] = []


@contextlib.contextmanager
def record(into: Anchors | None = None) -> Iterator[Anchors]:
    """Within this block every closed-loop frame motion the engine solves or reuses becomes an
    anchor of the :class:`Anchors` yielded (``into``, or new ones)."""
    anchors = Anchors() if into is None else into
    _RECORDING.append(anchors)
    try:
        yield anchors
    finally:
        _RECORDING.remove(anchors)


@contextlib.contextmanager
def warm_start(anchors: Anchors | None) -> Iterator[None]:
    """Within this block a closed loop of a new geometry starts from ``anchors`` (None: no warm
    start, the block does nothing)."""
    if anchors is None:
        yield
        return
    _ACTIVE.append(anchors)
    try:
        yield
    finally:
        _ACTIVE.pop()


def note(c: Compiled, t: np.ndarray, frame: np.ndarray) -> None:
    """A closed loop's frame motion was solved or reused: record it where asked."""
    for anchors in _RECORDING:
        anchors.add(c, t, frame)


def solved(key: tuple) -> np.ndarray | None:
    """A motion warm-started before from the active anchors, by exact motion key."""
    hit = _ACTIVE[-1].solved.get(key) if _ACTIVE else None
    return None if hit is None else hit[1]


def structure_key(c: Compiled, t: np.ndarray) -> tuple[tuple, np.ndarray]:
    """What must agree for a warm start: the names and types of the joints, the drivers (their
    laws by type), the bodies' named points and initial poses; and the numbers (lengths,
    offsets, poses) apart, to pick the nearest anchor. Of the time grid only
    the number of samples: a design with another duration starts from the anchor's motion sample
    by sample (the same positions when only the duration differs)."""
    shape, numbers, _ = model_keys(c)
    return (shape, len(t)), numbers


def motion_key(c: Compiled, t: np.ndarray) -> tuple:
    """Everything the motion of the bodies' own frames depends on: the joints, the drivers (their
    laws by identity: the caller keeps them alive), the bodies' named points, the initial poses
    (the branch) and the time grid, numbers exactly; not the mass properties, which move only
    the centres of mass within the bodies (a balancing stage, a mass design)."""
    shape, numbers, laws = model_keys(c)
    return shape, numbers.tobytes(), laws, t.tobytes()


def model_keys(c: Compiled) -> tuple[tuple, np.ndarray, tuple]:
    """(shape, numbers, law identities) of ``c``'s model, made once per compiled model."""
    if c.keys is None:
        m = c.model
        numbers: list[float] = []
        joints = tuple((type(j).__name__, *(_shape(getattr(j, f.name), numbers) for f in dataclasses.fields(j)))
                       for j in m.joints)
        drivers = tuple((d.name, _shape(d.target, numbers), type(d.law).__name__) for d in m.drivers)
        bodies = tuple((b.name, _shape(sorted(b.points.items()), numbers)) for b in m.bodies)
        initial = _shape(sorted(m.initial.items()), numbers)
        c.keys = ((joints, drivers, bodies, initial), np.array(numbers, dtype=float),
                  tuple(id(d.law) for d in m.drivers))
    return c.keys


def _shape(v: Any, numbers: list[float]) -> Any:
    """Nested tuples, lists and arrays with every number replaced by "#" (appended to ``numbers``)."""
    if isinstance(v, (str, type(None))):
        return v
    if isinstance(v, (tuple, list, np.ndarray)):
        return tuple(_shape(x, numbers) for x in v)
    numbers.append(float(v))
    return "#"


def start(c: Compiled, vz: Vectorised, dec: Decomposition, t: np.ndarray, f: np.ndarray,
          key: tuple) -> np.ndarray | None:
    """The frame motion (N, 3 nb) of the frame model ``c`` warm-started from the nearest active
    anchor, or None (no anchor block, no anchor of this structure, or rejected: take the
    continuation).

    Newton-Raphson by blocks (:func:`newton`) runs on all samples at once from the anchor's
    motion, together with one more column: the model's initial pose at the first time, which
    Newton's method assembles as the continuation starts. Accepted only when every column
    converges and the motion is on the branch of the design's own
    initial pose: its first sample is that assembled pose (to 1e-8), no angle is more than 0.2 rad
    from the anchor's (the continuation's branch guard, :data:`.positions._JUMP`), and no step
    between samples changes its angles by more than half the anchor's largest step."""
    if not _ACTIVE:
        return None
    anchors = _ACTIVE[-1]
    skey, numbers = structure_key(c, t)
    candidates = anchors.designs.get(skey)
    if not candidates:
        return None
    anchor = min(candidates, key=lambda d: float(np.abs(d[0] - numbers).max()))[1]
    guess = np.concatenate([c.q0[None, :], anchor])
    q = newton(c, vz, dec, guess, np.concatenate([t[:1], t]), np.concatenate([f[:, :1], f], axis=1))
    if q is None or not _same_branch(q[0], q[1:], anchor):
        STATS["warm_rejected"] += 1
        return None
    STATS["warm"] += 1
    if len(anchors.solved) >= _SOLVED:
        anchors.solved.clear()
    frame = q[1:]
    anchors.solved[key] = ([d.law for d in c.model.drivers], frame)
    return frame


def newton(c: Compiled, vz: Vectorised, dec: Decomposition, q: np.ndarray, t: np.ndarray,
           f: np.ndarray) -> np.ndarray | None:
    """Newton-Raphson by blocks on all columns of ``q`` (N, 3 nb) at times ``t`` (law values
    ``f``) at once, as the continuation's batched refinement (:class:`.newton_blocks.BlockOps`),
    then its polishing step to ~1e-16 (:func:`.newton_blocks.polish`); None when a column does not
    converge to 1e-12."""
    with np.errstate(all="ignore"):
        q, _, norms = BlockOps(c, vz, dec, t).newton(q, t, max_iter=_MAX_ITER)
    if not (np.all(norms < _TOL) and np.all(np.isfinite(q))):
        return None
    return polish(vz, dec, q, f)


def _same_branch(assembled: np.ndarray, q: np.ndarray, anchor: np.ndarray) -> bool:
    """The guard of :func:`start`."""
    if np.abs(q[0] - assembled).max() > _SAME_POSE * max(1.0, float(np.abs(assembled).max())):
        return False
    th, th0 = q[:, 2::3], anchor[:, 2::3]
    if np.abs(th - th0).max() > _JUMP:
        return False
    if len(q) > 1:
        step, step0 = np.diff(th, axis=0), np.diff(th0, axis=0)
        if np.abs(step - step0).max() > _STEP_CHANGE * float(np.abs(step0).max()):
            return False
    return True
