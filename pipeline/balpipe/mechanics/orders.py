"""Orders: the harmonic content of a periodic shaking force and moment.

For a motion of whole cycles of period P (constant speed, cam, Fourier, cycle; ``motion.cycles``),
the shaking force and moment are periodic with frequency w = 2 pi / P, and order k is the
harmonic of frequency k w. A real signal s(t) is written

    s(t) = s_0 + sum_k A_k cos(k w t + phi_k),      A_k >= 0 the peak amplitude, phi_k its phase,

with t measured from the start of the motion. The force F = Fx + i Fy, as a vector in the plane,
is also written as counter-rotating vectors per order,

    F(t) = sum_k ( F+_k e^{i k w t} + F-_k e^{-i k w t} ),

the forward component F+_k turning with the crank, the backward F-_k against it: |F+_k| and
|F-_k| are their (constant) magnitudes, their arguments the directions at t = 0. With X_k, Y_k
the complex amplitudes of Fx and Fy (s = Re(C_k e^{i k w t}), C_k = A_k e^{i phi_k}),
F+_k = (X_k + i Y_k) / 2 and F-_k = conj(X_k - i Y_k) / 2. An in-line slider-crank's primary
force along the stroke, A cos(w t), is two vectors of A/2 turning both ways.

The time grid of the engine includes both ends of the motion (``linspace(0, duration, N)``):
the last sample repeats the first cycle's start and is dropped, leaving N - 1 uniform samples over
``cycles`` whole periods, on which the discrete Fourier transform gives the harmonics exactly for
content below the Nyquist order (N - 1) / (2 cycles) (no aliasing for band-limited signals; the
error of a smooth signal falls as fast as its spectrum). Orders at or above the Nyquist order
are not reported. Pure numpy; nothing here reads a spec.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Harmonic:
    """Peak amplitude (signal units) and phase (rad, in (-pi, pi]) of one order."""

    amplitude: float
    phase: float

    def to_json(self) -> dict[str, float]:
        return {"amplitude": self.amplitude, "phase": self.phase}


@dataclass(frozen=True)
class Order:
    """Order ``k``'s shaking force along x and y (N), as forward and backward rotating vectors
    (N), and the shaking moment (N m)."""

    k: int
    fx: Harmonic
    fy: Harmonic
    forward: Harmonic
    backward: Harmonic
    moment: Harmonic

    @property
    def name(self) -> str:
        """"primary" for order 1, "secondary" for 2, else "order k"."""
        return {1: "primary", 2: "secondary"}.get(self.k, f"order {self.k}")

    def to_json(self) -> dict:
        return {"order": self.k, "name": self.name, "fx": self.fx.to_json(), "fy": self.fy.to_json(),
                "forward": self.forward.to_json(), "backward": self.backward.to_json(),
                "moment": self.moment.to_json()}


def whole_cycle_samples(t: np.ndarray, cycles: float, rtol: float = 1e-9) -> int:
    """The number of uniform samples that cover ``cycles`` whole periods exactly once: ``len(t)``
    when the grid stops one step short of the end, ``len(t) - 1`` when it includes both ends (the
    engine's). Raises ValueError when ``cycles`` is not a whole number or the grid not uniform."""
    n = len(t)
    c = round(cycles)
    if c < 1 or abs(cycles - c) > rtol * max(1.0, cycles):
        raise ValueError(f"orders need a whole number of cycles, not {cycles:g}")
    if n < 3:
        raise ValueError("orders need at least 3 samples")
    dt = np.diff(t)
    step = (t[-1] - t[0]) / (n - 1)
    if np.max(np.abs(dt - step)) > rtol * abs(step) * 10:
        raise ValueError("orders need a uniform time grid")
    return n - 1  # both ends given: the last sample is the first of the next cycle


def complex_amplitudes(values: np.ndarray, cycles: int, orders: int) -> np.ndarray:
    """C_k, k = 1..orders, of ``values`` (M samples over ``cycles`` whole periods, the end point
    excluded, along axis 0): s = Re(C_k e^{i k w t}) per order, from the DFT bin k * cycles."""
    m = values.shape[0]
    spectrum = np.fft.rfft(values, axis=0)
    bins = np.arange(1, orders + 1) * cycles
    return 2.0 * spectrum[bins] / m


def nyquist_order(samples: int, cycles: int) -> int:
    """The highest order strictly below the Nyquist frequency of ``samples`` uniform samples over
    ``cycles`` periods (each order's amplitude is then exact for band-limited content)."""
    return int(np.ceil(samples / (2 * cycles)) - 1)


def _harmonic(c: complex) -> Harmonic:
    return Harmonic(float(abs(c)), float(np.angle(c)))


def orders_of(t: np.ndarray, force: np.ndarray, moment: np.ndarray, cycles: float, orders: int) -> list[Order]:
    """Orders 1..``orders`` (fewer if the grid's Nyquist order is lower) of a shaking force
    (N, 2) and moment (N,) sampled on ``t`` (uniform, both ends of ``cycles`` whole periods
    included, as the engine samples)."""
    m = whole_cycle_samples(t, cycles)
    c = int(round(cycles))
    n = min(orders, nyquist_order(m, c))
    if n < 1:
        return []
    data = np.column_stack([np.asarray(force, float)[:m], np.asarray(moment, float)[:m]])
    C = complex_amplitudes(data, c, n)
    out = []
    for k in range(n):
        X, Y, M = C[k]
        out.append(Order(k + 1, _harmonic(X), _harmonic(Y), _harmonic((X + 1j * Y) / 2),
                         _harmonic(np.conj(X - 1j * Y) / 2), _harmonic(M)))
    return out
