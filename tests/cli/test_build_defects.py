"""Three defects of issue 19 item 6, found by a hostile run of the build: a YAML merge key whose
mapping overrides a merged value, two spec files on one page name, and the build's lock file in
the served output."""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time
from pathlib import Path

import pytest

from balpipe import build as build_mod
from balpipe.build import Options, build
from balpipe.loader import SpecErrors, load_text

ROOT = Path(__file__).resolve().parents[2]
SCOTT = (ROOT / "specs" / "scott_russell.yaml").read_text(encoding="utf-8")
MERGED = """name: merge keys
mechanism:
  template: slider_crank
  crank: &link {length: 0.2 m, mass: 1.2 kg, com: 0.1 m, inertia: 0.004 kg m^2}
  coupler: {<<: *link, mass: 1.0 kg, length: 0.5 m}
  slider: {mass: 0.6 kg}
motion:
  duration: 0.5 s
  drive:
    crank: {from: 0 deg, to: 90 deg}
"""


def quick(text: str) -> str:
    return text.replace("  samples: 501", "  samples: 41")


def test_a_merge_key_overridden_by_its_mapping_is_not_a_duplicate():
    spec, _ = load_text(MERGED, "m.yaml")
    c = spec.mechanism.coupler
    assert (c.mass, c.length) == (1.0, 0.5)  # the mapping's own values win
    assert (c.com, c.inertia) == (0.1, 0.004)  # the others come from the anchor
    assert spec.mechanism.crank.mass == 1.2


def test_a_key_written_twice_is_still_a_duplicate_with_or_without_a_merge():
    for text, line in ((MERGED.replace("mass: 1.0 kg, length", "mass: 1.0 kg, mass: 2 kg, length"), 5),
                       (MERGED.replace("name: merge keys\n", "name: merge keys\nname: again\n"), 2)):
        with pytest.raises(SpecErrors) as e:
            load_text(text, "m.yaml")
        assert f"m.yaml:{line}:" in str(e.value) and "duplicate key" in str(e.value)


def test_two_files_on_one_page_name_build_the_first_and_refuse_the_other(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "x.yaml").write_text(quick(SCOTT), encoding="utf-8")
    (d / "x.yml").write_text(quick(SCOTT).replace("name: ", "name: second ", 1), encoding="utf-8")
    out = tmp_path / "out"
    outcomes = {o.source: o for o in build([str(d)], Options(out=out, simulate=False), jobs=1)}
    # published names: relative to the folder holding the one named on the command line
    first, other = outcomes["specs/x.yaml"], outcomes["specs/x.yml"]
    assert first.status == "ok" and not first.spec_error
    assert other.status == "error" and other.spec_error
    assert "specs/x.yaml" in other.message and "rename" in other.message
    results = json.loads((out / "x" / "results.json").read_text(encoding="utf-8"))
    assert results["source"] == "specs/x.yaml"
    r = subprocess.run([sys.executable, "-m", "balpipe", "build", str(d), "-o", str(tmp_path / "cli"), "--no-sim"],
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 2 and (tmp_path / "cli" / "x" / "index.html").is_file()
    assert any(ln.startswith("specs/x.yml") and "rename" in ln for ln in r.stderr.splitlines())


def test_the_lock_file_is_not_left_in_the_output(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "s.yaml").write_text(quick(SCOTT), encoding="utf-8")
    out = tmp_path / "out"
    for _ in range(2):  # a fresh build and an unchanged one
        assert build([str(d)], Options(out=out, simulate=False), jobs=1)[0].status == "ok"
        assert not (out / build_mod.LOCK_NAME).exists()
        assert not [p for p in out.rglob("*") if "lock" in p.name]


def test_a_build_waiting_on_the_lock_gets_it_after_the_file_is_removed(tmp_path):
    """The build holding the lock removes the file as it ends; the one that waited on it locks
    the current file (not the removed one), so a third build still waits for it."""
    order = []
    first_in = threading.Event()

    def hold(name: str, wait: float) -> None:
        with build_mod.locked(tmp_path):
            order.append(name + " in")
            first_in.set()
            time.sleep(wait)
            order.append(name + " out")

    a = threading.Thread(target=hold, args=("a", 0.5))
    a.start()
    first_in.wait(5)
    b = threading.Thread(target=hold, args=("b", 0.5))
    b.start()
    time.sleep(0.1)
    c = threading.Thread(target=hold, args=("c", 0.0))
    c.start()
    for t in (a, b, c):
        t.join(10)
    # never two holders at once: every "in" is followed by its own "out"
    assert [order[i].split()[0] for i in range(0, len(order), 2)] == [order[i].split()[0] for i in range(1, len(order), 2)]
    assert len(order) == 6 and not (tmp_path / build_mod.LOCK_NAME).exists()
