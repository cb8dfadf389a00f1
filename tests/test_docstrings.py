"""The package's text states guarantees, not the issue numbers they came from: a reader of a
module learns what it promises without the tracker."""

from __future__ import annotations

import re
from pathlib import Path

PACKAGE = Path(__file__).resolve().parents[1] / "pipeline" / "balpipe"
ISSUE = re.compile(r"\bissues? #?\d+", re.IGNORECASE)


def test_no_issue_number_in_the_package():
    found = [f"{path.relative_to(PACKAGE)}:{n}: {line.strip()}"
             for path in sorted(PACKAGE.rglob("*.py"))
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
             if ISSUE.search(line)]
    assert not found, "\n".join(found)


def test_the_guard_sees_an_issue_number():
    assert ISSUE.search('"""Sweeps (issue 13, item 3)."""')
    assert ISSUE.search("# see Issue #7")
    assert not ISSUE.search("the issue of units")
