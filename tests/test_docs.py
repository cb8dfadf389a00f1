"""The README is a front door and the reference lives in docs/ (issue 19 item 5): the README is
short and keeps the two quick-start commands, docs/spec.md is generated from the schema, and
every command, option and spec field is documented."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from balpipe import plugins
from balpipe.cli import VERBS, _parser
from balpipe.loader import schema
from balpipe.report.spec_reference import markdown

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
DOCS = ROOT / "docs"
#: families installed beside balpipe's own: their spec sections are in the schema, not in docs/spec.md
OTHER_FAMILIES = sorted(f.name for f in plugins.discover() if not f.package.startswith(plugins.IN_TREE + "."))
only_own_families = pytest.mark.skipif(bool(OTHER_FAMILIES), reason=f"docs/spec.md documents balpipe's own families; "
                                       f"installed beside them: {', '.join(OTHER_FAMILIES)}")
# pages written by other parts of the work on balpipe; the README links them too
PLANNED = {"motion.md", "actuators.md", "validation.md", "partial-balancing.md", "pages.md"}
# pages the docs site makes at build time (docs/hooks/site.py GENERATED: the gallery of specs/)
GENERATED = {"gallery.md"}


def test_readme_is_a_front_door():
    assert len(README.splitlines()) <= 200
    assert "pip install . && python -m balpipe build specs/" in README
    assert 'pip install ".[test]" && python -m pytest -q' in README


def test_ci_runs_the_readme_test_command_word_for_word():
    ci = (ROOT / ".ci" / "run").read_text(encoding="utf-8").strip().splitlines()[-1]
    assert ci == 'pip install ".[test]" && python -m pytest -q'
    assert ci in README


def test_the_readme_links_every_reference_page():
    linked = set(re.findall(r"\]\(docs/([A-Za-z0-9_.-]+\.md)\)", README))
    pages = {p.name for p in DOCS.glob("*.md")}
    assert pages <= linked, sorted(pages - linked)
    assert PLANNED <= linked
    assert linked <= pages | PLANNED, sorted(linked - pages - PLANNED)


def test_links_between_pages_resolve():
    for page in [ROOT / "README.md", *DOCS.glob("*.md")]:
        for target in re.findall(r"\]\(([^)#:]+\.md)(?:#[^)]*)?\)", page.read_text(encoding="utf-8")):
            name = Path(target).name
            made = page.parent == DOCS and target in GENERATED
            assert (page.parent / target).resolve().is_file() or name in PLANNED or made, f"{page.name}: {target}"


@only_own_families
def test_spec_reference_is_the_generated_page():
    """Regenerate with: python -m balpipe.report.spec_reference > docs/spec.md"""
    assert (DOCS / "spec.md").read_text(encoding="utf-8") == markdown()


@only_own_families
def test_every_spec_field_is_in_the_reference():
    page = (DOCS / "spec.md").read_text(encoding="utf-8")
    s = schema()
    for name, node in [("Spec", s), *s["$defs"].items()]:
        assert f"## {name}\n" in page
        for field in node.get("properties", {}):
            assert f"| `{field}` |" in page, f"{name}.{field}"


def _options(parser: argparse.ArgumentParser) -> dict[str, list[str]]:
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    out = {}
    for verb, p in sub.choices.items():
        out[verb] = [max(a.option_strings, key=len) for a in p._actions
                     if a.option_strings and a.dest != "help"]
    return out


def test_every_command_and_option_is_documented():
    text = "\n".join(p.read_text(encoding="utf-8") for p in DOCS.glob("*.md"))
    options = _options(_parser())
    assert set(options) == set(VERBS)
    missing = [f"{verb} {opt}" for verb, opts in options.items() for opt in opts
               if not re.search(rf"balpipe {verb}\b[^\n]*{re.escape(opt)}\b|`{re.escape(opt)}\b", text)]
    assert not [v for v in VERBS if f"balpipe {v}" not in text]
    assert missing == []
