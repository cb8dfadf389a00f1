"""The examples of real machines in specs/ (issue 20 item 9): a six-bar at constant speed, a 3-RRR
with its base motors, a slider-crank driven by its slider with gravity on, a five-bar with two
motors tracing a circle, a pick-and-place cycle with dwells. Each stage's pymunk validation passes,
and the same mechanism with its counterweights 10 % heavier fails it: the check has the power to
see a design error on every one of them, not only on the papers' examples."""

from __future__ import annotations

from pathlib import Path

import pytest

from balpipe import study as study_mod
from balpipe.loader import load
from test_moving_start import _counterweights_scaled, _validate_stage

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = [
    "custom_stephenson_six_bar_120rpm.yaml",
    "custom_3rrr_motors.yaml",
    "custom_slider_driven_slider_crank_gravity.yaml",
    "custom_five_bar_circle.yaml",
    "custom_pick_and_place_cycle.yaml",
]


@pytest.mark.parametrize("name", EXAMPLES)
def test_example_passes_and_a_ten_percent_counterweight_error_fails(name):
    st = study_mod.run(load(ROOT / "specs" / name).spec)
    assert st.ok, st.problems
    for s in st.stages:
        v = _validate_stage(st, s)
        assert v.passed, (name, s.stage.name, v.reasons)
    balanced = [s for s in st.stages if "force" in s.stage.balances and any(b.attachments for b in s.stage.model.bodies)]
    assert balanced, f"{name}: no stage with counterweights that claims force balance"
    for s in balanced:
        off = _validate_stage(st, s, model=_counterweights_scaled(s.stage.model, 1.1))
        assert not off.passed and off.force_residual > 0.01, (name, s.stage.name, off.force_residual)
