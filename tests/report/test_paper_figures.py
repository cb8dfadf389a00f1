"""Each paper's figures one for one (issue 22): the figure numbers its pages reproduce, read
from their figure titles, against the table of the papers' figures."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe.report import paper_figures as PF

SPECS = Path(__file__).parents[2] / "specs"


def test_figure_numbers_read_from_titles():
    assert PF.numbers_in("Shaking force and moment, every stage (Fig. 8 of paper 000)") == ["8"]
    assert PF.numbers_in("Balance topologies (paper 001, Figs. 2a, 4a, 6b; least mass)") == ["2a", "4a", "6b"]
    assert PF.numbers_in("Shaking force and moment per trajectory (Figs. 3-4)") == ["3", "4"]
    assert PF.numbers_in("Mass matrix along the motion") == []
    assert PF.covered("6", ["6a"]) and not PF.covered("10a", ["10"]) and not PF.covered("6", ["16a"])


def test_the_table_names_the_issue_figures():
    assert PF.FIGURES == {"000": ("4", "8"), "001": ("2", "3", "4", "6a", "6b", "6c"), "002": ("2",), "003": ("2", "3", "4"),
                          "004": ("10a", "10b", "11", "12")}


#: the paper figures each paper spec's page lists (data-figures, the line under its title)
REPRODUCES = {
    "paper000_rpr3_idler_loop.yaml": ["4"],
    "paper000_rpr3_scott_russell.yaml": ["8"],
    "paper000_rpr3_scott_russell_corrected.yaml": ["8"],
    "paper001_4rrr.yaml": ["2a", "3", "4a", "4b"],
    "paper001_4rrr_fig6a.yaml": ["2a", "3", "4a", "4b", "6a"],
    "paper001_4rrr_fig6b.yaml": ["2a", "3", "4a", "4b", "6b"],
    "paper001_4rrr_fig6c.yaml": ["2a", "3", "4a", "4b", "6c"],
    "paper002_decoupling.yaml": ["2"],
    "paper002_decoupling_horizontal.yaml": ["2"],
    "paper003_com_planning.yaml": ["2", "3", "4"],
    "paper004_five_bar.yaml": ["7", "8", "9", "10a", "10b", "11", "12"],
}


def test_every_paper_spec_is_in_the_table_and_the_pages_cover_each_papers_figures():
    """The acceptance of issue 22: together, a paper's pages reproduce every figure of the table
    (each page's list is checked against its own figures' titles below, one spec per test so
    that the pages build in parallel)."""
    assert sorted(REPRODUCES) == sorted(p.name for p in SPECS.glob("paper*.yaml"))
    for paper, wanted in PF.FIGURES.items():
        found = sorted({n for spec, numbers in REPRODUCES.items() if spec.startswith(f"paper{paper}_") for n in numbers})
        missing = [n for n in wanted if not PF.covered(n, found)]
        assert not missing, f"paper {paper}: figures {missing} not on its pages (found {found})"


@pytest.mark.parametrize("spec", sorted(REPRODUCES))
def test_each_paper_page_lists_the_figures_it_draws(spec, pages):
    """A paper spec's page lists (data-figures) the paper's figure numbers read from its figures'
    titles, each shown on the page as "Fig. n", and they are the table's (the titles of the
    figures the page was rendered from: ``pages.figures``, study_figures' own result)."""
    import re

    titles = [t for t, _, _ in pages.figures(spec)["extra"]]
    html = pages(spec)
    m = re.search(r'data-figures="([^"]*)"', html)
    listed = m.group(1).split() if m else []
    assert listed == PF.listed(titles) == REPRODUCES[spec]
    assert all(f"Fig. {n}" in html for n in listed)


def test_the_papers_panels_keep_the_pages_stage_styles(studies, pages):
    """Fig. 12 of paper 004 draws the force-balanced stage in that stage's style of the page (one
    legend per page), not in the first style."""
    study = studies("paper004_five_bar.yaml")
    from balpipe.families.five_bar import figures as P4

    force_only = next(s for s in study.stages if s.stage.balances == "force" and s.stage.design is None)
    k = P4.style_of(study, force_only)
    assert k > 0 and study.stages[k] is force_only
    title, svg, _ = next(f for f in PF.own_figures(study) if f[0].startswith("Fig. 12"))
    a2 = force_only.analysis
    mine = P4.series(a2.t, [(force_only.stage.label, a2.moment, k)], "M (N m)", "p004fig12")
    first = P4.series(a2.t, [(force_only.stage.label, a2.moment, 0)], "M (N m)", "p004fig12")
    assert svg == mine and svg != first
    html = pages("paper004_five_bar.yaml")
    assert html.count('id="style-legend"') == 1
    assert 'data-figures="' in html and "10a 10b 11 12" in html


