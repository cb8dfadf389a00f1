"""Issue 13, item 3 (speed): mass-only sweeps skip building a spec per design (the designs'
parameters are affine in the varied values, found and checked on a few full builds) and give
the per-design path's results to 1e-9; other sweeps are not routed there."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe.sweep import METRICS, plan, run

ROOT = Path(__file__).resolve().parents[2]
SR = ROOT / "specs" / "scott_russell.yaml"


def _compare(a, b):
    assert len(a.rows) == len(b.rows)
    for ra, rb in zip(a.rows, b.rows):
        assert ra["design"] == rb["design"] and ra["values"] == rb["values"]
        assert ("error" in ra) == ("error" in rb), (ra, rb)
        if "error" in ra:
            assert ra["error"] == rb["error"]
            continue
        assert ra["si"] == rb["si"]  # the varied values in SI: converted as the spec does, not interpolated
        assert ra["route"] == rb["route"] == "mass"
        for m in METRICS:
            assert abs(ra[m] - rb[m]) <= 1e-9 * max(1.0, abs(rb[m])), (m, ra[m], rb[m])
        assert ra["pareto_moment"] == rb["pareto_moment"] or abs(ra["max_shaking_moment"]) < 1e-9


@pytest.mark.parametrize("varies, sample, stage", [
    # link masses and inertias, through the counterweight method (counterweight masses and the
    # coupler's counterweight inertia follow linearly, eqs. 15 and 20 of paper 000)
    (["mechanism.crank.mass=0.5 kg:2 kg:3", "mechanism.coupler.inertia=0.002:0.006:2",
      "mechanism.slider.mass=200 g,700 g"], "grid", None),
    (["mechanism.crank.mass=0.5:2", "mechanism.coupler.mass=0.5:2", "mechanism.slider.mass=0.2:1"], "lhs", "counterweights"),
    (["mechanism.crank.inertia=1 g m^2:5 g m^2", "mechanism.slider.mass=0.2:1"], "random", "full"),
])
def test_affine_route_equals_the_per_design_path(varies, sample, stage):
    p = plan(str(SR), varies, sample, 7, seed=2, stage=stage)
    fast, slow = run(p, jobs=1), run(p, jobs=1, affine=False)
    assert any("Mass-only sweep" in n for n in fast.notes) and not any("Mass-only" in n for n in slow.notes)
    assert fast.fast == slow.fast == len(p.designs)
    _compare(fast, slow)


def test_a_design_that_cannot_be_built_keeps_its_own_error():
    """Eq. 20 needs a negative counterweight inertia on the coupler for two designs of this
    grid (a large coupler inertia, light coupler and slider), though the coupler's total inertia
    stays positive: the route finds them and they keep the method's own error."""
    p = plan(str(SR), ["mechanism.coupler.inertia=0,0.1,0.2,0.3", "mechanism.slider.mass=10,0.5,2",
                       "mechanism.coupler.mass=1,3,10"])
    fast, slow = run(p, jobs=1), run(p, jobs=1, affine=False)
    assert any("Mass-only sweep" in n for n in fast.notes)
    assert fast.failed == slow.failed == 2 and "eq. 20 needs a negative inertia" in fast.rows[21]["error"]
    _compare(fast, slow)


@pytest.mark.parametrize("varies", [
    ["mechanism.crank.mass=0.5:2:2", "motion.duration=0.25,0.2"],        # time grid: geometry of the motion
    ["mechanism.crank.mass=0.5:2:2", "balancing.crank_counterweight=-0.1,-0.2"],  # m_cw = m c / r: not affine
    ["mechanism.crank.com=0.05,0.1,0.15"],  # J about the joint = I + m c^2: not affine
])
def test_other_sweeps_are_built_design_by_design(varies):
    p = plan(str(SR), varies, stage="counterweights")
    res = run(p, jobs=1)
    assert not any("Mass-only sweep" in n for n in res.notes)
    slow = run(p, jobs=1, affine=False)
    assert [r.get("max_shaking_moment") for r in res.rows] == [r.get("max_shaking_moment") for r in slow.rows]


def test_pareto_mask_is_the_set_of_non_dominated_points():
    from balpipe.sweep import pareto

    rng = np.random.default_rng(5)
    pts = rng.integers(0, 6, size=(60, 2)).astype(float)  # ties included
    mask = pareto(pts)
    for i, (x, y) in enumerate(pts):
        dominated = any((pts[j, 0] <= x and pts[j, 1] <= y and (pts[j] != pts[i]).any()) for j in range(len(pts)))
        if dominated:
            assert not mask[i]
    assert mask.any() and pareto(np.empty((0, 2))).size == 0


def test_geometry_sweeps_analyse_each_geometry_once_with_the_engines_results(tmp_path):
    """A grid over a length and a mass: one analysis per geometry serves both stages and every
    design of that geometry; each row equals engine.analyse of the design's own spec to 1e-9,
    and the table does not depend on how the designs are split between processes."""
    from balpipe import registry, sweep
    from balpipe.engine import analyse
    from balpipe.loader import load
    from balpipe.study import gravity_vector

    osc = ROOT / "specs" / "offset_slider_crank.yaml"
    p = plan(str(osc), ["mechanism.crank.length=0.09:0.1:2", "mechanism.crank.mass=0.5:2:3"])
    sweep._GEOMETRIES.clear()
    res = run(p, jobs=1)
    assert res.full == 6 and len(sweep._GEOMETRIES) == 2  # two lengths: two analyses for 12 stage loads
    for k in (0, 4):
        f = tmp_path / f"d{k}.yaml"
        f.write_text(sweep.design_spec_text(res, k))
        spec = load(f).spec
        stages = registry.balance_designs(spec).stages
        t, g, P = registry.time_grid(spec), gravity_vector(spec), tuple(spec.analysis.moment_point)
        an, an0 = analyse(stages[-1].model, t, g, P), analyse(stages[0].model, t, g, P)
        row = res.rows[k]
        assert row["route"] == "full"
        assert row["max_shaking_moment"] == pytest.approx(an.max_moment, rel=1e-9, abs=1e-12)
        assert row["max_shaking_force"] == pytest.approx(an.max_force, rel=1e-9, abs=1e-12)
        eff = max(float(np.max(np.abs(e))) for e in an.efforts.values())
        assert row["max_actuator_effort"] == pytest.approx(eff, rel=1e-9)
        assert row["unbalanced_max_shaking_force"] == pytest.approx(an0.max_force, rel=1e-9)
    sweep._GEOMETRIES.clear()
    assert sweep.csv_text(run(p, jobs=2)) == sweep.csv_text(res)
