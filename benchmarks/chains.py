"""Planar serial chains of n revolute joints, for the engine's benchmarks and tests.

    from chains import serial_chain       # (benchmarks/ on the path)
    model, data = serial_chain(10)        # a 10R chain and its links' numbers

Random links (``seed``): lengths 0.1-0.5 m, centres of mass 30-70 % along each link, masses
0.5-5 kg, centroidal inertias m l^2 / 12; every joint on the 3-4-5 law over 1 s, from a random
angle to one up to ``sweep`` rad away; the initial poses by the forward kinematics. Only the
public model API (``balpipe.model``, ``balpipe.motion``) is used, so that any version can
build it.
"""

from __future__ import annotations

import math

import numpy as np

from balpipe.model import FRAME, Body, Driver, Model, Revolute
from balpipe.motion import PointToPoint, quintic


def serial_chain(n: int, seed: int = 0, sweep: float = 1.0) -> tuple[Model, dict[str, np.ndarray]]:
    """The chain and its numbers: ``L`` (lengths), ``r`` (centres of mass from each joint),
    ``m``, ``I`` (centroidal), ``q0``, ``qf`` (joint angles at 0 and 1 s)."""
    rng = np.random.default_rng(seed)
    L = rng.uniform(0.1, 0.5, n)
    r, m = L * rng.uniform(0.3, 0.7, n), rng.uniform(0.5, 5.0, n)
    inertia = m * L**2 / 12
    q0 = rng.uniform(-0.5, 0.5, n) + 0.3
    qf = q0 + sweep * rng.uniform(-1.0, 1.0, n)
    bodies = tuple(Body(f"l{k}", m[k], (r[k], 0.0), inertia[k], points={"p": (0.0, 0.0), "d": (L[k], 0.0)})
                   for k in range(n))
    joints = tuple(Revolute(f"J{k}", FRAME if k == 0 else f"l{k - 1}", f"l{k}",
                            (0.0, 0.0) if k == 0 else (L[k - 1], 0.0), (0.0, 0.0)) for k in range(n))
    drivers = tuple(Driver(f"q{k}", ("joint", f"J{k}"), PointToPoint(q0[k], qf[k], 1.0, quintic)) for k in range(n))
    initial, x, y, th = {}, 0.0, 0.0, 0.0
    for k in range(n):
        th += q0[k]
        initial[f"l{k}"] = (x, y, th)
        x, y = x + L[k] * math.cos(th), y + L[k] * math.sin(th)
    model = Model(f"{n}R chain", bodies, joints, drivers, initial, frame_points={"O": (0.0, 0.0)})
    return model, {"L": L, "r": r, "m": m, "I": inertia, "q0": q0, "qf": qf}
