"""The assembly branch of a custom spec, chosen on purpose: the branch
of the spec's representative poses, or a located error at the pose that was not confirmed.

Rule: a custom spec's bodies' ``pose`` fields are a representative pose of the mechanism at
t = 0. balpipe assembles it by Newton-Raphson from those poses, with the drivers at their
start values, and keeps the assembly it reaches: for a dyad, the branch (elbow up or down,
the side of the line of its ends) on which the given poses put it. The assembly must
confirm the poses: a body that ends more than :data:`ANGLE_TOLERANCE` away in angle, or more
than :data:`POSITION_TOLERANCE` of the mechanism's size away in position, means the poses were
far from every assembly (or between two branches), and the spec is refused at that body's
``pose``, with the pose that was reached. A loop that cannot close at all is named by
:mod:`balpipe.diagnose.loop_closure`. The branch then stays the same along the motion (the analysis
follows it continuously and refuses a singular configuration, where it could switch).

The check runs when a spec is built or checked (:func:`balpipe.study.run`), not in design
sweeps, whose new geometries start from the base spec's motions instead
(:mod:`balpipe.engine.warmstart`).
"""

from __future__ import annotations

import math

import numpy as np

from . import loop_closure
from ..engine import AnalysisError, compile_model
from ..engine.positions import newton_raphson
from ..model import Model
from ..spec_parts import SpecFieldError

ANGLE_TOLERANCE = math.radians(30.0)
POSITION_TOLERANCE = 0.1  # fraction of the mechanism's size (its largest point distance from a body origin)


def size(model: Model) -> float:
    """A length scale: the largest distance of a body point or frame point from its origin."""
    r = [math.hypot(*p) for b in model.bodies for p in b.points.values()]
    r += [math.hypot(*p) for p in model.frame_points.values()]
    return max([1e-3] + r)


def check(model: Model, t0: float) -> None:
    """Assemble ``model`` at ``t0`` from its initial poses; raise :class:`SpecFieldError` (at the
    loop that cannot close, or at the body whose pose is far from the assembly reached)."""
    c = compile_model(model)
    q, ok, _ = newton_raphson(c, c.q0[None, :], np.array([t0]), max_iter=50)
    if not ok[0]:
        exc = AnalysisError("cannot assemble the mechanism at t = 0", t0)
        exc.q = q[0]
        raise loop_closure.explain(model, c, exc)
    poses = loop_closure.frame_poses(c, q)
    scale = size(model)
    for b in model.bodies:
        x, y, th = (float(v) for v in poses[b.name][0])
        x0, y0, th0 = model.initial[b.name]
        dth = abs(math.remainder(th - th0, 2 * math.pi))
        dpos = math.hypot(x - x0, y - y0)
        if dth > ANGLE_TOLERANCE or dpos > POSITION_TOLERANCE * scale:
            path = model.sources.get(b.name, ("mechanism",)) + ("pose",)
            raise SpecFieldError(
                path,
                f"the pose of {b.name!r} is far from every assembly: assembling the mechanism from the "
                f"given poses puts it at ({x:.6g}, {y:.6g}, {math.degrees(th):.6g} deg), {dpos:.3g} m and "
                f"{math.degrees(dth):.3g} deg away (limits {POSITION_TOLERANCE * scale:.3g} m, "
                f"{math.degrees(ANGLE_TOLERANCE):.3g} deg); give a pose near the assembly you mean "
                "(each dyad assembles on the side its given poses show)",
            )
