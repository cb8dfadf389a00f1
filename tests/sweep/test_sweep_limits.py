"""A sweep's size is checked from the counts of its ranges before any value is made or parsed:
``--vary ...:1000000000`` (or a random sample of 10^9) is refused at once with the limit, exit 2,
no traceback. The child's memory is capped, so a regression fails fast instead of loading the
machine."""

from __future__ import annotations

import resource
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.vary import vary_count

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "scott_russell.yaml"


def capped(*args) -> subprocess.CompletedProcess:
    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (2_000_000_000, 2_000_000_000))
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          preexec_fn=cap, timeout=600)


@pytest.mark.parametrize("args", [
    ["--vary", "mechanism.slider.mass=0.2:0.7:1000000000"],
    ["--vary", "mechanism.slider.mass=0.2:0.7:100000", "--vary", "mechanism.crank.mass=0.2:0.7:100000"],
    ["--vary", "mechanism.slider.mass=0.2:0.7", "--sample", "random", "-n", "1000000000"],
], ids=["one-huge-grid", "product", "random"])
def test_a_huge_sweep_is_refused_before_any_value_is_made(tmp_path, args):
    r = capped("sweep", SPEC, *args, "-o", tmp_path / "sw", "-q")
    assert r.returncode == 2 and "Traceback" not in r.stderr and "MemoryError" not in r.stderr, r.stderr
    assert "above the limit of" in r.stderr and "--max-designs" in r.stderr
    assert not (tmp_path / "sw").exists()


@pytest.mark.parametrize("n, words", [("1000000000", "sweep.vary.mechanism.crank.mass: N = 1000000000 is above the limit"),
                                      ("5000", "sweep.max_designs: the sweep has 10000 designs, above the limit of 100")])
def test_a_huge_sweep_block_is_a_located_error(tmp_path, n, words):
    text = (ROOT / "tests" / "fixtures" / "sweep_block.yaml").read_text()
    spec = tmp_path / "s.yaml"
    spec.write_text(text.replace("500 g:2 kg:3", f"500 g:2 kg:{n}"))
    r = capped("sweep", spec, "-o", tmp_path / "sw", "-q")
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert words in r.stderr and r.stderr.startswith(f"{spec}:"), r.stderr


def test_the_count_of_a_range_is_read_without_its_values():
    assert vary_count("a.b=0:1:7") == 7 and vary_count("a.b=1,2,3") == 3
    assert vary_count("a.b=0:1") is None and vary_count("a.b=0:1:x") is None
    assert vary_count("a.b=0:1:" + "9" * 40) is None  # parse_vary refuses it (not an integer it takes)
