"""Optimal partial balancing over several motions at once (issue 21, ``partial_balance.motions``):
the peak over the motions is the largest per-motion peak and equals a full re-analysis on each
motion, the joint optimum is bracketed by the single-motion optima, it equals a derivative-free
search, a motion at double speed has four times the inertial loads, and errors in the further
motions are located."""

from __future__ import annotations

import math

import numpy as np
import pytest

from balpipe import registry
from balpipe.balancing.partial import method as P
from balpipe.balancing.partial import motions as PMo
from balpipe.engine import analyse
from balpipe.spec import Spec
from generic_specs import four_bar
from test_partial import SEGMENTS, _bad, _physical_many, de_minimum, method

BUDGET = 0.6


def two_motions(seed: int, other: dict | None = None, samples: int = 151, **kw) -> dict:
    """A random four-bar (quintic, 0.4 s) and a second motion: by default a shorter turn in 0.3 s
    from the same start, so that the two motions load the mechanism differently."""
    rng = np.random.default_rng(seed)
    d = four_bar(rng, method(SEGMENTS, budget=BUDGET, **kw))
    if other is None:
        th = d["motion"]["drive"]["crank"]["from"]
        other = {"law": "quintic", "duration": 0.3, "drive": {"crank": {"from": th, "to": th + 1.0 * math.pi}}}
    d["balancing"]["motions"] = [{"name": "second", "samples": samples, "motion": other}]
    return d


def motions_of(spec: Spec):
    return P.motion_maps(registry.context(spec))


def alone(d: dict, k: int) -> Spec:
    """The spec with only motion k (0: its own, 1: the second) and no further motions."""
    e = {**d, "balancing": {**d["balancing"], "motions": []}}
    if k == 1:
        other = d["balancing"]["motions"][0]
        e = {**e, "motion": other["motion"], "analysis": {**d["analysis"], "samples": other["samples"]}}
    return Spec.model_validate(e)


def test_peak_over_two_motions_is_the_largest_and_equals_a_reanalysis_on_each():
    d = two_motions(7)
    spec = Spec.model_validate(d)
    motions = motions_of(spec)
    assert [len(m.t) for m in motions] == [201, 151]
    _, out, terms, *_ = P.solve(motions, spec.balancing)
    force = terms[0]
    per = []
    for m in motions:
        an = analyse(m.design(out.z), m.t)
        peak = float(np.max(np.hypot(an.force[:, 0], an.force[:, 1])))
        assert PMo.restrict(force, m).value(out.z) == pytest.approx(peak, rel=1e-9)
        per.append(peak)
    assert force.value(out.z) == pytest.approx(max(per), rel=1e-9)
    det = registry.balance(spec).details["partial_balance"]
    assert [r["name"] for r in det["motions"]] == ["motion", "second"]
    assert det["peaks"]["shaking_force"] == max(r["peaks"]["shaking_force"] for r in det["motions"])
    assert [r["peaks"]["shaking_force"] for r in det["motions"]] == pytest.approx(per, rel=1e-9)
    assert det["terms"][0]["unbalanced"] == max(r["terms"][0]["unbalanced"] for r in det["motions"])


@pytest.mark.parametrize("objective", [{"load": "shaking_force"}, {"load": "effort", "measure": "rms"}])
def test_two_motion_optimum_is_bracketed_by_the_single_motion_optima(objective):
    """On each motion alone the joint design is never better than that motion's own optimum; the
    joint optimum (the worse motion) is at least the worse single optimum and at most what either
    single optimum gives over both motions."""
    d = two_motions(5, objective=[objective])
    spec = Spec.model_validate(d)
    motions = motions_of(spec)
    _, out, (term,), *_ = P.solve(motions, spec.balancing)
    joint = term.value(out.z)
    singles = []
    for k in (0, 1):
        one = alone(d, k)
        maps = P.motion_maps(registry.context(one))
        _, o, (t1,), *_ = P.solve(maps, one.balancing)
        best_k = t1.value(o.z)
        assert PMo.restrict(term, motions[k]).value(out.z) >= best_k * (1 - 1e-7)
        assert best_k == pytest.approx(PMo.restrict(term, motions[k]).value(o.z), rel=1e-12)  # same loads, same z
        singles.append(o.z)
        assert joint >= best_k * (1 - 1e-7)
    assert joint <= min(term.value(z) for z in singles) * (1 + 1e-7)


def test_two_motion_optimum_equals_differential_evolution():
    spec = Spec.model_validate(two_motions(7))
    motions = motions_of(spec)
    _, out, (term,), *_ = P.solve(motions, spec.balancing)
    best = term.value(out.z)
    res = de_minimum(term, lambda X: _physical_many(motions[0], X), [(0, 2), (0, 1), (0, 2), (0, 1)], [1, 0, 1, 0],
                     BUDGET, seed=1, maxiter=3000, popsize=30)
    assert best <= res.fun * (1 + 1e-7)
    assert abs(res.fun - best) <= 1e-6 * best


