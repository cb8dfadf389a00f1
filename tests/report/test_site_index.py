"""The index of the whole site (issue 22): building some specs into an existing site keeps the
others listed, marked as built earlier, and stale when their spec changed since."""

from __future__ import annotations

import os
import re
import shutil
from pathlib import Path

from balpipe.build import Options, build

SPECS = Path(__file__).parents[2] / "specs"


def _row(html: str, slug: str) -> str:
    row = html[html.index(f'data-spec="{slug}"'):]
    return row[:row.index("</tbody>")]


def test_partial_builds_keep_the_other_pages_listed_and_mark_stale_ones(tmp_path):
    specs = tmp_path / "specs"
    specs.mkdir()
    shutil.copy(SPECS / "scott_russell.yaml", specs / "a.yaml")
    shutil.copy(SPECS / "offset_slider_crank.yaml", specs / "b.yaml")
    out = tmp_path / "site"
    cwd = os.getcwd()
    os.chdir(tmp_path)
    try:
        build(["specs/a.yaml"], Options(out=out, simulate=False))
        build(["specs/b.yaml"], Options(out=out, simulate=False))
        html = (out / "index.html").read_text(encoding="utf-8")
        assert 'href="a/index.html"' in html and 'href="b/index.html"' in html
        a = _row(html, "a")
        assert "built in an earlier build" in a and "stale" not in a and "data-verdict=" in a
        assert "built in an earlier build" not in _row(html, "b")
        assert re.search(r"1 spec built now: 1 ok.*1 more from earlier builds", html, re.S)
        # a's spec changes: its page no longer shows it
        text = (specs / "a.yaml").read_text()
        (specs / "a.yaml").write_text(text + "\n# edited\n")
        build(["specs/b.yaml"], Options(out=out, simulate=False))
        a = _row((out / "index.html").read_text(encoding="utf-8"), "a")
        assert "stale: its spec or balpipe changed since this page was built" in a
        (specs / "a.yaml").unlink()
        build(["specs/b.yaml"], Options(out=out, simulate=False))
        a = _row((out / "index.html").read_text(encoding="utf-8"), "a")
        assert "stale: spec specs/a.yaml no longer found" in a
    finally:
        os.chdir(cwd)
