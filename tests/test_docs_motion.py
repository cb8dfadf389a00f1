"""Every example of docs/motion.md parses and analyses: ```yaml blocks starting with ``name:``
are whole specs; the others are ``motion:`` sections run on the page's first spec (the
four-bar); the page's ```csv block is the crank.csv that the table example reads."""

from __future__ import annotations

import re
from pathlib import Path

import balpipe  # noqa: F401
import pytest
import yaml

from balpipe.loader import load
from balpipe.study import run

PAGE = Path(__file__).resolve().parents[1] / "docs" / "motion.md"
BLOCKS = re.findall(r"```(yaml|csv)\n(.*?)```", PAGE.read_text(), flags=re.S)
YAML = [b for kind, b in BLOCKS if kind == "yaml"]
CSV = [b for kind, b in BLOCKS if kind == "csv"]


def test_the_page_has_an_example_of_every_law():
    text = "\n".join(YAML)
    for law in ("constant_speed", "cam", "fourier", "table", "cycle", "path", "polynomial", "dwell", "harmonic",
                "circle", "polyline", "ramp", "stages"):
        assert f"{law}" in text, law
    assert len(CSV) == 1 and len(YAML) >= 12


@pytest.mark.parametrize("k", range(len(YAML)))
def test_example_parses_and_analyses(k, tmp_path):
    block = YAML[k]
    if block.startswith("name:"):
        data = yaml.safe_load(block)
    else:
        data = yaml.safe_load(YAML[0])
        data["motion"] = yaml.safe_load(block)["motion"]
    data.setdefault("validation", {})["enabled"] = False
    (tmp_path / "crank.csv").write_text(CSV[0])
    p = tmp_path / "example.yaml"
    p.write_text(yaml.safe_dump(data, sort_keys=False))
    study = run(load(p).spec)
    assert study.ok, study.problems
    an = study.unbalanced.analysis
    assert an.t[-1] == pytest.approx(study.spec.motion.duration) and an.max_force > 0
