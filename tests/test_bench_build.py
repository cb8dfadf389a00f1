"""benchmarks/bench_build.py: phases of a cold build, per spec and in total, against a revision."""

from __future__ import annotations

import importlib.util
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def _bench():
    spec = importlib.util.spec_from_file_location("bench_build", ROOT / "benchmarks" / "bench_build.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def test_table_sums_the_phases_and_gives_ratios():
    b = _bench()
    res = {
        "a": {"this": {"rc": 0, "times": {"validate": 1.0, "figures": 2.0, "total": 4.0}},
              "old": {"rc": 0, "times": {"validate": 4.0, "figures": 2.0, "total": 8.0}}},
        "b": {"this": {"rc": 0, "times": {"validate": 1.0, "total": 2.0}},
              "old": {"rc": 1, "times": {"validate": 1.0, "total": 2.0}}},
    }
    out = b.table(res, ["this", "old"])
    rows = {tuple(line.split()[:2]): line.split()[2:] for line in out.splitlines()[1:] if line.strip()}
    assert rows[("a", "validate")] == ["1.000", "4.000", "0.250"]
    assert rows[("TOTAL", "validate")] == ["2.000", "5.000", "0.400"]
    assert rows[("TOTAL", "total")] == ["6.000", "10.000", "0.600"]
    assert ("a", "torque") not in rows  # phases that took no time in either version are left out
    assert any(line.split()[-2:] == ["0", "1"] for line in out.splitlines() if "status" in line)


def test_specs_by_name_or_path():
    b = _bench()
    assert b.resolve_specs(["scott_russell"], ROOT) == [ROOT / "specs" / "scott_russell.yaml"]
    assert ROOT / "specs" / "custom_stephenson_six_bar_120rpm.yaml" in b.resolve_specs(None, ROOT)


def test_one_cold_build_is_timed_by_phase(tmp_path):
    b = _bench()
    res = b.run_one(sys.executable, ROOT / "pipeline", ROOT / "specs" / "scott_russell.yaml", tmp_path / "site",
                    ["--no-sim"])
    t = res["times"]
    assert res["rc"] == 0 and (tmp_path / "site" / "scott_russell" / "results.json").exists()
    assert t["load"] > 0 and t["analyse"] > 0 and t["figures"] > 0 and t["write"] > 0
    assert "validate" not in t  # --no-sim
    parts = sum(v for k, v in t.items() if k != "total")
    assert abs(parts - t["total"]) < 1e-6 * t["total"]  # the phases and `other` make up the total


def test_cpu_seconds_on_a_busy_machine(tmp_path):
    """--cpu: the phases in CPU seconds of the build's process (-j 1: its simulations run there),
    which other work on the machine does not inflate; they make up the total as the wall times do."""
    b = _bench()
    res = b.run_one(sys.executable, ROOT / "pipeline", ROOT / "specs" / "scott_russell.yaml", tmp_path / "site",
                    ["--no-sim"], cpu=True)
    t = res["times"]
    assert res["rc"] == 0 and t["analyse"] > 0 and t["figures"] > 0
    parts = sum(v for k, v in t.items() if k != "total")
    assert abs(parts - t["total"]) < 1e-6 * t["total"]


def test_results_numbers_compares_every_number_to_a_relative_tolerance(tmp_path, capsys):
    spec = importlib.util.spec_from_file_location("results_numbers", ROOT / "benchmarks" / "results_numbers.py")
    r = importlib.util.module_from_spec(spec)
    sys.modules["results_numbers"] = r  # its dataclass looks its module up
    spec.loader.exec_module(r)
    a = {"x": 1.0, "y": [2.0, {"z": 3}], "s": "ok", "code_hash": "abc"}
    near = {"x": 1.0 + 1e-12, "y": [2.0, {"z": 3}], "s": "ok", "code_hash": "def"}
    far = {"x": 1.0 + 1e-8, "y": [2.0, {"z": 3}], "s": "ok", "code_hash": "abc"}
    c = r.compare(a, near, 1e-9)
    assert (c.numbers, c.identical, c.problems) == (3, 2, ["/code_hash: 'abc' and 'def'"])
    assert r.compare(a, far, 1e-9).problems[0].startswith("/x: 1.0 and 1.00000001")
    assert r.compare(a, {**a, "y": [2.0]}, 1e-9).problems == ["/y: lengths 2 and 1"]
    tiny, moved = {"r": 1e-13}, {"r": 3e-13}  # round-off of a balanced stage: 100 % relative
    assert r.compare(tiny, moved, 1e-9).problems and not r.compare(tiny, moved, 1e-9, floor=1e-12).problems
    assert r.compare(tiny, moved, 1e-9, floor=1e-12).floored == 1
    assert r.compare(tiny, moved, 1e-9, floor=1e-14).problems  # the floor is absolute, not a pass for all
    newer = {**a, "added": 7.0}
    assert r.compare(a, newer, 1e-9).problems == ["/: keys differ: ['added']"]
    c = r.compare(a, newer, 1e-9, common=True)
    assert not c.problems and c.one_sided == ["/: keys differ: ['added']"] and c.numbers == 3
    assert r.compare(a, {**far, "added": 7.0}, 1e-9, common=True).problems  # common keys still compared
    for d, v in (("A", a), ("B", near), ("C", far)):
        (tmp_path / d / "spec").mkdir(parents=True)
        (tmp_path / d / "spec" / "results.json").write_text(json.dumps(v))
    assert r.main([str(tmp_path / "A"), str(tmp_path / "B")]) == 0  # code_hash is ignored in files
    assert r.main([str(tmp_path / "A"), str(tmp_path / "C")]) == 1
    assert "beyond 1e-09" in capsys.readouterr().out


def test_a_warm_build_rebuilds_the_changed_spec(tmp_path):
    b = _bench()
    out = tmp_path / "site"
    res = b.warm_one(sys.executable, ROOT / "pipeline", ROOT / "specs" / "scott_russell.yaml", out, ["--no-sim"],
                     tmp_path / "specs")
    assert res["rc"] == 0 and res["times"]["analyse"] > 0  # computed again, not skipped as unchanged
    assert (tmp_path / "specs" / "scott_russell.yaml").read_text().endswith(b.WARM_EDIT)
    assert (out / ".cache" / "figures" / "scott_russell").is_dir()
