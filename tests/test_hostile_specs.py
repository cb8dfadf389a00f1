"""Mutated specs that once gave an internal error, an error without a line or field, or an error
at the wrong field: each is a located error (file:line:column: field: what), exit 2, no traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from balpipe.cli import main
from test_motion_specs import FOUR_BAR

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
STEADY = FOUR_BAR + "motion:\n  duration: 1 s\n  drive:\n    crank: {law: constant_speed, from: 0 deg, speed: 60 rpm}\n"


def line_of(text: str, needle: str, nth: int = 1) -> int:
    """The 1-based line of the ``nth`` occurrence of ``needle`` in ``text``."""
    lines = [k + 1 for k, ln in enumerate(text.splitlines()) if needle in ln]
    return lines[nth - 1]


def located(tmp_path: Path, capsys, text: str) -> tuple[Path, str]:
    p = tmp_path / "s.yaml"
    p.write_text(text)
    assert main(["check", str(p)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "internal error" not in err and "computation failed" not in err, err
    return p, err.splitlines()[0]


def changed(text: str, old: str, new: str, count: int = 1) -> str:
    assert old in text, old
    return text.replace(old, new, count)


@pytest.mark.parametrize("old, new, at, field, words", [
    ("{type: revolute, name: A,", "{type: revolute, name: O2,", ("name: O2", 2), "mechanism.joints[1].name",
     "joint name 'O2' is used twice"),
    ("    - {name: crank, joint: O2}\n", "    - {name: crank, joint: O2}\n    - {name: crank, joint: O4}\n",
     ("joint: O4}", 1), "mechanism.drivers[1].name", "driver name 'crank' is used twice"),
], ids=["joint", "driver"])
def test_a_name_used_twice_in_a_custom_mechanism_is_located(tmp_path, capsys, old, new, at, field, words):
    text = changed(STEADY, old, new)
    p, line = located(tmp_path, capsys, text)
    assert line.startswith(f"{p}:{line_of(text, *at)}:") and f"{field}: {words}" in line, line


def test_a_zero_length_link_is_located_at_its_point(tmp_path, capsys):
    text = changed(STEADY, "points: {O4: [0, 0], B: [0.22, 0]}", "points: {O4: [0, 0], B: [0, 0]}")
    p, line = located(tmp_path, capsys, text)
    assert line.startswith(f"{p}:{line_of(text, 'name: rocker')}:") and "mechanism.bodies[2].points" in line
    assert "rocker has zero length" in line


def test_a_stage_tolerance_error_names_its_field_and_line(tmp_path, capsys):
    text = changed((SPECS / "custom_four_bar_balancing.yaml").read_text(), "          label: 1 kg at 80 mm behind O2\n",
                   "          label: 1 kg at 80 mm behind O2\n          tolerance: 2\n")
    p, line = located(tmp_path, capsys, text)
    assert line.startswith(f"{p}:{line_of(text, 'tolerance: 2')}:"), line
    assert "compare[1].balancing.stages[0].tolerance: must be < 1" in line and "stages.stages" not in line


def test_a_table_value_beyond_the_limits_is_blamed_on_its_row_not_a_joint(tmp_path, capsys):
    (tmp_path / "big.csv").write_text("t [s], crank [deg]\n" + "".join(f"{k / 20}, {1e7 if k == 5 else k}\n" for k in range(21)))
    text = FOUR_BAR + "motion:\n  duration: 1 s\n  drive:\n    crank: {law: table, file: big.csv}\n"
    p, line = located(tmp_path, capsys, text)
    assert "motion.drive.crank.file: big.csv:7: column 'crank [deg]': out of range" in line, line
    assert "exceeds the limit 100000 rad" in line and "joint" not in line


def test_a_circle_outside_a_five_bars_workspace_is_located_at_its_path(tmp_path, capsys):
    text = changed((SPECS / "custom_five_bar_circle.yaml").read_text(), "radius: 60 mm", "radius: 900 mm")
    p, line = located(tmp_path, capsys, text)
    assert line.startswith(f"{p}:{line_of(text, 'path: {type: circle')}:"), line
    assert "motion.drive.gripper.path: the path leaves the workspace" in line
    assert "straight" not in line and ".to:" not in line
