"""The motion before and after the analysed interval, as the simulation needs it.

The simulation reads the drivers' laws a little outside the analysed interval [t0, t1]: the
dead-beat drive aims two steps ahead (the last step reads the law at t1 + dt), and the corner
tests look on both sides of every sample. The laws themselves hold their end values outside
[t0, t1] (at rest). That is the motion of a machine that starts and stops at rest, but not of
one that is already moving at t0 or still moving at t1 (a crank at constant speed): there,
holding would stop the crank dead within one step and the simulated load would spike at t0
and t1 (a 120 rpm six-bar showed a force residual of 150 times the unbalanced peak).

``continued(model, analysis)`` returns the model with each driver's law continued:

* **periodic moving motion** (every body at t1 in its pose at t0, angles up to whole turns,
  with the same velocities, and some velocity not zero): the law repeats itself, shifted by
  its travel per cycle: q(t + k P) = q(t) + k (q(t1) - q(t0)), P = t1 - t0. The simulation
  then starts a run-in early, from the cycle's own analysed state there (:func:`settling_steps`),
  and measures the cycle in steady state;
* **otherwise**: the law continues at its end velocity, q(t) = q(t1) + q'(t1) (t - t1) after t1
  and q(t0) + q'(t0) (t - t0) before t0, with zero acceleration. For a law at rest at its ends
  (every point-to-point law) this is exactly the law's own hold, so rest-to-rest motions are
  simulated as before. A motion moving at t0 starts RUN_IN_STEPS early (see
  :func:`settling_steps`).

Inside [t0, t1] the laws are untouched.
"""

from __future__ import annotations

import math
import weakref
from dataclasses import dataclass, replace

import numpy as np

from ..engine import Analysis
from ..model import Model

#: relative tolerance of the periodicity test (poses, velocities and the laws' rates)
PERIODIC_RTOL = 1e-9
#: steps simulated before t0 when the motion is moving there but is not periodic
RUN_IN_STEPS = 20


@dataclass(frozen=True)
class ContinuedLaw:
    """A law continued outside [t0, t1] (see the module's docstring)."""

    law: object
    t0: float
    t1: float
    periodic: bool

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        outside = (t < self.t0) | (t > self.t1)
        if not outside.any():
            return self.law(t)
        q, v, a = (np.array(x, dtype=float, copy=True) for x in np.broadcast_arrays(*self.law(t), t)[:3])
        to = t[outside]
        if self.periodic:
            P = self.t1 - self.t0
            k = np.floor((to - self.t0) / P)
            inner = to - k * P
            qi, vi, ai = (np.asarray(x, dtype=float) for x in self.law(inner))
            travel = float(self.law(np.array([self.t1]))[0][0] - self.law(np.array([self.t0]))[0][0])
            q[outside], v[outside], a[outside] = qi + k * travel, vi, ai
        else:
            ends = np.array([self.t0, self.t1])
            (q0, q1), (v0, v1), _ = (np.asarray(x, dtype=float) for x in self.law(ends))
            after = to > self.t1
            qe = np.where(after, q1 + v1 * (to - self.t1), q0 + v0 * (to - self.t0))
            q[outside], v[outside], a[outside] = qe, np.where(after, v1, v0), 0.0
        return q, v, a


def _scale(x: np.ndarray) -> float:
    return float(np.max(np.abs(x))) if x.size else 0.0


def is_moving_start(analysis: Analysis) -> bool:
    """Some body moves at t0 (a motion from rest is simulated from rest, as before)."""
    v = np.asarray(analysis.v, dtype=float)
    vscale = _scale(v)
    return vscale > 0.0 and _scale(v[0]) > PERIODIC_RTOL * vscale


def is_periodic_moving(model: Model, analysis: Analysis) -> bool:
    """The motion repeats from t1 exactly as it started at t0 (every body's pose up to whole
    turns, every velocity, every law's rate and acceleration, to PERIODIC_RTOL), and the
    mechanism is moving at t0 (a motion from rest is simulated from rest)."""
    q, v = np.asarray(analysis.q, dtype=float), np.asarray(analysis.v, dtype=float)
    if len(q) < 2 or not model.drivers or not is_moving_start(analysis):
        return False
    vscale = _scale(v)
    size = max(_scale(q[:, :, :2]), 1e-12)
    if _scale(q[-1, :, :2] - q[0, :, :2]) > PERIODIC_RTOL * size:
        return False
    turns = (q[-1, :, 2] - q[0, :, 2]) / (2 * math.pi)
    if _scale(turns - np.round(turns)) * 2 * math.pi > PERIODIC_RTOL * max(1.0, _scale(q[:, :, 2])):
        return False
    if _scale(v[-1] - v[0]) > PERIODIC_RTOL * vscale:
        return False
    t0, t1 = float(analysis.t[0]), float(analysis.t[-1])
    for d in model.drivers:
        _, dv, da = (np.asarray(x, dtype=float) for x in d.law(np.array([t0, t1])))
        _, vs, as_ = (np.asarray(x, dtype=float) for x in d.law(np.asarray(analysis.t, dtype=float)))
        if abs(dv[1] - dv[0]) > PERIODIC_RTOL * max(_scale(vs), 1e-300):
            return False
        if abs(da[1] - da[0]) > PERIODIC_RTOL * max(_scale(as_), _scale(vs) / max(t1 - t0, 1e-300)):
            return False
    return True


