"""Issue 7, item 2: relative figures divide by a reference with an absolute floor from the
model's own scale, so a spec that is already balanced does not fail on noise over noise."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe import loader, study
from balpipe.engine import analyse
from balpipe.engine.load_reference import FLOOR_FRACTION, gross_inertial_loads, load_reference

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "reactionless_arm.yaml"

sys.path.insert(0, str(Path(__file__).parents[1]))
from conftest import slider_crank_spec  # noqa: E402
from test_validate import GRID, arm_2r, five_bar, geared_disc, reactionless_arm, slider_crank  # noqa: E402


def test_balanced_one_stage_spec_has_no_false_failure():
    """Failed on the code before the fix: ratios 1.0 and reactions-vs-momentum 5e3 "of the
    unbalanced peak" (both routes are round-off)."""
    st = study.run(loader.load(FIXTURE).spec)
    assert len(st.stages) == 1
    an = st.unbalanced.analysis
    assert an.max_force < 1e-12 and an.max_moment < 1e-12  # already balanced: round-off
    assert st.problems == []
    m = study.stage_metrics(st.unbalanced, st.unbalanced, 1e-9)
    assert m.force_ratio < 1e-12 and m.moment_ratio < 1e-12
    ref = st.reference
    assert ref.force_basis == "floor" and ref.moment_basis == "floor"
    assert ref.force == pytest.approx(FLOOR_FRACTION * ref.force_scale)
    assert st.checks["reactions_vs_momentum"] < 1e-9
    assert m.force_balanced and m.moment_balanced
    assert st.checks["reference"]["force_basis"] == "floor"


