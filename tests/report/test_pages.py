"""Presentation of numbers and pages (issue 11): round-off as zero, one ratio format, units per
driver, a table of contents, no "-0" in the CSV."""

from __future__ import annotations

import re

import numpy as np

from balpipe.report import present, toc
from balpipe.report.render import load, num, ratio, tol


def test_round_off_shows_as_zero_of_its_reference():
    assert load(2.344e-13, 263.2, 1e-9) == "0 (< 1e-9 of reference)"
    assert load(263.2, 263.2, 1e-9) == "263.2"
    assert load(3e-7, 263.2, 1e-9) == "3×10⁻⁷"  # above the tolerance: a real number, shown (never in e-notation)
    assert load(0.5, 263.2, 1e-9, "N") == "0.5 N"


def test_one_ratio_convention_across_the_site():
    assert ratio(1.0) == "100 %" and ratio(0.1234567) == "12.35 %" and ratio(9.99) == "999 %"
    assert ratio(10.5919353366) == "× 10.6" and ratio(41.73) == "× 41.7"  # "×" from ten times on, as costs
    assert ratio(1.1e-15, 1e-9) == "0 (< 1e-9)"  # round-off of a balanced stage
    assert ratio(2e-9, 1e-9).endswith(" %")  # above the tolerance: still percent
    assert ratio(0) == "0" and ratio(None) == "—"
    assert tol(1e-9) == "1e-9" and tol(0.001) == "0.001"


def test_four_significant_digits():
    assert num(263.2345) == "263.2" and num(0.0123456) == "0.01235" and num(-0.0) == "0"


def test_no_negative_zero_in_the_csv():
    from balpipe.loader import load as load_spec
    from balpipe.report.results import timeseries_csv
    from balpipe.study import run
    from pathlib import Path

    spec = load_spec(Path(__file__).parents[2] / "specs" / "offset_slider_crank.yaml").spec
    text = timeseries_csv(run(spec))
    cells = [c for line in text.splitlines()[1:] for c in line.split(",")]
    assert cells and "-0" not in cells


def test_effort_units_per_driver_and_costs():
    from balpipe.loader import load as load_spec
    from balpipe.study import run
    from pathlib import Path

    specs = Path(__file__).parents[2] / "specs"
    st = run(load_spec(specs / "offset_slider_crank.yaml").spec)
    m = st.unbalanced.stage.model
    assert [present.driver_unit(m, d.name) for d in m.drivers] == ["N m"]  # a crank: revolute
    rows = present.effort_rows([(s.stage.name, s.stage.label, s.stage.model, s.analysis) for s in st.stages])
    assert {r["stage"] for r in rows} == {s.stage.name for s in st.stages}
    for r in rows:
        e = st.stages[[s.stage.name for s in st.stages].index(r["stage"])].analysis.efforts[r["driver"]]
        assert r["peak"] == float(np.max(np.abs(e))) and 0 < r["rms"] <= r["peak"]
        assert r["power"] is not None and r["power"] > 0


def test_table_of_contents_links_every_h2():
    page = "<!--toc--><h2>Balancing stages</h2>x<h2 id='k'>Other</h2><h2>Balancing stages</h2>"
    out = toc.add_toc(page)
    assert '<a href="#balancing-stages">Balancing stages</a>' in out
    assert '<a href="#balancing-stages-section">' in out and '<h2 id="balancing-stages-section">' in out
    assert toc.add_toc('<!--toc--><section id="history"><h2>History</h2></section>').count('id="history"') == 1
    assert toc.add_toc("<h2>x</h2>") == "<h2>x</h2>"  # no marker, no change


def test_page_ids_are_the_word_bounded_id_attributes():
    """toc.page_ids is re.findall(r'\bid="([^"]+)"') as a set, on the cases where a literal scan
    could differ: an id attribute inside another name (grid=, data_id=), one starting inside a
    rejected one's value, the start of the text, non-ASCII word characters, and random text."""
    import random
    import re

    def reference(page):
        return set(re.findall(r'\bid="([^"]+)"', page))

    cases = ['id="a" x', 'grid="b" <p id="c">', 'grid="foo id="bar"', 'data_id="u" data-id="v"',
             'éid="w" -id="z"', 'id=""', '<a\nid="n1">', 'xid="id="q"']
    rng = random.Random(0)
    alphabet = ['id="', "i", "d", "=", '"', " ", "g", "_", "-", "é", "x"]
    cases += ["".join(rng.choice(alphabet) for _ in range(rng.randint(0, 40))) for _ in range(3000)]
    for page in cases:
        assert toc.page_ids(page) == reference(page), page


def test_an_effort_and_its_unit_stay_on_one_line(pages):
    """The stage tables give each driver's peak effort with its unit ("0.9462 N m"): value and
    unit in one span that does not wrap (td.num may wrap between drivers, never inside "N m")."""
    import re

    page = pages("paper001_4rrr.yaml")
    cells = re.findall(r"<td class=\"num\">([^<]*<span class=\"sym\".*?)</td>", page)
    efforts = [c for c in cells if " N m" in c]
    assert efforts, "no per-driver effort cell found"
    for c in efforts:  # every "N m" of the cell closes a span that holds its value
        assert len(re.findall(r'<span class="qty">[0-9.e+-]+ N m</span>', c)) == c.count(" N m"), c
    import pathlib

    css = (pathlib.Path(__file__).resolve().parents[2] / "templates" / "style.css").read_text()
    assert re.search(r"span\.qty\s*\{\s*white-space:\s*nowrap", css)


def test_the_papers_figures_and_the_published_numbers_are_open_at_load():
    from balpipe.report import sections

    body = "".join(f"<h2>{t}</h2><p>{k}</p>" for k, t in enumerate((
        "Balancing stages", "What balancing costs the actuators", "Published vs computed",
        "Fig. 8 of paper 000", "Figs. 10a, 11 of paper 004", "Joint loads", "Checks", "Figures of the method")))
    page = sections.collapse(f"<main>{sections.START}{body}{sections.END}</main>")
    opened = re.findall(r'<details class="section"( open)?><summary><h2>([^<]*)</h2>', page)
    assert {t: bool(o) for o, t in opened} == {
        "Balancing stages": True, "What balancing costs the actuators": True, "Published vs computed": True,
        "Fig. 8 of paper 000": True, "Figs. 10a, 11 of paper 004": True,
        "Joint loads": False, "Checks": False, "Figures of the method": False}
    assert sections.collapse(f"<main>{sections.START}{body}{sections.END}</main>") == page  # deterministic
