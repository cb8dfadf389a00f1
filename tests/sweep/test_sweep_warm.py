"""Geometry sweeps start every design's closed-loop motion from fixed anchors (issue 13, item 1):
the base spec's motions and those of the sweep's corner designs, solved before any design is
evaluated (:func:`balpipe.sweep._corner_anchors`, :mod:`balpipe.engine.warmstart`). The table
must equal full cold analyses of each design and be the same bits for any chunking or number of
processes."""

from __future__ import annotations

from pathlib import Path

import pytest

from balpipe import engine, sweep
from balpipe.engine import analyse, warmstart
from balpipe.sweep import build_design, csv_text, plan, run

OSC = Path(__file__).resolve().parents[2] / "specs" / "offset_slider_crank.yaml"


def test_a_wide_geometry_sweep_starts_from_the_base_and_corners_with_the_same_table_in_any_chunking():
    """A crank length +-25 % around the base spec's: the base alone would be too far for the
    designs near the ends (the 0.2 rad branch guard); with the corners every design but a few
    starts warm. One process or a pool of two: the same CSV; every design equals its cold
    analysis."""
    p = plan(str(OSC), ["mechanism.crank.length=0.15:0.25:8"])
    sweep._GEOMETRIES.clear()
    before = dict(warmstart.STATS)
    one = run(p, jobs=1)
    counts = {k: warmstart.STATS[k] - before[k] for k in before}
    assert one.failed == 0 and one.full == 8
    assert any("start from 3 fixed motions" in n for n in one.notes)  # the base and two corners
    # base (+ its balancing) and the two corners by the continuation, the designs warm
    assert counts["warm"] >= 5 and counts["continuation"] <= 3 + counts["warm_rejected"]
    sweep._GEOMETRIES.clear()
    two = run(p, jobs=2)
    assert csv_text(two) == csv_text(one)
    paths = [v.path for v in p.varies]
    for row in one.rows:
        spec, sr, _ = build_design(p.data, paths, row["values"], None)
        engine.clear_cache()
        an = analyse(sr.model, *sweep._settings(spec))
        assert row["max_shaking_force"] == pytest.approx(an.max_force, rel=1e-9)
        assert row["max_shaking_moment"] == pytest.approx(an.max_moment, rel=1e-9)


def test_corner_anchors_are_the_first_and_last_values_and_skip_what_cannot_be_built():
    """Two varied fields: four corners; a corner whose crank cannot reach the guide is left out
    (its design's row carries the error)."""
    p = plan(str(OSC), ["mechanism.crank.length=0.19,0.2,0.5", "mechanism.coupler.length=0.3,0.31"])
    anchors = engine.Anchors()
    sweep._corner_anchors(p, [v.path for v in p.varies], anchors)
    numbers = sorted(tuple(float(x) for x in n) for designs in anchors.designs.values() for n, _ in designs)
    assert len(numbers) == 2  # (0.19, 0.3) and (0.19, 0.31); the 0.5 m crank cannot turn
    res = run(p, jobs=1)
    assert res.failed == 2 and all("error" in r for r in res.rows if r["values"][0] == 0.5)
