"""The planar vocabulary, once: the scalar cross product, the rotation A(theta) s, an angle
wrapped to (-pi, pi], a body-frame point in the world (``world_point``), and the straight bar body of the
families' templates.

Every function computes exactly the operations the engine, the balancing, the validation and
the drawings computed before they shared it (same order, same temporaries), so results are
bit-identical: ``cross`` is u_x w_y - u_y w_x; ``rotate`` is (c s_x - s s_y, s s_x + c s_y)
with c, s = cos theta, sin theta; ``world_point`` adds the rotated point to the pose's origin
term by term (x + c p_x - s p_y), the order the drawings used. Scalars are computed with
:mod:`math` and arrays with numpy, as each caller did.
"""

from __future__ import annotations

import math
from typing import Protocol, Sequence, overload

import numpy as np

from ..model import Attachment, Body

__all__ = ["cross", "rotate", "wrap_angle", "world_point", "BarLink", "bar_body"]

def cross(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    """The z component of u x w for planar vectors (..., 2): u_x w_y - u_y w_x, shape (...)."""
    return u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]


def rotate(theta: np.ndarray, s: np.ndarray) -> np.ndarray:
    """A(theta) s: the vectors s (..., 2) turned by theta (...), broadcast against each other
    (theta (N,) with s (2,) gives (N, 2); theta (N, K) with s (K, 2) gives (N, K, 2))."""
    s = np.asarray(s)
    c, si = np.cos(theta), np.sin(theta)
    shape = np.shape(theta) if s.ndim == 1 else np.broadcast_shapes(np.shape(theta), s.shape[:-1])
    out = np.empty(shape + (2,))
    out[..., 0] = c * s[..., 0] - si * s[..., 1]
    out[..., 1] = si * s[..., 0] + c * s[..., 1]
    return out


@overload
def wrap_angle(a: float) -> float: ...
@overload
def wrap_angle(a: np.ndarray) -> np.ndarray: ...
def wrap_angle(a: float | np.ndarray) -> float | np.ndarray:
    """The angle a wrapped to (-pi, pi]: the shorter rotation of the same end (pi itself stays
    pi, -pi becomes pi). A Python number gives a Python float, an array an array."""
    if isinstance(a, (int, float)):
        return math.pi - (math.pi - a) % (2 * math.pi)
    return np.pi - np.mod(np.pi - a, 2 * np.pi)


def world_point(pose: Sequence[float] | np.ndarray, p: Sequence[float] | np.ndarray) -> np.ndarray:
    """The world position of the body-frame point p on a body at pose (x, y, theta): shape (2,)
    for one pose (computed with :mod:`math`), (N, 2) for poses (N, 3)."""
    if np.ndim(pose) == 1:
        x, y, th = pose
        c, s = math.cos(th), math.sin(th)
        return np.array([x + c * p[0] - s * p[1], y + s * p[0] + c * p[1]])
    pose = np.asarray(pose)
    c, s = np.cos(pose[:, 2]), np.sin(pose[:, 2])
    return np.stack([pose[:, 0] + c * p[0] - s * p[1], pose[:, 1] + s * p[0] + c * p[1]], axis=1)


class BarLink(Protocol):
    """What a straight bar's spec gives: its mass, centre of mass along (``com``) and normal to
    (``com_offset``, left positive) the line of its ends, and its centroidal inertia."""

    @property
    def mass(self) -> float: ...
    @property
    def com(self) -> float: ...
    @property
    def com_offset(self) -> float: ...
    @property
    def inertia(self) -> float: ...


def bar_body(name: str, link: BarLink, a: str, b: str, length: float,
             attachments: Sequence[Attachment] = ()) -> Body:
    """A straight bar: its frame's origin at the end ``a``, x along the bar to the end ``b`` at
    (length, 0), drawn as the line a-b, with the spec's mass properties and attachments."""
    return Body(name, link.mass, (link.com, link.com_offset), link.inertia,
                {a: (0.0, 0.0), b: (length, 0.0)}, attachments=tuple(attachments), outline=(a, b))