#: the continued laws alive, by (id of the law, t0, t1, periodic): :func:`continued` gives one object
#: for one law continued the same way (a value lives as long as some model holds it, and holds its law)
_CONTINUED: weakref.WeakValueDictionary[tuple[int, float, float, bool], ContinuedLaw] = weakref.WeakValueDictionary()


def continued_law(law: object, t0: float, t1: float, periodic: bool) -> ContinuedLaw:
    """``ContinuedLaw(law, t0, t1, periodic)``, the same object for the same law continued the same
    way while one is alive. The engine keys a geometry's motion by its laws' identities
    (:func:`balpipe.engine.warmstart.motion_key`): every model of a mechanism continued over one
    interval (a stage's torque-driven plans, the other stages') then shares its frame motion on a
    grid, solved once, instead of once per continued model (the same values: a continued law is a
    pure function of these four)."""
    key = (id(law), t0, t1, periodic)
    hit = _CONTINUED.get(key)
    if hit is None or hit.law is not law:
        hit = _CONTINUED[key] = ContinuedLaw(law, t0, t1, periodic)
    return hit


def continued(model: Model, analysis: Analysis) -> Model:
    """``model`` with every driver's law continued outside the analysed interval (by
    :func:`continued_law`: one object per law and interval)."""
    if any(isinstance(d.law, ContinuedLaw) for d in model.drivers):
        return model
    t0, t1 = float(analysis.t[0]), float(analysis.t[-1])
    periodic = is_periodic_moving(model, analysis)
    drivers = tuple(replace(d, law=continued_law(d.law, t0, t1, periodic)) for d in model.drivers)
    return replace(model, drivers=drivers)


def settling_steps(model: Model, analysis: Analysis, nsteps: int) -> int:
    """Steps to run before t0: a run-in of at least RUN_IN_STEPS for a motion that is moving at
    t0, none for a start from rest. A periodic moving motion starts on its own cycle's state at
    an analysis sample (the run-in rounded up to whole sample intervals of a uniform grid, so
    that :func:`start_state` reads the analysed state there, on the constraints); on a grid that
    is not uniform, a whole cycle (``nsteps``). Before, a periodic motion always settled over a
    whole cycle: half of its run, for nothing more than the run-in gives (the same steady state
    from the 20th step on: the first step's missing correction settles within a step or two).

    Why a moving start needs them: pymunk integrates positions along straight lines and its
    joints (``error_bias`` 0) pull them back onto the constraints in the next step, so in a
    running simulation the velocity after a step carries that correction, half a step's
    centripetal acceleration. A run started on the constraints lacks it in its first step: the
    simulated load is off by half the centripetal part there and the next step makes up for it
    (on a slider-crank at 120 rpm: 0.5 and 1.5 times the load at t0 and t0 + dt). After the
    run-in the recorded steps are those of a running simulation."""
    if any(isinstance(d.law, ContinuedLaw) and d.law.periodic for d in model.drivers):
        sub = _sample_steps(analysis, nsteps)
        if sub is None:
            return nsteps
        return min(sub * math.ceil(RUN_IN_STEPS / sub), nsteps)
    return RUN_IN_STEPS if is_moving_start(analysis) else 0


def _sample_steps(analysis: Analysis, nsteps: int) -> int | None:
    """Simulation steps per interval of a uniform analysis grid (None: not uniform, or not a
    whole number of steps per interval)."""
    t = np.asarray(analysis.t, dtype=float)
    if len(t) < 2 or nsteps % (len(t) - 1):
        return None
    h = np.diff(t)
    return nsteps // (len(t) - 1) if np.allclose(h, h[0], rtol=1e-9, atol=0.0) else None


def start_state(model: Model, analysis: Analysis, settle: int, dt: float):
    """Centre-of-mass poses, velocities and accelerations (nb, 3) of the model ``settle`` steps
    before t0: the analysed state at t0 itself when ``settle`` is 0; for a periodic motion, the
    analysed state that many steps before the cycle's end, less one cycle's travel (angles less
    their whole turns; :func:`settling_steps` puts it on a sample), or the state at t0 less the
    travel for a whole cycle; otherwise moved back at the velocities of t0 (the continued laws'
    constant speed; the first step's correction settles during the run-in)."""
    q0, v0, a0 = (np.asarray(x[0], dtype=float) for x in (analysis.q, analysis.v, analysis.a))
    if not settle:
        return q0, v0, a0
    if any(isinstance(d.law, ContinuedLaw) and d.law.periodic for d in model.drivers):
        travel = np.asarray(analysis.q[-1], dtype=float) - q0  # one cycle's (angles: whole turns)
        t = np.asarray(analysis.t, dtype=float)
        back = int(round(settle * dt / (t[1] - t[0]))) if len(t) > 1 else 0  # sample intervals before t0
        k = len(t) - 1 - back
        if 0 <= k < len(t) and abs(t[-1] - back * (t[1] - t[0]) - t[k]) <= 1e-9 * max(t[-1] - t[0], 1e-300):
            return (np.asarray(analysis.q[k], dtype=float) - travel, np.asarray(analysis.v[k], dtype=float),
                    np.asarray(analysis.a[k], dtype=float))
        return q0 - travel, v0, a0
    return q0 - settle * dt * v0, v0, np.zeros_like(a0)
