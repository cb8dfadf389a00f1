"""Issue 13, item 3: the ``sweep:`` block of a spec. ``balpipe sweep SPEC`` without ``--vary``
runs it; flags override it; its errors are located like every spec field; ``build`` ignores it."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.loader import SpecErrors, load_text

ROOT = Path(__file__).resolve().parents[2]
FIXTURE = ROOT / "tests" / "fixtures" / "sweep_block.yaml"
TEXT = FIXTURE.read_text()


def balpipe(*args):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True)


def _with(old: str, new: str) -> str:
    assert old in TEXT, old
    return TEXT.replace(old, new, 1)


def _line_of(text: str, needle: str) -> int:
    return next(k for k, line in enumerate(text.splitlines(), 1) if needle in line)


def test_sweep_block_runs_as_the_equivalent_flags(tmp_path):
    a, b = tmp_path / "a", tmp_path / "b"
    r = balpipe("sweep", FIXTURE, "-o", a, "-q", "-j", "1")
    assert r.returncode == 0, r.stderr
    assert "6 designs: 6 mass-only" in r.stderr
    r = balpipe("sweep", FIXTURE, "--vary", "mechanism.crank.mass=500 g:2 kg:3", "--vary",
                "mechanism.slider.mass=0.2 kg,0.7 kg", "--stage", "counterweights", "-o", b, "-q", "-j", "1")
    assert r.returncode == 0, r.stderr
    assert (a / "sweep.csv").read_bytes() == (b / "sweep.csv").read_bytes()
    for f in (a / "designs").glob("*.yaml"):  # the designs are specs without the block
        assert "sweep:" not in f.read_text()
        spec, _ = load_text(f.read_text(), str(f))
        assert spec.sweep is None


def test_flags_override_the_block():
    from balpipe.sweep import plan

    p = plan(str(FIXTURE))
    assert len(p.designs) == 6 and p.stage == "counterweights" and [v.origin for v in p.varies] == ["sweep.vary"] * 2
    p = plan(str(FIXTURE), ["mechanism.coupler.mass=1,2,3"])  # --vary replaces the vary mapping
    assert [v.name for v in p.varies] == ["mechanism.coupler.mass"] and len(p.designs) == 3
    assert p.stage == "counterweights"  # the rest of the block still applies
    p = plan(str(FIXTURE), stage="full", sample="lhs", n=4, seed=3)
    assert p.stage == "full" and len(p.designs) == 4 and p.sample == "lhs"
    text = _with("max_designs: 100", "max_designs: 5")
    f = FIXTURE.parent / "_tmp_limit.yaml"
    try:
        f.write_text(text)
        assert len(plan(str(f), max_designs=10).designs) == 6  # --max-designs overrides sweep.max_designs
    finally:
        f.unlink()


def test_block_errors_are_located_and_refused_before_work(tmp_path, capsys):
    from balpipe.cli import main

    out = tmp_path / "s"
    cases = [
        # (replacement, the line's needle, expected words)
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mas: 500 g:2 kg:3"),
         "mechanism.crank.mas:", "sweep.vary.mechanism.crank.mas: unknown path"),
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.length: 1 kg:2 kg:3"),
         "mechanism.crank.length:", "not a length unit"),
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank: '1:2:3'"), "mechanism.crank:", "not a numeric field"),
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mass: 1:2:3"),
         "mechanism.crank.mass:", "YAML reads 1:2:3 as a number"),  # sexagesimal 3723
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mass: 1 kg:2 kg:x"), "mechanism.crank.mass:",
         "N must be an integer"),
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mass: 1 kg:2 kg"), "mechanism.crank.mass:", "grid needs"),
        (("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mass: -1 kg:2 kg:3"), "mechanism.crank.mass:", ">= 0"),
        (("max_designs: 100", "max_designs: 5"), "max_designs:", "above the limit of 5"),
        (("max_designs: 100", "max_designs: 2.5"), "max_designs:", "whole number"),
        (("max_designs: 100", "seed: true"), "seed:", "boolean"),
        (("max_designs: 100", "sample: lhs"), "  vary:", "sweep: sample: lhs needs designs"),  # the block starts there
        (("max_designs: 100", "samples: 3"), "  samples: 3", "unknown key"),
        (("mechanism.slider.mass: [0.2 kg, 0.7 kg]", "mechanism.slider.mass: [0.2 kg, .nan]"), "mechanism.slider.mass:",
         "finite"),
    ]
    for (old, new), needle, words in cases:
        text = _with(old, new)
        f = tmp_path / "spec.yaml"
        f.write_text(text)
        rc = main(["sweep", str(f), "-o", str(out), "-q"])
        err = capsys.readouterr().err
        line = _line_of(text, needle)
        assert rc == 2, (new, err)
        assert f"spec.yaml:{line}:" in err and words in err, (new, err)
    assert not out.exists()
    r = balpipe("sweep", f, "-o", out)  # the command as a user runs it: no traceback
    assert r.returncode == 2 and "Traceback" not in r.stderr and "finite" in r.stderr


def test_units_parsers_guard_the_block():
    with pytest.raises(SpecErrors) as e:
        load_text(_with("max_designs: 100", "designs: .inf"), "s.yaml")
    assert "sweep.designs" in str(e.value)
    spec, _ = load_text(_with("max_designs: 100", "designs: '12'\n  sample: random"), "s.yaml")
    assert spec.sweep.designs == 12 and spec.sweep.vary["mechanism.slider.mass"] == "0.2 kg,0.7 kg"


def test_nothing_to_vary_without_block_or_flags(tmp_path):
    r = balpipe("sweep", ROOT / "specs" / "scott_russell.yaml", "-o", tmp_path / "s")
    assert r.returncode == 2 and "nothing to vary" in r.stderr and "sweep: block" in r.stderr


def test_build_ignores_the_block(tmp_path):
    """The same spec with and without the block builds the same results (but for its name)."""
    d = tmp_path / "specs"
    d.mkdir()
    shutil.copy(FIXTURE, d / "with_block.yaml")
    (d / "without_block.yaml").write_text(TEXT.split("\nsweep:")[0] + "\n")
    r = balpipe("build", d, "-o", tmp_path / "site", "--no-sim", "-q")
    assert r.returncode == 0, r.stderr
    a = json.loads((tmp_path / "site" / "with_block" / "results.json").read_text())
    b = json.loads((tmp_path / "site" / "without_block" / "results.json").read_text())
    for x in (a, b):
        x.pop("spec", None), x.pop("source", None), x.pop("input_hash", None)
    assert a.get("stages") and a["stages"] == b["stages"]


def test_check_reports_the_blocks_paths_located(tmp_path, capsys):
    from balpipe.cli import main

    f = tmp_path / "spec.yaml"
    f.write_text(_with("mechanism.crank.mass: 500 g:2 kg:3", "mechanism.crank.mas: 500 g:2 kg:3"))
    assert main(["check", str(f)]) == 2
    err = capsys.readouterr().err
    line = _line_of(f.read_text(), "mechanism.crank.mas:")
    assert f"spec.yaml:{line}:5: sweep.vary.mechanism.crank.mas: unknown path" in err and "1 invalid" in err
    assert main(["check", str(FIXTURE)]) == 0
