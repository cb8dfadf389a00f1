"""The verdicts as a reviewer reads them beside the papers, in headless Chromium at 400 and
1400 px: the index and each paper page say what was claimed and whether it holds in one
vocabulary (paper 001's force balance "force balanced as designed" with the moment's growth as a
cost; the Scott-Russell legs as printed "the paper's claim fails"; paper 004 "balanced as
claimed" with its misprint counted apart; paper 003 reproduced within its stated tolerance),
and ``balpipe diff`` says first whether each side is still balanced, then the inputs, with
interactive overlays and links to both pages."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.build import Options, build

# one worker with the other browser tests (tests/conftest.py GROUPS): one browser for the run
pytestmark = pytest.mark.xdist_group("site_browser")

SPECS = Path(__file__).resolve().parents[2] / "specs"
SITE_SPECS = ("paper001_4rrr.yaml", "paper000_rpr3_scott_russell.yaml", "paper004_five_bar.yaml",
              "paper003_com_planning.yaml")
WIDTHS = (400, 1400)


@pytest.fixture(scope="module")
def verdict_site(tmp_path_factory) -> Path:
    """The four paper specs built without simulation, and a diff page beside them: the corrected
    Scott-Russell legs (old) against the printed ones (new)."""
    out = tmp_path_factory.mktemp("verdicts") / "site"
    outcomes = build([str(SPECS / s) for s in SITE_SPECS], Options(out=out, simulate=False))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    r = subprocess.run([sys.executable, "-m", "balpipe", "diff", str(SPECS / "paper000_rpr3_scott_russell_corrected.yaml"),
                        str(SPECS / "paper000_rpr3_scott_russell.yaml"), "--no-sim", "-f", "html",
                        "-o", str(out / "diff.html")], capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    return out


def results(site: Path, slug: str) -> dict:
    return json.loads((site / slug / "results.json").read_text(encoding="utf-8"))


def open_page(browser, path: Path, width: int):
    """A page at ``width`` px, with the JavaScript errors and failed requests it records."""
    ctx = browser.new_context(viewport={"width": width, "height": 900})
    page = ctx.new_page()
    problems: list[str] = []
    page.on("pageerror", lambda e: problems.append(f"JavaScript error: {e}"))
    page.on("console", lambda m: problems.append(f"console {m.type}: {m.text}") if m.type == "error" else None)
    page.on("requestfailed", lambda r: problems.append(f"request failed: {r.url}"))
    page.goto(path.as_uri(), wait_until="load")
    return page, problems


def visible_in_width(page, selector: str) -> bool:
    """The element is laid out and within the window's width (nothing cut at 400 px)."""
    return page.eval_on_selector(selector, """el => { const r = el.getBoundingClientRect();
        return r.width > 0 && r.height > 0 && r.left >= -1 && r.right <= document.documentElement.clientWidth + 1; }""")


def row(page, slug: str) -> dict:
    """The index row of ``slug``: its level, badge words, costs and published-numbers line."""
    return page.eval_on_selector(f'#studies tbody.entry[data-spec="{slug}"]', """e => ({
        level: e.dataset.verdict,
        words: e.querySelector('.verdict .badge').textContent,
        costs: [...e.querySelectorAll('.verdict > .cost')].map(c => c.textContent),
        refs: (e.querySelector('.verdict .refs-badge') || {}).textContent || '',
        text: e.querySelector('.verdict').innerText })""")


