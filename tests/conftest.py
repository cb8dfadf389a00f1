"""Shared helpers for the tests: slider-crank specs with random parameters."""

from __future__ import annotations

import math

import balpipe  # noqa: F401  (first: it sets one BLAS thread before numpy loads)
import numpy as np
import pytest

from balpipe.spec import Spec


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


@pytest.fixture(scope="module")
def studies():
    """``studies(name)``: the study of ``specs/<name>``, run once per test module."""
    from pathlib import Path

    from balpipe import loader
    from balpipe import study as study_mod

    specs = Path(__file__).resolve().parents[1] / "specs"
    cache: dict = {}

    def get(name: str):
        if name not in cache:
            cache[name] = study_mod.run(loader.load(specs / name).spec)
        return cache[name]

    return get


def pytest_addoption(parser):
    parser.addoption(
        "--built-site", metavar="DIR", default=None,
        help="run the browser's page checks (tests/test_site_browser.py, the tests named built_site) "
             "on every HTML page of a site already built into DIR (balpipe build specs/ -o DIR)")
