"""The partial balancing's fronts on spare cores (issue 23 item 5): forked processes, the same
numbers bit for bit, the same site whatever ``-j``."""

from __future__ import annotations

from pathlib import Path

import numpy as np

from _edits import replaced
from balpipe import build as build_mod
from balpipe.runtime import pool
from balpipe.balancing.partial import method as P
from balpipe.balancing.partial import fronts as PF
from balpipe.balancing.partial.active import ActiveProgram
from balpipe.spec import Spec
from generic_specs import four_bar
from test_partial import POLYGON, SEGMENTS, method, setup

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _spy(monkeypatch) -> list:
    """The ``workers`` of every call of :func:`balpipe.runtime.pool.forked` (the real one runs)."""
    seen = []
    real = pool.forked
    monkeypatch.setattr(pool, "forked", lambda tasks, workers, shared: seen.append(workers) or real(tasks, workers, shared))
    return seen


def test_fronts_on_two_workers_equal_the_fronts_one_after_another(monkeypatch):
    spec = Spec.model_validate(four_bar(np.random.default_rng(21), method(SEGMENTS + [POLYGON], budget=0.7)))
    seen = _spy(monkeypatch)
    out = []
    for workers in (1, 2):
        maps = setup(spec)
        with pool.spare_workers(workers):
            out.append(PF.compute(ActiveProgram(maps), P.standard_terms(maps), 0.7, 6, None))
    assert seen == [1, 2]
    assert pool.spare() == 1  # the block's setting undone
    assert list(out[0]) == ["points", "max_mass", "budget", "complete_force", "complete_force_moment",
                            "force_vs_mass", "moment_vs_mass", "force_vs_moment", "effort_vs_force"]
    assert all(len(out[0][f]) == 6 for f in PF.FRONTS)
    assert out[0] == out[1]  # every number, not only to 1e-9


def test_one_partial_spec_on_spare_cores_splits_its_fronts_with_the_same_site(tmp_path, monkeypatch):
    """A one-spec build on two cores computes the fronts in two processes; the page, results and
    time series are the same bytes as on one core."""
    seen = _spy(monkeypatch)
    spec = tmp_path / "partial_offset_slider_crank.yaml"
    spec.write_text(replaced((SPECS / "partial_offset_slider_crank.yaml").read_text(), "  samples: 361", "  samples: 61"))
    one, two = tmp_path / "one", tmp_path / "two"
    build_mod.build([str(spec)], build_mod.Options(one, simulate=False), jobs=1)
    build_mod.build([str(spec)], build_mod.Options(two, simulate=False), jobs=2)
    assert seen == [1, 2]
    for f in ("index.html", "results.json", "timeseries.csv"):
        assert (one / spec.stem / f).read_bytes() == (two / spec.stem / f).read_bytes(), f