@pytest.mark.parametrize("width", WIDTHS)
def test_the_index_reads_each_paper_in_one_vocabulary(verdict_site, browser, width):
    page, problems = open_page(browser, verdict_site / "index.html", width)
    r001 = row(page, "paper001_4rrr")
    general = next(s for s in results(verdict_site, "paper001_4rrr")["stages"] if s["name"] == "general")
    assert r001["words"] == "force balanced as designed" and r001["level"] == "good"
    assert r001["costs"] == [f"cost: moment × {general['moment_ratio']:.3g}"]  # the moment's growth: a cost
    sr = row(page, "paper000_rpr3_scott_russell")
    cr = next(s for s in results(verdict_site, "paper000_rpr3_scott_russell")["stages"] if s["name"] == "counter_rotations")
    assert sr["words"] == f"the paper's claim fails: moment × {cr['moment_ratio']:.3g}" and sr["level"] == "bad"
    r004 = row(page, "paper004_five_bar")
    assert r004["words"] == "balanced as claimed" and r004["level"] == "good"  # the misprint never lowers it
    assert r004["refs"].endswith("1 misprint explained")
    r003 = row(page, "paper003_com_planning")
    assert "4 of 4 reproduced (4 within the stated tolerance)" in r003["refs"] and r003["level"] == "good"
    body = page.inner_text("main")
    assert "mixed" not in body and "the paper's own numbers" not in body
    for slug in ("paper001_4rrr", "paper000_rpr3_scott_russell", "paper004_five_bar"):
        assert visible_in_width(page, f'#studies tbody.entry[data-spec="{slug}"] .verdict .badge'), (slug, width)
    assert not problems, problems


@pytest.mark.parametrize("width", WIDTHS)
def test_each_paper_page_opens_with_its_verdict_and_counts_published_numbers_apart(verdict_site, browser, width):
    expected = {"paper001_4rrr": "force balanced as designed", "paper004_five_bar": "balanced as claimed",
                "paper000_rpr3_scott_russell": "the paper's claim fails: moment ×",
                "paper003_com_planning": "loads reduced"}
    for slug, words in expected.items():
        page, problems = open_page(browser, verdict_site / slug / "index.html", width)
        badge = page.text_content("#verdict .badge")
        assert badge.startswith(words), (slug, badge)
        assert badge == results(verdict_site, slug)["verdict"]["words"]  # the page says what results.json says
        assert visible_in_width(page, "#verdict .badge"), (slug, width)
        # the verdict box comes before the page's sections
        assert page.evaluate("() => document.querySelector('#verdict').compareDocumentPosition("
                             "document.querySelector('main h2')) & Node.DOCUMENT_POSITION_FOLLOWING") > 0
        kinds = page.eval_on_selector_all("[data-reference]", "els => els.map(e => e.dataset.reference)")
        refs = results(verdict_site, slug)["references"]
        assert kinds == [r["kind"] for r in refs], slug
        text = page.inner_text("main")
        assert "mixed" not in text and "the paper's own numbers" not in text
        if slug == "paper001_4rrr":
            assert "cost: moment ×" in page.text_content("#verdict")
        if slug == "paper004_five_bar":  # r5: printed 0.79, computed 0.0789 m, explained and counted apart
            assert kinds.count("misprint") == 1 and set(kinds) == {"reproduced", "misprint"}
            assert "1 misprint the page explains" in page.text_content("#verdict")
        if slug == "paper003_com_planning":
            assert set(kinds) == {"assumption"} and "0 of 4" not in text
        assert not problems, (slug, problems)
        page.context.close()


