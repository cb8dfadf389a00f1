"""The position-driven run's inertial forces (balpipe.validate.feedforward), the convergence test on
the samples that enter the verdict, and the torque-driven run's floor share from the analysis."""

from __future__ import annotations

import dataclasses
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.validate import ValidationSettings, validate
from balpipe.validate.extend import continued
from balpipe.validate.feedforward import inertial_forces, periodic_times
from balpipe.validate.run import simulate
from balpipe.validate.settings import _step_grid
from balpipe.validate.torque import _plan
from test_validate import GRID, gear_train

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _stages(name: str):
    spec = load(SPECS / f"{name}.yaml").spec
    t = np.linspace(0.0, spec.motion.duration, 101)
    stages = {s.name: s for s in registry.balance(spec).stages}
    return stages, t


def test_inertial_forces_follow_a_cubic_velocity_exactly():
    """The derivative of the cubic Hermite interpolant of v (slopes a) is exact for a cubic v."""
    t = np.linspace(0.0, 1.0, 5)
    v = np.stack([t**3 - t, 2 * t**2, 0.5 * t**3], axis=1)[:, None, :]
    a = np.stack([3 * t**2 - 1, 4 * t, 1.5 * t**2], axis=1)[:, None, :]
    times = np.linspace(-0.1, 1.1, 37)
    f = inertial_forces(SimpleNamespace(t=t, v=v, a=a), times, np.array([2.0]), np.array([0.5]), np.array([0.0, -9.81]))
    tt = np.clip(times, 0.0, 1.0)  # outside the interval: the nearest end's acceleration
    assert np.allclose(f[:, 0, 0], 2.0 * (3 * tt**2 - 1), atol=1e-12)
    assert np.allclose(f[:, 0, 1], 2.0 * (4 * tt + 9.81), atol=1e-12)
    assert np.allclose(f[:, 0, 2], 0.5 * 1.5 * tt**2, atol=1e-12)
    assert np.allclose(periodic_times(np.array([-0.25, 0.0, 0.5, 1.0]), 0.0, 1.0), [0.75, 0.0, 0.5, 1.0])


def test_feedforward_changes_the_constraint_impulses_not_the_motion():
    """The drivers impose the motion: with the solver converged the loads measured from the
    momenta are the same with and without the inertial forces (paper 004's counterweights stage,
    relative to the unbalanced stage's peaks)."""
    stages, t = _stages("paper004_five_bar")
    first = analyse(stages["unbalanced"].model, t)
    model = stages["counterweights"].model
    a = analyse(model, t)
    model = continued(model, a)
    dt, _, _ = _step_grid(t, 5e-4)
    runs = [simulate(model, a, dt, 800, feedforward=ff, mass_floor=0.1) for ff in (False, True)]
    F0, M0 = first.max_force, first.max_moment
    assert np.max(np.linalg.norm(runs[0].force - runs[1].force, axis=1)) < 1e-4 * F0
    assert np.max(np.abs(runs[0].moment - runs[1].moment)) < 1e-3 * M0


def test_feedforward_needs_fewer_solver_iterations():
    """Paper 004's counterweights stage: 400 iterations without, 100 with (measured), both passing."""
    stages, t = _stages("paper004_five_bar")
    first = analyse(stages["unbalanced"].model, t)
    model = stages["counterweights"].model
    a = analyse(model, t)
    peaks = (first.max_force, first.max_moment)
    off = validate(model, a, peaks, ValidationSettings(feedforward=False), expect=("force",))
    on = validate(model, a, peaks, ValidationSettings(), expect=("force",))
    assert off.passed and on.passed
    assert on.iterations < off.iterations
    assert on.force_residual <= off.force_residual


def test_idler_loop_counterweights_converge_without_the_largest_count():
    """The idler loop's counterweights stage at the spec's step: converged at 1600 iterations (the
    change from 800 within tolerance / 10 on the samples that enter the residuals), moment residual
    0.0025; without the inertial forces it ran to 3200 (0.0019, not converged)."""
    spec = load(SPECS / "paper000_rpr3_idler_loop.yaml").spec
    stages = {s.name: s for s in registry.balance(spec).stages}
    t = np.linspace(0.0, spec.motion.duration, 101)
    first = analyse(stages["unbalanced"].model, t)
    model = stages["counterweights"].model
    v = validate(model, analyse(model, t), (first.max_force, first.max_moment), ValidationSettings(dt=spec.validation.dt),
                 expect=("force",))
    assert v.passed, v.reasons
    assert v.iterations <= 1600
    assert not any("did not converge" in n for n in v.notes)


def test_floor_share_over_the_steps_agrees_with_the_analysis_samples():
    """The floor parts' share of the effort (over every step time, the bare model analysed on the
    same times) agrees, on a smooth law, with the share read at the analysis samples (the
    floored model's efforts there less the analysis' own)."""
    model = gear_train()
    a = analyse(model, GRID)
    plan = _plan(model, a, ValidationSettings(), None, 5e-4)
    assert plan.idx is not None and plan.floored
    at_samples = analyse(plan.sim_model, GRID).efforts
    peak = max(float(np.max(np.abs(v))) for v in a.efforts.values())
    share = max(float(np.max(np.abs(at_samples[k] - a.efforts[k]))) for k in a.efforts) / peak
    assert plan.share == pytest.approx(share, rel=1e-3)
    assert plan.share > 0.05