"""The live what-if in a real browser (playwright and the system's Chromium, as
tests/report/test_site_browser.py; skipped with the reason when either is missing): sliders set
to random values recompute the loads in the page, which equal the engine's analysis of the model
with those parts to 1e-9 of each series' scale; the plots draw them; the reset restores the
computed design exactly; the panel is usable at 400 and 1400 px. Pages are opened from
``file://``: no server, no network."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from test_site_browser import Watched, open_sections

from balpipe.report import whatif
from balpipe.report.results import results_dict

# on the worker of tests/report/test_site_browser.py, with its browser (one Chromium per run)
pytestmark = pytest.mark.xdist_group("site_browser")
WHATIF_SPECS = ["offset_slider_crank.yaml", "custom_four_bar_balancing.yaml", "partial_offset_slider_crank.yaml"]


@pytest.fixture(scope="module")
def whatif_site(shared_build) -> Path:
    folder, done = shared_build(tuple(WHATIF_SPECS), "specs", "-o", "site", "--no-sim")
    assert done.returncode == 0, done.stdout + done.stderr
    return folder / "site"


def _open(browser, site: Path, slug: str, width: int):
    w = Watched(browser)
    w.page.set_viewport_size({"width": width, "height": 900})
    w.page.goto((site / slug / "index.html").as_uri(), wait_until="load")
    open_sections(w.page)
    w.page.wait_for_function("window.balpipeWhatif && document.getElementById('live-whatif').uplots")
    return w, w.page


_SET = """([values, before]) => {
  document.querySelectorAll('#whatif-panel input[type=range]').forEach(r => {
    r.value = String(values[+r.dataset.part][+r.dataset.param]);
    r.dispatchEvent(new Event('input', { bubbles: true }));
  });
}"""
_STATE = """() => { const a = window.balpipeWhatif;
  const out = {}; for (const k in a.series) out[k] = Array.from(a.series[k]);
  const design = {}; for (const k in a.design) design[k] = Array.from(a.design[k]);
  return { series: out, design: design, values: a.values.map(v => v.slice()), updates: a.updates, t: Array.from(a.t) }; }"""
# per plot of the what-if figure: its panel's key and the drawn data of each series (legend order)
_PLOTS = """() => { const host = document.getElementById('live-whatif');
  const fig = JSON.parse(document.querySelector("script[data-live='live-whatif']").textContent);
  const order = fig.draw || fig.series.map((s, i) => i);
  return host.uplots.map((u, k) => ({ key: fig.panels[k].key,
    series: fig.series.map((s, i) => Array.from(u.data[1 + order.indexOf(i)])) })); }"""


def _scale(key: str, exact: dict) -> float:
    return float(np.max(np.abs(exact["F" if key in ("Fx", "Fy") else key])))


@pytest.mark.parametrize("slug", ["offset_slider_crank", "custom_four_bar_balancing"])
def test_random_sliders_give_the_engines_loads_and_the_reset_the_design(whatif_site, browser, studies, slug):
    w, p = _open(browser, whatif_site, slug, 1400)
    st = studies(slug + ".yaml")
    ref = whatif.build(st, results_dict(st, slug + ".yaml", "h", simulated=False))
    assert isinstance(ref, whatif.WhatIf)
    start = p.evaluate(_STATE)
    assert np.array_equal(start["t"], ref.t) and np.allclose(start["values"], ref.values(), rtol=0, atol=0)
    rng = np.random.default_rng(7)
    lo = np.array([q.lo for q in ref.parts]).reshape(-1, 4)
    hi = np.array([q.hi for q in ref.parts]).reshape(-1, 4)
    for _ in range(2):
        p.evaluate(_SET, [rng.uniform(lo, hi).tolist(), start["updates"]])
        state = p.evaluate(_STATE)
        values = np.array(state["values"])
        assert np.all(values >= lo) and np.all(values <= hi) and not np.array_equal(values, ref.values())
        exact = whatif.engine_series(ref, values)  # the engine's analysis of the model with these parts
        assert set(state["series"]) == set(ref.keys) | {"F"}
        for k, y in state["series"].items():
            assert np.max(np.abs(np.array(y) - exact[k])) <= 1e-9 * _scale(k, exact), (slug, k)
        p.wait_for_function("() => window.balpipeWhatif.drawn === window.balpipeWhatif.updates")  # redrawn on the next frame
        plots = p.evaluate(_PLOTS)
        for plot in plots:  # the plot draws the design tried; the computed design stays
            assert plot["series"][2] == state["series"][plot["key"]], plot["key"]
            assert plot["series"][1] == start["design"][plot["key"]], plot["key"]
        assert any(plot["series"][2] != plot["series"][1] for plot in plots)  # the sliders moved the curves
    p.click("text=Reset to the computed design")
    state = p.evaluate(_STATE)
    assert state["values"] == [list(q.design) for q in ref.parts]
    for k, y in state["series"].items():
        assert y == start["design"][k], k
    p.wait_for_function("() => window.balpipeWhatif.drawn === window.balpipeWhatif.updates")
    for plot in p.evaluate(_PLOTS):
        assert plot["series"][2] == plot["series"][1], plot["key"]
    assert not w.problems, "\n".join(w.problems)


_LAYOUT = """() => {
  const vw = document.documentElement.clientWidth;
  const box = el => { const r = el.getBoundingClientRect(); return [r.left, r.right, r.width, r.height]; };
  return { vw: vw, scroll: document.documentElement.scrollWidth,
    ranges: [...document.querySelectorAll('#whatif-panel input[type=range]')].map(box),
    numbers: [...document.querySelectorAll('#whatif-panel input[type=number]')].map(box),
    marks: [...document.querySelectorAll('#whatif-panel .whatif-mark')].map(box),
    labels: [...document.querySelectorAll('#whatif-panel .whatif-row label')].map(el => [el.scrollWidth, el.clientWidth]),
    plots: [...document.querySelectorAll('#live-whatif .live-plot')].map(box),
    reset: box(document.querySelector('.whatif-reset')) };
}"""


@pytest.mark.parametrize("width", [400, 1400])
def test_the_panel_is_usable_at_400_and_1400_px(whatif_site, browser, width):
    """Every slider, number box and design mark lies within the page's width and is wide enough to
    use, no label is cut, the page does not scroll sideways, the plots take a readable width, and
    dragging a slider with the mouse moves its part (and the curves)."""
    w, p = _open(browser, whatif_site, "custom_four_bar_balancing", width)
    p.locator("#whatif-panel").scroll_into_view_if_needed()
    got = p.evaluate(_LAYOUT)
    vw = got["vw"]
    assert got["scroll"] <= vw, got["scroll"]
    assert len(got["ranges"]) == 4 * len(p.evaluate("window.balpipeWhatif.parts")) == len(got["marks"])
    for left, right, wd, h in got["ranges"] + got["numbers"]:
        assert 0 <= left and right <= vw and wd >= 60 and h >= 10, (left, right, wd, h)
    for (left, right, *_), (rl, rr, *_) in zip(got["marks"], got["ranges"]):
        assert rl <= left and right <= rr + 1  # the design's mark on its slider
    assert all(sw <= cw + 1 for sw, cw in got["labels"])
    assert all(wd >= min(300, vw - 60) for _, _, wd, _ in got["plots"]), got["plots"]
    assert got["reset"][2] > 0 and got["reset"][1] <= vw
    # a drag of the first mass slider by the mouse: its value and the curves follow
    before = p.evaluate("Array.from(window.balpipeWhatif.series.M)")
    r = p.locator("#whatif-panel input[type=range]").first
    r.scroll_into_view_if_needed()
    b = r.bounding_box()
    p.mouse.click(b["x"] + b["width"] * 0.95, b["y"] + b["height"] / 2)
    assert p.evaluate("window.balpipeWhatif.values[0][0]") > p.evaluate("window.balpipeWhatif.parts[0].design[0]")
    assert p.evaluate("Array.from(window.balpipeWhatif.series.M)") != before
    assert not w.problems, "\n".join(w.problems)


def test_round_off_of_the_computed_parts_reads_zero(whatif_site, browser):
    """The partial balancing's counterweights sit at y = 7e-32 m (the optimiser's round-off): the
    labels, marks and number boxes read 0, while the sliders keep the exact value (so the
    computed design's curves are the engine's)."""
    w, p = _open(browser, whatif_site, "partial_offset_slider_crank", 1400)
    design = p.evaluate("window.balpipeWhatif.parts.map(q => q.design)")
    assert any(v != 0 and abs(v) < 1e-20 for q in design for v in q)
    text = p.evaluate("""() => [document.getElementById('whatif-panel').innerText,
      ...[...document.querySelectorAll('#whatif-panel input[type=number]')].map(e => e.value),
      ...[...document.querySelectorAll('#whatif-panel .whatif-mark')].map(e => e.title),
      document.getElementById('whatif-peaks').innerText].join(' ')""")
    assert not re.search(r"\de-\d", text), re.findall(r"\S*\de-\d\S*", text)
    assert p.evaluate("window.balpipeWhatif.values") == design
    assert not w.problems, "\n".join(w.problems)


def test_a_design_tried_before_the_plots_are_built_is_drawn_when_they_are(whatif_site, browser):
    """Charts are built when their section opens: sliders moved while the section is folded (no
    plot yet) are drawn once it opens, the tried design's curves and not the computed one's."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto((whatif_site / "offset_slider_crank" / "index.html").as_uri(), wait_until="load")
    p.wait_for_function("() => window.balpipeWhatif")
    assert not p.evaluate("() => !!(document.getElementById('live-whatif').uplots || []).length")
    p.evaluate("""() => { const r = document.querySelector('#whatif-panel input[type=range]');
      r.value = String(+r.max); r.dispatchEvent(new Event('input', { bubbles: true })); }""")
    p.evaluate("document.getElementById('whatif-panel').closest('details').open = true")
    p.wait_for_function("() => (document.getElementById('live-whatif').uplots || []).length > 0")
    p.wait_for_function("() => window.balpipeWhatif.drawn === window.balpipeWhatif.updates")
    state = p.evaluate(_STATE)
    plots = p.evaluate(_PLOTS)
    assert state["series"]["M"] != state["design"]["M"]
    for plot in plots:
        assert plot["series"][2] == state["series"][plot["key"]], plot["key"]
    assert not w.problems, "\n".join(w.problems)


def test_the_design_card_links_to_the_sliders(whatif_site, browser):
    """The design card's link opens the folded section of the sliders and brings them into view."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.goto((whatif_site / "offset_slider_crank" / "index.html").as_uri(), wait_until="load")
    assert not p.locator("#whatif-panel input[type=range]").first.is_visible()
    p.click("#design-summary a[href='#designs-tried-live']")
    p.wait_for_function("() => document.getElementById('whatif-panel').closest('details').open")
    assert p.locator("#whatif-panel input[type=range]").first.is_visible()
    assert not w.problems, "\n".join(w.problems)
