"""Shared helpers for the tests: slider-crank specs with random parameters, the ``--long``
option (see ``_long.py``), studies and builds computed once per session."""

from __future__ import annotations

import hashlib
import json
import math
import os
import shutil
import subprocess
import sys
from pathlib import Path

import balpipe  # noqa: F401  (first: it sets one BLAS thread before numpy loads)

# tests/ mirrors the package's folders (tests/engine/ for balpipe.engine, ...); a test module may
# read another's helpers by its name (``from test_validate import ...``), wherever it lives
_TESTS = Path(__file__).resolve().parent
sys.path[1:1] = [str(d) for d in sorted(_TESTS.iterdir()) if d.is_dir() and any(d.glob("test_*.py"))]
import numpy as np
import pytest

from balpipe.spec import Spec
from _long import ENV as LONG_ENV

SPECS = Path(__file__).resolve().parents[1] / "specs"


def pytest_addoption(parser):
    parser.addoption("--long", action="store_true", default=False,
                     help=f"run the long random samples ({LONG_ENV}=1 does the same); "
                          "by default a short seeded sample of them runs")
    parser.addoption(
        "--built-site", metavar="DIR", default=None,
        help="run the browser's page checks (tests/report/test_site_browser.py, the tests named built_site) "
             "on every HTML page of a site already built into DIR (balpipe build specs/ -o DIR)")


def pytest_configure(config):
    if config.getoption("long"):  # every xdist worker runs this too, before it imports the tests
        os.environ[LONG_ENV] = "1"


def slider_crank_spec(rng: np.random.Generator | None = None, *, scott_russell: bool = False,
                      law: str = "quintic", duration: float = 0.3, mass_scale: float = 1.0,
                      gravity: bool = False, moment_unknown: str | None = None, **over) -> Spec:
    """A valid slider-crank spec; random lengths, masses, centres of mass and inertias when
    ``rng`` is given."""
    r = rng if rng is not None else np.random.default_rng(0)
    L1 = float(r.uniform(0.1, 0.3))
    L2 = L1 if scott_russell else float(r.uniform(1.3, 2.5) * L1)
    offset = 0.0 if scott_russell else float(r.uniform(-0.3, 0.3) * (L2 - L1))
    k = mass_scale

    def link(L):
        m = float(r.uniform(0.3, 3.0))
        return {"length": L, "mass": k * m, "com": float(r.uniform(0.2, 0.8) * L),
                "inertia": k * m * L * L * float(r.uniform(0.05, 0.12))}

    if scott_russell:
        start, end = math.radians(float(r.uniform(-80, -30))), math.radians(float(r.uniform(30, 80)))
    else:
        start = float(r.uniform(0, 2 * math.pi))
        end = start + float(r.uniform(0.5, 2.0)) * math.pi
    data = {
        "name": "random slider-crank",
        "mechanism": {"template": "slider_crank", "offset": offset, "crank": link(L1), "coupler": link(L2),
                      "slider": {"mass": k * float(r.uniform(0.2, 2.0))}},
        "motion": {"law": law, "duration": duration, "drive": {"crank": {"from": start, "to": end}}},
        "balancing": {"method": "slider_crank_counterweights",
                      "crank_counterweight": -float(r.uniform(0.3, 1.0)) * L1,
                      "coupler_counterweight": -float(r.uniform(0.3, 1.0)) * L2,
                      "moment_unknown": moment_unknown},
        "analysis": {"samples": 201, "gravity": gravity},
        "validation": {"enabled": False},
    }
    for key, value in over.items():
        data[key] = value
    return Spec.model_validate(data)


@pytest.fixture
def rng() -> np.random.Generator:
    return np.random.default_rng(20261122)


def _shared_root(tmp_path_factory) -> Path:
    """A folder that every xdist worker of this run sees (the parent of the workers' own)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


class Shared:
    """Values computed once per run whatever the number of xdist workers: ``get(key, compute)``
    runs ``compute()`` in the first worker that asks, under a lock, and keeps its pickle in the
    run's shared folder; the other workers load it. A value that holds local functions (paper
    003's study: its motion profiles and its ``derived`` hook) is pickled by cloudpickle, which
    keeps such functions by value (installed with dask.distributed, a test dependency); without
    it, or when that fails too, each worker that asks computes the value."""

    def __init__(self, root: Path):
        self.root = root
        root.mkdir(exist_ok=True)

    def get(self, key: str, compute):
        import fcntl
        import pickle

        name = hashlib.sha256(key.encode()).hexdigest()[:16]
        path, refused = self.root / f"{name}.pickle", self.root / f"{name}.unpicklable"
        with open(self.root / f"{name}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            if path.exists():
                return pickle.loads(path.read_bytes())
            if not refused.exists():
                value = compute()
                data = _pickled(value)
                if data is None:
                    refused.touch()
                    return value
                tmp = path.with_suffix(".part")
                tmp.write_bytes(data)
                tmp.replace(path)
                return value
        return compute()


def _pickled(value) -> bytes | None:
    """``value``'s pickle (pickle, else cloudpickle for local functions), or None. Either loads
    with :func:`pickle.loads`."""
    import pickle

    try:
        return pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, AttributeError, TypeError):
        pass
    try:
        import cloudpickle
    except ImportError:
        return None
    try:
        return cloudpickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
    except (pickle.PicklingError, AttributeError, TypeError):
        return None


@pytest.fixture(scope="session")
def shared(tmp_path_factory) -> Shared:
    """:class:`Shared` in this run's folder shared by the xdist workers."""
    return Shared(_shared_root(tmp_path_factory) / "shared-objects")


