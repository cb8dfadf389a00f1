"""Issue 23: the balancing's numerical searches cached by content (``balpipe.cache.balance``). A
rebuild whose searches' inputs did not change computes none of them (the partial balancing's
fronts, the 4-RRR's topology counter-masses, finder check and design peaks) and writes the same
results and page, byte for byte, as a build without the cache; a changed input, a damaged entry,
another library version and ``--force`` compute again; unused entries and the folders of specs
that are gone are pruned; another spec with the same search reads it; two processes needing one
entry compute it once; nested searches take no second lock."""

from __future__ import annotations

import multiprocessing
import shutil
from pathlib import Path

import pytest

from balpipe.cache import balance as balance_cache, content as content_cache
from balpipe.balancing import conditions as C
from balpipe.balancing.partial import fronts as PF
from balpipe.families.rrr4 import counter_masses
import _content_caches as caches
from _content_caches import DAMAGES, build_ok, computed_once_by_two_processes, entry_damaged, record_puts
from _edits import replaced, stage_steps_kept

ROOT = Path(__file__).resolve().parents[2]
SPEC = (ROOT / "specs" / "partial_offset_slider_crank.yaml").read_text()
PARTIAL = replaced(replaced(SPEC, "  samples: 361", "  samples: 61"),  # small and quick: 61 samples, fronts of 5 points
                   "  budget: {mass: 1.5 kg}", "  budget: {mass: 1.5 kg}\n  fronts: {points: 5}")
SLUG = "partial_offset_slider_crank"
DESCRIPTION = "The offset slider-crank of offset_slider_crank.yaml"


@pytest.fixture
def fronts(monkeypatch):
    """How many times the fronts were computed (:func:`balpipe.balancing.partial.fronts.compute`
    called) in this process."""
    calls: list[int] = []
    real = PF.compute

    def counted(*a, **k):
        calls.append(1)
        return real(*a, **k)

    monkeypatch.setattr(PF, "compute", counted)
    return calls


@pytest.fixture
def stored(monkeypatch):
    """The keys of the searches computed (and stored) in this process."""
    return record_puts(monkeypatch, balance_cache.Store)


def write_spec(folder: Path, text: str = PARTIAL, name: str = SLUG) -> Path:
    return caches.write_spec(folder, text, name)


def run(specs: Path, out: Path, **kw) -> list:
    return build_ok(specs, out, False, **kw)


def entries(out: Path, slug: str = SLUG) -> dict[str, bytes]:
    return caches.entries(out, "balance", slug)


def page(out: Path, slug: str = SLUG) -> tuple[bytes, bytes]:
    return caches.page(out, slug)


def test_a_rebuild_reads_the_fronts_instead_of_computing_them(tmp_path, fronts, stored):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    assert len(fronts) == 1 and set(entries(out)) == {f"{k}.pickle" for k in stored} and len(stored) == 1
    kept = entries(out)
    fronts.clear()
    write_spec(specs, replaced(PARTIAL, DESCRIPTION, "A slider-crank with an offset"))
    (o,) = run(specs, out)
    assert not o.skipped and fronts == [] and entries(out) == kept  # read, not computed; nothing pruned
    fresh = tmp_path / "fresh"  # the same results and page as a build that computes them
    run(specs, fresh)
    assert len(fronts) == 1 and page(out) == page(fresh)


def test_a_changed_input_computes_again_and_its_old_entry_is_pruned(tmp_path, fronts, stored):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    old = set(entries(out))
    fronts.clear()
    stored.clear()
    write_spec(specs, replaced(PARTIAL, "fronts: {points: 5}", "fronts: {points: 6}"))
    run(specs, out)
    assert len(fronts) == 1 and set(entries(out)) == {f"{k}.pickle" for k in stored} and not set(entries(out)) & old
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert page(out) == page(fresh)


