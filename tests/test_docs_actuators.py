"""Every YAML example of docs/actuators.md builds and does what the page says."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from balpipe import study
from balpipe.loader import load_text
from balpipe.spec_parts import SpecFieldError

DOC = Path(__file__).resolve().parents[1] / "docs" / "actuators.md"
BLOCKS = re.findall(r"```yaml\n(.*?)```", DOC.read_text(), re.S)


def test_the_page_has_its_four_examples():
    assert len(BLOCKS) == 4


def test_3rrr_example_reports_base_motor_torques():
    st = study.run(load_text(BLOCKS[0], "doc.yaml")[0])
    assert sorted(st.unbalanced.analysis.efforts) == ["A1", "A2", "A3"]
    assert st.ok


def test_five_bar_example_reports_two_motor_torques():
    st = study.run(load_text(BLOCKS[1], "doc.yaml")[0])
    assert sorted(st.unbalanced.analysis.efforts) == ["A1", "A2"]


def test_loop_example_is_the_error_the_page_quotes():
    with pytest.raises(SpecFieldError) as err:
        study.run(load_text(BLOCKS[2], "doc.yaml")[0])
    assert err.value.path == ("mechanism", "bodies", 1, "points", "B")
    quoted = re.search(r"`mechanism.bodies\[1\].points.B: (.*?)`", DOC.read_text(), re.S).group(1)
    assert err.value.message == " ".join(quoted.split())


def test_dead_centre_example_warns_as_quoted():
    st = study.run(load_text(BLOCKS[3], "doc.yaml")[0])
    assert st.ok
    kinds = [w["kind"] for w in st.warnings]
    assert "dead_centre" in kinds
    quoted = re.search(r"`warning: (stage 'unbalanced': the motion passes.*?)`", DOC.read_text(), re.S).group(1)
    assert st.warnings[kinds.index("dead_centre")]["message"] == " ".join(quoted.split())
