"""benchmarks/bench_dense.py: the general path's analyses of a spec, first seen and placed, per
version, as a table (this version only here: no worktree of another revision)."""

from __future__ import annotations

import importlib.util
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_one_version_gives_a_row_per_spec_and_size(capsys):
    spec = importlib.util.spec_from_file_location("bench_dense", ROOT / "benchmarks" / "bench_dense.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    assert mod.main(["--specs", "specs/paper001_4rrr.yaml", "--samples", "101", "--repeat", "1"]) == 0
    lines = capsys.readouterr().out.strip().splitlines()
    assert lines[0] == "| spec | samples | this: first seen / placed (ms) |"
    cells = [c.strip() for c in lines[2].strip("|").split("|")]
    assert cells[:2] == ["paper001_4rrr", "101"]
    first, placed = (float(x) for x in cells[2].split(" / "))
    assert first > 0 and placed > 0
