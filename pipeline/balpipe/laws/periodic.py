"""Constant-speed and periodic laws of one coordinate.

A periodic law with period P satisfies q(t + P) = q(t) + D (D = 0 for an oscillation, one turn
for a crank at constant speed), q'(t + P) = q'(t), q''(t + P) = q''(t), so that a motion of
several cycles is in steady state: the end state of a cycle is the start state of the next.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import Law
from ..motion import PROFILES, Profile

Triple = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class ConstantSpeed(Law):
    """q = q0 + w t (steady state, for every t). With ``ramp`` > 0 the coordinate starts from
    rest at t = 0 and reaches w at t = ramp with the smooth step of the velocity
    q' = w (3 u^2 - 2 u^3), u = t / ramp (zero acceleration at both ends of the ramp), so
    q = q0 + w ramp (u^3 - u^4 / 2) on the ramp and q0 + w ramp / 2 + w (t - ramp) after it."""

    start: float
    speed: float
    ramp: float = 0.0

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        w = self.speed
        if self.ramp <= 0:
            return self.start + w * t, np.full(t.shape, w), np.zeros(t.shape)
        R = self.ramp
        u = np.clip(t / R, 0.0, 1.0)
        on = t < R
        q = np.where(on, self.start + w * R * (u**3 - u**4 / 2), self.start + w * R / 2 + w * (t - R))
        qd = np.where(on, w * (3 * u**2 - 2 * u**3), w)
        qdd = np.where(on & (t > 0), 6 * w * u * (1 - u) / R, 0.0)
        return q, qd, qdd


def harmonic(tau: np.ndarray) -> Triple:
    """Simple harmonic rise: s = (1 - cos(pi tau)) / 2."""
    p = math.pi
    return (1 - np.cos(p * tau)) / 2, p / 2 * np.sin(p * tau), p * p / 2 * np.cos(p * tau)


CAM_PROFILES: dict[str, Profile] = {"cycloidal": PROFILES["cycloidal"], "harmonic": harmonic,
                                    "quintic": PROFILES["quintic"]}


@dataclass(frozen=True)
class Cam(Law):
    """A periodic cam law of period P: rise from ``low`` to ``high`` on the fraction ``rise`` of
    the period, dwell (``dwell_high``), return on ``ret``, dwell at ``low`` for the rest; the
    rise and the return follow ``profile`` (s(0) = 0, s(1) = 1):
    q = low + h s(u), q' = h s'(u) / (rise P), q'' = h s''(u) / (rise P)^2 on the rise,
    q = high - h s(u) on the return. Cycloidal and 3-4-5 profiles start and end with zero
    velocity and acceleration, so every join is continuous to the second derivative; the
    harmonic one only without dwells and with rise = return (checked by :func:`cam_jumps`)."""

    low: float
    high: float
    period: float
    profile: str = "cycloidal"
    rise: float = 0.5
    dwell_high: float = 0.0
    ret: float = 0.5

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        P, h, f = self.period, self.high - self.low, CAM_PROFILES[self.profile]
        tau = np.mod(t, P) / P
        q, qd, qdd = np.full(t.shape, self.low), np.zeros(t.shape), np.zeros(t.shape)
        a, b = self.rise, self.rise + self.dwell_high
        c = b + self.ret
        for lo, span, sign, base, end in ((0.0, a, 1.0, self.low, a), (b, self.ret, -1.0, self.high, c)):
            inside = (tau >= lo) & (tau < end)
            s, ds, dds = f(np.clip((tau - lo) / span, 0.0, 1.0))
            T = span * P
            q = np.where(inside, base + sign * h * s, q)
            qd = np.where(inside, sign * h * ds / T, qd)
            qdd = np.where(inside, sign * h * dds / T**2, qdd)
        q = np.where((tau >= a) & (tau < b), self.high, q)
        return q, qd, qdd


def cam_jumps(profile: str, rise: float, dwell_high: float, ret: float) -> float:
    """Largest jump of the normalised acceleration s'' (lift / period^2 units) at the joins of a
    :class:`Cam` cycle (0 for cycloidal and 3-4-5 profiles)."""
    f = CAM_PROFILES[profile]
    a0, a1 = float(f(np.array([0.0]))[2][0]), float(f(np.array([1.0]))[2][0])
    # ends of the pieces in order: rise (a0 / r^2 .. a1 / r^2), dwell (0), return (-a0 / b^2 .. -a1 / b^2), dwell (0)
    pieces = [(a0 / rise**2, a1 / rise**2)]
    if dwell_high > 0:
        pieces.append((0.0, 0.0))
    pieces.append((-a0 / ret**2, -a1 / ret**2))
    if 1 - rise - dwell_high - ret > 1e-12:
        pieces.append((0.0, 0.0))
    return max(abs(pieces[k][1] - pieces[(k + 1) % len(pieces)][0]) for k in range(len(pieces)))


@dataclass(frozen=True)
class Fourier(Law):
    """q = mean + sum_k (a_k cos(k w t) + b_k sin(k w t)), w = 2 pi / period; periodic to every
    order. ``terms`` = ((a_1, b_1), (a_2, b_2), ...)."""

    mean: float
    period: float
    terms: tuple[tuple[float, float], ...]

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        w = 2 * math.pi / self.period
        q, qd, qdd = np.full(t.shape, self.mean), np.zeros(t.shape), np.zeros(t.shape)
        for k, (a, b) in enumerate(self.terms, start=1):
            c, s = np.cos(k * w * t), np.sin(k * w * t)
            q = q + a * c + b * s
            qd = qd + k * w * (b * c - a * s)
            qdd = qdd - (k * w) ** 2 * (a * c + b * s)
        return q, qd, qdd
