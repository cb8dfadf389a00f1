"""Issue 43: one torque-driven run proves both checks of a stage where it can
(:mod:`balpipe.validate.shared`), and never hides a design error: a counter-rotation 1 % off
is still measured by the position-driven run, as before (a counterweight 1 % off on the heavily
counterbalanced arm: tests/validate/test_fast_and_heavy_machines.py)."""

from __future__ import annotations

import dataclasses
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe.engine import analyse
from balpipe.validate import ValidationSettings, validate
from balpipe.validate.shared import proves_loads, stage_runs
from balpipe.validate.torque import torque_driven

sys.path.insert(0, str(Path(__file__).parents[1]))
from test_validate import GRID, arm_2r, five_bar, force_balanced_arm, reactionless_arm  # noqa: E402


def _peaks():
    un = analyse(arm_2r(), GRID)
    return (un.max_force, un.max_moment)


@pytest.mark.parametrize("make, expect", [
    (arm_2r, ()),
    (force_balanced_arm, ("force",)),
    (reactionless_arm, ("force", "moment")),
    (five_bar, ()),
])
def test_a_correct_design_is_proved_by_its_torque_driven_run(make, expect):
    """The torque-driven run at 100 iterations passes by ten times over and matches the analysed
    loads to a tenth of the tolerance: it is the only run, and both verdicts pass as the two runs'
    did, with the position-driven run's residuals' order of magnitude."""
    model = make()
    a = analyse(model, GRID)
    peaks = (a.max_force, a.max_moment) if not expect else _peaks()
    v, tq = stage_runs(model, a, peaks, ValidationSettings(), expect)
    assert v.proved_by == "torque-driven run" and v.to_json()["proved_by"] == "torque-driven run"
    assert v.status == tq.status == "pass"
    assert v.iterations == tq.iterations == 100 and v.dt == tq.dt
    assert max(v.force_residual, v.moment_residual) <= 1e-3
    assert any("proved by the torque-driven run" in n for n in v.notes)
    full = validate(model, a, peaks, ValidationSettings(shared_runs=False), expect)
    assert full.proved_by == "position-driven run" and full.passed
    assert v.measured.sum() == full.measured.sum()  # the same samples judged
    for what in expect:  # the claimed cancellation holds in the run that proves it
        assert getattr(v, f"{what}_peak") <= 0.01


@pytest.mark.parametrize("disc", ["disc1", "disc2"])
def test_a_one_percent_counter_rotation_error_is_not_proved_by_the_torque_run(disc):
    """A counter-rotation's inertia 1 % off: the torque-driven run tracks its plan (its efforts
    are the off design's own) but its moment is off the claimed analysis by the error's effect,
    above a tenth of the tolerance: never proved at the first effort, and the verdict is the
    position-driven run's (a fail where the effect exceeds the tolerance)."""
    good = reactionless_arm()
    claimed = analyse(good, GRID)
    b = good.body(disc)
    off = good.replace_body(dataclasses.replace(b, inertia=1.01 * b.inertia))
    peaks = _peaks()
    settings = ValidationSettings()
    v, tq = stage_runs(off, claimed, peaks, settings, ("force", "moment"))
    assert not proves_loads(tq, settings, ("force", "moment"))  # never ten times within the tolerance
    before = validate(off, claimed, peaks, ValidationSettings(shared_runs=False), ("force", "moment"))
    assert v.status == before.status
    assert v.moment_residual == pytest.approx(before.moment_residual, rel=1e-4)  # the error's effect, measured
    if disc == "disc1":  # the frame's disc: 2.8 % of the reference moment, the claim fails
        assert v.status == "fail" and v.proved_by == "position-driven run"
    else:  # 0.59 %, within the tolerance: a pass either way, here proved with twice the solver effort
        assert v.status == "pass" and 0.005 < v.moment_residual < 0.01


def test_the_torque_verdict_is_the_one_of_its_own_path():
    """Where the torque-driven try does not prove the loads, the torque-driven check is the one
    made at the position-driven run's step and iterations (this try reused where it is that run):
    the same numbers as without the shared try."""
    claimed = analyse(force_balanced_arm(), GRID)
    off = force_balanced_arm(1.01)
    peaks = _peaks()
    v, tq = stage_runs(off, claimed, peaks, ValidationSettings(), ("force",))
    alone = torque_driven(off, claimed, ValidationSettings(), economic=True, reference=peaks, dt=v.dt,
                          iterations=v.iterations)
    assert tq.status == alone.status and tq.iterations == alone.iterations
    assert tq.tracking_error_max == alone.tracking_error_max
    assert np.array_equal(tq.force, alone.force)


def test_a_moving_start_is_never_proved_by_the_torque_run():
    """A crank already turning at t0 (120 rpm, braking to rest): the torque-driven run leaves its
    first sample out of its load residuals, which the position-driven run measures after its
    run-in: the position-driven run is always made."""
    import math

    from balpipe.model import Driver
    from balpipe.motion import Polynomial
    from test_validate import T, slider_crank

    model = slider_crank()
    law = Polynomial.from_boundary((0.3, 4 * math.pi, 0.0), (0.3 + 2.0, 0.0, 0.0), T)
    model = dataclasses.replace(model, drivers=(Driver("crank", ("joint", "O"), law),))
    a = analyse(model, GRID)
    v, tq = stage_runs(model, a, (a.max_force, a.max_moment), ValidationSettings())
    assert v.proved_by == "position-driven run" and v.passed


@pytest.fixture(scope="module")
def idler():
    from balpipe import study
    from balpipe.loader import load

    return study.run(load(Path(__file__).resolve().parents[2] / "specs" / "paper000_rpr3_idler_loop.yaml").spec)


