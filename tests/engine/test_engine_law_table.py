"""The general path's continuation takes its drivers' values from one table of the motion's grid
(:class:`balpipe.engine.positions.DenseOps` with ``t``): the same motion, bit for bit, as the
drivers evaluated one time at a time, with the 4-RRR's inverse kinematics solved once per leg
instead of once per continuation step."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe import loader, registry
from balpipe.engine import compile_model
from balpipe.engine.positions import DenseOps, follow_motion
from balpipe.families.rrr4 import template as rrr4_template

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _model(name: str):
    spec = loader.load(SPECS / name).spec
    return registry.unbalanced_model(spec), registry.time_grid(spec)


@pytest.mark.parametrize("name", ["paper001_4rrr.yaml", "paper001_4rrr_fig6c.yaml", "scott_russell.yaml",
                                  "custom_stephenson_six_bar_120rpm.yaml"])
def test_the_grid_table_gives_the_same_motion(name, monkeypatch):
    model, t = _model(name)
    solves = []
    original = rrr4_template.JointLaw.solve
    monkeypatch.setattr(rrr4_template.JointLaw, "solve", lambda self, tt: solves.append(len(tt)) or original(self, tt))
    with_table = follow_motion(compile_model(model), t, DenseOps(compile_model(model), t))
    tabled = len(solves)
    model, t = _model(name)  # fresh laws: their own stores of solutions
    solves.clear()
    one_by_one = follow_motion(compile_model(model), t, DenseOps(compile_model(model)))
    assert with_table.tobytes() == one_by_one.tobytes()
    if "4rrr" in name:
        legs = len(model.drivers)
        assert tabled == legs  # the grid once per driver's leg
        assert len(solves) > 10 * legs  # before: once per continuation step and driver


def test_times_off_the_grid_are_evaluated_as_asked():
    model, t = _model("scott_russell.yaml")
    c = compile_model(model)
    ops = DenseOps(c, t)
    off = np.array([0.5 * (t[3] + t[4])])
    assert ops._laws(off) is None and ops._laws(t[3:5]) is None  # the callee evaluates them
    on = ops._laws(t[3:4])
    table = ops._laws(t)
    for row, whole in zip(on, table):
        assert (row is None) == (whole is None)
        if row is not None:
            assert all(np.array_equal(a, b[3:4]) for a, b in zip(row, whole))
