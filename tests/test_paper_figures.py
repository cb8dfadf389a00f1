"""Each paper's figures one for one (issue 22): the figure numbers its pages reproduce, read
from their figure titles, against the table of the papers' figures."""

from __future__ import annotations

from pathlib import Path

import pytest

from balpipe.loader import load
from balpipe.report import paper_figures as PF
from balpipe.report.page import study_figures
from balpipe.study import run

SPECS = Path(__file__).parent.parent / "specs"


def test_figure_numbers_read_from_titles():
    assert PF.numbers_in("Shaking force and moment, every stage (Fig. 8 of paper 000)") == ["8"]
    assert PF.numbers_in("Balance topologies (paper 001, Figs. 2a, 4a, 6b; least mass)") == ["2a", "4a", "6b"]
    assert PF.numbers_in("Shaking force and moment per trajectory (Figs. 3-4)") == ["3", "4"]
    assert PF.numbers_in("Mass matrix along the motion") == []
    assert PF.covered("6", ["6a"]) and not PF.covered("10a", ["10"]) and not PF.covered("6", ["16a"])


def test_the_table_names_the_issue_figures():
    assert PF.FIGURES == {"000": ("4", "8"), "001": ("2", "3", "4", "6a", "6b", "6c"), "002": ("2",), "003": ("2", "3", "4"),
                          "004": ("10a", "10b", "11", "12")}


@pytest.mark.parametrize("paper", sorted(PF.FIGURES))
def test_each_papers_pages_reproduce_its_figures(paper):
    found: set[str] = set()
    for path in sorted(SPECS.glob(f"paper{paper}_*.yaml")):
        study = run(load(path).spec)
        titles = [t for t, _, _ in study_figures(study)["extra"]]
        found |= set(PF.listed(titles))
    missing = [n for n in PF.FIGURES[paper] if not PF.covered(n, sorted(found))]
    assert not missing, f"paper {paper}: figures {missing} not on its pages (found {sorted(found)})"


def test_the_papers_panels_keep_the_pages_stage_styles():
    """Fig. 12 of paper 004 draws the force-balanced stage in that stage's style of the page (one
    legend per page), not in the first style."""
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict

    study = run(load(SPECS / "paper004_five_bar.yaml").spec)
    force_only = next(s for s in study.stages if s.stage.balances == "force" and ":" not in s.stage.name)
    k = PF._k(study, force_only)
    assert k > 0 and study.stages[k] is force_only
    title, svg, _ = next(f for f in PF.own_figures(study) if f[0].startswith("Fig. 12"))
    a2 = force_only.analysis
    mine = PF._series(a2.t, [(force_only.stage.label, a2.moment, k)], "M (N m)", "p004fig12")
    first = PF._series(a2.t, [(force_only.stage.label, a2.moment, 0)], "M (N m)", "p004fig12")
    assert svg == mine and svg != first
    html = render_page(study, results_dict(study, "x", "h", False), "")
    assert html.count('id="style-legend"') == 1
    assert 'data-figures="' in html and "10a 10b 11 12" in html


def test_live_plots_draw_each_stage_in_its_static_line_style():
    """The interactive curves keep the page's one style legend: stage k has the colour, dashes and
    width of the static figures' stage k (issue 22: one style per stage on a page)."""
    from matplotlib.colors import to_hex

    from balpipe.draw import figures
    from balpipe.report.live_plots import DASHES, line_style

    for k in range(8):
        st = figures.style(k)
        assert line_style(k) == {"stroke": to_hex(st["color"]), "dash": DASHES[st["linestyle"]], "width": st["linewidth"]}
    assert line_style(1)["dash"] and not line_style(0)["dash"] and line_style(2)["stroke"] != line_style(0)["stroke"]