def test_a_motion_at_double_speed_has_four_times_the_inertial_loads():
    """The same law in half the time (no gravity): every acceleration x 4, so every load x 4 at
    every sample; the optimum of the relative peak is then the single motion's."""
    base = four_bar(np.random.default_rng(3), method(SEGMENTS, [{"load": "shaking_force"},
                                                                 {"load": "effort", "measure": "rms"}], budget=BUDGET))
    fast = {**base["motion"], "duration": base["motion"]["duration"] / 2}
    d = {**base, "balancing": {**base["balancing"], "motions": [{"name": "double", "motion": fast}]}}
    spec = Spec.model_validate(d)
    slow_maps, fast_maps = motions_of(spec)
    for name, L in slow_maps.loads.items():
        F = fast_maps.loads[name]
        scale = max(float(np.abs(L.b).max()), float(np.abs(L.A).max()), 1e-300)
        assert np.abs(F.A - 4 * L.A).max() <= 1e-9 * 4 * scale, name
        assert np.abs(F.b - 4 * L.b).max() <= 1e-9 * 4 * scale, name
    det = registry.balance(spec).details["partial_balance"]
    slow, double = det["motions"]
    for k in ("shaking_force", "shaking_moment", "effort"):
        assert double["peaks"][k] == pytest.approx(4 * slow["peaks"][k], rel=1e-9)
    for a, b in zip(slow["terms"], double["terms"]):
        assert b["ratio"] == pytest.approx(a["ratio"], rel=1e-9)
    single = registry.balance(Spec.model_validate(base)).details["partial_balance"]
    assert det["objective"] == pytest.approx(single["objective"], rel=1e-6)
    assert det["added_mass"] == pytest.approx(single["added_mass"], rel=1e-5, abs=1e-9)


def test_several_motions_are_reported_on_the_page_notes():
    res = registry.balance(Spec.model_validate(two_motions(7)))
    notes = [n for n in res.notes if n.startswith("Motion ")]
    assert [n.split(" (")[0] for n in notes] == ["Motion motion", "Motion second"]
    assert "2 motions (motion: 201 samples, second: 151 samples" in res.notes[0]
    assert "validated on the spec's motion" in res.stages[1].description


@pytest.mark.parametrize("change, needle", [
    (lambda m: m["motion"]["drive"].update(wheel={"from": 0, "to": 1}), "balancing.motions[0].motion.drive.wheel: unknown drive 'wheel'"),
    (lambda m: m.update(name="motion"), "balancing.motions[0].name: the motion name 'motion' is taken"),
    (lambda m: m["motion"].update(drive={}), "balancing.motions[0].motion.drive: the driver 'crank' has no law"),
    (lambda m: m["motion"].update(cycles=2), "balancing.motions[0].motion: "),
    (lambda m: m["motion"]["drive"].update(crank={"law": "table", "file": "missing.csv"}),
     "balancing.motions[0].motion.drive.crank.file: cannot read the table 'missing.csv'"),
])
def test_errors_in_a_further_motion_are_located(tmp_path, capsys, change, needle):
    d = two_motions(7)
    change(d["balancing"]["motions"][0])
    err = _bad(tmp_path, capsys, d, needle)
    line = next(x for x in err.splitlines() if needle in x)
    assert line.startswith(f"{tmp_path / 'bad.yaml'}:") and line.split(":")[1].isdigit()


def test_a_located_error_in_a_compared_design_s_motion(tmp_path, capsys):
    d = two_motions(7)
    bal = d.pop("balancing")
    bal["motions"][0]["motion"]["drive"]["wheel"] = {"from": 0, "to": 1}
    d["compare"] = [{"name": "other", "balancing": bal}]
    _bad(tmp_path, capsys, d, "compare[0].balancing.motions[0].motion.drive.wheel: design 'other': unknown drive")


def test_a_custom_driver_without_a_law_is_located(tmp_path, capsys):
    """The spec's own motion too (it was a KeyError of the custom template)."""
    d = two_motions(7)
    d["motion"]["drive"] = {}
    _bad(tmp_path, capsys, d, "motion.drive: the driver 'crank' has no law: give motion.drive.crank")


def test_the_fronts_over_several_motions_mark_only_designs_measured_the_same_way():
    """The fronts' peaks are over every motion; a stage's analysis is over the spec's motion alone.
    So a front of several motions marks the unbalanced mechanism and the chosen design at their
    peaks over every motion (the method's own), and no design lies below the least-effort front:
    the least effort is non-increasing in the force cap, so the chosen design's effort is at least
    that of every front point at a larger peak force (the old markers, on the spec's motion alone,
    fell below it)."""
    from pathlib import Path

    from balpipe.loader import load
    from balpipe.report import partial_figures as PF
    from balpipe.study import run

    st = run(load(Path(__file__).parents[2] / "specs" / "custom_four_bar_partial_two_motions.yaml").spec)
    det = st.balance.details["partial_balance"]
    marks = {label: (vx, vy) for label, vx, vy in PF._marks(st, det, "shaking_force", "effort")}
    chosen = marks["optimal for both motions (over every motion)"]
    assert chosen == (det["peaks"]["shaking_force"], det["peaks"]["effort"])
    assert marks["unbalanced (over every motion)"] == (det["unbalanced"]["shaking_force"], det["unbalanced"]["effort"])
    assert not any(label.startswith("optimal for the steady state alone") for label in marks)
    front = det["fronts"]["effort_vs_force"]
    above = [p["effort"] for p in front if p["shaking_force"] >= chosen[0]]
    assert above and chosen[1] >= max(above) * (1 - 1e-6)
    _, _, caption = next(f for f in PF.figures(st) if f[0] == "Actuator effort against shaking force")
    assert "their peaks over every motion as the front's" in caption
