"""A hand-written stage that aims at loads (``stages[].aim``: a crank counterbalance's peak
gearbox torque) is judged on them: each term measured on the stage and on the unbalanced
mechanism as the study analyses them, the shaking force and moment it does not name as side
effects; names that do not exist and a stage that both claims and aims are located errors."""

from __future__ import annotations

import numpy as np
import pytest
from pydantic import ValidationError

from balpipe import study
from balpipe.balancing.load_measures import time_rms
from balpipe.report.results import results_dict
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError


def slider_crank(aim, cw_mass=3.0, balances="") -> Spec:
    """An in-line slider-crank lifting its slider against gravity at 60 rpm, a crank counterweight
    opposite the pin added by hand."""
    return Spec.model_validate({
        "name": "slider-crank with a hand-placed crank counterweight",
        "mechanism": {"template": "slider_crank", "offset": 0.0,
                      "crank": {"length": 0.1, "mass": 2.0, "com": 0.05, "inertia": 1e-3},
                      "coupler": {"length": 0.4, "mass": 1.0, "com": 0.2, "inertia": 1e-2}, "slider": {"mass": 0.5}},
        "motion": {"cycles": 1, "drive": {"crank": {"law": "constant_speed", "from": 0.0, "speed": "60 rpm"}}},
        "balancing": {"method": "stages", "stages": [
            {"name": "cw", "balances": balances, "aim": aim,
             "parts": [{"body": "crank", "name": "cw", "mass": cw_mass, "position": [-0.05, 0.0]}]}]},
        "analysis": {"samples": 241, "gravity": True}, "validation": {"enabled": False}})


def test_each_aim_is_measured_on_the_analysed_stage_and_the_verdict_judges_by_it():
    aim = [{"load": "effort", "actuator": "crank", "measure": "rms"}, {"load": "joint", "joint": "A"},
           {"load": "frame_force"}]
    s = study.run(slider_crank(aim))
    r = results_dict(s, "spec.yaml", "hash", False)
    goals = r["stages"][1]["aim"]["goals"]
    before, after = s.stages[0].analysis, s.stages[1].analysis
    t = after.t
    # independent measures of the analyses the study made: the time RMS by the trapezoidal rule
    # written here, the joint's |F|, the frame's |F|
    rms = lambda x: float(np.sqrt(np.trapezoid(x * x, t) / (t[-1] - t[0])))  # noqa: E731
    joint = lambda an: float(np.max(np.hypot(an.reactions["A"]["Fx"], an.reactions["A"]["Fy"])))  # noqa: E731
    frame = lambda an: float(np.max(np.hypot(*an.frame_load[0].T)))  # noqa: E731
    expected = [(rms(after.efforts["crank"]), rms(before.efforts["crank"]), "N m"),
                (joint(after), joint(before), "N"), (frame(after), frame(before), "N")]
    for g, exact, (value, reference, unit) in zip(goals, s.stages[1].stage.aim.goals, expected):
        assert g["role"] == "objective" and g["unit"] == unit
        assert exact.value == pytest.approx(value, rel=1e-12) and exact.reference == pytest.approx(reference, rel=1e-12)
        assert g["value"] == pytest.approx(value, rel=1e-11)  # results.json: 12 significant digits
    assert [g["label"] for g in goals] == ["RMS effort of crank", "peak load of joint A", "peak frame force"]
    v = r["verdict"]
    words = {"reduced": "objective reduced", "worse": "objective worse"}
    assert v["words"] in words.values() and "mixed" not in v["text"]
    assert v["text"].endswith("(side effects)")  # neither the shaking force nor the moment is aimed at
    assert "(objective)" in v["stages"]["cw"]["text"]


def test_a_counterweight_that_raises_the_torque_is_objective_worse_not_balancing_fails():
    # at constant speed under gravity a crank counterweight opposite the pin against the crank's
    # own unbalance: three times too heavy, it raises the peak torque
    r = results_dict(study.run(slider_crank([{"load": "effort"}], cw_mass=20.0)), "spec.yaml", "hash", False)
    goal = r["stages"][1]["aim"]["goals"][0]
    assert goal["ratio"] > 1
    assert r["verdict"]["words"] == "objective worse" and "fails" not in r["verdict"]["text"]


def test_time_rms_of_a_sine_over_whole_periods_is_its_amplitude_over_root_two():
    t = np.linspace(0.0, 2.0, 4001)
    assert time_rms(3.0 * np.sin(2 * np.pi * t), t) == pytest.approx(3.0 / np.sqrt(2.0), rel=1e-6)


@pytest.mark.parametrize("aim, field", [
    ([{"load": "effort", "actuator": "motor"}], "actuator"),
    ([{"load": "joint", "joint": "Z"}], "joint"),
])
def test_an_unknown_name_is_a_located_error(aim, field):
    with pytest.raises(SpecFieldError) as e:
        study.run(slider_crank(aim))
    assert e.value.path == ("balancing", "stages", 0, "aim", 0, field)


def test_a_stage_claims_or_aims_not_both():
    with pytest.raises(ValidationError, match="not both"):
        slider_crank([{"load": "effort"}], balances="force")


@pytest.mark.parametrize("name", ["custom_pumpjack_rod_load.yaml", "custom_four_bar_partial.yaml"])
def test_the_verdict_box_says_what_the_stage_aimed_at(pages, name):
    """A stage judged by its aim (hand-written or optimised): the page's "Did balancing work?"
    sentence is its objective and side effects, not the shaking loads alone beside an
    "objective reduced" badge."""
    html = pages(name)
    sentence = html.split("Did balancing work?</strong>", 1)[1].split("</p>", 1)[0]
    assert "(objective)" in sentence and "side effect" in sentence
    assert not sentence.lstrip().startswith("Force ")


def test_the_index_lists_an_aimed_stage_by_its_objective(shared_build):
    """The site index's verdict column of a spec judged by its aim: the objective first, the
    shaking loads it did not aim at as side effects, a shaking load it aimed at not repeated."""
    import re

    from conftest import SPECS

    # the build of every spec that tests/test_api.py reads too (the same key: built once a run)
    folder, done = shared_build(tuple(sorted(p.name for p in SPECS.iterdir() if p.is_file())), "specs", "-o", "site", "--no-sim")
    assert done.returncode in (0, 1), done.stderr
    html = (folder / "site" / "index.html").read_text(encoding="utf-8")
    cells = {m.group(1): re.sub(r"<[^>]+>", "|", m.group(2)) for m in re.finditer(
        r'data-spec="([^"]+)".*?<td data-label="Verdict" class="verdict">(.*?)</td>', html, re.S)}
    pump, four = cells["custom_pumpjack_rod_load"], cells["custom_four_bar_partial"]
    assert "peak effort of crank reduced by 68.5 % (objective)" in pump
    assert "side effects: force worse" in pump and ", moment unchanged" in pump
    assert "peak shaking force reduced by" in four and "side effects: moment worse" in four
    assert "side effects: force" not in four  # the force is the objective, no side effect
