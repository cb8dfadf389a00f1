"""A loop that cannot close, named as an engineer would: its joints and
bodies, and for an RRR dyad the length a link would need and the field that sets it.

When the position analysis fails (at assembly or on the way), the configuration where it
stopped is split into the blocks of its constraint equations (:mod:`balpipe.diagnose.dyads`); the first
block that is not closed is the loop to blame. An RRR dyad is diagnosed from its lengths: its
two ends are d apart, its links l_i and l_j long, and it closes only when
|l_i - l_j| <= d <= l_i + l_j; the message gives the length each link would need and the one it
has, and the error points at the field that sets that length (a custom body's point, or a
template's ``length``). Another loop is named by its joints and bodies.
"""

from __future__ import annotations

import math

import numpy as np

from . import dyads
from ..engine import AnalysisError, Compiled, compile_model, jacobian, residual
from ..engine.constraints import with_frame
from ..engine.positions import follow_motion
from ..model import Model
from ..spec_parts import SpecFieldError

CLOSED = 1e-9  # residual (m or rad) below which a block counts as closed


def frame_poses(c: Compiled, q: np.ndarray) -> dict[str, np.ndarray]:
    """Poses (N, 3) of each body's own frame from centre-of-mass coordinates q (N, 3 nb)."""
    qb = q.reshape(q.shape[0], -1, 3)
    out = {}
    for k, name in enumerate(c.names):
        th = qb[:, k, 2]
        cx, cy = c.com_local[k]
        x = qb[:, k, 0] - (np.cos(th) * cx - np.sin(th) * cy)
        y = qb[:, k, 1] - (np.sin(th) * cx + np.cos(th) * cy)
        out[name] = np.stack([x, y, th], axis=1)
    return out


def _length_field(model: Model, body: str, d: dyads.Dyad) -> tuple:
    """The spec field that sets ``body``'s length in the dyad: its named point at the middle
    joint (custom), else the middle joint's point on it, else the body's own entry."""
    src = model.sources.get(body)
    local = d.middle.point_a if d.middle.a == body else d.middle.point_b
    if src is not None:
        for name, p in model.body(body).points.items():
            if math.dist(p, local) < 1e-12:
                return src + ("points", name)
        return src
    jsrc = model.sources.get(d.middle.name)
    if jsrc is not None:
        return jsrc + ("point_a" if d.middle.a == body else "point_b",)
    return model.sources.get("", ("mechanism",))


def _dyad_message(model: Model, d: dyads.Dyad, dist: float, t: float) -> tuple[tuple, str] | None:
    li, lj = d.length_i, d.length_j
    head = (f"the loop through joints {d.joints} cannot be closed at t = {t:.6g} s: the dyad {d.body_i}-{d.body_j} "
            f"must span {dist:.6g} m between joints {d.end_i.name} and {d.end_j.name}, but {d.body_i} "
            f"({d.end_i.name} to {d.middle.name}) is {li:.6g} m long and {d.body_j} ({d.end_j.name} to "
            f"{d.middle.name}) {lj:.6g} m")
    if dist > li + lj:
        need = {d.body_i: dist - lj, d.body_j: dist - li}
        text = (f"{head}, {li + lj:.6g} m together: {d.body_i} needs at least {need[d.body_i]:.6g} m "
                f"(has {li:.6g} m), or {d.body_j} at least {need[d.body_j]:.6g} m (has {lj:.6g} m)")
        have = {d.body_i: li, d.body_j: lj}
    elif dist < abs(li - lj):
        long_, short = (d.body_i, d.body_j) if li > lj else (d.body_j, d.body_i)
        ll, ls = max(li, lj), min(li, lj)
        need = {long_: dist + ls, short: ll - dist}
        text = (f"{head}, differing by {ll - ls:.6g} m: {long_} needs at most {need[long_]:.6g} m "
                f"(has {ll:.6g} m), or {short} at least {need[short]:.6g} m (has {ls:.6g} m)")
        have = {long_: ll, short: ls}
    else:
        return None
    zero = [b for b in have if have[b] <= 0.0]
    if zero:  # a link of zero length (its two joints at one point): that is the one to fix
        blame = zero[0]
        end = d.end_i.name if blame == d.body_i else d.end_j.name
        return _length_field(model, blame, d), (f"{text}; {blame} has zero length: its joints {end} and "
                                                f"{d.middle.name} are at one point, give them distinct points")
    blame = min(need, key=lambda b: abs(math.log(need[b] / have[b])) if need[b] > 0 else math.inf)
    return _length_field(model, blame, d), text