def test_another_library_version_computes_again(tmp_path, fronts, monkeypatch):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    env = balance_cache.environment()
    assert all(f"{lib} " in env for lib in ("numpy", "scipy", "clarabel")) and " -" not in env
    fronts.clear()
    monkeypatch.setattr(balance_cache, "environment", lambda: env.replace("clarabel ", "clarabel 0+"))
    write_spec(specs, replaced(PARTIAL, DESCRIPTION, "Changed text"))
    run(specs, out)
    assert len(fronts) == 1


@pytest.mark.parametrize("damage", DAMAGES + ("not a pickle",))
def test_a_damaged_entry_is_computed_again(tmp_path, fronts, damage):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    (name,) = entries(out)
    entry = out / ".cache" / "balance" / SLUG / name
    good = entry.read_bytes()
    entry.write_bytes(content_cache.pack(balance_cache.Store.HEADER, b"junk") if damage == "not a pickle"
                      else entry_damaged(good, damage))
    fronts.clear()
    write_spec(specs, replaced(PARTIAL, DESCRIPTION, "Changed text"))
    run(specs, out)
    assert len(fronts) == 1 and entry.read_bytes() == good  # computed again, the same bytes stored
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert page(out) == page(fresh)


def test_force_computes_everything_again_with_the_same_results(tmp_path, fronts):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    kept, before = entries(out), page(out)
    fronts.clear()
    run(specs, out, force=True)
    assert len(fronts) == 1 and entries(out) == kept and page(out) == before


def test_another_spec_reads_the_same_search_and_a_removed_spec_loses_its_folder(tmp_path, fronts):
    specs = write_spec(tmp_path / "specs")
    out = tmp_path / "out"
    run(specs, out)
    first = entries(out)
    fronts.clear()
    write_spec(specs, replaced(PARTIAL, DESCRIPTION, "A copy of it"), name="copy")
    run(specs, out)
    assert fronts == [] and entries(out, "copy") == first  # copied into its own folder
    (specs / f"{SLUG}.yaml").unlink()  # the spec and its page gone, another spec rebuilt
    shutil.rmtree(out / SLUG)
    write_spec(specs, replaced(PARTIAL, DESCRIPTION, "A copy, changed"), name="copy")
    run(specs, out)
    assert fronts == [] and entries(out, SLUG) == {} and entries(out, "copy") == first
    assert not (out / ".cache" / "balance" / SLUG).exists()  # the removed spec's folder pruned


def test_the_4rrr_rebuild_searches_nothing(tmp_path, stored, monkeypatch):
    """paper001_4rrr_fig6a: the drawn topologies' counter-masses, the finder's check (with its
    translating-platform states) and the designs' peak forces are read on a rebuild."""
    finds, analyses = [], []
    real_find, real_analyse = C.find, counter_masses.analyse
    monkeypatch.setattr(C, "find", lambda *a, **k: finds.append(1) or real_find(*a, **k))
    monkeypatch.setattr(counter_masses, "analyse", lambda *a, **k: analyses.append(1) or real_analyse(*a, **k))
    text = (ROOT / "specs" / "paper001_4rrr_fig6a.yaml").read_text()
    specs = write_spec(tmp_path / "specs", text, "fig6a")
    out = tmp_path / "out"
    run(specs, out)
    assert finds and analyses and len(stored) == 15  # 7 topologies' counter-masses, their 7 peaks, the finder
    assert set(entries(out, "fig6a")) == {f"{k}.pickle" for k in stored}
    finds.clear(), analyses.clear(), stored.clear()
    write_spec(specs, text + "\n# a comment\n", "fig6a")
    (o,) = run(specs, out)
    assert not o.skipped and finds == [] and analyses == [] and stored == []
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert page(out, "fig6a") == page(fresh, "fig6a")


def test_without_a_store_or_a_key_the_search_is_computed(tmp_path):
    assert balance_cache.Memo()(max, 1, 2) == 2  # no build: no store
    store = balance_cache.Store(tmp_path, "spec", "salt")
    memo = balance_cache.Memo(store)
    assert memo(lambda x: x + 1, 1) == 2  # no name to key by
    assert memo(len, [object()]) == 1  # an argument that is not plain data
    assert store.used == set() and not (tmp_path / ".cache").exists()