@pytest.fixture(scope="session")
def api_studies(shared):
    """``api_studies(name)``: ``balpipe.run(balpipe.load("specs/<name>"))`` (no simulation; the
    path relative to the repository, as ``balpipe build specs/`` names it), run once per run (the
    first xdist worker that needs it runs it, the others load it: :class:`Shared`); the tests
    only read it."""
    import contextlib

    cache: dict = {}

    def compute(name: str):
        with contextlib.chdir(SPECS.parent):
            return balpipe.run(balpipe.load(Path("specs") / name), simulate=False)

    def get(name: str):
        if name not in cache:
            text = (SPECS / name).read_text(encoding="utf-8")
            cache[name] = shared.get(f"api study\n{name}\n{text}", lambda: compute(name))
        return cache[name]

    return get


@pytest.fixture(scope="session")
def studies(api_studies):
    """``studies(name)``: the pipeline's study of ``specs/<name>``
    (:attr:`balpipe.Study.engine_study` of :func:`api_studies`'s); the tests only read it."""
    return lambda name: api_studies(name).engine_study


class Pages:
    """``pages(name)``: the page of ``studies(name)`` without the simulation (results of "x",
    hash "h", no spec text); ``pages.figures(name)``: the figures that page drew
    (:func:`balpipe.report.page.study_figures`'s dict, the very one the page was rendered
    from). Each rendered once per run (:class:`Shared`)."""

    def __init__(self, studies, shared: Shared):
        self._studies = studies
        self._shared = shared
        self._html: dict[str, str] = {}
        self._figures: dict[str, dict] = {}

    def _render(self, name: str) -> None:
        text = (SPECS / name).read_text(encoding="utf-8")
        self._html[name], self._figures[name] = self._shared.get(f"page\n{name}\n{text}", lambda: self._draw(name))

    def _draw(self, name: str) -> tuple[str, dict]:
        from balpipe.report import page, results

        st = self._studies(name)
        real = page.study_figures
        drawn: list[dict] = []

        def keep(*args, **kwargs):  # the page's own call, its result kept
            drawn.append(real(*args, **kwargs))
            return drawn[-1]

        page.study_figures = keep
        try:
            html = page.render_page(st, results.results_dict(st, "x", "h", False), "")
        finally:
            page.study_figures = real
        assert len(drawn) == 1
        return html, drawn[0]

    def __call__(self, name: str) -> str:
        if name not in self._html:
            self._render(name)
        return self._html[name]

    def figures(self, name: str) -> dict:
        if name not in self._figures:
            self._render(name)
        return self._figures[name]


@pytest.fixture(scope="session")
def pages(studies, shared) -> Pages:
    """:class:`Pages` of the specs' studies (``pages(name)``, ``pages.figures(name)``); the tests
    only read them."""
    return Pages(studies, shared)


@pytest.fixture(scope="session")
def shared_build(tmp_path_factory):
    """``shared_build(names, *args)``: ``specs/<name>`` for each name copied to ``<folder>/specs``
    and ``python -m balpipe build *args`` run in ``<folder>``, once per run whatever the number
    of xdist workers (the first worker builds under a lock, keyed by the specs' text and the
    arguments; the others read its result): (folder, the build's completed process). The
    folder is shared: a test that changes it must work on a copy."""
    import fcntl

    root = _shared_root(tmp_path_factory) / "shared-builds"
    root.mkdir(exist_ok=True)

    def get(names: tuple[str, ...], *args: str) -> tuple[Path, subprocess.CompletedProcess]:
        key = hashlib.sha256(json.dumps([[(n, (SPECS / n).read_text()) for n in names], list(args)]).encode())
        folder = root / key.hexdigest()[:16]
        with open(root / f"{folder.name}.lock", "w") as lock:
            fcntl.flock(lock, fcntl.LOCK_EX)
            done = folder / "completed.json"
            if not done.exists():
                shutil.rmtree(folder, ignore_errors=True)
                (folder / "specs").mkdir(parents=True)
                for n in names:
                    shutil.copy(SPECS / n, folder / "specs" / n)
                r = subprocess.run([sys.executable, "-m", "balpipe", "build", *args], capture_output=True,
                                   text=True, cwd=folder)
                done.write_text(json.dumps([r.args, r.returncode, r.stdout, r.stderr]))
        a, rc, out, err = json.loads(done.read_text())
        return folder, subprocess.CompletedProcess(a, rc, out, err)

    return get


