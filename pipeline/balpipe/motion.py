"""Motion laws: point-to-point profiles of a driven coordinate, vectorised over time.

Every law moves a coordinate from ``start`` to ``end`` in ``duration`` seconds through a
normalised profile s(tau), tau = t / T in [0, 1], s(0) = 0, s(1) = 1:

    q(t) = q0 + (q1 - q0) s(t/T),  q' = (q1 - q0) s'(tau) / T,  q'' = (q1 - q0) s''(tau) / T^2

so halving the duration multiplies every acceleration, and every inertial load, by 4.
``polynomial`` instead solves for the coefficients from boundary conditions given in physical
units (position, velocity, acceleration, ... at both ends).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .model import Law

Profile = Callable[[np.ndarray], tuple[np.ndarray, np.ndarray, np.ndarray]]


def quintic(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """3-4-5 polynomial: s = 10 tau^3 - 15 tau^4 + 6 tau^5 (paper 000, eq. 10)."""
    return (
        tau**3 * (10 - 15 * tau + 6 * tau**2),
        30 * tau**2 * (1 - tau) ** 2,
        60 * tau * (1 - tau) * (1 - 2 * tau),
    )


def cycloidal(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Cycloidal: s = tau - sin(2 pi tau) / (2 pi)."""
    w = 2 * math.pi
    return tau - np.sin(w * tau) / w, 1 - np.cos(w * tau), w * np.sin(w * tau)


def bang_bang(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Constant acceleration for the first half, constant deceleration for the second
    (paper 003's law): s'' = +4 then -4."""
    first = tau < 0.5
    s = np.where(first, 2 * tau**2, 1 - 2 * (1 - tau) ** 2)
    ds = np.where(first, 4 * tau, 4 * (1 - tau))
    dds = np.where(first, 4.0, -4.0)
    return s, ds, dds


def trapezoidal(accel_fraction: float) -> Profile:
    """Trapezoidal velocity: accelerate for a fraction ``f`` of the time, cruise, decelerate
    for ``f``. Peak velocity v = 1 / (1 - f), acceleration a = v / f (normalised)."""
    f = accel_fraction
    if not 0 < f <= 0.5:
        raise ValueError("accel_fraction must be in (0, 0.5]")
    v = 1.0 / (1.0 - f)
    a = v / f

    def profile(tau: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        up, down = tau < f, tau > 1 - f
        s = np.where(up, 0.5 * a * tau**2, np.where(down, 1 - 0.5 * a * (1 - tau) ** 2, v * (tau - f / 2)))
        ds = np.where(up, a * tau, np.where(down, a * (1 - tau), v))
        dds = np.where(up, a, np.where(down, -a, 0.0))
        return s, ds, dds

    return profile


PROFILES: dict[str, Profile] = {
    "quintic": quintic,
    "cycloidal": cycloidal,
    "bang_bang": bang_bang,
}


@dataclass(frozen=True)
class PointToPoint(Law):
    """q0 -> q1 in ``duration`` along a normalised profile; constant outside [0, T]."""

    start: float
    end: float
    duration: float
    profile: Profile

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.asarray(t, dtype=float)
        tau = np.clip(t / self.duration, 0.0, 1.0)
        s, ds, dds = self.profile(tau)
        inside = (t >= 0) & (t <= self.duration)
        h = self.end - self.start
        T = self.duration
        return (
            self.start + h * s,
            np.where(inside, h * ds / T, 0.0),
            np.where(inside, h * dds / T**2, 0.0),
        )


@dataclass(frozen=True)
class Polynomial(Law):
    """The lowest-degree polynomial meeting boundary conditions at t = 0 and t = T.

    ``start_derivatives`` = (q(0), q'(0), q''(0), ...), ``end_derivatives`` likewise at T.
    """

    coefficients: tuple[float, ...]  # ascending powers of t
    duration: float

    @classmethod
    def from_boundary(
        cls, start: tuple[float, ...], end: tuple[float, ...], duration: float
    ) -> "Polynomial":
        n = len(start) + len(end)
        rows, rhs = [], []
        for t, conds in ((0.0, start), (duration, end)):
            for k, value in enumerate(conds):
                row = [
                    (math.factorial(p) / math.factorial(p - k)) * t ** (p - k) if p >= k else 0.0
                    for p in range(n)
                ]
                rows.append(row)
                rhs.append(value)
        coeffs = np.linalg.solve(np.array(rows), np.array(rhs))
        return cls(tuple(float(c) for c in coeffs), duration)

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Inside [0, T] the polynomial; outside, held at its end values (at rest)."""
        t = np.asarray(t, dtype=float)
        inside = (t >= 0) & (t <= self.duration)
        tc = np.clip(t, 0.0, self.duration)
        c = np.polynomial.Polynomial(self.coefficients)
        return c(tc), np.where(inside, c.deriv(1)(tc), 0.0), np.where(inside, c.deriv(2)(tc), 0.0)


def law_for(motion, start: float, end: float, drive=None) -> Law:
    """The law of one coordinate from ``start`` to ``end`` (SI) following the spec's ``motion``
    section (law, duration, accel_fraction); ``drive`` gives the polynomial law's boundary
    velocities and accelerations, and may name its own ``law`` and ``accel_fraction``."""
    T = motion.duration
    law = getattr(drive, "law", None) or motion.law
    fraction = getattr(drive, "accel_fraction", None) or motion.accel_fraction
    if law == "polynomial":
        d = drive
        return Polynomial.from_boundary(
            (start, d.start_velocity if d else 0.0, d.start_acceleration if d else 0.0),
            (end, d.end_velocity if d else 0.0, d.end_acceleration if d else 0.0),
            T,
        )
    if law not in PROFILES and law != "trapezoidal":
        raise ValueError(f"unknown law {law!r}; known: {', '.join(sorted(PROFILES) + ['polynomial', 'trapezoidal'])}")
    profile = trapezoidal(fraction) if law == "trapezoidal" else PROFILES[law]
    return PointToPoint(start, end, T, profile)
