"""The simulation loop's shortcuts (issue 23, item 2) give the same runs, bit for bit, and the
torque-driven run's cheaper tries keep its verdict.

* Body states are appended to one pymunk.batch buffer per step and converted once at the end:
  the recorded rows are the bodies' own states.
* Revolute actuators' torques are summed per body before the loop (in the actuators' order, as
  ``_Actuator.apply`` adds them up step by step): the run is the same to the last bit.
* ``torque_driven(economic=True)`` doubles the solver iterations while a try comes apart and
  keeps the first try that holds together only when it passes by ten times over.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

from balpipe.engine import analyse
from balpipe.validate import ValidationSettings, simulate
from balpipe.validate import run as run_mod
from balpipe.validate import torque as torque_mod
from balpipe.validate.settings import ITERATIONS
from balpipe.validate.torque import floored_model, torque_driven
from test_validate import GRID, arm_2r, five_bar, planetary, reactionless_arm


def _torque_run(model, **kw):
    a = analyse(model, GRID)
    sim_model, _ = floored_model(model, 0.1)
    efforts = {k: np.asarray(v, dtype=float) for k, v in analyse(sim_model, GRID).efforts.items()}
    return simulate(sim_model, a, float(GRID[1] - GRID[0]), 100, efforts=efforts, measure_with=model,
                    mass_floor=0.1, **kw)


def test_recorded_states_are_the_bodies_states():
    model = five_bar()
    a = analyse(model, GRID)
    r = simulate(model, a, 1e-3, 100, mass_floor=0.1)
    assert r.poses.shape == (len(r.t), len(model.bodies), 3)
    last = np.array([(b.position.x, b.position.y, b.angle) for b in r.sim.bodies])
    assert np.array_equal(r.poses[-1], last)
    assert np.isfinite(r.force).all() and np.isfinite(r.moment).all()


def test_summed_torques_give_the_step_by_step_run_bit_for_bit(monkeypatch):
    for model in (arm_2r(), reactionless_arm()):
        summed = _torque_run(model)
        # the per-step path: every actuator applied in turn before each step
        monkeypatch.setattr(run_mod, "_actuator_inputs",
                            lambda acts, efforts, settle, n: ([], [(a, np.asarray(efforts[a.name], dtype=float))
                                                                   for a in acts]))
        stepwise = _torque_run(model)
        monkeypatch.undo()
        for name in ("force", "moment", "poses", "momentum"):
            assert np.array_equal(getattr(summed, name), getattr(stepwise, name)), name
        for k, v in summed.driver_error.items():
            assert np.array_equal(v, stepwise.driver_error[k])


def test_a_run_that_comes_apart_stops_early():
    """The checks against the plan are compared a block at a time: the run still ends within
    CHECK_BLOCK checks (ten steps apart) of the first one that strays."""
    model = arm_2r()
    a = analyse(model, GRID)
    half = len(GRID) // 2
    moved = a.q.copy()
    moved[half:, :, 2] += 0.1  # the plan turns away half-way: the run strays from it there
    with pytest.raises(FloatingPointError, match="came apart") as e:
        simulate(model, dataclasses.replace(a, q=moved), 1e-3, 100, abort=(1e-2, 1.0))
    t_stop = float(str(e.value).split("t = ")[1].split(" s")[0])
    assert GRID[half] <= t_stop <= GRID[half] + 10 * 1e-3  # the first check that strays, named


def _tries(monkeypatch, apart_below: int, pass_from: int):
    """Record the solver iterations of each torque-driven try; tries below ``apart_below`` are made
    to come apart and those from ``pass_from`` on pass by ten times over."""
    real = torque_mod._torque_driven_once
    seen = []

    def fake(model, analysis, settings=None, **kw):
        it = kw.get("iterations")
        seen.append((it, kw.get("trial", False)))
        r = real(model, analysis, settings, **kw)
        if it < apart_below:
            r.tracking_error_max, r.passed = math.inf, False
        elif it < pass_from:
            r.tracking_error_max = settings.tracking_tolerance / 2  # holds together, not ten times over
        return r

    monkeypatch.setattr(torque_mod, "_torque_driven_once", fake)
    return seen


def test_torque_tries_double_while_they_come_apart(monkeypatch):
    model = reactionless_arm()
    a = analyse(model, GRID)
    seen = _tries(monkeypatch, apart_below=400, pass_from=400)
    r = torque_driven(model, a, ValidationSettings(), economic=True, dt=1e-3, iterations=3200)
    assert seen == [(ITERATIONS, True), (2 * ITERATIONS, True), (4 * ITERATIONS, True)]
    assert r.passed and r.iterations == 4 * ITERATIONS


def test_a_try_that_holds_together_without_ten_times_margin_goes_to_the_full_effort(monkeypatch):
    model = reactionless_arm()
    a = analyse(model, GRID)
    seen = _tries(monkeypatch, apart_below=200, pass_from=10**9)
    r = torque_driven(model, a, ValidationSettings(), economic=True, dt=1e-3, iterations=3200)
    assert seen == [(ITERATIONS, True), (2 * ITERATIONS, True), (3200, False)]
    assert r.iterations == 3200


def test_steps_straight_into_chipmunk_give_pymunks_run_bit_for_bit(monkeypatch):
    """``_Stepper.first`` hands the steps after pymunk's first to ``cpSpaceStep``: the same run
    as ``space.step`` every step (position-driven with gears, and torque-driven)."""
    model = five_bar()
    a = analyse(model, GRID)
    real = run_mod._Stepper.first
    handed = []

    def recorded(self, dt):
        handed.append(real(self, dt))
        return handed[-1]

    monkeypatch.setattr(run_mod._Stepper, "first", recorded)
    direct = simulate(model, a, 1e-3, 100, mass_floor=0.1, feedforward=True)
    torque = _torque_run(arm_2r())
    assert len(handed) == 2 and all(fn is run_mod._cp.cpSpaceStep for fn, _ in handed)  # the direct path
    steps = []

    def through_pymunk(self, dt):
        self.space.step(dt)
        steps.append(1)
        return lambda space, dt: (steps.append(1), space.step(dt)), self.space

    monkeypatch.setattr(run_mod._Stepper, "first", through_pymunk)
    slow = simulate(model, a, 1e-3, 100, mass_floor=0.1, feedforward=True)
    slow_torque = _torque_run(arm_2r())
    monkeypatch.undo()
    assert len(steps) == len(slow.t) + len(slow_torque.t)  # every step through pymunk
    for fast, ref in ((direct, slow), (torque, slow_torque)):
        for name in ("force", "moment", "poses", "momentum"):
            assert np.array_equal(getattr(fast, name), getattr(ref, name)), name


def test_the_meshes_placed_through_chipmunk_give_pymunks_run_bit_for_bit(monkeypatch):
    """``_Mesh.update`` reads the bodies and sets the groove through Chipmunk's accessors: the same
    run as through pymunk's properties (a planetary gear on a moving carrier)."""
    from balpipe.validate import space as space_mod

    model = planetary()
    a = analyse(model, GRID)
    fast = simulate(model, a, 1e-3, 100, mass_floor=0.1, feedforward=True)
    assert fast.sim.meshes  # the gear pair is a mesh

    def through_pymunk(self, dt):
        def pred(body):
            th = body.angle + dt * body.angular_velocity
            cog = body.center_of_gravity
            g = body.local_to_world(cog)
            v = body.velocity
            o = space_mod._rot(th, cog)
            return g.x + dt * v.x - o[0], g.y + dt * v.y - o[1], th

        xc, yc, thc = pred(self.c)
        xa, ya, tha = pred(self.a)
        xb, yb, thb = pred(self.b)
        tha_r = self.ta.angle + dt * self.ta.angular_velocity
        thb_r = self.tb.angle + dt * self.tb.angular_velocity
        wa, wb = space_mod._rot(thc, self.oa), space_mod._rot(thc, self.ob)
        wa, wb = (xc + wa[0], yc + wa[1]), (xc + wb[0], yc + wb[1])
        dx, dy = wb[0] - wa[0], wb[1] - wa[1]
        d = math.hypot(dx, dy)
        u = (dx / d, dy / d)
        t = (-u[1], u[0])
        R = self.ratio
        p, q = R * d / (R - 1.0), d / (R - 1.0)
        err = (thb_r - thc) - R * (tha_r - thc) - self.phase
        P = (wa[0] + p * u[0], wa[1] + p * u[1])
        anchor = (P[0] + q * err * t[0], P[1] + q * err * t[1])
        L = self.half_length
        self.groove.groove_a = space_mod._unrot(tha, (P[0] - L * u[0] - xa, P[1] - L * u[1] - ya))
        self.groove.groove_b = space_mod._unrot(tha, (P[0] + L * u[0] - xa, P[1] + L * u[1] - ya))
        self.groove.anchor_b = space_mod._unrot(thb, (anchor[0] - xb, anchor[1] - yb))

    monkeypatch.setattr(space_mod._Mesh, "update", through_pymunk)
    slow = simulate(model, a, 1e-3, 100, mass_floor=0.1, feedforward=True)
    for name in ("force", "moment", "poses", "momentum"):
        assert np.array_equal(getattr(fast, name), getattr(slow, name)), name


