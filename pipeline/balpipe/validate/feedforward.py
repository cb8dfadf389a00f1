"""The solver's head start in a position-driven run: each body's inertial force applied as a force.

Why
    Chipmunk's solver (Gauss-Seidel on the constraint impulses, started from the previous step's
    impulses) leaves an error in each step's impulses that shrinks with the iterations and grows
    with the change of the impulses from one step to the next. Where it converges slowly (light
    idlers between heavy gears, the paper-000 idler loop) that error is the residual: moment
    residual 0.15 / 0.056 / 0.011 at 800 / 1600 / 3200 iterations on the idler loop's
    counterweights stage at dt = 2.5e-4, about proportional to dt at a given count.

Method
    In a position-driven run every degree of freedom is imposed by a driver, so the simulated
    motion is fixed by the constraints whatever forces act on the bodies; forces only change the
    constraint impulses. Before each step every moving body gets the force m (a - g) and the
    torque I alpha, with pymunk's masses and moments (floors included) and the accelerations of
    the analysed motion at the time the step's velocities are integrated at (the end of the step:
    symplectic Euler), interpolated between the analysis samples by the derivative of the cubic
    Hermite interpolant of the velocities (error third order in the sample spacing). The
    constraints are then left with the small remainder only (discretisation and interpolation),
    which the warm-started solver finds in a few iterations. The loads are measured, as before,
    from the simulated momenta with the model's masses (:mod:`balpipe.validate.run`), never from
    these forces; a design error (a wrong mass or inertia measured with the model's own values)
    changes the momenta, not the motion, so the check keeps its power (tests/validate/test_validation_power.py).

Measured (idler loop, counterweights / counter-rotations stages, dt = 2.5e-4, moment residual):
800 iterations 0.15 -> 0.0057, 1600 0.056 -> 0.0057 / 0.015 -> 0.0046, unchanged from 800 (counterweights)
and 1600 (counter-rotations) on: what remains is first order in dt (0.0025 / 0.0023 at 1.25e-4).
Without it the same stages need 3200 iterations for 0.0019 / 0.0026 at 1.25e-4.
Not for the torque-driven run (the forces there are the actuators' and the motion is free) nor
the free-floating frame (its base moves with the mechanism's reaction).
"""

from __future__ import annotations

import numpy as np

from ..engine import Analysis


def inertial_forces(analysis: Analysis, times: np.ndarray, mass: np.ndarray, moment: np.ndarray,
                    gravity: np.ndarray) -> np.ndarray:
    """(len(times), nb, 3): m (a - g) and I alpha of the analysis' bodies at ``times``, with the
    masses ``mass`` and moments ``moment`` (nb,) that the bodies are simulated with. Times
    outside the analysed interval take the nearest end's accelerations (a run-in of a
    periodic motion is mapped into the cycle)."""
    t = np.asarray(analysis.t, dtype=float)
    t0, t1 = float(t[0]), float(t[-1])
    tt = np.clip(np.asarray(times, dtype=float), t0, t1)
    if len(t) < 2:
        acc = np.broadcast_to(analysis.a[:1], (len(tt),) + analysis.a.shape[1:]).copy()
    else:
        j = np.clip(np.searchsorted(t, tt, side="right") - 1, 0, len(t) - 2)
        h = (t[j + 1] - t[j])[:, None, None]
        s = ((tt - t[j])[:, None, None]) / h
        v, a = analysis.v, analysis.a
        # d/dt of the cubic Hermite interpolant of v with slopes a
        acc = ((6.0 * s * s - 6.0 * s) * (v[j] - v[j + 1]) / h + (3.0 * s * s - 4.0 * s + 1.0) * a[j]
               + (3.0 * s * s - 2.0 * s) * a[j + 1])
    out = np.empty_like(acc)
    out[:, :, 0] = mass * (acc[:, :, 0] - gravity[0])
    out[:, :, 1] = mass * (acc[:, :, 1] - gravity[1])
    out[:, :, 2] = moment * acc[:, :, 2]
    return out


def periodic_times(times: np.ndarray, t0: float, t1: float) -> np.ndarray:
    """``times`` before t0 (a periodic motion's run-in) moved into [t0, t1] by whole periods t1 - t0."""
    times = np.asarray(times, dtype=float)
    return np.where(times < t0, t0 + np.mod(times - t0, t1 - t0), times)
