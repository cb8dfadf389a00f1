"""Issue 23: the pymunk simulations cached by content (``balpipe.cache.simulation``). A rebuild whose
stages did not change runs no simulation and writes the same results and page, byte for byte; a
changed stage is simulated again, the unchanged ones are not; another spec with the same stage
reuses its simulation; a damaged entry is simulated again; ``--force`` simulates everything;
the keys of forked workers are kept; two processes needing one simulation run it once."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe.cache import content as content_cache, simulation as sim_cache
from balpipe.build import Options, build
from balpipe.loader import load
from balpipe.study import run as run_study
from balpipe.validation_stage import simulated_model
import _content_caches as caches
from _content_caches import DAMAGES, build_ok, computed_once_by_two_processes, entry_damaged, record_puts
from _edits import replaced

ROOT = Path(__file__).resolve().parents[2]
QUICK = replaced((ROOT / "specs" / "scott_russell.yaml").read_text(), "  samples: 501", "  samples: 41")
DESCRIPTION = "The slider-crank of Fig. 5 with the Scott-Russell geometry"


@pytest.fixture
def simulated(monkeypatch):
    """The simulations that ran (not served from the cache) in this process: their keys."""
    return record_puts(monkeypatch, sim_cache.Store)


def write_spec(folder: Path, text: str = QUICK, name: str = "scott_russell") -> Path:
    return caches.write_spec(folder, text, name)


def run(specs: Path, out: Path, **kw) -> list:
    return build_ok(specs, out, True, **kw)


def sims(out: Path, slug: str = "scott_russell") -> dict[str, bytes]:
    return caches.entries(out, "sims", slug)


def page(out: Path, slug: str = "scott_russell") -> tuple[bytes, bytes]:
    """What a simulation feeds (timing.js, the run times, excepted): the page and results.json."""
    return caches.page(out, slug)


def test_a_rebuild_of_unchanged_stages_runs_no_simulation(tmp_path, simulated):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    n = len(simulated)
    assert n >= 5 and set(sims(out)) == {f"{k}.pickle" for k in simulated}  # 3 stages checked, 2 on the free frame
    kept = sims(out)
    simulated.clear()
    write_spec(specs, replaced(QUICK, DESCRIPTION, "A slider-crank with the Scott-Russell geometry"))
    (o,) = run(specs, out)
    assert not o.skipped and simulated == [] and sims(out) == kept
    # the same results and page as a build that simulated everything (another output folder)
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert len(simulated) == n
    assert page(out) == page(fresh)


def test_a_changed_stage_is_simulated_again_and_the_others_are_not(tmp_path, simulated):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    n, old = len(simulated), set(sims(out))
    simulated.clear()
    # the coupler's counterweight moves: its stages change, the unbalanced stage does not
    write_spec(specs, replaced(QUICK, "coupler_counterweight: -0.1 m", "coupler_counterweight: -0.09 m"))
    run(specs, out)
    new = set(sims(out))
    assert 0 < len(simulated) < n
    assert new - old == {f"{k}.pickle" for k in simulated}  # exactly what ran is new
    assert len(new & old) >= 2  # the unbalanced stage's runs (prescribed motion, torque-driven) kept
    assert len(new) == len(old)  # the changed stages' old entries pruned


def test_another_spec_with_the_same_stages_reuses_their_simulations(tmp_path, simulated):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    first = sims(out)
    simulated.clear()
    write_spec(specs, replaced(QUICK, DESCRIPTION, "A copy of it"), name="copy")
    run(specs, out)
    assert simulated == []  # scott_russell unchanged (skipped), copy: every run from scott_russell's entries
    assert sims(out, "copy") == first  # copied into its own folder: scott_russell's changes cannot take them away


@pytest.mark.parametrize("damage", DAMAGES)
def test_a_damaged_entry_is_simulated_again(tmp_path, simulated, damage):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    name = sorted(sims(out))[0]
    entry = out / ".cache" / "sims" / "scott_russell" / name
    good = entry.read_bytes()
    entry.write_bytes(entry_damaged(good, damage))
    simulated.clear()
    write_spec(specs, replaced(QUICK, DESCRIPTION, "Changed text"))
    run(specs, out)
    assert simulated == [name.removesuffix(".pickle")] and entry.read_bytes() != entry_damaged(good, damage)
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert page(out) == page(fresh)  # the run again gives what a build without the cache gives


def test_force_simulates_everything_and_no_sim_keeps_the_cache(tmp_path, simulated):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    n, kept = len(simulated), sims(out)
    simulated.clear()
    before = page(out)
    run(specs, out, force=True)
    assert len(simulated) == n and set(sims(out)) == set(kept)  # the same keys, every entry written again
    assert page(out) == before  # deterministic: the same results
    outcomes = build([str(specs)], Options(out, simulate=False, force=True), jobs=1)
    assert [o.status for o in outcomes] == ["ok"] and set(sims(out)) == set(kept)  # --no-sim: uses none, prunes none


def test_force_simulates_a_stage_shared_by_two_specs_once(tmp_path, simulated):
    """``--force`` trusts no entry of an earlier build, but what this build computed for one spec
    serves the other: every run once, the same pages as two separate builds."""
    specs = write_spec(tmp_path / "specs")
    write_spec(specs, replaced(QUICK, DESCRIPTION, "A copy of it"), name="copy")
    out = tmp_path / "out"
    run(specs, out)
    n = len(simulated)
    kept = sims(out, "copy")
    assert n >= 5 and kept == sims(out, "scott_russell")  # one spec's runs serve the other
    before = {s: page(out, s) for s in ("copy", "scott_russell")}
    simulated.clear()
    run(specs, out, force=True)
    assert sorted(simulated) == sorted(k.removesuffix(".pickle") for k in kept)  # every run again, once for both
    assert sims(out, "copy") == sims(out, "scott_russell") != kept  # rewritten (their run times), then shared
    assert {s: page(out, s) for s in ("copy", "scott_russell")} == before


def test_the_keys_of_forked_simulation_workers_are_kept(tmp_path, simulated):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out, sim_workers=2)  # the runs in two forked workers: their puts happen there
    kept = sims(out)
    assert len(kept) >= 5
    write_spec(specs, replaced(QUICK, DESCRIPTION, "Changed text"))
    simulated.clear()
    run(specs, out, sim_workers=2)
    assert sims(out) == kept  # none pruned as unused, none run again
    assert simulated == []


def test_keys_see_the_model_and_not_its_spec_locations():
    st = run_study(load(ROOT / "specs" / "offset_slider_crank.yaml").spec)
    s = st.stages[0]
    model = simulated_model(s.stage.model)
    assert model.sources == {}  # the spec locations of the parts are for messages only

    def k(m, an=s.analysis):
        return content_cache.key(sim_cache.run, (m, an), {}, "salt")

    assert k(model) == k(simulated_model(s.stage.model))
    from dataclasses import replace

    heavier = replace(model, bodies=(replace(model.bodies[0], mass=model.bodies[0].mass * (1 + 1e-12)),) + model.bodies[1:])
    assert k(heavier) != k(model)
    shifted = replace(s.analysis, q=s.analysis.q + np.where(np.arange(s.analysis.q.size) == 7, 1e-15, 0.0).reshape(s.analysis.q.shape))
    assert k(model, shifted) != k(model)
    assert k(st.stages[1].stage.model) != k(s.stage.model)


def test_two_processes_needing_one_simulation_run_it_once(tmp_path):
    computed_once_by_two_processes(sim_cache, tmp_path / "out", tmp_path / "log")


def test_what_cannot_be_keyed_is_run_not_cached(tmp_path):
    store = sim_cache.Store(tmp_path, "spec", "salt")
    with sim_cache.using(store):
        def local(x):
            return x + 2

        assert sim_cache.run(lambda x: x + 1, 1) == 2  # no name to key by
        assert sim_cache.run(local, 1) == 3  # a function inside another: not a module's name
        assert sim_cache.run(len, [object()]) == 1  # an argument that is not plain data
    assert store.used == set() and not (tmp_path / ".cache" / "sims" / "spec").exists()


def test_keys_do_not_see_what_a_law_memoised():
    """A serial arm's joint laws keep their inverse kinematics per time grid (a memo field,
    ``content_cache.MEMO``): a key is the same before and after a law was evaluated. (Paper
    003's torque-driven runs were keyed differently when the prescribed-motion run before them
    had been simulated, filling the memo, than when it had been served: a rebuild ran them all.)"""
    from balpipe.families.serial_arm import template as serial_arm
    from balpipe.motion import PointToPoint, quintic

    chain = serial_arm.Chain((0.0, 0.0), ((0.5, 0.0), (0.3, 0.0), (0.1, 0.0)))
    laws = tuple(PointToPoint(a, b, 1.0, quintic) for a, b in ((0.3, 0.5), (0.2, 0.4), (0.0, 1.0)))
    joint = serial_arm.joint_laws(chain, serial_arm.TaskMotion(laws, "tip"), 1)
    before = content_cache.key(sim_cache.run, (joint,), {}, "salt")
    joint[0](np.linspace(0, 1, 11))
    assert joint[0]._cache  # the memo holds the solution now
    assert content_cache.key(sim_cache.run, (joint,), {}, "salt") == before
    other = serial_arm.joint_laws(chain, serial_arm.TaskMotion(laws, "tip"), -1)  # the other working mode
    assert content_cache.key(sim_cache.run, (other,), {}, "salt") != before
