"""Issue 43: the free-floating demonstration runs where the spec claims or asks for it
(:func:`balpipe.validation_stage.reactionless_stages`): every stage when the spec asks
(``validation.reactionless: true``), none when it turns it off, and by default, in a paper's
spec, the stages claiming to cancel force and moment with their reference stage. The
demonstration carries no verdict: every stage is still validated by its own runs."""

from __future__ import annotations

import copy

import pytest

from balpipe import validation_stage
from balpipe.validation_stage import reactionless_stages


def _names(st, ks):
    return [st.stages[k].stage.name for k in ks]


def test_a_papers_spec_shows_its_reactionless_stage_beside_its_unbalanced_one(studies):
    st = studies("scott_russell.yaml")
    assert st.spec.paper is not None and st.spec.validation.reactionless is None
    assert _names(st, reactionless_stages(st)) == ["unbalanced", "full"]  # not the force-balanced stage


@pytest.mark.parametrize("name", ["offset_slider_crank.yaml", "paper000_rpr3_scott_russell.yaml"])
def test_a_papers_spec_that_claims_no_reactionless_stage_runs_none(studies, name):
    st = studies(name)
    assert not any("force" in s.stage.balances and "moment" in s.stage.balances for s in st.stages)
    assert reactionless_stages(st) == [] and not validation_stage.reactionless_enabled(st)


def test_a_spec_that_asks_gets_every_stage(studies):
    st = studies("paper004_five_bar.yaml")
    assert st.spec.validation.reactionless is True
    assert reactionless_stages(st) == list(range(len(st.stages)))


def test_a_spec_that_turns_it_off_or_names_no_paper_gets_none(studies):
    assert reactionless_stages(studies("paper003_com_planning.yaml")) == []  # reactionless: false
    st = studies("custom_four_bar_balancing.yaml")  # a stage claims both, but no paper and no request
    assert st.spec.paper is None and any("moment" in s.stage.balances for s in st.stages)
    assert reactionless_stages(st) == []


def test_every_stage_is_still_validated_when_the_demonstration_shows_two(studies, monkeypatch):
    """The demonstration's selection touches no verdict: each stage's own runs are all made."""
    shared = studies("scott_russell.yaml")
    st = copy.copy(shared)  # the shared study is only read: its stages copied, their results set here
    st.stages = [copy.copy(s) for s in shared.stages]
    st.problems, st.unconfirmed = [], []
    ran, floated = [], []

    class Done:
        passed, reasons = True, []

    monkeypatch.setattr(validation_stage, "_stage_runs", lambda k, study: ran.append(k) or (Done(), Done()))
    monkeypatch.setattr(validation_stage, "_floating_run", lambda k, *a: floated.append(k) or object())
    validation_stage.simulate_study(st)
    assert ran == [0, 1, 2] and floated == [0, 2]
    assert st.reactionless.names == ["unbalanced", "full"]


def test_the_demonstration_runs_at_the_motions_own_step():
    """A spec's validation.dt is its checks' step (chosen for their residual limits); the
    demonstration, which has no verdict, runs at DEMONSTRATION_STEP times the motion's default
    step (on the analysis grid), and still tells the reactionless arm (at rest) from the
    unbalanced one (pushed around), each close to its exact conservation solution."""
    import sys
    from pathlib import Path

    from balpipe.engine import analyse
    from balpipe.validate import ValidationSettings, default_settings, free_floating
    from balpipe.validate.floating import DEMONSTRATION_STEP
    from balpipe.validate.settings import _step_grid

    sys.path.insert(0, str(Path(__file__).parent))
    from test_validate import GRID, arm_2r, reactionless_arm

    runs = {}
    for name, make in (("unbalanced", arm_2r), ("reactionless", reactionless_arm)):
        model = make()
        a = analyse(model, GRID)
        ff = free_floating(model, a, settings=ValidationSettings(dt=1e-4))
        step = _step_grid(GRID, DEMONSTRATION_STEP * default_settings(model, a)[0])[0]
        assert ff.dt == pytest.approx(step, rel=1e-9) and ff.dt > default_settings(model, a)[0] > 1e-4
        if ff.method == "pymunk":  # the reactionless arm's gears come apart on a free base at either step
            assert ff.reference_difference[0] < 1e-4 * ff.reference_max_drift
        runs[name] = ff
    assert runs["unbalanced"].method == "pymunk"
    assert runs["unbalanced"].max_drift > 1e6 * runs["reactionless"].max_drift
