"""A prismatic pair between two moving links drawn as one connected leg.

A model describes a sliding pair (:class:`balpipe.model.Prismatic`) by its two bodies, each
with its own outline: the guide (e.g. a hydraulic cylinder, pivoted at its base) and the slider
(the piston and its rod, pinned at the other end). Their outlines are only the link points the
spec names, and a spec's links are mass models that may be shorter than the stroke (paper 000's
3-RPR: pistons of 0.05 m, cylinders of 0.1 m, legs from 0.10 to 0.44 m), so at a long extension
the piston's outline leaves the cylinder's and the leg looks broken. The drawing therefore adds
the guide's sleeve along the pair's axis: at each drawn pose, the interval of the axis (guide
frame)

    [min(g0, s1), max(g1, s0)],

[g0, g1] the guide's outline and [s0, s1] the slider's, projected on the axis: the guide's own
extent, stretched to the slider's nearer end where the two would not meet. The slider's outline
is drawn as its rod over it, so rod and sleeve always touch. A pair whose guide is the frame
keeps its block on the frame's guide line (not a sleeve).
"""

from __future__ import annotations

import math

import numpy as np

from ..mechanics.planar import world_point
from ..model import Model, Prismatic


def _local_points(body) -> list[tuple[float, float]]:
    names = body.outline if len(body.outline) >= 2 else tuple(body.points)
    return [tuple(body.points[n]) for n in names] or [(0.0, 0.0)]


def _to_local(pose, q: np.ndarray) -> np.ndarray:
    x, y, th = pose
    c, s = math.cos(th), math.sin(th)
    dx, dy = q[0] - x, q[1] - y
    return np.array([c * dx + s * dy, -s * dx + c * dy])


def pairs(model: Model) -> list[tuple[int, int, Prismatic]]:
    """(guide index, slider index, joint) of every prismatic pair between two moving bodies."""
    index = {b.name: i for i, b in enumerate(model.bodies)}
    return [(index[j.guide], index[j.slider], j) for j in model.joints
            if isinstance(j, Prismatic) and j.guide in index and j.slider in index]


def guided_sliders(model: Model) -> set[str]:
    """Names of the bodies that slide in a moving guide (drawn as a rod in a sleeve, not as a block)."""
    return {model.bodies[s].name for _, s, _ in pairs(model)}


def sleeves(model: Model, pose_row: np.ndarray) -> list[tuple[np.ndarray, np.ndarray]]:
    """The sleeve of every prismatic pair between two moving bodies at one pose (module
    docstring), as its two ends in global coordinates, in the order the model lists its joints;
    ``pose_row`` (bodies, 3) one row of ``analysis.frame_pose``."""
    out = []
    for g, s, j in pairs(model):
        u = np.array(j.axis, dtype=float) / math.hypot(*j.axis)
        o = np.array(j.point_guide, dtype=float)
        own = [float(np.dot(np.array(p) - o, u)) for p in _local_points(model.bodies[g])]
        rod = [float(np.dot(_to_local(pose_row[g], world_point(pose_row[s], p)) - o, u))
               for p in _local_points(model.bodies[s])]
        lo, hi = min(min(own), max(rod)), max(max(own), min(rod))
        out.append((world_point(pose_row[g], o + lo * u), world_point(pose_row[g], o + hi * u)))
    return out
