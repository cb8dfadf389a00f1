"""The loops of a mechanism as an engineer names them: the blocks of its constraint equations,
and the RRR dyads among them.

The constraint Jacobian of the prescribed motion (joints and drivers) is put in block-triangular
form (:mod:`balpipe.engine.structure`: a maximum matching, then the strongly connected
components, each block after those it needs). A block is solved once the blocks before it are:
its bodies' poses follow from bodies already placed. A block of two bodies closed by three
revolute joints is an RRR dyad: body i pinned at E_i to a placed body, body j pinned at E_j,
the two pinned to each other at the middle joint M. It closes only when
|l_i - l_j| <= |E_i E_j| <= l_i + l_j (l_i = |E_i M| on body i), and its transmission angle
(the angle at M between M E_i and M E_j, folded into [0, 90] deg) is zero at a dead centre,
where the dyad is stretched or folded and its motion is no longer determined by its ends.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..engine import Compiled, jacobian
from ..engine.constraints import with_frame
from ..engine.structure import maximum_matching, strong_components
from ..mechanics.planar import world_point
from ..model import FRAME, Model, Revolute


@dataclass(frozen=True)
class Dyad:
    """Bodies ``i`` and ``j`` joined at ``middle``; ``end_i`` pins i to a placed body (``ends``
    give the joint names). Lengths are the distances on each body from its end joint to the
    middle joint."""

    body_i: str
    body_j: str
    end_i: Revolute
    end_j: Revolute
    middle: Revolute
    length_i: float
    length_j: float

    @property
    def name(self) -> str:
        return f"{self.body_i}-{self.body_j}"

    @property
    def joints(self) -> str:
        return f"{self.end_i.name}, {self.middle.name}, {self.end_j.name}"


@dataclass(frozen=True)
class Block:
    """One block of the constraint equations: its rows' owners (joints, drivers) and bodies."""

    owners: tuple[str, ...]
    bodies: tuple[str, ...]
    rows: tuple[int, ...]
    cols: tuple[int, ...]  # the free coordinates it solves for (3 k + 0, 1, 2 for body k)
    dyad: Dyad | None


def _local(jt: Revolute, body: str) -> tuple[float, float]:
    return jt.point_a if jt.a == body else jt.point_b


def _other(jt: Revolute, body: str) -> str:
    return jt.b if jt.a == body else jt.a


def blocks(c: Compiled, q: np.ndarray) -> list[Block]:
    """The blocks of ``c``'s constraint equations in solving order, from the Jacobian's pattern
    near positions ``q`` (3 nb,) (a fixed small perturbation keeps coincidental zeros out)."""
    rng = np.random.default_rng(0)
    qp = q + 1e-3 * rng.standard_normal(q.shape)
    J = jacobian(c, with_frame(qp[None, :]))[0, :, 3:]
    m, n = J.shape
    if m != n:
        return []
    adj = [list(np.flatnonzero(np.abs(J[r]) > 1e-14)) for r in range(m)]
    match = maximum_matching(adj, n)
    if -1 in match:
        return []
    row_of_col = [0] * n
    for r, col in enumerate(match):
        row_of_col[col] = r
    out = []
    model = c.model
    for rows in strong_components([[row_of_col[col] for col in a] for a in adj]):
        owners = tuple(dict.fromkeys(c.row_owner[r] for r in rows))
        bodies = tuple(dict.fromkeys(c.names[match[r] // 3] for r in rows))
        cols = tuple(sorted(int(match[r]) for r in rows))
        out.append(Block(owners, bodies, tuple(rows), cols, _dyad(model, owners, bodies)))
    return out


def _dyad(model: Model, owners: tuple[str, ...], bodies: tuple[str, ...]) -> Dyad | None:
    if len(bodies) != 2 or len(owners) != 3:
        return None
    joints = {j.name: j for j in model.joints}
    if not all(isinstance(joints.get(o), Revolute) for o in owners):
        return None
    bi, bj = bodies
    middle = [joints[o] for o in owners if {joints[o].a, joints[o].b} == {bi, bj}]
    if len(middle) != 1:
        return None
    mid = middle[0]
    ends = [joints[o] for o in owners if joints[o] is not mid]
    end_i = next((e for e in ends if bi in (e.a, e.b)), None)
    end_j = next((e for e in ends if bj in (e.a, e.b) and e is not end_i), None)
    if end_i is None or end_j is None:
        return None
    li = math.dist(_local(end_i, bi), _local(mid, bi))
    lj = math.dist(_local(end_j, bj), _local(mid, bj))
    return Dyad(bi, bj, end_i, end_j, mid, li, lj)


def end_points(model: Model, d: Dyad, frame_pose: dict[str, np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Global positions (N, 2) of the dyad's end joints, on the placed bodies; ``frame_pose``
    maps body names to poses (N, 3) of their frames (the frame itself is implied)."""
    out = []
    for e, b in ((d.end_i, d.body_i), (d.end_j, d.body_j)):
        other = _other(e, b)
        p = np.asarray(_local(e, other), dtype=float)
        if other == FRAME:
            n = len(next(iter(frame_pose.values())))
            out.append(np.broadcast_to(p, (n, 2)).copy())
            continue
        out.append(world_point(frame_pose[other], p))
    return out[0], out[1]


def transmission_angle(d: Dyad, Ei: np.ndarray, Ej: np.ndarray) -> np.ndarray:
    """The angle (rad, in [0, pi/2]) at the middle joint between the two links, from the ends'
    distance by the law of cosines: 0 at a dead centre (stretched or folded), pi/2 at best."""
    dist2 = np.sum((Ei - Ej) ** 2, axis=1)
    li, lj = d.length_i, d.length_j
    cos_mu = np.clip((li * li + lj * lj - dist2) / (2 * li * lj), -1.0, 1.0)
    mu = np.arccos(cos_mu)
    return np.minimum(mu, np.pi - mu)
