"""docs/parts.md: its example runs and prints what the page says, its materials table is the
module's, and the example spec it names makes parts that fit."""

from __future__ import annotations

import re
from pathlib import Path

from balpipe.mechanics.materials import DENSITIES

ROOT = Path(__file__).resolve().parents[1]
PAGE = (ROOT / "docs" / "parts.md").read_text(encoding="utf-8")


def test_the_example_prints_what_the_page_says(capsys):
    code = re.search(r"```python\n(.*?)```", PAGE, re.S).group(1)
    printed = re.search(r"prints\n\n```\n(.*?)```", PAGE, re.S).group(1)
    exec(compile(code, "docs/parts.md", "exec"), {})
    assert capsys.readouterr().out == printed


def test_the_materials_table_is_the_modules():
    rows = dict(re.findall(r"^\| `([a-z_]+)` \| (\d+) \|$", PAGE, re.M))
    assert {k: float(v) for k, v in rows.items()} == DENSITIES


def test_the_example_spec_makes_parts_that_fit():
    import balpipe

    st = balpipe.run(balpipe.load(ROOT / "specs" / "custom_v_twin_6000rpm.yaml"))
    parts = st.results()["parts"]
    assert {(p["design"], p["shape"], p["material"]) for p in parts} == {
        ("textbook", "annular_sector", "steel"), ("complete", "annular_sector", "tungsten_alloy")}
    assert all(p["fits"] for p in parts) and st.ok