def test_the_fixed_frames_check_in_floats_gives_numpys_answer():
    """``_strayed_fixed`` (the fixed frame's check in Python floats) answers as ``_strayed``
    (numpy's) row by row: random states near and far from the plan, deviations exactly at the
    limit, signed zeros, infinities and NaNs in every coordinate."""
    rng = np.random.default_rng(7)
    limit, scale = 0.25, 2.0
    specials = [np.nan, np.inf, -np.inf, -0.0, 0.0, limit * scale, -limit * scale, limit, -limit,
                np.nextafter(limit * scale, np.inf), np.nextafter(limit, np.inf), 1e308, -1e308]
    for trial in range(300):
        m, nb = int(rng.integers(1, 6)), int(rng.integers(1, 4))
        q_ref = rng.normal(size=(m, nb, 3)) * rng.choice([0.0, 1.0])
        states = np.zeros((m, nb + int(rng.integers(0, 2)), 6))
        states[:, :nb, :3] = q_ref + rng.normal(size=(m, nb, 3)) * rng.choice([0.0, 0.1, 1.0])
        for _ in range(int(rng.integers(0, 4))):  # special values, or a deviation of exactly them
            i, j, c = int(rng.integers(m)), int(rng.integers(nb)), int(rng.integers(3))
            v = float(rng.choice(specials))
            states[i, j, c] = v if rng.random() < 0.5 else q_ref[i, j, c] + v
        if rng.random() < 0.3:
            q_ref[int(rng.integers(m)), int(rng.integers(nb)), int(rng.integers(3))] = float(rng.choice(specials))
        with np.errstate(all="ignore"):
            expected = run_mod._strayed(states, nb, None, q_ref, (limit, scale))
        assert run_mod._strayed_fixed(states, nb, q_ref, (limit, scale)) == expected, trial
