"""An optimised stage (partial_balance) judged by what it optimised: its objective and caps in the
verdict's words, the shaking loads it did not minimise as side effects, and why a design that adds
nothing adds nothing."""

from __future__ import annotations

import pytest

from balpipe import study
from balpipe.report import verdict as V
from balpipe.report.results import results_dict
from balpipe.spec import Spec
from test_verdict import results, stage


def slider_crank(objective, budget=5.0, speed="30 rpm", gravity=True, caps=()) -> Spec:
    return Spec.model_validate({
        "name": "slider-crank under gravity",
        "mechanism": {"template": "slider_crank", "offset": 0.0,
                      "crank": {"length": 0.1, "mass": 2.0, "com": 0.05, "inertia": 1e-3},
                      "coupler": {"length": 0.4, "mass": 1.0, "com": 0.2, "inertia": 1e-2}, "slider": {"mass": 0.5}},
        "motion": {"cycles": 1, "drive": {"crank": {"law": "constant_speed", "from": 0.0, "speed": speed}}},
        "balancing": {"method": "partial_balance",
                      "counterweights": [{"body": "crank", "name": "cw", "segment": [[0, 0], [-0.1, 0]]}],
                      "objective": objective, "budget": {"mass": budget}, "caps": list(caps), "fronts": None},
        "analysis": {"samples": 181, "gravity": gravity}, "validation": {"enabled": False}})


def verdict_of(spec: Spec) -> dict:
    return results_dict(study.run(spec), "spec.yaml", "hash", False)


def test_least_peak_torque_is_judged_by_the_torque_the_shaking_force_a_side_effect():
    r = verdict_of(slider_crank([{"load": "effort"}]))
    v, row = r["verdict"], r["stages"][1]
    goal = row["aim"]["goals"][0]
    assert goal["role"] == "objective" and goal["load"] == "effort"
    # the goal's numbers are the analysed stage's: its peak effort over the unbalanced one's
    assert goal["value"] == pytest.approx(row["max_actuator_effort"], rel=1e-9)
    assert goal["reference"] == pytest.approx(r["stages"][0]["max_actuator_effort"], rel=1e-9)
    assert v["level"] == "good" and v["words"] == "objective reduced"
    reduced = f"peak effort reduced by {V.percent(1 - goal['ratio'])} (objective)"
    assert v["text"].startswith(f"objective reduced: {reduced}; force ")
    assert v["text"].endswith("(side effects)") and "mixed" not in v["text"]
    assert v["stages"]["partial"]["aim"]["side_effects"] == ["force", "moment"]


def test_a_force_objective_is_no_side_effect_and_a_cap_is_kept():
    r = verdict_of(slider_crank([{"load": "shaking_force", "measure": "rms"}], speed="600 rpm", gravity=False,
                                caps=[{"load": "effort", "at_most": 1.5}]))
    v = r["verdict"]["stages"]["partial"]
    assert v["aim"]["side_effects"] == ["moment"]
    assert [c["kept"] for c in v["aim"]["caps"]] == [True]
    assert "RMS shaking force reduced by" in v["text"] and "cap 1.5 x kept" in v["text"]


@pytest.mark.parametrize("budget, gravity, why", [
    (0.0, True, "the mass budget (0 kg) is zero"),
    (5.0, False, "no part in these regions lowers the objective"),  # constant speed: a crank part needs no torque
])
def test_a_design_that_adds_nothing_says_why(budget, gravity, why):
    r = verdict_of(slider_crank([{"load": "effort", "measure": "rms"}], budget=budget, speed="600 rpm", gravity=gravity))
    v = r["verdict"]
    assert r["stages"][1]["added_mass"] <= 1e-9
    assert v["level"] == "neutral" and v["words"] == "adds nothing"
    assert v["text"].startswith(f"adds nothing: {why}")


def _aimed(ratio, cap_ratio=None, f=2.16):
    goals = [{"label": "peak effort", "role": "objective", "load": "effort", "ratio": ratio}]
    if cap_ratio is not None:
        goals.append({"label": "peak shaking moment", "role": "cap", "load": "shaking_moment", "ratio": cap_ratio,
                      "at_most": 1.2})
    return stage("partial", f=f, aim={"goals": goals, "nothing_added": ""})


def test_levels_by_the_objective_and_the_caps():
    v = V.verdict(results(_aimed(0.18)))
    assert v["level"] == "good"
    assert v["text"] == ("objective reduced: peak effort reduced by 82 % (objective); force worse: 216 % of the "
                         "reference, moment unchanged (side effects)")
    assert V.verdict(results(_aimed(0.18, 1.19)))["level"] == "good"
    broken = V.verdict(results(_aimed(0.18, 1.3)))
    assert broken["level"] == "bad" and broken["words"] == "a cap broken" and "cap 1.2 x broken" in broken["text"]
    worse = V.verdict(results(_aimed(1.1)))
    assert worse["level"] == "warn" and worse["words"] == "objective worse"
    # a stage that claims a balance is judged by its claim, as before
    claimed = V.verdict(results(stage("cw", "force", f=0.5, aim={"goals": [], "nothing_added": ""})))
    assert claimed["level"] == "bad"
