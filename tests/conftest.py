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
        help="run the browser's page checks (tests/test_site_browser.py, the tests named built_site) "
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


@pytest.fixture(scope="session")
def studies():
    """``studies(name)``: the study of ``specs/<name>``, run once per session (per xdist worker);
    the tests only read it."""
    from balpipe import loader
    from balpipe import study as study_mod

    cache: dict = {}

    def get(name: str):
        if name not in cache:
            cache[name] = study_mod.run(loader.load(SPECS / name).spec)
        return cache[name]

    return get


@pytest.fixture(scope="session")
def pages(studies):
    """``pages(name)``: the page of ``studies(name)`` without the simulation (results of "x",
    hash "h", no spec text), rendered once per session (per xdist worker)."""
    from balpipe.report import page, results

    cache: dict = {}

    def get(name: str) -> str:
        if name not in cache:
            st = studies(name)
            cache[name] = page.render_page(st, results.results_dict(st, "x", "h", False), "")
        return cache[name]

    return get


def _shared_root(tmp_path_factory) -> Path:
    """A folder that every xdist worker of this run sees (the parent of the workers' own)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


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
