"""Issue 23, item 3: the figures cached by content (``balpipe.cache.figures``). A hit is the SVG a
fresh drawing gives, byte for byte; a changed input misses; a damaged entry is redrawn, never
served; ``--force`` redraws and rewrites; a build keeps only the entries it used; a symlink in the
cache is never followed; the cache is invisible in the site."""

from __future__ import annotations

import shutil
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe import build as build_mod
from balpipe.build import Options, build
from balpipe.cache import figures as cache
from balpipe.draw import figures
from _edits import replaced

ROOT = Path(__file__).resolve().parents[2]
SCOTT = (ROOT / "specs" / "scott_russell.yaml").read_text()
QUICK = replaced(SCOTT, "  samples: 501", "  samples: 41")
DESCRIPTION = "The slider-crank of Fig. 5 with the Scott-Russell geometry"


def site(out: Path) -> dict[str, bytes]:
    """Every file of the site, ``.cache/`` left out (it is not published)."""
    return {p.relative_to(out).as_posix(): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and p.relative_to(out).parts[0] != cache.CACHE_DIR}


def entries(out: Path, slug: str = "scott_russell") -> dict[str, bytes]:
    folder = out / cache.CACHE_DIR / cache.FIGURES / slug
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.is_dir() else {}


@pytest.fixture
def drawn(monkeypatch):
    """Counts the figures that are drawn in this process: matplotlib's (``to_svg`` calls, in
    ``draw.figures`` and in every balpipe module already imported that bound ``to_svg`` to its
    own name, e.g. ``report.history_figures``: imported by an earlier test of the same worker,
    it would otherwise keep calling the uncounted function) and the mechanism drawings
    (``canvas.Canvas.svg`` calls)."""
    from balpipe.draw import canvas

    calls = []
    real = figures.to_svg
    real_canvas = canvas.Canvas.svg

    def counted(fig, prefix):
        calls.append(prefix)
        return real(fig, prefix)

    def counted_canvas(self, prefix):
        calls.append(prefix)
        return real_canvas(self, prefix)

    for name, module in list(sys.modules.items()):
        if (name == "balpipe" or name.startswith("balpipe.")) and getattr(module, "to_svg", None) is real:
            monkeypatch.setattr(module, "to_svg", counted)
    monkeypatch.setattr(canvas.Canvas, "svg", counted_canvas)
    return calls


def one_spec(tmp_path: Path, text: str = QUICK) -> Path:
    folder = tmp_path / "specs"
    folder.mkdir(exist_ok=True)
    (folder / "scott_russell.yaml").write_text(text)
    return folder


def run(specs: Path, out: Path, **kw) -> list:
    outcomes = build([str(specs)], Options(out, simulate=False, **kw), jobs=1)
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    return outcomes


# --- the key ----------------------------------------------------------------------------------


def _plot(*args, **kwargs) -> str:
    return "x"


