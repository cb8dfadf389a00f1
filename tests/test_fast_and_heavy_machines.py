"""A check that never cries wolf, on machines unlike the examples: a 90-degree V-twin at 6000
rpm (specs/custom_v_twin_6000rpm.yaml) and a SCARA-like 3R arm counterbalanced to nearly eight
times its own mass, with counter-rotating discs on its moving links
(tests/fixtures/scara_3r_counterbalanced.yaml).

Both, correct, validate at the default settings: every stage's position-driven and torque-driven
runs pass (none unconfirmed). A 10 % counterweight error still fails (``status == "fail"``: a
claim shown false). A run that cannot resolve its own error within the validator's budget is
``unconfirmed`` with the setting that would resolve it, and the build exits 0 on it, 3 under
``--strict``. The auxiliary gears that pymunk needs for a coaxial disc on a moving link are part
of the machine the torque-driven run's efforts describe: the simulated kinetic energy equals the
effort model's at every state.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe import study as study_mod
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.report.verdict import verdict
from balpipe.study import ratio_reference
from balpipe.validate import ValidationSettings, validate
from balpipe.validate.space import build_space
from balpipe.validate.torque import auxiliary_gear_parts, floored_model, torque_driven
from balpipe.validation_stage import settings_for, simulated_model
from test_moving_start import _counterweights_scaled, _validate_stage

ROOT = Path(__file__).resolve().parents[1]
V_TWIN = ROOT / "specs" / "custom_v_twin_6000rpm.yaml"
SCARA = ROOT / "tests" / "fixtures" / "scara_3r_counterbalanced.yaml"


@pytest.fixture(scope="module")
def v_twin():
    return study_mod.run(load(V_TWIN).spec)


@pytest.fixture(scope="module")
def scara():
    return study_mod.run(load(SCARA).spec)


def _torque(st, s, model=None, analysis=None, settings=None, **kw):
    ref = ratio_reference(st.reference_stage(s))
    return torque_driven(simulated_model(model or s.stage.model), analysis or s.analysis, settings or settings_for(st),
                         economic=True, reference=(ref.force, ref.moment), **kw)


def _stage(st, name):
    return next(s for s in st.stages if s.stage.name == name)


@pytest.mark.parametrize("which", ["v_twin", "scara"])
def test_correct_machines_validate_at_default_settings(which, request):
    st = request.getfixturevalue(which)
    assert st.ok, st.problems
    if which == "v_twin":  # thousands of rpm
        assert abs(st.stages[0].analysis.v[:, 0, 2]).max() == pytest.approx(2 * np.pi * 100, rel=1e-9)
    else:  # counterweights several times the arm's own mass
        arm = sum(b.mass_properties()[0] for b in st.stages[0].stage.model.bodies)
        added = sum(a.mass for b in st.stages[-1].stage.model.bodies for a in b.attachments)
        assert added > 5 * arm
    for s in st.stages:
        v = _validate_stage(st, s)
        assert v.status == "pass", (s.stage.name, v.reasons, v.remedy)
        tq = _torque(st, s, dt=v.dt, iterations=v.iterations)
        assert tq.status == "pass", (s.stage.name, tq.reasons, tq.remedy, tq.notes)


@pytest.mark.parametrize("which, stage", [("v_twin", "complete:counterweights"), ("scara", "counter_rotations")])
def test_a_ten_percent_counterweight_error_fails(which, stage, request):
    """The stage's design with every counterweight 10 % heavy, claiming what the stage claims, on
    its own motion: the simulation shows the claimed cancellation false (it agrees with the
    analysis of that design, which does not cancel the force either)."""
    st = request.getfixturevalue(which)
    s = _stage(st, stage)
    off_model = _counterweights_scaled(s.stage.model, 1.1)
    ref = ratio_reference(st.reference_stage(s))
    expect = tuple(x for x in ("force", "moment") if x in s.stage.balances)
    off = validate(off_model, analyse(off_model, s.analysis.t), (ref.force_peak, ref.moment_peak), settings_for(st),
                   expect, reference=ref)
    assert off.status == "fail" and not off.unconfirmed and off.force_peak > 0.01, (off.reasons, off.remedy)
    assert off.force_residual < 0.01 and any("force not balanced" in r for r in off.reasons)


def test_the_arms_efforts_with_a_ten_percent_counterweight_error_leave_the_plan(scara):
    """The torque-driven run of the true arm driven by the efforts of a model whose counterweights
    are 10 % heavy: the motion leaves the plan by more than the tolerance at an error that does
    not shrink with the step, a failure (not unconfirmed)."""
    s = _stage(scara, "counter_rotations")
    wrong = _counterweights_scaled(s.stage.model, 1.1)
    r = _torque(scara, s, analysis=analyse(wrong, s.analysis.t), analytic_model=simulated_model(wrong),
                calibrate=False)
    assert r.status == "fail" and r.tracking_error_max > 1e-2, (r.reasons, r.notes)


def test_the_auxiliary_gears_are_in_the_machine_the_efforts_drive(scara):
    """Kinetic energy of every pymunk body (the auxiliary gears included) equals that of the
    model the efforts come from (floors and auxiliary-gear parts added), at states of the motion;
    without the auxiliary-gear parts it does not."""
    s = _stage(scara, "counter_rotations")
    floor = ValidationSettings().mass_floor
    sim_model, _ = floored_model(simulated_model(s.stage.model), floor)

    def kinetic(model, t):
        a = analyse(model, np.array([t]))
        return sum(0.5 * (b.mass_properties()[0] * (v[0] ** 2 + v[1] ** 2) + b.mass_properties()[2] * v[2] ** 2)
                   for b, v in zip(model.bodies, a.v[0]))

    for t in (0.1, 0.3, 0.45):
        a = analyse(sim_model, np.array([t]))
        parts = auxiliary_gear_parts(sim_model, floor, a.q[0])
        assert sorted(parts) == ["disc2", "disc3", "link1", "link2", "link3"]
        effort_model = sim_model
        for name, extra in parts.items():
            effort_model = effort_model.replace_body(effort_model.body(name).with_attachments(*extra))
        sim = build_space(sim_model, a.q[0], a.v[0], mass_floor=floor, drive=False)
        assert len(sim.auxiliary) == 4
        ke_sim = sum(0.5 * (b.mass * b.velocity.length_squared + b.moment * b.angular_velocity ** 2)
                     for b in sim.space.bodies)
        assert ke_sim == pytest.approx(kinetic(effort_model, t), rel=1e-9)
        assert abs(ke_sim / kinetic(sim_model, t) - 1) > 0.01