def diagnose(model: Model, t: np.ndarray) -> SpecFieldError | None:
    """Follow ``model``'s motion on ``t``; where its position analysis stops, the located error
    that names the loop (None when the motion can be followed)."""
    c = compile_model(model)
    try:
        follow_motion(c, t)
        return None
    except AnalysisError as exc:
        return explain(model, c, exc)


def _close_block(c: Compiled, q: np.ndarray, t: float, b: dyads.Block, iterations: int = 50) -> float:
    """Newton-Raphson (least squares) on one block's rows over its own coordinates, the blocks
    before it held fixed (in place in ``q``); returns the block's remaining residual."""
    rows, cols = list(b.rows), list(b.cols)
    tt = np.array([t])
    for _ in range(iterations):
        phi = residual(c, with_frame(q[None, :]), tt)[0, rows]
        if np.max(np.abs(phi)) <= 1e-13:
            break
        J = jacobian(c, with_frame(q[None, :]))[0][np.ix_(rows, [k + 3 for k in cols])]
        q[cols] += np.linalg.lstsq(J, -phi, rcond=None)[0]
    return float(np.max(np.abs(residual(c, with_frame(q[None, :]), tt)[0, rows])))


def explain(model: Model, c: Compiled, exc: AnalysisError) -> SpecFieldError:
    """The located error for a failed position analysis of ``model`` (``exc.q``: where it stopped)."""
    where = ("motion",)
    if exc.q is None:
        return SpecFieldError(where, str(exc))
    q = np.asarray(exc.q, dtype=float).copy()
    tf = float(exc.time or 0.0)
    for b in dyads.blocks(c, q):
        phi = _close_block(c, q, tf, b)
        if phi <= CLOSED:
            continue
        poses = frame_poses(c, q[None, :])
        if b.dyad is not None:
            Ei, Ej = dyads.end_points(model, b.dyad, poses)
            found = _dyad_message(model, b.dyad, float(np.hypot(*(Ei[0] - Ej[0]))), tf)
            if found is not None:
                return SpecFieldError(*found)
        joints = [o for o in b.owners if o in {j.name for j in model.joints}]
        first = next((model.sources[o] for o in joints if o in model.sources), where)
        return SpecFieldError(
            first, f"the loop through joints {', '.join(joints) or ', '.join(b.owners)} (bodies "
            f"{', '.join(b.bodies)}) cannot be closed at t = {tf:.6g} s (residual {phi:.3g}): "
            "its links are too short or too long for the positions the motion prescribes")
    return SpecFieldError(where, str(exc))


def located(model: Model, t: np.ndarray, exc: AnalysisError, stage: str | None = None) -> SpecFieldError:
    """The spec error for an analysis of ``model`` (or of a stage built from it) that failed:
    a loop that cannot close (:func:`diagnose`), actuators that cannot produce the motion (at
    ``mechanism.actuators``), else the engine's message at ``motion``."""
    found = diagnose(model, t)
    if found is not None:
        return found
    prefix = f"stage {stage!r}: " if stage else ""
    if model.actuators and str(exc).startswith("not realisable"):
        return SpecFieldError(("mechanism", "actuators"), prefix + str(exc))
    return SpecFieldError(("motion",), prefix + str(exc))
