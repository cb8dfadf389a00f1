"""The type check runs clean: mypy with the configuration of pyproject.toml ([tool.mypy]), strict
on the engine and the contracts (balpipe.engine, model, units, plugins, balancing.base,
mechanics.planar, testing), the rest with mypy's defaults but for a listed backlog that only
shrinks. The package ships py.typed, so that a family's own type check reads balpipe's types."""

from __future__ import annotations

import os
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
CONFIG = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
#: the most modules the backlog may hold: lower it when a module leaves, never raise it
BACKLOG_LIMIT = 60
STRICT = {"balpipe.engine.*", "balpipe.model", "balpipe.units", "balpipe.plugins", "balpipe.balancing.base",
          "balpipe.mechanics.planar", "balpipe.testing", "balpipe.testing.*"}


def _overrides() -> list[dict]:
    return CONFIG["tool"]["mypy"]["overrides"]


def test_mypy_reports_no_error():
    pytest.importorskip("mypy")
    env = {k: v for k, v in os.environ.items() if k != "MYPYPATH"}
    r = subprocess.run([sys.executable, "-m", "mypy", "--cache-dir", str(ROOT / ".mypy_cache")],
                       capture_output=True, text=True, cwd=ROOT, env=env, timeout=900)
    assert r.returncode == 0, r.stdout + r.stderr
    assert r.stdout.startswith("Success: no issues found"), r.stdout


def test_the_engine_and_the_contracts_are_strict_and_never_in_the_backlog():
    strict = next(o for o in _overrides() if o.get("disallow_untyped_defs"))
    assert STRICT <= set(strict["module"])
    assert strict["check_untyped_defs"] and strict["disallow_incomplete_defs"] and strict["disallow_untyped_calls"]
    backlog = next(o for o in _overrides() if o.get("ignore_errors"))["module"]
    assert len(backlog) <= BACKLOG_LIMIT, f"the backlog grew to {len(backlog)} modules"
    for m in backlog:
        assert not any(m == s or (s.endswith(".*") and m.startswith(s[:-1])) for s in STRICT), m


def test_the_package_ships_py_typed():
    assert (ROOT / "pipeline" / "balpipe" / "py.typed").is_file()
    assert "py.typed" in CONFIG["tool"]["setuptools"]["package-data"]["balpipe"]