def _idler_runs(st, model=None, analysis=None):
    from balpipe.study import ratio_reference
    from balpipe.validation_stage import settings_for, simulated_model

    s = next(x for x in st.stages if x.stage.name == "counter_rotations")
    ref = ratio_reference(st.reference_stage(s))
    return s, stage_runs(simulated_model(model or s.stage.model), analysis or s.analysis,
                         (ref.force_peak, ref.moment_peak), settings_for(st), ("force", "moment"), reference=ref)


@pytest.fixture
def efforts(monkeypatch):
    """The solver efforts of the torque-driven runs that :func:`stage_runs` makes, in order, with
    "x" for a run that came apart."""
    import balpipe.validate.shared as shared

    made: list[str] = []
    original = shared._torque_driven_once

    def recording(*args, **kw):
        r = original(*args, **kw)
        made.append(f"{r.iterations}" + ("" if np.isfinite(r.tracking_error_max) else "x"))
        return r

    monkeypatch.setattr(shared, "_torque_driven_once", recording)
    return made


def test_four_times_the_effort_after_a_try_that_came_apart_proves_the_idler_loop(idler, efforts):
    """Paper 000's idler-loop counter-rotations stage: the torque-driven tries at 100 and 400
    iterations come apart, the one at 1600 holds together with its moment residual 4.9e-4, ten
    times within the tolerance: it proves the stage and is the torque-driven verdict. (Doubling,
    200 came apart too and 800 held at 2.4e-3, within the tolerance but not ten times: 1600 was made
    after it; the position-driven run needed 1600 and 3200 iterations to show its own convergence.)"""
    s, (v, tq) = _idler_runs(idler)
    assert efforts == ["100x", "400x", "1600"]
    assert v.proved_by == "torque-driven run" and v.status == "pass" and v.iterations == 1600
    assert v.timing["total_s"] > 0.0  # the tries that came apart count in the page's run time
    assert max(v.force_residual, v.moment_residual) <= 1e-3 and v.moment_peak <= 0.01
    assert tq.status == "pass" and tq.iterations == 1600 and tq.resolution >= 100


def _spec_stage_runs(st, name: str):
    """:func:`stage_runs` of the stage ``name`` of the study ``st``, as the build runs it
    (relative to the stage's reference loads), and the spec's validation settings."""
    from balpipe.validation_stage import settings_for, simulated_model

    s = next(x for x in st.stages if x.stage.name == name)
    ref = s.metrics.reference_loads
    expect = tuple(x for x in ("force", "moment") if x in s.stage.balances)
    v, tq = stage_runs(simulated_model(s.stage.model), s.analysis, (ref.force_peak, ref.moment_peak), settings_for(st),
                       expect, reference=ref)
    return v, tq, settings_for(st)


def test_the_first_try_that_holds_together_proves_the_stage_where_it_passes_ten_times(studies, efforts):
    """Paper 002's decoupled stage: the try at 100 iterations comes apart, the one at 400 holds
    together and passes by ten times over: it proves the stage, without a run at twice its effort.
    (Before, the first try that held together after one that came apart was never taken as the
    proof: it was doubled, and the stage proved at 200 was run at 400 as well.)"""
    v, tq, settings = _spec_stage_runs(studies("paper002_decoupling.yaml"), "decoupled")
    assert efforts == ["100x", "400"]
    assert v.proved_by == "torque-driven run" and v.passed and v.iterations == tq.iterations == 400
    assert max(v.force_residual, v.moment_residual) <= settings.tolerance / 10


def test_a_one_percent_counter_rotation_error_on_the_idler_loop_still_fails(idler):
    """The same stage with its heaviest gear's inertia 1 % off, analysed as it is and claiming the
    moment balance: the torque-driven run's loads show the claim false, so they prove nothing, and
    the position-driven run fails it."""
    s = next(x for x in idler.stages if x.stage.name == "counter_rotations")
    gears = [b for b in s.stage.model.bodies if b.kind == "gear" and b.inertia > 0]
    heaviest = max(gears, key=lambda b: b.inertia)
    off = s.stage.model.replace_body(dataclasses.replace(heaviest, inertia=1.01 * heaviest.inertia))
    a_off = analyse(off, s.analysis.t, s.analysis.gravity, s.analysis.moment_point)
    _, (v, tq) = _idler_runs(idler, off, a_off)
    assert v.proved_by == "position-driven run"
    assert v.status == "fail" and any("moment not balanced" in r for r in v.reasons), v.reasons


def test_the_torque_driven_run_doubles_its_effort_until_its_loads_converge(studies):
    """Paper 000's Scott-Russell stage, from rest: the torque-driven run at 100 and at 200 solver
    iterations is within the tolerance but its loads still change; at 400 they are those of 200 to
    a tenth of the tolerance, which proves the stage (the position-driven run's own convergence
    test). Before, one doubling was all, and the position-driven run it fell back on took 200 to
    1600 iterations for the same verdict."""
    v, tq, settings = _spec_stage_runs(studies("paper000_rpr3_scott_russell.yaml"), "scott_russell")
    assert v.passed and tq.passed and v.proved_by == "torque-driven run"
    assert v.iterations == 400 and "the run with 200 solver iterations gave the same loads" in v.notes[0]
    assert tq.iterations == 100  # the torque-driven verdict: the first run, calibrated
    assert v.timing["total_s"] > 0.0  # the runs at 200 and 400 iterations count in the page's run time
    assert settings.tolerance / 10 < v.moment_residual <= settings.tolerance
