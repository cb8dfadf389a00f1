"""The pymunk run's per-step loads (balpipe.engine.step_loads, compiled once per run, plain floats)
equal the engine's (balpipe.engine.loads.terms, numpy along a motion) at random states, for every
kind of load: spring, damper, torsion, tables against time, a driver (periodic), a stroke (rising
and falling) and a deflection, gas pressure, applied forces and torques in body and frame axes,
internal and external, viscous friction and Coulomb friction (revolute and prismatic, on the frame
and between moving links); the table lookup of one float equals numpy's interpolation; and
AppliedLoads adds exactly the engine's forces, the Coulomb magnitudes of the plan included.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pymunk
import pytest

from balpipe import registry
from balpipe.engine import analyse
from balpipe.engine.analysis import compiled
from balpipe.engine.loads import terms
from balpipe.engine.step_loads import StepLoads
from balpipe.loader import load_text
from balpipe.mechanics.loads import Anchor, AppliedLoad, ForceElement, JointFriction, LoadTable
from balpipe.model import FRAME
from balpipe.validate.applied import AppliedLoads
from test_loads_engine import SLIDER_CRANK, loaded


def _four_bar(rng):
    """test_loads_engine's loaded four-bar (spring-damper to the frame, torsion, a body-axes rod
    load against a stroke with two branches, viscous and Coulomb friction) plus a damper and a
    deflection table between moving links, a time table, an internal frame-axes load."""
    model = loaded(rng)
    x = np.linspace(-0.1, 0.1, 7)
    extra = (
        ForceElement("link", Anchor("crank", (0.05, 0.01)), Anchor("rocker", (0.15, -0.02)), free_length=0.3,
                     damping=4.0, law=LoadTable(("deflection",), (x, 100.0 * rng.uniform(size=7))), scale=2.0,
                     source="external"),
        AppliedLoad("push", Anchor("coupler", (0.1, 0.02)), force=(3.0, -1.5), torque=0.4,
                    law=LoadTable(("time",), (np.linspace(0, 0.4, 5), rng.normal(size=5))), source="internal"),
        AppliedLoad("still", Anchor(FRAME, (0.1, 0.1)), force=(1.0, 2.0), torque=0.5),
    )
    return dataclasses.replace(model, loads=model.loads + extra)


def _slider_crank():
    """test_loads_engine's slider-crank with its gas pressure tabulated against the crank's angle
    (one turn, repeated), viscous and Coulomb friction on the slideway, in the crank pin and in
    the main bearing."""
    model = registry.unbalanced_model(load_text(SLIDER_CRANK, "x.yaml")[0])
    gas = model.loads[0]
    assert isinstance(gas, ForceElement)
    pressure = LoadTable(("driver", "crank"), (np.radians([0.0, 90.0, 180.0, 360.0]), np.array([3e5, 1e5, 0.0, 3e5])),
                         period=2 * np.pi)
    friction = (JointFriction("rings", "guide", viscous=2.0, coefficient=0.12),
                JointFriction("pin", "B", viscous=0.01, coefficient=0.2, pin_radius=0.008),
                JointFriction("bearing", "A", coefficient=0.05, pin_radius=0.015))
    return dataclasses.replace(model, loads=(dataclasses.replace(gas, preload=0.0, law=pressure, scale=-20e-4),) + friction)


def _moving_guide():
    """The slider-crank with its slideway on the coupler (an axis of length 2, at an angle): the
    guide's own motion in the sliding speed (the random states need no assembled mechanism)."""
    model = _slider_crank()
    guide = dataclasses.replace(model.joint("guide"), guide="coupler", axis=(1.2, 1.6))
    return dataclasses.replace(model, joints=tuple(guide if j.name == "guide" else j for j in model.joints),
                               loads=tuple(ld for ld in model.loads if isinstance(ld, JointFriction)))


