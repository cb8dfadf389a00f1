"""Joint laws from a pose-driven analysis: the generic part of every template that moves a pose
(a platform's, an end-effector's, a centre of mass's) and drives its actuated joints.

A template that takes a task-space motion (x(t), y(t), phi(t)) turns it into joint laws
q(t), q'(t), q''(t) by inverse kinematics with exact derivatives (chain rule); the engine then
analyses the mechanism as any joint-driven one. Two pieces are the same for every such template
and live here:

* :func:`body_point` (:func:`body_point_xy`: by components): a point fixed in a moving body,
  with its velocity and acceleration, from the body's pose laws: C = P + R(phi) c,
  C' = P' + phi' J R(phi) c, C'' = P'' + phi'' J R(phi) c - phi'^2 R(phi) c (J: the rotation by
  +90 deg);
* :class:`PoseJointLaw`: a driver's law that is one coordinate of such an inverse-kinematics
  solution. The template says how to solve a time grid for all the coordinates at once
  (:meth:`PoseJointLaw.solve`) and which coordinate the law is (:attr:`PoseJointLaw.coordinate`);
  the solution is computed once per time grid and shared by the laws that share a store;
* :func:`dyad_rates`: the angular rates and accelerations of a two-link dyad whose end point's
  velocity and acceleration are known (the n-RRR's legs, the serial arm's first two links).

Used by the 3-RPR (paper 000: leg lengths or angles from the platform pose), the n-RRR (paper
001: joint angles from the platform pose) and the serial arm (papers 002-003: joint angles from
the tip's or the centre of mass's motion).
"""

from __future__ import annotations

from collections.abc import Hashable, Mapping
from typing import Callable

import numpy as np

from ..model import Law

Triple = tuple[np.ndarray, np.ndarray, np.ndarray]  # values, first and second time derivatives

#: time grids whose solutions a store keeps (the engine asks for the same few grids repeatedly)
KEEP = 8


def body_point(pose: tuple[Triple, Triple, Triple], c) -> Triple:
    """(N, 2) position, velocity and acceleration of the point with local coordinates ``c`` of a
    body whose frame has the pose (x, y, phi), each given with its two derivatives (the values
    of the pose laws): C = P + R c, C' = P' + phi' J R c, C'' = P'' + phi'' J R c - phi'^2 R c."""
    pos, vel, acc = (np.stack(xy, axis=-1) for xy in body_point_xy(pose, c))
    return pos, vel, acc


def body_point_xy(pose: tuple[Triple, Triple, Triple], c,
                  cos_sin: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[tuple[np.ndarray, np.ndarray], ...]:
    """:func:`body_point` as ((x, y), (x', y'), (x'', y'')), each an (N,) array (the same
    values, half the time where the caller wants the components); ``cos_sin``: cos phi and
    sin phi when the caller has them."""
    (x, xd, xdd), (y, yd, ydd), (f, fd, fdd) = pose
    cf, sf = (np.cos(f), np.sin(f)) if cos_sin is None else cos_sin
    rx, ry = cf * c[0] - sf * c[1], sf * c[0] + cf * c[1]  # R c
    jx, jy = -ry, rx  # J R c
    w2 = fd**2
    return ((x + rx, y + ry), (xd + fd * jx, yd + fd * jy), (xdd + fdd * jx - w2 * rx, ydd + fdd * jy - w2 * ry))


def dyad_rates(a: float, c1, s1, b: float, c2, s2, det, Cd, Cdd) -> tuple[np.ndarray, ...]:
    """Angular rates and accelerations (w1, w2, a1, a2) of a dyad, two links of lengths ``a``
    and ``b`` at absolute angles alpha1, alpha2 (cosines and sines ``c1, s1, c2, s2``), whose
    end point moves with velocity and acceleration ``Cd = (x', y')``, ``Cdd = (x'', y'')``
    (pairs of (N,) arrays): a perp(e1) w1 + b perp(e2) w2 = C' and, differentiating,
    a perp(e1) a1 + b perp(e2) a2 = C'' + a w1^2 e1 + b w2^2 e2, by Cramer's rule with
    ``det`` = a b sin(alpha2 - alpha1) (inf or NaN where the dyad is stretched or folded: the
    callers check the configuration). The second-order inverse kinematics of the n-RRR's legs
    and of the serial arm's first two links."""
    (Wdx, Wdy), (Wddx, Wddy) = Cd, Cdd
    with np.errstate(divide="ignore", invalid="ignore"):
        inv = 1.0 / det
        # x1 = (r x q)/det, x2 = (p x r)/det with the columns p = a perp(e1), q = b perp(e2)
        w1 = (Wdx * b * c2 + Wdy * b * s2) * inv
        w2 = (-a * s1 * Wdy - a * c1 * Wdx) * inv
        Rx = Wddx + a * w1**2 * c1 + b * w2**2 * c2
        Ry = Wddy + a * w1**2 * s1 + b * w2**2 * s2
        a1 = (Rx * b * c2 + Ry * b * s2) * inv
        a2 = (-a * s1 * Ry - a * c1 * Rx) * inv
    return w1, w2, a1, a2


def grid_key(t: np.ndarray) -> tuple:
    """A time grid's identity for the caches: its shape and exact values."""
    return (t.shape, t.tobytes())


def solved(store: dict, t: np.ndarray, solve: Callable[[np.ndarray], Mapping]) -> Mapping:
    """``solve(t)``, computed once per time grid and kept in ``store`` (the last :data:`KEEP`
    grids)."""
    key = grid_key(t)
    if key not in store:
        if len(store) >= KEEP:
            store.pop(next(iter(store)))
        store[key] = solve(t)
    return store[key]


class PoseJointLaw(Law):
    """One actuated coordinate of a pose-driven motion, by inverse kinematics, as a driver's law.

    Subclasses (dataclasses of the template's own data) define :meth:`solve`, every coordinate
    of the solution on a time grid, and :attr:`coordinate`, the key of this law's. The solution
    of a grid is computed once and kept in :meth:`store`: by default the law's own; a template
    whose laws come from one solution (the joints of a serial arm) returns a store they share.
    A copy made by ``dataclasses.replace`` (another pose, say) starts with an empty store of its
    own unless the shared store is one of its fields."""

    coordinate: Hashable

    def solve(self, t: np.ndarray) -> Mapping[Hashable, Triple]:
        """Every coordinate's (q, q', q'') on the 1-D time grid ``t``."""
        raise NotImplementedError

    def store(self) -> dict:
        return self.__dict__.setdefault("_solutions", {})

    def __call__(self, t):
        t = np.atleast_1d(np.asarray(t, dtype=float))
        sol = solved(self.store(), t.reshape(-1), self.solve)[self.coordinate]
        return tuple(np.array(v).reshape(t.shape) for v in sol)  # copies: callers may write to them
