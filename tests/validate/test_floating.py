"""Issue 7, item 4: the free-floating demonstration says per stage whether it is a simulation or
the conservation solution; massless gears get a small mass so that pymunk really simulates
them, and the difference to the massless design is shown; every stage uses the same frame and
the page prints the inertia each stage used."""

from __future__ import annotations

import math
import sys
from pathlib import Path

import pytest

from balpipe.engine import analyse
from balpipe.validate import free_floating
from balpipe.validation_stage import BASE_MASS, reactionless_runs

sys.path.insert(0, str(Path(__file__).parents[1]))
from test_validate import GRID, arm_2r, gear_train  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]


def test_massless_gears_are_simulated_with_a_small_mass():
    """Failed on the code before: massless bodies made it fall back to the conservation
    solution (method "momentum") while the page said "simulation (pymunk)"."""
    model = gear_train()  # massless idler and disc on the frame
    a = analyse(model, GRID)
    ff = free_floating(model, a, base_mass=10.0, base_inertia=1.0)
    assert ff.method == "pymunk" and ff.method_label.startswith("simulation (pymunk)")
    assert set(ff.small_masses) == {"idler", "disc"}
    total = model.total_mass()
    assert ff.small_mass_fraction in (0.01, 0.1)  # the smallest of 1 %, 10 %, 100 % that holds together
    assert all(m == pytest.approx(ff.small_mass_fraction * total) for m, _ in ff.small_masses.values())
    assert ff.small_masses["idler"][1] > 0 and ff.small_masses["disc"][1] == 0  # the disc has an inertia
    # the simulation agrees with the conservation solution of the design it simulates ...
    assert ff.reference_difference[0] < 1e-6 and ff.reference_difference[1] < 1e-5
    # ... and the massless design's solution is reported with the difference the masses make
    assert math.isfinite(ff.massless_max_drift) and math.isfinite(ff.massless_max_rotation)
    assert 0 < ff.massless_difference[1] < 0.05 * ff.max_rotation
    j = ff.to_json()
    assert j["method_label"] == ff.method_label and j["small_masses"]["idler"]["mass"] > 0


def test_without_small_masses_the_label_says_conservation_solution():
    model = gear_train()
    a = analyse(model, GRID)
    ff = free_floating(model, a, small_mass=None)
    assert ff.method == "momentum"
    assert ff.method_label == "conservation solution (not simulated)"
    assert ff.small_masses == {} and math.isnan(ff.massless_max_drift)


def test_models_without_massless_bodies_are_unchanged():
    model = arm_2r()
    a = analyse(model, GRID)
    ff = free_floating(model, a, base_mass=10.0, base_inertia=1.0)
    assert ff.method == "pymunk" and ff.small_masses == {} and ff.method_label == "simulation (pymunk)"


@pytest.fixture(scope="module")
def five_bar_runs(studies):
    st = studies("paper004_five_bar.yaml")
    return st, reactionless_runs(st)


def test_five_bar_stages_are_simulated_on_one_frame(five_bar_runs):
    """Every stage of paper 004's five-bar (massless gears 1', 5, 2', planets 6, 7) is now a
    pymunk simulation, on the same frame; the page rows carry the inertia each stage used
    (1.569 and 1.728 kg m^2 before, printed as one number)."""
    st, rl = five_bar_runs
    assert [r.method for r in rl.runs] == ["pymunk"] * len(st.stages)
    assert rl.same_base
    inertias = {r.base_inertia for r in rl.runs}
    assert len(inertias) == 1 and {r.base_mass for r in rl.runs} == {BASE_MASS}
    rows = rl.rows()
    assert [row["base_inertia"] for row in rows] == [r.base_inertia for r in rl.runs]
    assert all(row["method"].startswith("simulation (pymunk)") for row in rows)
    unb, cw, *full_stages = rl.runs  # full (paper's reading) and full_point_masses
    assert unb.max_drift > 0.02 and unb.max_rotation > 0.05  # unbalanced: it moves
    assert cw.max_drift < 1e-4 and cw.max_rotation > 0.05  # force balanced: it turns
    for full in full_stages:  # fully balanced: it stays
        assert full.max_drift < 1e-6 and full.max_rotation < 1e-5
    for r in rl.runs:  # the small masses change the unbalanced motion by little
        assert r.massless_difference[0] < 0.01 * max(unb.max_drift, 1e-3)
        assert r.reference_difference[0] < 1e-6 and r.reference_difference[1] < 1e-5


def test_the_demonstration_reads_the_motion_alone_and_is_shared_across_gravity(tmp_path):
    """What the free-floating run reads of an analysis is its motion (:func:`motion_only`): the
    same run bit for bit, and one simulation for two analyses of the same motion under other
    gravity (paper 002's vertical and horizontal specs ran their three demonstrations twice)."""
    import numpy as np

    from balpipe.cache import simulation as sim_cache
    from balpipe.validate.floating import motion_only

    model = gear_train()
    down, sideways = analyse(model, GRID, (0.0, -9.81)), analyse(model, GRID, (-9.81, 0.0))
    assert not np.array_equal(down.efforts["q"], sideways.efforts["q"])  # the analyses differ
    full = free_floating(model, down, base_mass=10.0, base_inertia=1.0)
    view = free_floating(model, motion_only(down), base_mass=10.0, base_inertia=1.0)
    for name in ("base", "poses", "drift", "rotation"):
        assert np.array_equal(getattr(full, name), getattr(view, name))
    assert full.to_json() == view.to_json()
    store = sim_cache.Store(tmp_path, "spec", "salt")
    with sim_cache.using(store):
        a = sim_cache.run(free_floating, model, motion_only(down), 10.0, 1.0)
        b = sim_cache.run(free_floating, model, motion_only(sideways), 10.0, 1.0)
    assert store.computed == 1 and a.to_json() == b.to_json()


def test_the_demonstration_runs_without_the_start_up_to_the_same_motion(monkeypatch):
    """Issue 43: the demonstration runs every step at its own solver effort (it has no residual
    limit; the checks' start-up serves theirs): the base's drift and rotation are those of a run
    with the start-up to 1e-9 (measured 2e-14), and agree with the conservation solution to 1e-4
    of them (measured 1.4e-5)."""
    import balpipe.validate.floating as floating
    import balpipe.validate.run as run_module

    seen = []
    original = run_module.simulate

    def recording(model, analysis, dt, iterations, **kw):
        seen.append((iterations, kw["startup_iterations"]))
        return original(model, analysis, dt, iterations, **kw)

    monkeypatch.setattr(run_module, "simulate", recording)
    model = arm_2r()
    a = analyse(model, GRID)
    plain = free_floating(model, a, base_mass=10.0, base_inertia=1.0)
    assert seen and all(startup == it for it, startup in seen)
    monkeypatch.setattr(floating, "DEMONSTRATION_STARTUP", True)
    boosted = free_floating(model, a, base_mass=10.0, base_inertia=1.0)
    assert seen[-1][1] > seen[-1][0]
    assert plain.method == boosted.method == "pymunk"
    assert plain.max_drift == pytest.approx(boosted.max_drift, rel=1e-9)
    assert plain.max_rotation == pytest.approx(boosted.max_rotation, rel=1e-9)
    assert plain.reference_difference[0] < 1e-4 * plain.max_drift
    assert plain.reference_difference[1] < 1e-4 * plain.max_rotation