def test_balanced_one_stage_spec_builds_with_exit_0(tmp_path):
    """The acceptance: the whole build, pymunk validation included, exits 0; results.json and
    the page say which reference the figures are relative to."""
    r = subprocess.run([sys.executable, "-m", "balpipe", "build", str(FIXTURE), "-o", str(tmp_path / "out")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    res = json.loads((tmp_path / "out" / "reactionless_arm" / "results.json").read_text())
    assert res["status"] == "ok" and res["problems"] == []
    ref = res["checks"]["reference"]
    assert ref["force_basis"] == "floor" and ref["moment_basis"] == "floor"
    assert ref["gross_inertial_force"] > 10 and ref["unbalanced_force_peak"] < 1e-12
    v = res["validation"]["unbalanced"]
    assert v["passed"] and v["reference_basis"] == "force: floor; moment: floor"
    assert v["force_reference"] == pytest.approx(ref["force"])
    page = (tmp_path / "out" / "reactionless_arm" / "index.html").read_text()
    assert "of the gross inertial force" in page and "already (nearly) balanced" in page


@pytest.mark.parametrize("make", [arm_2r, five_bar, slider_crank, geared_disc])
def test_reference_is_the_unbalanced_peak_for_unbalanced_mechanisms(make):
    model = make()
    a = analyse(model, GRID)
    ref = load_reference(model, a)
    assert ref.force_basis == ref.moment_basis == "unbalanced peak" and not ref.floored
    assert ref.force == a.max_inertial_force and ref.moment == a.max_inertial_moment


@pytest.mark.parametrize("seed", range(4))
def test_gross_loads_bound_the_shaking_loads_and_scale_with_mass(seed):
    """|sum m a| <= sum |m a| (and the same for the moment) for random slider-cranks, every
    stage; scaling every mass and inertia by k scales the gross loads by k."""
    scales = {}
    for k in (1.0, 3.0):
        st = study.run(slider_crank_spec(np.random.default_rng(seed), mass_scale=k))
        for s in st.stages:
            sf, sm = gross_inertial_loads(s.stage.model, s.analysis)
            assert s.analysis.max_inertial_force <= sf * (1 + 1e-12)
            assert s.analysis.max_inertial_moment <= sm * (1 + 1e-12)
            scales[k, s.stage.name] = np.array([sf, sm])
    for (k, name), v in scales.items():
        np.testing.assert_allclose(v, k * scales[1.0, name], rtol=1e-9)


def test_reactionless_arm_model_gets_the_floor():
    model = reactionless_arm()
    a = analyse(model, GRID)
    ref = load_reference(model, a)
    assert ref.floored and "gross inertial force" in ref.describe("force")
    sf, sm = gross_inertial_loads(model, a)
    assert ref.force == pytest.approx(0.01 * sf) and ref.moment == pytest.approx(0.01 * sm)


YOKE = """\
name: Scotch yoke on its axis
mechanism:
  template: custom
  frame_points: {O: [0, 0], G: [0, 0]}
  bodies:
    - {name: crank, mass: 0.5 kg, com: [0.02, 0], inertia: 0.0001 kg m^2, pose: [0, 0, 0], points: {O: [0, 0], A: [0.04, 0]}}
    - {name: block, mass: 0.2 kg, com: [0, 0], inertia: 0.00002 kg m^2, pose: [0.04, 0, 0], points: {A: [0, 0]}}
    - {name: yoke, mass: 1.5 kg, com: [0.10, 0], inertia: 0.004 kg m^2, pose: [0.04, 0, 0], points: {S: [0, 0]}}
  joints:
    - {type: revolute, name: O, a: frame, b: crank, point_a: O, point_b: O}
    - {type: revolute, name: A, a: crank, b: block, point_a: A, point_b: A}
    - {type: prismatic, name: slot, guide: yoke, slider: block, point_guide: S, axis: [0, 1]}
    - {type: prismatic, name: guide, guide: frame, slider: yoke, point_guide: G, axis: [1, 0]}
  drivers:
    - {name: crank, joint: O}
motion:
  cycles: 1
  drive:
    crank: {law: constant_speed, from: 0 deg, speed: 900 rpm}
analysis: {samples: 121}
validation: {enabled: false}
"""


def test_a_machine_without_shaking_moment_still_has_a_moment_floor():
    """A Scotch yoke on its axis at constant speed: every mass moves along a line through O, so
    its shaking moment is round-off (~1e-15 N m) and sum |r x a| is round-off too. The moment
    figures are relative to 1 % of sum m |r| |a| (a few N m), so the reactions agree with the
    momentum rates and the moment reads as cancelled, not as '150 %' of round-off."""
    from balpipe.loader import load_text

    spec, _ = load_text(YOKE, "yoke.yaml")
    st = study.run(spec)
    un = st.unbalanced
    ref = load_reference(un.stage.model, un.analysis)
    sf, sm = gross_inertial_loads(un.stage.model, un.analysis)
    assert un.analysis.max_inertial_moment < 1e-12 * un.analysis.max_inertial_force
    assert ref.moment_basis != "unbalanced peak" and ref.moment == pytest.approx(FLOOR_FRACTION * sm) and sm > 1.0
    assert ref.force_basis == "unbalanced peak"
    assert st.problems == [] and st.checks["reactions_vs_momentum"] <= 1e-9


def test_a_moment_already_zero_reads_zero_before_and_after_not_cancelled():
    """The yoke's crank given a counterweight by optimal partial balancing: the shaking force is
    reduced, and the shaking moment, round-off before (every mass on a line through O) and after
    (the counterweight turns about O at constant speed), reads '0 before and after' on the
    verdict and the index, never 'cancelled': the design cancelled nothing."""
    from balpipe.loader import load_text
    from balpipe.report.results import results_dict
    from balpipe.report.site import headline

    text = YOKE + """balancing:
  method: partial_balance
  counterweights:
    - {body: crank, name: cw, segment: [[0, 0], [-0.05, 0]]}
  objective:
    - {load: shaking_force}
  budget: {mass: 1 kg}
"""
    spec, _ = load_text(text, "yoke.yaml")
    st = study.run(spec)
    v = results_dict(st, "yoke.yaml", "h", False)["verdict"]
    final = v["motions"][0]["final"]
    assert v["stages"][final]["force"]["outcome"] == "reduced"
    assert v["stages"][final]["moment"]["outcome"] == "zero"
    assert "moment 0 before and after" in v["text"] and "cancelled" not in v["text"]
    assert v["level"] == "good"
    row = headline(v, 1e-9)
    assert row["moment"].startswith("0 (<") and row["moment"].count("0 (<") == 2
    assert not row["force"].startswith("0 (<")


def test_each_reference_stage_loads_are_computed_once(monkeypatch):
    """study.run computes a reference stage's loads once for every stage that refers to it (and
    for the checks), the same metrics as each stage computing its own."""
    spec = loader.load(ROOT / "specs" / "custom_four_bar_balancing.yaml").spec
    calls = []
    real = study.ratio_reference
    monkeypatch.setattr(study, "ratio_reference", lambda sr: calls.append(sr.stage.name) or real(sr))
    st = study.run(spec, page=False)
    assert len(st.stages) > 2 and calls == [st.stages[0].stage.name]
    monkeypatch.undo()
    tol = spec.analysis.balance_tolerance
    for s in st.stages:
        own = study.stage_metrics(s, st.stages[0], tol, spec.analysis.claim_tolerance)
        assert s.metrics.to_json() == own.to_json() and s.metrics.reference_loads == own.reference_loads
    assert st.checks["reference"] == real(st.stages[0]).to_json()
