"""A model's loads applied in the pymunk simulation (the torque-driven run).

Before every step, each load of the model (:mod:`balpipe.mechanics.loads`) is evaluated from the
simulated bodies' own state (positions, angles, velocities: pymunk's body position is the centre
of mass) by the engine's load terms (:func:`balpipe.engine.loads.terms`), and its generalized
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

from ..engine import Analysis
from ..engine.analysis import compiled
from ..engine.loads import terms
from ..model import Model

#: what the page says of the friction in the simulation
COULOMB_NOTE = ("Coulomb friction is applied with the engine's magnitude along the plan and the simulated joint's "
                "direction of sliding (pymunk's constraint impulses have no direction, so the simulation cannot "
                "compute the friction from its own reactions); springs, dampers, applied loads and viscous "
                "friction act from the simulated state")


class AppliedLoads:
    """Applies ``model``'s loads to ``bodies`` (pymunk bodies in ``model.bodies`` order) before
    each step; ``plan``: the analysis on the simulation's step times ``times`` (the Coulomb
    friction's magnitudes)."""

    def __init__(self, model: Model, plan: Analysis, times: np.ndarray):
        self.model = model
        self.c = compiled(model)
        self.times = np.asarray(times, dtype=float)
        self.coulomb = {name: np.asarray(s["coulomb"], dtype=float)
                        for name, s in plan.loads.items() if "coulomb" in s}
        self.bodies: list = []

    @property
    def has_coulomb(self) -> bool:
        return bool(self.coulomb)

    def bind(self, bodies: list) -> "AppliedLoads":
        self.bodies = list(bodies[: len(self.model.bodies)])
        return self

    def apply(self, t: float, dt: float) -> None:
        """Add every load for the step of ``dt`` that lands on time ``t``: pymunk moves the
        positions first (with the current velocities) and then integrates the velocities with
        the forces, so the loads are those at the positions the step lands on."""
        nb = len(self.bodies)
        q = np.empty((1, 3 * nb))
        v = np.empty((1, 3 * nb))
        for k, b in enumerate(self.bodies):
            p, vel = b.position, b.velocity
            q[0, 3 * k: 3 * k + 3] = (p.x + dt * vel.x, p.y + dt * vel.y, b.angle + dt * b.angular_velocity)
            v[0, 3 * k: 3 * k + 3] = (vel.x, vel.y, b.angular_velocity)
        lt = terms(self.model, self.c, np.array([t]), q, v)
        Q = lt.Q[0].copy()
        if lt.coulomb:
            k = min(max(int(round((t - self.times[0]) / (self.times[1] - self.times[0]))), 0), len(self.times) - 1) \
                if len(self.times) > 1 else 0
            for cf in lt.coulomb:
                Q += self.coulomb[cf.name][k] * cf.Q[0]
        for k, b in enumerate(self.bodies):
            f = b.force
            b.force = (f.x + float(Q[3 * k]), f.y + float(Q[3 * k + 1]))
            b.torque = b.torque + float(Q[3 * k + 2])