def chromium() -> str | None:
    """The system's Chromium: ``BALPIPE_CHROMIUM``, /usr/bin/chromium or one on ``PATH``."""
    for cand in (os.environ.get("BALPIPE_CHROMIUM"), "/usr/bin/chromium", shutil.which("chromium"),
                 shutil.which("chromium-browser"), shutil.which("google-chrome")):
        if cand and Path(cand).exists():
            return cand
    return None


@pytest.fixture(scope="session")
def browser():
    """Headless Chromium through playwright, launched once per xdist worker: the browser tests
    (tests/report/test_site_browser.py, tests/report/test_live_browser.py) share one xdist_group, so one worker
    launches it. Skipped with the reason when playwright or Chromium is missing."""
    # CI installs Chromium and sets BALPIPE_REQUIRE_BROWSER: there a missing browser fails
    missing = pytest.fail if os.environ.get("BALPIPE_REQUIRE_BROWSER") else pytest.skip
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        missing("playwright for Python is not installed: pip install '.[test]'")
    exe = chromium()
    if exe is None:
        missing("no Chromium found (/usr/bin/chromium, chromium on PATH, or BALPIPE_CHROMIUM)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=exe)
        try:
            yield b
        finally:
            b.close()


@pytest.fixture(autouse=True)
def _close_browser_pages(request):
    """After each test that uses the session's Chromium, close the pages it opened (every browser
    context): a study page left open keeps its player animating, and in a browser shared by the
    whole run two such pages kept two renderer processes at half a core each until the end."""
    yield
    if "browser" in request.fixturenames:
        for context in list(request.getfixturevalue("browser").contexts):
            context.close()


#: Test modules whose tests take longest, slowest first (wall time of a full run, 2 cores). They
#: are collected first, so xdist hands them out first and the short tests fill the workers'
#: last minutes; the xdist groups (the browser tests) go first anyway (xdist orders the work
#: units by their number of tests). A deterministic order: every worker collects the same.
SLOW_FIRST = (
    "test_rrr4_topologies.py", "test_check_parallel.py", "test_partial.py", "test_rrr4_finder.py",
    "test_sweep.py", "test_history.py", "test_paper_figures.py", "test_realisable.py", "test_sweep_block.py",
    "test_drawing_labels.py", "test_rrr4.py", "test_partial_motions.py", "test_build_cluster.py",
    "test_validation_power.py", "test_hostile.py", "test_diff.py", "test_rpr3_pymunk.py", "test_rpr3_generic.py",
    "test_engine_paths.py", "test_cli.py", "test_own_machine_examples.py", "test_verdict.py", "test_families.py",
)


#: The xdist groups (``--dist loadgroup``, the default of pyproject's addopts): the modules whose
#: tests run on one worker, as their ``xdist_group`` mark says. The scheduler below reads this
#: table, not the marks: pytest-xdist 3.8 sends a mark's group to the controller in the test's
#: node id, which pytest 9.2 no longer lets it change (pytest-xdist issue 1386), and the groups
#: were silently spread over the workers (each built the browser tests' sites and a browser).
GROUPS = {"test_site_browser.py": "site_browser", "test_live_browser.py": "site_browser",
          "test_whatif_browser.py": "site_browser", "test_verdict_browser.py": "site_browser"}


def pytest_collection_modifyitems(session, config, items):
    """The modules of :data:`SLOW_FIRST` first, in that order; the others after them, each
    module's tests in their own order. A module's ``xdist_group`` mark must be its entry in
    :data:`GROUPS`."""
    for item in items:
        for mark in item.iter_markers("xdist_group"):
            name = mark.args[0] if mark.args else mark.kwargs.get("name", "default")
            if GROUPS.get(item.path.name) != name:
                raise pytest.UsageError(f"{item.path.name}: xdist_group {name!r} is not its entry in "
                                        f"tests/conftest.py GROUPS ({GROUPS.get(item.path.name)!r})")
    rank = {name: k for k, name in enumerate(SLOW_FIRST)}
    items.sort(key=lambda item: rank.get(item.path.name, len(rank)))  # stable: the modules stay whole


@pytest.hookimpl(optionalhook=True)
def pytest_xdist_make_scheduler(config, log):
    """``--dist loadgroup`` with the groups of :data:`GROUPS`, found from the node ids' module
    (the mark's ``@group`` suffix, where xdist can still add it, names the same group)."""
    if config.getvalue("dist") != "loadgroup":
        return None
    from xdist.scheduler import LoadGroupScheduling

    class ModuleGroups(LoadGroupScheduling):
        def _split_scope(self, nodeid: str) -> str:
            group = GROUPS.get(nodeid.split("::", 1)[0].rsplit("/", 1)[-1])
            return group if group is not None else super()._split_scope(nodeid)

    return ModuleGroups(config, log)