def test_the_key_is_deterministic_and_sees_every_input():
    t = np.linspace(0.0, 1.0, 11)
    base = cache.key(_plot, (t, [("a", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "salt")
    assert base == cache.key(_plot, (t.copy(), [("a", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "salt")
    nudged = t.copy()
    nudged[3] = np.nextafter(nudged[3], 2.0)
    changed = [
        ((nudged, [("a", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "salt"),  # one ulp of one sample
        ((t.astype(np.float32), [("a", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "salt"),  # the dtype
        ((t, [("a", 1)], {"p": (1, 2)}), {"prefix": "m"}, "salt"),  # 1 is not 1.0
        ((t, [["a", 1.0]], {"p": (1, 2)}), {"prefix": "m"}, "salt"),  # a list is not a tuple
        ((t, [("b", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "salt"),  # a label
        ((t, [("a", 1.0)], {"p": (1, 2)}), {"prefix": "n"}, "salt"),  # the ids' prefix
        ((t, [("a", 1.0)], {"p": (1, 2)}), {"prefix": "m"}, "other code"),  # balpipe's code
    ]
    keys = {cache.key(_plot, a, k, s) for a, k, s in changed}
    assert base not in keys and len(keys) == len(changed)
    # dicts in their order: the order a figure draws (and places labels) in
    assert cache.key(_plot, ({"a": 1, "b": 2},), {}, "") != cache.key(_plot, ({"b": 2, "a": 1},), {}, "")
    assert cache.key(series_svg, (), {}, "") != cache.key(figures.mechanism_svg, (), {}, "")


def test_what_cannot_be_hashed_is_refused():
    with pytest.raises(cache.Unhashable):
        cache.key(_plot, (object(),), {}, "")
    with pytest.raises(cache.Unhashable):
        cache.key(lambda: "x", (), {}, "")  # a closure's captured data would be missing from the key
    with pytest.raises(cache.Unhashable):
        cache.key(_plot, (np.array([None]),), {}, "")


# --- the store --------------------------------------------------------------------------------


def series_svg(t: np.ndarray, curves: list, ylabel: str, prefix: str, title: str = "") -> str:
    """A plain time-series figure, drawn by matplotlib (through ``figures.to_svg``, which
    ``drawn`` counts): a stand-in for any figure a build caches."""
    fig, ax = figures.plt.subplots(figsize=(6.0, 3.0))
    for k, (label, y) in enumerate(curves):
        ax.plot(t, y, label=label, **figures.style(k))
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    return figures.to_svg(fig, prefix)


def series_figure(t: np.ndarray, curves: list, ylabel: str, prefix: str, title: str = "") -> str:
    return cache.svg(series_svg, t, curves, ylabel, prefix, title)


def _series() -> tuple:
    t = np.linspace(0.0, 1.0, 50)
    return t, [("unbalanced", np.sin(6 * t)), ("balanced", 0.1 * np.cos(6 * t))], "force (N)", "s"


def test_a_hit_is_the_fresh_drawing_byte_for_byte(tmp_path, drawn):
    fresh = series_figure(*_series())  # no store: drawn
    store = cache.Store(tmp_path, "spec", "salt")
    with cache.using(store):
        first = series_figure(*_series())
        again = series_figure(*_series())
    assert first == fresh and again == fresh
    assert (store.drawn, store.hits) == (1, 1) and len(drawn) == 2
    t, curves, ylabel, prefix = _series()
    with cache.using(cache.Store(tmp_path, "spec", "salt")) as other:
        series_figure(t, curves[:1], ylabel, prefix)  # another input: a miss
    assert (other.drawn, other.hits) == (1, 0)


@pytest.mark.parametrize("damage", ["truncated", "flipped", "empty", "no header"])
def test_a_damaged_entry_is_redrawn_and_rewritten(tmp_path, damage):
    fresh = series_figure(*_series())
    with cache.using(cache.Store(tmp_path, "spec", "salt")):
        series_figure(*_series())
    (entry,) = (tmp_path / ".cache" / "figures" / "spec").iterdir()
    good = entry.read_bytes()
    bad = {"truncated": good[: len(good) // 2], "flipped": good.replace(b"<path", b"<pbth", 1), "empty": b"",
           "no header": good.split(b"\n", 1)[1]}[damage]
    entry.write_bytes(bad)
    with cache.using(cache.Store(tmp_path, "spec", "salt")) as store:
        assert series_figure(*_series()) == fresh
    assert (store.drawn, store.hits) == (1, 0)
    assert entry.read_bytes() == good


def test_a_symlinked_entry_or_folder_is_never_followed(tmp_path):
    fresh = series_figure(*_series())
    forged = tmp_path / "forged.svg"
    forged.write_text(cache._pack("<svg>forged</svg>"))  # a valid entry, planted outside the cache
    out = tmp_path / "out"
    store = cache.Store(out, "spec", "salt")
    k = cache.key(series_svg, _series() + ("",), {}, "salt")  # series_figure's call, title ""
    store.folder.mkdir(parents=True)
    (store.folder / f"{k}.svg").symlink_to(forged)
    with cache.using(store):
        assert series_figure(*_series()) == fresh
    assert store.hits == 0 and forged.read_text() == cache._pack("<svg>forged</svg>")  # the target untouched
    assert not (store.folder / f"{k}.svg").is_symlink()  # the link was replaced by the entry
    # a cache folder that is a link: neither read nor written
    elsewhere = tmp_path / "elsewhere"
    (elsewhere / "figures" / "spec").mkdir(parents=True)
    (elsewhere / "figures" / "spec" / f"{k}.svg").write_text(cache._pack("<svg>forged</svg>"))
    out2 = tmp_path / "out2"
    out2.mkdir()
    (out2 / ".cache").symlink_to(elsewhere, target_is_directory=True)
    with cache.using(cache.Store(out2, "spec", "salt")) as s2:
        assert series_figure(*_series()) == fresh
        s2.prune()
    assert s2.hits == 0 and s2.drawn == 1
    assert [p.name for p in (elsewhere / "figures" / "spec").iterdir()] == [f"{k}.svg"]
    # another spec's folder that is a link (to a folder with a valid entry): not read from
    out3 = tmp_path / "out3"
    (out3 / ".cache" / "figures").mkdir(parents=True)
    (out3 / ".cache" / "figures" / "other").symlink_to(elsewhere / "figures" / "spec", target_is_directory=True)
    with cache.using(cache.Store(out3, "spec3", "salt")) as s3:
        assert series_figure(*_series()) == fresh
    assert s3.hits == 0 and s3.drawn == 1
    # and the same entry in another spec's own folder is read (copied into this spec's folder)
    out4 = tmp_path / "out4"
    (out4 / ".cache" / "figures" / "other").mkdir(parents=True)
    (out4 / ".cache" / "figures" / "other" / f"{k}.svg").write_text(cache._pack(fresh))
    with cache.using(cache.Store(out4, "spec4", "salt")) as s4:
        assert series_figure(*_series()) == fresh
    assert s4.hits == 1 and s4.drawn == 0 and (out4 / ".cache" / "figures" / "spec4" / f"{k}.svg").is_file()


# --- builds -----------------------------------------------------------------------------------


def test_a_spec_changed_where_no_figure_looks_redraws_nothing(tmp_path, drawn):
    specs = one_spec(tmp_path)
    out = tmp_path / "out"
    run(specs, out)
    assert len(drawn) >= 2 and len(entries(out)) == len(drawn)
    cached = entries(out)
    drawn.clear()
    one_spec(tmp_path, replaced(QUICK, DESCRIPTION, "A slider-crank with the Scott-Russell geometry"))
    (o,) = run(specs, out)
    assert not o.skipped and drawn == []  # rebuilt, every figure from the cache
    assert entries(out) == cached
    # the same site as a build without any cache, byte for byte
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert site(out) == site(fresh) and "A slider-crank with the Scott" in (out / "scott_russell" / "index.html").read_text()


def test_force_redraws_every_figure_and_refreshes_the_cache(tmp_path, drawn):
    specs = one_spec(tmp_path)
    out = tmp_path / "out"
    run(specs, out)
    before, n = site(out), len(drawn)
    name = sorted(entries(out))[0]
    entry = out / ".cache" / "figures" / "scott_russell" / name
    good = entry.read_bytes()
    entry.write_bytes(good.replace(b"</svg>", b"<!-- stale --></svg>"))  # not servable, and it must be rewritten
    drawn.clear()
    run(specs, out, force=True)
    assert len(drawn) == n and site(out) == before and entry.read_bytes() == good


def test_a_build_keeps_only_the_entries_it_used(tmp_path, drawn):
    specs = one_spec(tmp_path)
    out = tmp_path / "out"
    run(specs, out)
    old = set(entries(out))
    stray = out / ".cache" / "figures" / "scott_russell" / ("0" * 64 + ".svg")
    stray.write_text("left by an earlier build")
    keep = out / ".cache" / "figures" / "scott_russell" / "notes.txt"  # not a cache entry: left alone
    keep.write_text("mine")
    one_spec(tmp_path, replaced(QUICK, "slider:  {mass: 0.5 kg}", "slider:  {mass: 0.6 kg}"))
    drawn.clear()
    run(specs, out)
    new = set(entries(out))
    assert not stray.exists() and keep.exists()
    new.discard("notes.txt")
    assert new and len(new) == len(drawn)  # exactly what this build drew
    assert len(old & new) < len(old)  # the drawings that changed replaced their old entries
    # a spec gone from the site (its page folder removed) loses its cache at the next build
    ghost = out / ".cache" / "figures" / "deleted_spec"
    ghost.mkdir()
    (ghost / ("1" * 64 + ".svg")).write_text("x")
    one_spec(tmp_path, QUICK)
    run(specs, out)
    assert not ghost.exists() and entries(out)


def test_a_build_never_writes_through_a_planted_cache_link(tmp_path, drawn):
    specs = one_spec(tmp_path)
    outside = tmp_path / "outside"
    outside.mkdir()
    out = tmp_path / "out"
    out.mkdir()
    (out / ".cache").symlink_to(outside, target_is_directory=True)
    run(specs, out)
    n = len(drawn)
    run(specs, out, force=True)
    assert n and len(drawn) == 2 * n  # no cache: drawn both times
    assert list(outside.iterdir()) == [] and (out / ".cache").is_symlink()
    fresh = tmp_path / "fresh"
    run(specs, fresh)
    assert site(out) == site(fresh)


def test_jobs_and_cache_give_the_same_site(tmp_path):
    specs = tmp_path / "specs"
    specs.mkdir()
    (specs / "scott_russell.yaml").write_text(QUICK)
    (specs / "five_bar.yaml").write_text(replaced((ROOT / "specs" / "paper004_five_bar.yaml").read_text(),
                                                  "  samples: 501", "  samples: 41"))  # a family's own figures
    a, b = tmp_path / "a", tmp_path / "b"
    build([str(specs)], Options(a, simulate=False), jobs=1)
    build([str(specs)], Options(b, simulate=False), jobs=2)
    assert site(a) == site(b) and entries(a) == entries(b) and entries(a, "five_bar") == entries(b, "five_bar")
    build([str(specs)], Options(b, simulate=False, force=True), jobs=2)  # every page rebuilt, from the cache
    assert site(a) == site(b)


def test_a_worker_without_the_cache_draws_everything(tmp_path, drawn):
    specs = one_spec(tmp_path)
    out = tmp_path / "out"
    run(specs, out)
    drawn.clear()
    job = build_mod.plan_one(specs / "scott_russell.yaml", Options(out, simulate=False, force=True))
    assert job.figure_cache == out and job.redraw
    job = build_mod.plan_one(specs / "scott_russell.yaml", Options(out, simulate=False, force=True), figure_cache=False)
    assert job.figure_cache is None and job.figure_keys == frozenset()  # what --scheduler sends to its workers
    done = build_mod.compute(job)
    assert done.status == "ok" and len(drawn) == len(entries(out))
    assert done.files["index.html"] == (out / "scott_russell" / "index.html").read_text()


def test_git_ignores_the_cache():
    """The CI workflow publishes the site without ``.cache/`` (tests/test_workflow.py); git ignores it."""
    assert ".cache/" in (ROOT / ".gitignore").read_text().split()


def test_the_history_figures_are_cached_too(tmp_path, monkeypatch, drawn):
    from _gitrepo import Repo

    from balpipe import history

    repo = Repo(tmp_path / "repo")
    repo.copy_spec("scott_russell.yaml", "specs/scott_russell.yaml")
    repo.commit("first", {"specs/scott_russell.yaml": QUICK})
    repo.commit("heavier slider", {"specs/scott_russell.yaml": replaced(QUICK, "slider:  {mass: 0.5 kg}",
                                                                       "slider:  {mass: 0.6 kg}")})
    monkeypatch.chdir(repo.path)
    history.run(["specs"], Path("out"), Path("cache"), simulate=False)
    drawn.clear()
    run(Path("specs"), Path("out"))
    # the page's history section: interactive plots of history.json's numbers, nothing drawn
    assert 'data-live="live-hist-loads"' in Path("out/scott_russell/index.html").read_text()
    assert not any(p.startswith("hist-") for p in drawn)
    n = len(entries(Path("out")))
    drawn.clear()
    spec = Path("specs/scott_russell.yaml")
    spec.write_text(replaced(spec.read_text(), DESCRIPTION, "A slider-crank with the Scott-Russell geometry"))
    (o,) = run(Path("specs"), Path("out"))
    assert not o.skipped and drawn == [] and len(entries(Path("out"))) == n  # nothing drawn, nothing pruned
    fresh = Path("fresh")
    shutil.copytree("out", fresh, ignore=shutil.ignore_patterns(".cache"))
    run(Path("specs"), fresh, force=True)
    assert site(Path("out")) == site(fresh)


def test_another_spec_drawing_the_same_figures_draws_none(tmp_path, drawn):
    specs = one_spec(tmp_path)
    out = tmp_path / "out"
    run(specs, out)
    first = entries(out)
    drawn.clear()
    (specs / "the_copy.yaml").write_text(replaced(QUICK, DESCRIPTION, "A copy of it"))
    run(specs, out)
    assert drawn == [] and entries(out, "the_copy") == first  # read from scott_russell's, copied
    assert (out / "the_copy" / "index.html").read_text().count("<svg") == (out / "scott_russell" / "index.html").read_text().count("<svg")
