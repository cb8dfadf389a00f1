"""Issue 43: a spec gives the stages that need it their own time step (``validation.stage_dt``,
by stage name: paper 003's trapezoidal stages, whose ramps last a few milliseconds), the other
stages keep ``validation.dt`` or the default; a name that is no stage, or a step beyond the
simulation's limits, is refused with its place in the spec."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from balpipe.cli import main
from balpipe.limits import stage_dt
from balpipe.loader import load_text

ROOT = Path(__file__).resolve().parents[2]
SCOTT = (ROOT / "specs" / "scott_russell.yaml").read_text()


def test_a_named_stage_runs_at_its_own_step_and_the_others_at_the_default(tmp_path):
    (tmp_path / "specs").mkdir()
    (tmp_path / "specs" / "s.yaml").write_text(SCOTT + "validation:\n  stage_dt: {full: 0.125 ms}\n")
    assert main(["build", str(tmp_path / "specs"), "-o", str(tmp_path / "out")]) == 0
    r = json.loads((tmp_path / "out" / "s" / "results.json").read_text())
    assert r["validation"]["full"]["dt"] == r["torque_driven"]["full"]["dt"] == pytest.approx(1.25e-4)
    default = r["validation"]["unbalanced"]["dt"]  # the motion's own (0.25 ms: 0.01 / the fastest body's speed)
    assert default == r["validation"]["counterweights"]["dt"] == r["torque_driven"]["unbalanced"]["dt"] == pytest.approx(2.5e-4)
    assert all(v["status"] == "pass" for v in r["validation"].values())


def test_the_stage_step_overrides_the_specs_step_for_its_stage_only():
    spec, _ = load_text(SCOTT + "validation:\n  dt: 0.5 ms\n  stage_dt: {full: 0.25 ms}\n", "s.yaml")
    assert stage_dt(spec, "full") == pytest.approx(2.5e-4)
    assert stage_dt(spec, "unbalanced") == pytest.approx(5e-4)
    spec, _ = load_text(SCOTT, "s.yaml")
    assert stage_dt(spec, "full") is None


@pytest.mark.parametrize("setting, where, says", [
    ("stage_dt: {fulll: 0.25 ms}", "validation.stage_dt.fulll", "no stage 'fulll' (stages: unbalanced, counterweights, full)"),
    ("stage_dt: {full: 1.0e-9}", "validation.stage_dt.full", "steps over the"),
])
def test_a_wrong_stage_step_is_refused_with_its_place(tmp_path, capsys, setting, where, says):
    (tmp_path / "s.yaml").write_text(SCOTT + "validation:\n  " + setting + "\n")
    assert main(["check", str(tmp_path / "s.yaml")]) == 2
    err = capsys.readouterr()
    text = err.out + err.err
    assert where in text and says in text and "Traceback" not in text