def test_two_processes_needing_one_search_compute_it_once(tmp_path):
    computed_once_by_two_processes(balance_cache, tmp_path / "out", tmp_path / "log")


def _nested(out: str) -> None:
    store = balance_cache.Store(Path(out), "spec", "salt")
    with store.lock("ab" + "0" * 62), store.lock("ab" + "1" * 62):  # one lock file: flock would wait on itself
        pass


def test_a_search_inside_a_locked_one_takes_no_second_lock(tmp_path):
    (tmp_path / "out").mkdir()
    p = multiprocessing.get_context("fork").Process(target=_nested, args=(str(tmp_path / "out"),))
    p.start()
    p.join(20)
    if p.is_alive():
        p.kill()
    assert p.exitcode == 0


def _hold(out: str, held, done) -> None:
    store = balance_cache.Store(Path(out), "spec", "salt")
    with store.lock("ab" + "0" * 62):
        held.set()
        done.wait(30)


def _take(out: str) -> None:
    store = balance_cache.Store(Path(out), "other", "salt")
    with store.lock("ab" + "1" * 62):
        pass


def test_a_process_never_waits_for_another_key_and_no_lock_file_stays(tmp_path):
    """Issue 43: a lock per key, not per first two hex digits of the key: while one process holds
    a key's lock (computing it), another takes the lock of a key that begins the same at once
    (before, a build of specs/ on two processes waited 0.69 s for a simulation of another spec);
    the lock files go when their locks are released."""
    out = tmp_path / "out"
    out.mkdir()
    ctx = multiprocessing.get_context("fork")
    held, done = ctx.Event(), ctx.Event()
    holder = ctx.Process(target=_hold, args=(str(out), held, done))
    holder.start()
    try:
        assert held.wait(20)
        taker = ctx.Process(target=_take, args=(str(out),))
        taker.start()
        taker.join(20)  # with one lock file for both keys it would wait for the holder, which waits for it
        if taker.is_alive():
            taker.kill()
        assert taker.exitcode == 0
    finally:
        done.set()
        holder.join(20)
    assert holder.exitcode == 0
    assert list((out / content_cache.CACHE_DIR / balance_cache.Store.KIND / content_cache.LOCKS).iterdir()) == []


def test_paper003s_phi_optimisation_is_read_on_a_rebuild(tmp_path, stored, monkeypatch):
    """paper 003's phi optimisation (Nelder-Mead per trajectory, ~2 s) is a search of the cache:
    a rebuild after a comment optimises nothing and writes the same page; the note still counts
    the objective's evaluations (read with the searches)."""
    from balpipe.families.serial_arm import com_planning as CP

    runs = []
    real = CP.Planner.optimise_phi
    monkeypatch.setattr(CP.Planner, "optimise_phi", lambda self, *a: runs.append(1) or real(self, *a))
    text = (ROOT / "specs" / "paper003_com_planning.yaml").read_text()
    text = replaced(replaced(text, "trajectories: [P1P13, P2P12, P3P11, P4P10, P5P9, P15P7, P14P8, P13P9]",
                             "trajectories: [P1P13, P15P7]"), "samples: 501", "samples: 101")
    text = stage_steps_kept(text, "[P1P13, P15P7]")
    specs = write_spec(tmp_path / "specs", text, "p3")
    out = tmp_path / "out"
    run(specs, out)
    assert len(runs) == 2 and len(stored) == 2  # one search per trajectory
    runs.clear(), stored.clear()
    write_spec(specs, text + "\n# a comment\n", "p3")
    (o,) = run(specs, out)
    assert not o.skipped and runs == [] and stored == []
    results = (out / "p3" / "results.json").read_text()
    assert "0 objective evaluations" not in results and " objective evaluations in all for 2 trajectories" in results
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert page(out, "p3") == page(fresh, "p3")
