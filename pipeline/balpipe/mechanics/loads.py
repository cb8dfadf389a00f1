"""Loads on a model: force elements, applied forces and torques, joint friction (SI units).

These are the data of :attr:`balpipe.model.Model.loads`; the engine turns them into generalized
forces (:mod:`balpipe.engine.loads`) and the pymunk validation applies them
(:mod:`balpipe.validate.applied`). A point is an :class:`Anchor`: a body's name and a point in
that body's frame (global coordinates on the frame).

Every load says where it comes from (``source``): ``internal`` loads act between two parts of the
machine, the frame included (a spring anchored on the frame, a gas force on the piston and the
cylinder head, friction), so the frame feels the frame-side reaction; ``external`` loads come from
outside the machine (a well's rod load, a workpiece) and reach the frame only through the joints.
The shaking force and moment stay the inertial ones; the *frame load* (everything the frame feels)
equals the shaking load plus the external loads (DESIGN.md, "Loads, and what the frame feels").
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass
from functools import cached_property
from typing import Literal

import numpy as np

from ..model import FRAME, Vec2

Source = Literal["internal", "external"]


@dataclass(frozen=True)
class Anchor:
    """Point ``point`` of body ``body`` (its own frame; global coordinates on the frame)."""

    body: str
    point: Vec2

    @property
    def on_frame(self) -> bool:
        return self.body == FRAME


@dataclass(frozen=True, eq=False)
class LoadTable:
    """A load value (N, N m or Pa, SI) tabulated against an argument, interpolated linearly.

    ``argument``: ``("time",)`` (s, the motion's time), ``("driver", name)`` (the driver's
    prescribed coordinate: an angle in rad or a length in m; an angle table repeats every turn),
    ``("stroke", body, (px, py), (dx, dy))`` (the displacement of that point along the unit
    direction (dx, dy) in frame axes, from its position at the motion's start), or
    ``("deflection",)`` (a force element's own length minus its free length). ``rising`` holds
    the rows (x, value) used while the argument increases (or stays); ``falling``, when given,
    those used while it decreases (a pumpjack's rod load: up-stroke and down-stroke). Outside
    the rows the end values hold (except an angle's, which wraps).
    """

    argument: tuple
    rising: tuple[np.ndarray, np.ndarray]
    falling: tuple[np.ndarray, np.ndarray] | None = None
    period: float | None = None

    def __call__(self, x: np.ndarray, rate: np.ndarray) -> np.ndarray:
        """The value at arguments ``x`` moving at ``rate`` (the branch by the rate's sign)."""
        up = np.interp(x, *self.rising, period=self.period)
        if self.falling is None:
            return up
        down = np.interp(x, *self.falling, period=self.period)
        return np.where(rate < 0.0, down, up)

    def at(self, x: float, rate: float) -> float:
        """The value at one argument ``x`` moving at ``rate``, in plain floats: equal to the
        array call's to the last bit (numpy's interpolation, its periodic rows and its rules at
        the rows, outside them and on NaN, taken step by step; ``tests/validate/test_step_loads.py``)."""
        rows = self._rows[1] if rate < 0.0 and self._rows[1] is not None else self._rows[0]
        return _interp(x % abs(self.period) if self.period is not None else x, *rows)

    @cached_property
    def _rows(self) -> tuple[tuple[list[float], list[float]], tuple[list[float], list[float]] | None]:
        """The rising and falling rows as lists, a periodic table's as numpy's ``interp`` makes
        them (wrapped into one period, sorted, one row repeated a period off at each end)."""
        return _periodic(self.rising, self.period), None if self.falling is None else _periodic(self.falling, self.period)


def _periodic(rows: tuple[np.ndarray, np.ndarray], period: float | None) -> tuple[list[float], list[float]]:
    xp, fp = (np.asarray(r, dtype=np.float64) for r in rows)
    if period is not None:
        period = abs(period)
        xp = xp % period
        order = np.argsort(xp)
        xp, fp = xp[order], fp[order]
        xp = np.concatenate((xp[-1:] - period, xp, xp[0:1] + period))
        fp = np.concatenate((fp[-1:], fp, fp[0:1]))
    return xp.tolist(), fp.tolist()


def _interp(x: float, xp: list[float], fp: list[float]) -> float:
    """numpy's linear interpolation of one float (``np.interp`` with the end values outside)."""
    if x != x:
        return x
    j = bisect.bisect_right(xp, x) - 1
    if j < 0:
        return fp[0]
    if j >= len(xp) - 1 or xp[j] == x:
        return fp[j]
    slope = (fp[j + 1] - fp[j]) / (xp[j + 1] - xp[j])
    y = slope * (x - xp[j]) + fp[j]
    if y != y:  # numpy's retry from the other end of the interval
        y = slope * (x - xp[j + 1]) + fp[j + 1]
        if y != y and fp[j] == fp[j + 1]:
            y = fp[j]
    return y


@dataclass(frozen=True)
class ForceElement:
    """A force along the line between two points: spring, damper, table, pressure.

    Tension (positive when it pulls the two points together):
    T = T0 + k (L - L_ref) + c dL/dt + scale * law(argument), with L the distance between the
    points, L_ref the ``free_length`` (T0 = 0) or, when only a ``preload`` is given, the length at
    the motion's start (T0 = preload, the tension there). A pressure p on an area A pushing a
    piston off its cylinder head is ``scale = -A``, ``law`` the pressure. The element pulls
    ``a`` by +T u and ``b`` by -T u (u the unit vector from a to b).
    """

    name: str
    a: Anchor
    b: Anchor
    stiffness: float = 0.0
    free_length: float | None = None
    preload: float = 0.0
    damping: float = 0.0
    law: LoadTable | None = None
    scale: float = 1.0
    source: Source = "internal"


@dataclass(frozen=True)
class TorsionElement:
    """A torsional spring and damper at a revolute joint: the torque on body b (reacted on a)
    is -(T0 + k (phi - phi_ref) + c dphi/dt), phi = theta_b - theta_a the joint's angle, phi_ref
    the ``free_angle`` or (None) the angle at the motion's start, T0 the ``preload`` there."""

    name: str
    joint: str
    stiffness: float = 0.0
    free_angle: float | None = None
    preload: float = 0.0
    damping: float = 0.0
    source: Source = "internal"


@dataclass(frozen=True)
class AppliedLoad:
    """A force (fx, fy) at ``at`` and a torque on its body, in the body's axes (``axes =
    "body"``: they turn with it) or the frame's, each times ``law``'s value when a table is
    given (then ``force`` is the direction and scale of the tabulated value). ``internal``: the
    frame takes the opposite force at the same place and the opposite torque."""

    name: str
    at: Anchor
    force: Vec2 = (0.0, 0.0)
    torque: float = 0.0
    axes: Literal["body", "frame"] = "frame"
    law: LoadTable | None = None
    source: Source = "external"


@dataclass(frozen=True)
class JointFriction:
    """Friction in a revolute or prismatic joint, opposing the joint's relative motion.

    Revolute: torque on b -(c w + mu r |R| sgn w), w = theta_b' - theta_a', R the joint's
    reaction force, r the pin radius. Prismatic: force on the slider along the guide's axis
    -(c s' + mu |N| sgn s'), s' the sliding speed, N the normal reaction. The reaction includes
    the friction itself (solved together with the efforts, :func:`balpipe.engine.loads.solve`).
    """

    name: str
    joint: str
    viscous: float = 0.0
    coefficient: float = 0.0
    pin_radius: float = 0.0
    source: Source = "internal"


Load = ForceElement | TorsionElement | AppliedLoad | JointFriction