def test_live_plots_draw_each_stage_in_its_line_style_of_the_page():
    """The interactive curves keep the page's one style legend: stage k has the colour, dashes and
    width of the matplotlib figures' stage k (issue 22: one style per stage on a page)."""
    from matplotlib.colors import to_hex

    from balpipe.draw import figures
    from balpipe.draw.live import DASHES, line_style

    for k in range(8):
        st = figures.style(k)
        assert line_style(k) == {"stroke": to_hex(st["color"]), "dash": DASHES[st["linestyle"]], "width": st["linewidth"]}
    assert line_style(1)["dash"] and not line_style(0)["dash"] and line_style(2)["stroke"] != line_style(0)["stroke"]


def _live(html: str, name: str) -> dict:
    import json

    start = html.index(f'data-live="live-{name}">') + len(f'data-live="live-{name}">')
    return json.loads(html[start:html.index("</script>", start)])


@pytest.mark.parametrize("spec", ["paper000_rpr3_idler_loop", "paper000_rpr3_scott_russell"])
def test_paper000_figures_draw_each_stage_in_its_style_of_the_page(spec, studies):
    """Issue 22, point 4: on a paper-000 page dashed means the counterweights in every figure
    (Fig. 4 / 8 and the stage figures), as the paper draws them; the added linkage, which the
    paper does not plot, is never dashed."""
    from balpipe.draw.live import line_style
    from balpipe.report.page import shown_stages

    study = studies(f"{spec}.yaml")
    html = next(h for title, h, _ in study.extra_figures() if "of paper 000)" in title)
    shown = [s.stage.name for s in shown_stages(study)]
    assert shown[:3] == ["unbalanced", "counterweights", "counter_rotations"]
    for x in _live(html, "rpr3-loads")["series"]:
        name = next(s.stage.name for s in study.stages if s.stage.label == x["label"])
        assert {key: x[key] for key in ("stroke", "dash", "width")} == line_style(shown.index(name))
        assert bool(x["dash"] == line_style(1)["dash"]) == (name == "counterweights")


def test_paper000_fig4_draws_the_dashed_zero_force_over_the_grey_line(studies):
    """Issue 22: on Fig. 4 of paper 000 the counterweights' force (dashed) and the
    counter-rotations' (grey, wide) are both 0; the interactive plot draws the dashed curve
    after the grey one, on top (its ``draw`` order, as matplotlib's zorder would), and its
    legend keeps the stages' order."""
    study = studies("paper000_rpr3_idler_loop.yaml")
    html = next(h for title, h, _ in study.extra_figures() if "(Fig. 4 of paper 000)" in title)
    by = {s.stage.label: s.stage.name for s in study.stages}
    cw = next(s for s in study.stages if s.stage.name == "counterweights")
    cr = next(s for s in study.stages if s.stage.name == "counter_rotations")
    scale = study.unbalanced.analysis.max_force
    assert np.max(np.abs(cw.analysis.force)) < 1e-9 * scale and np.max(np.abs(cr.analysis.force)) < 1e-9 * scale
    data = _live(html, "rpr3-loads")
    labels = [x["label"] for x in data["series"]]
    drawn_names = [by[labels[i]] for i in data["draw"]]
    assert sorted(data["draw"]) == list(range(len(labels)))
    assert drawn_names[0] == "counter_rotations" and drawn_names.index("counterweights") > 0
    assert [by[x] for x in labels][:3] == ["unbalanced", "counterweights", "counter_rotations"]  # the legend's order


def test_stage_styles_apply_only_to_a_complete_set_of_the_main_designs_stages():
    """Stage.style orders the page's stages only when the main design's stages carry the styles
    0..n-1 (compared designs follow in their order); a balancing that wraps a paper's method
    (the partial balancing: its own unbalanced stage has no style) keeps its order."""
    from types import SimpleNamespace as NS

    from balpipe.balancing.base import in_style_order, style_index, styled

    def r(name, style):
        design, _, _ = name.rpartition(":")  # this test's shorthand: a compared design's stage as design:stage
        return NS(stage=NS(name=name, style=style, group="", design=design or None))

    main = [r("unbalanced", 0), r("linkage", 3), r("counterweights", 1), r("counter_rotations", 2)]
    other = [r("b:unbalanced", 0), r("b:counterweights", 1)]
    assert styled(main + other)
    assert [x.stage.name for x in in_style_order(main + other)] == [
        "unbalanced", "counterweights", "counter_rotations", "linkage", "b:unbalanced", "b:counterweights"]
    assert style_index(main + other, main[1]) == 3 and style_index(main + other, other[0]) == 4
    wrapped = [r("unbalanced", None), r("a:counterweights", 1), r("a:linkage", 3), r("partial", None)]
    assert not styled(wrapped) and in_style_order(wrapped) == wrapped
    assert not styled([r("x", 0), r("y", 0)]) and not styled([r("x", 1)])
