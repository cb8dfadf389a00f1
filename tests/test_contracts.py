"""The typed contracts between the pipeline's steps: a stage's metrics are computed once, by the
study, and every reader (results.json, the page, ``balpipe diff``) reads that one object."""

from __future__ import annotations

import dataclasses
from pathlib import Path

import pytest

from balpipe import diff, loader, registry, study
from balpipe.report.results import results_dict

ROOT = Path(__file__).resolve().parents[1]
SPEC = ROOT / "specs" / "scott_russell.yaml"


def test_stage_metrics_are_computed_once_and_read_by_results_and_diff(monkeypatch):
    calls = []
    real = study.stage_metrics
    monkeypatch.setattr(study, "stage_metrics", lambda *a, **k: calls.append(a[0].stage.name) or real(*a, **k))
    loaded = loader.load(SPEC)
    st = study.run(loaded.spec)
    names = [s.stage.name for s in st.stages]
    assert calls == names  # once per stage, by the study
    res = results_dict(st, SPEC.name, "h", simulated=False)
    side = diff.Side(str(SPEC), loaded, st)
    d = diff.compare(side, side)
    assert calls == names  # neither results.json nor diff computes them again
    for s, row in zip(st.stages, res["stages"]):
        assert row["name"] == s.metrics.name and row["force_ratio"] == pytest.approx(s.metrics.force_ratio, rel=1e-11)
        assert set(row) == {f.name for f in dataclasses.fields(study.StageMetrics)} - {"reference_loads"}
    assert [r["name"] for r in d["stages"]] == names
    assert all(r["max_shaking_force"]["old"] == r["max_shaking_force"]["new"] for r in d["stages"])


def test_stage_metrics_are_frozen_and_need_the_study():
    st = study.run(loader.load(SPEC).spec)
    m = st.stages[-1].metrics
    with pytest.raises(dataclasses.FrozenInstanceError):
        m.force_ratio = 0.0  # type: ignore[misc]
    assert m.number("force_ratio") == m.force_ratio and m.number("label") is None
    bare = study.run_stage_analyses(st.spec, st.balance)[0]
    with pytest.raises(RuntimeError, match="computed by balpipe.study.run"):
        bare.metrics


def test_a_compared_designs_stages_carry_their_design_as_data(studies):
    st = studies("custom_four_bar_balancing.yaml")
    designs = {s.stage.name: s.stage.design for s in st.stages}
    compared = {d.name for d in st.spec.compare}
    assert compared and set(designs.values()) == {None} | compared
    for s in st.stages:  # the name shown on the page and in results.json stays design:stage
        assert (s.stage.design is None) == (s.stage.name in {x.name for x in registry.balance(st.spec).stages})
        if s.stage.design is not None:
            assert s.stage.name.startswith(f"{s.stage.design}:")
    rows = results_dict(st, "custom_four_bar_balancing.yaml", "h", simulated=False)["comparison"]["rows"]
    assert [r["design"] for r in rows] == [s.stage.design or "main" for s in st.stages]


def test_no_module_parses_a_stage_name_for_its_design():
    """The design travels as :attr:`Stage.design`; nothing splits "design:stage" names."""
    import re

    parse = re.compile(r'''["']:["']\s+(not\s+)?in\s+[\w.\[\]"']*name|name\w*\.r?(split|partition)\(\s*["']:''')
    found = [f"{p.relative_to(ROOT)}:{i}" for p in sorted((ROOT / "pipeline" / "balpipe").rglob("*.py"))
             for i, line in enumerate(p.read_text(encoding="utf-8").splitlines(), 1) if parse.search(line)]
    assert found == []
    assert parse.search('chosen = [s for s in stages if ":" not in s.stage.name]')  # the test can fail
    assert parse.search('design, _, stage = s.stage.name.rpartition(":")')