@pytest.mark.parametrize("width", WIDTHS)
def test_the_diff_says_first_whether_each_side_is_still_balanced(verdict_site, browser, width):
    page, problems = open_page(browser, verdict_site / "diff.html", width)
    first = page.eval_on_selector("main", "m => [...m.children].find(e => e.matches('.verdict-box, h2')).id")
    assert first == "verdict"  # before what changed, the inputs and the results
    still = page.text_content("#verdict .still")
    new = results(verdict_site, "paper000_rpr3_scott_russell")["verdict"]["words"]
    assert still == f"No longer balanced: {new} (was: balanced as claimed)"
    sides = page.eval_on_selector_all("#verdict .side-verdict .badge", "els => els.map(e => e.textContent)")
    assert sides == ["balanced as claimed", new]
    order = page.eval_on_selector_all("main h2", "els => els.map(e => e.textContent)")
    assert order.index("Inputs") < order.index("Stages")
    # the new side's page is on this site: linked, and it exists
    href = page.get_attribute('#verdict [data-side="new"] a.page-link', "href")
    assert href == "paper000_rpr3_scott_russell/index.html" and (verdict_site / href).exists()
    assert page.locator('#verdict [data-side="old"] a.page-link').count() == 0  # no page: no dead link
    # the overlays are the pages' interactive plots: drawn, and hovering reads both designs
    page.wait_for_selector(".live .u-over")
    plots = page.locator(".live")
    assert plots.count() >= 3 and page.locator(".live canvas").count() >= 4 * plots.count()
    over = page.locator(".live .u-over").first
    over.scroll_into_view_if_needed()
    box = over.bounding_box()
    page.mouse.move(box["x"] + 0.4 * box["width"], box["y"] + 0.5 * box["height"])
    legend = page.eval_on_selector(".live .uplot", "el => [...el.querySelectorAll('.u-legend .u-series')]"
                                   ".map(s => s.textContent)")
    assert any("old design" in s for s in legend) and any("new design" in s for s in legend)
    assert visible_in_width(page, "#verdict"), width
    assert not problems, problems


@pytest.fixture(scope="module")
def history_site(tmp_path_factory) -> Path:
    """A spec committed twice (its slider made heavier, a note committed beside it), its history
    recorded and built without simulation; returns the site."""
    from _gitrepo import Repo, edit

    repo = Repo(tmp_path_factory.mktemp("hist") / "repo")
    repo.copy_spec("offset_slider_crank.yaml", "specs/osc.yaml")
    text = repo.read("specs/osc.yaml") + "analysis:\n  samples: 81\n"
    repo.commit("first design", {"specs/osc.yaml": text})
    repo.commit("heavier slider", {"specs/osc.yaml": edit(text, "slider:  {mass: 600 g}", "slider:  {mass: 800 g}"),
                                   "notes.txt": "why the slider is heavier\n"})
    for args in (("history", "specs", "-o", "out", "--no-sim", "--cache", "cache"), ("build", "specs", "-o", "out", "--no-sim")):
        r = subprocess.run([sys.executable, "-m", "balpipe", *args], cwd=repo.path, capture_output=True, text=True)
        assert r.returncode == 0, r.stderr
    return repo.path / "out"


@pytest.mark.parametrize("width", WIDTHS)
def test_the_history_says_which_inputs_each_commit_changed_and_its_plots_are_live(history_site, browser, width):
    page, problems = open_page(browser, history_site / "osc" / "history.html", width)
    rows = page.eval_on_selector_all(".history-table tr", """trs => trs.slice(1).filter(t => t.querySelector('.inputs-changed'))
        .map(t => [t.cells[0].textContent, t.querySelector('.inputs-changed').innerText, t.cells[5].innerText])""")
    assert [r[0] for r in rows] == ["2", "1"]  # newest first
    (_, changed2, verdict2), (_, changed1, verdict1) = rows
    assert changed2.splitlines() == ["mechanism.slider.mass: 0.6 → 0.8", "files: notes.txt"]
    assert changed1 == "first commit of the spec"
    assert verdict1.startswith("force balanced as designed") and "cost: moment ×" in verdict2
    # the plots over the commits are the pages' interactive ones: drawn, and hovering reads a commit
    page.wait_for_selector("#live-hist-loads .u-over")
    assert page.locator(".live").count() == 3  # loads, added mass and inertia, changing parameters
    over = page.locator("#live-hist-loads .u-over").first
    over.scroll_into_view_if_needed()
    box = over.bounding_box()
    page.mouse.move(box["x"] + 0.95 * box["width"], box["y"] + 0.5 * box["height"])
    legend = page.eval_on_selector("#live-hist-loads .uplot", "el => [...el.querySelectorAll('.u-legend .u-series')]"
                                   ".map(s => s.textContent)")
    assert legend[0].startswith("commit #") and any(s.startswith("counterweights") for s in legend)
    assert visible_in_width(page, ".history-table .inputs-changed code"), width
    assert not problems, problems
