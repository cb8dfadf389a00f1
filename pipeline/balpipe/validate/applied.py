"""A model's loads applied in the pymunk simulation (the torque-driven run).

Before every step, each load of the model (:mod:`balpipe.mechanics.loads`) is evaluated from the
simulated bodies' own state (positions, angles, velocities: pymunk's body position is the centre
of mass) as the engine evaluates it (:class:`balpipe.engine.step_loads.StepLoads`, compiled once
per run: the engine's load terms at one state in plain floats, equal to theirs), and its generalized
force on each body, a force through the centre of mass and a torque, is added to the body: so
springs, dampers, force laws, pressures, applied forces and torques, and viscous friction act on
the simulated mechanism as they would on the real one, and an error in the engine's treatment of
them shows as a tracking error. Coulomb friction is the exception: its magnitude mu r |R| needs
the joint's reaction force, and pymunk's constraint impulses are scalar magnitudes without a
direction, so the simulation cannot read it back. Its magnitude is the engine's, along the plan
(the analysis on the simulation's step times); its direction, against the joint's relative
velocity, is the simulation's own. Frame-side reactions act on the static frame and are not
simulated; a floating-base run applies no loads (it demonstrates the inertial shaking loads).
"""

from __future__ import annotations

import numpy as np
from pymunk._chipmunk_cffi import lib as _cp

from ..engine import Analysis
from ..engine.analysis import compiled
from ..engine.step_loads import StepLoads
from ..model import Model

#: what the page says of the friction in the simulation
COULOMB_NOTE = ("Coulomb friction is applied with the engine's magnitude along the plan and the simulated joint's "
                "direction of sliding (pymunk's constraint impulses have no direction, so the simulation cannot "
                "compute the friction from its own reactions); springs, dampers, applied loads and viscous "
                "friction act from the simulated state")

# the Chipmunk functions that pymunk's properties call (the same calls, without their Python layer and Vec2d objects)
_position, _velocity, _angle, _spin = _cp.cpBodyGetPosition, _cp.cpBodyGetVelocity, _cp.cpBodyGetAngle, _cp.cpBodyGetAngularVelocity
_force, _set_force, _torque, _set_torque = _cp.cpBodyGetForce, _cp.cpBodySetForce, _cp.cpBodyGetTorque, _cp.cpBodySetTorque


class AppliedLoads:
    """Applies ``model``'s loads to ``bodies`` (pymunk bodies in ``model.bodies`` order) before
    each step; ``plan``: the analysis on the simulation's step times ``times`` (the Coulomb
    friction's magnitudes). The loads are evaluated by :class:`balpipe.engine.step_loads.StepLoads`,
    compiled once: the engine's generalized forces at the simulated state, to the last bit."""

    def __init__(self, model: Model, plan: Analysis, times: np.ndarray):
        self.model = model
        self.loads = StepLoads(model, compiled(model))
        self.times = np.asarray(times, dtype=float)
        self.coulomb = {name: np.asarray(s["coulomb"], dtype=float)
                        for name, s in plan.loads.items() if "coulomb" in s}
        self._magnitudes = [self.coulomb[name].tolist() for name in self.loads.coulomb]
        self.bodies: list = []

    @property
    def has_coulomb(self) -> bool:
        return bool(self.coulomb)

    def bind(self, bodies: list) -> "AppliedLoads":
        self.bodies = list(bodies[: len(self.model.bodies)])
        return self

    def _step(self, t: float) -> int:
        """The index of the step time nearest ``t`` (the Coulomb magnitudes' sample)."""
        if len(self.times) <= 1:
            return 0
        k = int(round((t - self.times[0]) / (self.times[1] - self.times[0])))
        return min(max(k, 0), len(self.times) - 1)

    def apply(self, t: float, dt: float) -> None:
        """Add every load for the step of ``dt`` that lands on time ``t``: pymunk moves the
        positions first (with the current velocities) and then integrates the velocities with
        the forces, so the loads are those at the positions the step lands on. (The bodies are
        read and their force and torque set through the Chipmunk functions that pymunk's
        properties call, in the same order.)"""
        n = 3 * len(self.bodies)
        q, v = [0.0] * n, [0.0] * n  # the bodies no load reads stay at zero
        for k in self.loads.bodies:
            b = self.bodies[k]._body
            p, vel, w = _position(b), _velocity(b), _spin(b)
            q[3 * k: 3 * k + 3] = (p.x + dt * vel.x, p.y + dt * vel.y, _angle(b) + dt * w)
            v[3 * k: 3 * k + 3] = (vel.x, vel.y, w)
        Q, units = self.loads(t, q, v)
        if units:
            k = self._step(t)
            for magnitudes, unit in zip(self._magnitudes, units):
                m = magnitudes[k]
                for i, u in unit:
                    Q[i] += m * u
        for k in self.loads.bodies:
            b = self.bodies[k]._body
            f = _force(b)
            _set_force(b, (f.x + Q[3 * k], f.y + Q[3 * k + 1]))
            _set_torque(b, _torque(b) + Q[3 * k + 2])