def _states(model, rng, n):
    """n random states near the model's assembled pose: positions, angles and rates."""
    nb = len(model.bodies)
    q0 = np.concatenate([model.initial[b.name] for b in model.bodies])
    q = q0 + rng.normal(scale=0.05, size=(n, 3 * nb))
    v = rng.normal(scale=3.0, size=(n, 3 * nb))
    v[: n // 4, 2::3] = 0.0  # joints at rest: friction's direction 0
    return rng.uniform(0.0, 0.4, n), q, v


def _dense(unit, n):
    out = np.zeros(n)
    for i, u in unit:
        out[i] += u
    return out


@pytest.mark.parametrize("build", [_four_bar, _slider_crank, _moving_guide])
def test_every_load_at_random_states_equals_the_engine(build):
    rng = np.random.default_rng(7)
    model = build(rng) if build is _four_bar else build()
    c = compiled(model)
    t, q, v = _states(model, rng, 40)
    for load in model.loads:  # each load alone: every kind is seen to act
        alone = dataclasses.replace(model, loads=(load,))
        step = StepLoads(alone, compiled(alone))
        lt = terms(alone, compiled(alone), t, q, v)
        scale = max([np.abs(lt.Q).max()] + [np.abs(cf.Q).max() for cf in lt.coulomb])
        assert scale > 0.0 or load.name == "still", load.name
        for j in range(len(t)):
            Q, units = step(float(t[j]), q[j].tolist(), v[j].tolist())
            assert np.abs(np.array(Q) - lt.Q[j]).max() <= 1e-12 * scale, load.name
            assert step.coulomb == [cf.name for cf in lt.coulomb]
            for unit, cf in zip(units, lt.coulomb):
                assert np.abs(_dense(unit, q.shape[1]) - cf.Q[j]).max() <= 1e-12 * scale, load.name
            touched = set(np.flatnonzero(lt.Q[j]) // 3) | {i // 3 for u in units for i, _ in u}
            assert touched <= set(step.bodies)
    step = StepLoads(model, c)  # all at once: the same sums in the engine's order
    lt = terms(model, c, t, q, v)
    for j in range(len(t)):
        Q, _ = step(float(t[j]), q[j].tolist(), v[j].tolist())
        assert np.abs(np.array(Q) - lt.Q[j]).max() <= 1e-12 * np.abs(lt.Q).max()


def test_a_table_of_one_float_equals_numpys_interpolation():
    """Rows inside and outside, on the rows, repeated rows, a periodic table with rows beyond one
    period, the falling branch by the rate's sign, NaN and infinities."""
    rng = np.random.default_rng(3)
    for trial in range(120):
        n = int(rng.integers(2, 10))
        period = (None, 2 * np.pi, 360.0)[trial % 3]
        span = period or 1.0
        xp = np.sort(rng.uniform(-span, 2 * span, n)) if trial % 2 else np.linspace(0.0, span, n)
        if n > 3 and trial % 5 == 0:
            xp[2] = xp[1]
        table = LoadTable(("time",), (xp, rng.normal(size=n)), (xp, rng.normal(size=n)) if trial % 4 else None, period)
        x = np.concatenate([rng.uniform(xp[0] - 2 * span, xp[-1] + 2 * span, 50), xp, xp + span, [np.nan, np.inf]])
        rate = rng.choice([-1.0, 0.0, 1.0], size=len(x))
        with np.errstate(invalid="ignore"):
            want = table(x, rate)
        got = np.array([table.at(float(a), float(r)) for a, r in zip(x, rate)])
        assert np.array_equal(got, want, equal_nan=True), (xp, period)


def test_applied_loads_add_the_engines_forces_and_the_plans_coulomb_friction():
    """AppliedLoads on pymunk bodies: each body's force and torque grow by the engine's Q at the
    state the step lands on (positions moved by dt at the current velocities) plus every Coulomb
    joint's unit force times the plan's magnitude at the nearest step time."""
    model = _slider_crank()
    times = np.linspace(0.0, 0.1, 101)
    plan = analyse(model, times)
    applied = AppliedLoads(model, plan, times)
    assert applied.has_coulomb
    rng = np.random.default_rng(5)
    _, q, v = _states(model, rng, 5)
    bodies = [pymunk.Body(1.0, 1.0) for _ in model.bodies]
    applied.bind(bodies)
    c, dt = compiled(model), 1e-3
    for j, t in enumerate((0.0, 0.0304, 0.05, 0.1, 0.2)):
        for k, b in enumerate(bodies):
            b.angle, b.position = q[j, 3 * k + 2], (q[j, 3 * k], q[j, 3 * k + 1])
            b.velocity, b.angular_velocity = (v[j, 3 * k], v[j, 3 * k + 1]), v[j, 3 * k + 2]
            b.force, b.torque = (1.0, -2.0), 0.5
        applied.apply(t, dt)
        landed = q[j] + dt * v[j]
        lt = terms(model, c, np.array([t]), landed[None], v[j][None])
        k_t = min(int(round(t / 1e-3)), len(times) - 1)
        want = lt.Q[0] + sum(plan.loads[cf.name]["coulomb"][k_t] * cf.Q[0] for cf in lt.coulomb)
        got = np.array([(b.force.x - 1.0, b.force.y + 2.0, b.torque - 0.5) for b in bodies]).reshape(-1)
        assert np.abs(got - want).max() <= 1e-9 * np.abs(want).max()
