"""The interactive figures in a real browser (issue 22), as tests/report/test_site_browser.py drives it
(playwright and the system's Chromium; skipped with the reason when either is missing): the
curves' drawing order against the legend's, the joint selector of a figure of many joints and the
partial balancing's interactive fronts. Pages are opened from ``file://``: no server, no network."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from test_site_browser import Watched, assert_printed, open_sections

from balpipe.build import Options, build

SPECS = Path(__file__).resolve().parents[2] / "specs"

# on the worker of tests/report/test_site_browser.py, with its browser (one Chromium per run)
pytestmark = pytest.mark.xdist_group("site_browser")
LIVE_SPECS = ["paper000_rpr3_idler_loop.yaml", "paper000_rpr3_scott_russell.yaml", "partial_offset_slider_crank.yaml"]


@pytest.fixture(scope="module")
def live_site(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("live") / "site"
    outcomes = build([str(SPECS / s) for s in LIVE_SPECS], Options(out=out, simulate=False))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    return out


def _json(page, figure: str) -> dict:
    return page.eval_on_selector(f"script[data-live='{figure}']", "s => JSON.parse(s.textContent)")


def _open(browser, site: Path, slug: str, figure: str) -> tuple:
    """A watched page of ``slug`` at 1400 px, its sections open: (watcher, page, the figure's JSON)."""
    w = Watched(browser)
    w.page.set_viewport_size({"width": 1400, "height": 900})
    w.page.goto((site / slug / "index.html").as_uri(), wait_until="load")
    open_sections(w.page)
    return w, w.page, _json(w.page, figure)


_VALUES = "el => [...el.querySelectorAll('.u-legend .u-series .u-value')].map(v => v.textContent)"


def test_wide_curves_are_drawn_first_and_the_legend_keeps_the_stages_order(live_site, browser):
    """Paper 000 Fig. 4: the grey counter-rotations (0 force) are drawn first, under the dashed
    counterweights (0 force too), while the legend lists the stages in their order; hovering still
    shows each stage's own value beside its name."""
    w, p, d = _open(browser, live_site, "paper000_rpr3_idler_loop", "live-rpr3-loads")
    labels = [s["label"] for s in d["series"]]
    plot = p.locator("#live-rpr3-loads .live-plot").first
    plot.scroll_into_view_if_needed()
    legend = plot.evaluate("el => [...el.querySelectorAll('.u-legend .u-series .u-label')].map(v => v.textContent)")
    assert legend == ["t (s)"] + labels  # the stages' order, not the drawing order
    assert d["draw"][0] == labels.index("counter-rotations") and d["draw"].index(labels.index("counterweights")) > 0
    box = plot.locator(".u-over").bounding_box()
    p.mouse.move(box["x"] + box["width"] * 0.2, box["y"] + box["height"] * 0.5)
    shown = plot.evaluate(_VALUES)
    t = float(shown[0])
    k = min(range(len(d["t"])), key=lambda i: abs(d["t"][i] - t))
    for label, value in zip(labels, shown[1:]):
        exact = next(s for s in d["series"] if s["label"] == label)["y"]["x"][k]
        if value == "0 (< tolerance)":  # round-off reads as the tables write it (its panel's floor)
            assert abs(exact) <= d["panels"][0]["floor"], (label, value, exact)
            continue
        assert abs(float(value) - exact) <= 1e-3 * max(1.0, abs(exact)), (label, value, exact)
    assert not w.problems, "\n".join(w.problems)


def test_a_figure_of_many_joints_shows_one_joint_at_a_time(live_site, browser):
    """The Scott-Russell legs' 30 joint loads: a selector above the plot shows one joint, first
    the largest load; choosing another shows that one (hover still shows its values), 'every
    joint' shows them all; printing prints every panel, drawn for print."""
    w, p, d = _open(browser, live_site, "paper000_rpr3_scott_russell", "live-joints")
    n = len(d["panels"])
    assert n >= 30 and d["choose"] is not None
    visible = "h => [...h.querySelectorAll('.live-plot')].map(e => e.offsetParent !== null)"
    sel = p.locator("#live-joints select")
    assert sel.count() == 1 and sel.input_value() == str(d["choose"])
    shown = p.eval_on_selector("#live-joints", visible)
    assert len(shown) == n and shown.count(True) == 1 and shown[d["choose"]]
    # the largest peak over every stage among the force panels
    peak = [max(max(abs(v) for v in s["y"][q["key"]] if v is not None) for s in d["series"] if q["key"] in s["y"])
            for q in d["panels"]]
    forces = [i for i, q in enumerate(d["panels"]) if q["title"].endswith("(N)")]
    assert peak[d["choose"]] == max(peak[i] for i in forces)
    other = (d["choose"] + 1) % n
    sel.select_option(str(other))
    shown = p.eval_on_selector("#live-joints", visible)
    assert shown.count(True) == 1 and shown[other]
    plot = p.locator("#live-joints .live-plot").nth(other)
    plot.scroll_into_view_if_needed()
    box = plot.locator(".u-over").bounding_box()
    assert box and box["width"] > 400  # drawn at its width once shown, not the hidden 240 px
    p.mouse.move(box["x"] + box["width"] * 0.4, box["y"] + box["height"] * 0.5)
    values = plot.evaluate(_VALUES)
    assert re.search(r"\d", values[0]) and any(re.search(r"\d", v) for v in values[1:]), values
    sel.select_option("all")
    assert p.eval_on_selector("#live-joints", visible).count(True) == n
    sel.select_option(str(d["choose"]))  # one joint on screen: printing shows every one
    assert p.eval_on_selector("#live-joints", visible).count(True) == 1
    assert_printed(p, "live-joints")
    assert p.eval_on_selector("#live-joints", visible).count(True) == 1  # the screen's choice again
    assert not w.problems, "\n".join(w.problems)


def test_the_partial_fronts_are_interactive_over_their_budget(live_site, browser):
    """A partial balancing's force-against-mass front: hovering a design shows its added mass
    and its peak force (those of a design of the front), a click on a legend entry hides a
    curve, the plot is not linked to time, and printing prints the plot drawn for print."""
    figure = "live-partial_force_vs_mass"
    w, p, d = _open(browser, live_site, "partial_offset_slider_crank", figure)
    assert d["x"] == "added mass (kg)"
    plot = p.locator(f"#{figure} .live-plot").first
    plot.scroll_into_view_if_needed()
    labels = plot.evaluate("el => [...el.querySelectorAll('.u-legend .u-series .u-label')].map(v => v.textContent)")
    assert labels[0] == "added mass (kg)" and labels[1] == "optimal front"  # its long label in the tooltip
    box = plot.locator(".u-over").bounding_box()
    assert box and box["width"] > 400
    front = [(x, y) for x, y in zip(d["t"], d["series"][0]["y"]["y"]) if y is not None]
    x, y = front[len(front) // 3]  # the axes are the front's (a far mark is off them): the plot places x
    left = p.eval_on_selector(f"#{figure}", "(h, x) => h.uplots[0].valToPos(x, 'x')", x)
    p.mouse.move(box["x"] + left, box["y"] + box["height"] * 0.5)
    shown = plot.evaluate(_VALUES)
    assert float(shown[0]) == pytest.approx(x, rel=1e-3) and float(shown[1]) == pytest.approx(y, rel=1e-3), shown
    entry = plot.locator(".u-legend .u-series").nth(2)
    entry.click()
    assert "u-off" in (entry.get_attribute("class") or "")
    assert_printed(p, figure)
    assert not w.problems, "\n".join(w.problems)


@pytest.fixture(scope="module")
def simulated_site(tmp_path_factory) -> Path:
    """The Scott-Russell slider-crank with its pymunk runs (41 samples: a few seconds)."""
    folder = tmp_path_factory.mktemp("simulated")
    spec = folder / "scott_russell.yaml"
    spec.write_text((SPECS / "scott_russell.yaml").read_text().replace("  samples: 501", "  samples: 41"))
    out = folder / "site"
    outcomes = build([str(spec)], Options(out=out, simulate=True))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    return out


_TICKS = "el => el.uplots.map(u => u.axes[1]._values.filter(v => v !== ''))"
# per plot: the decades its y axis spans and the CSS px between neighbouring tick labels
_LABEL_GAPS = """el => el.uplots.map(u => {
  const ys = u.axes[1]._splits.filter((s, i) => u.axes[1]._values[i] !== '').map(s => u.valToPos(s, 'y'));
  return [Math.log10(u.scales.y.max / u.scales.y.min), ys.slice(1).map((y, i) => Math.abs(y - ys[i]))];
})"""


def test_the_simulations_figures_are_interactive_with_readable_axes(simulated_site, browser):
    """Residuals, tracking errors and the free frame's drift are live plots (issue 23: no
    matplotlib): the residuals on log axes labelled in powers of ten, the two panels side by side
    at 1400 px; the tracking error's ticks of 1e-5 written as such (1×10⁻⁵, not rounded to "0"); each
    prints itself."""
    w, p, d = _open(browser, simulated_site, "scott_russell", "live-residuals")
    assert [x["log"] for x in d["panels"]] == [True, True]
    host = p.locator("#live-residuals")
    host.scroll_into_view_if_needed()
    assert "live-grid" in (host.get_attribute("class") or "")
    # both boxes read at once: the page may still scroll between two reads (a figure above drawn late)
    boxes = host.evaluate("h => [...h.querySelectorAll('.live-plot')].map(e => { const r = e.getBoundingClientRect(); return {x: r.x, y: r.y}; })")
    assert len(boxes) == 2 and boxes[0]["y"] == boxes[1]["y"] and boxes[0]["x"] < boxes[1]["x"]
    for ticks in host.evaluate(_TICKS):
        assert len(ticks) >= 2 and all(re.fullmatch(r"1×10⁻[⁰¹²³⁴⁵⁶⁷⁸⁹]+|0\.0*1|1", t) for t in ticks), ticks
    tracking = _json(p, "live-tracking")
    peak = max(abs(v) for s in tracking["series"] for v in s["y"]["q"] if v is not None)
    assert peak < 1e-3  # a tracking error of a few 1e-5 of the travel
    (ticks,) = p.locator("#live-tracking").evaluate(_TICKS)
    assert len(set(ticks)) == len(ticks) >= 3 and "0" in ticks and any("×10⁻" in t for t in ticks), ticks
    assert not any("e-" in t for t in ticks), ticks  # the pages' powers of ten, never exponent notation
    drift = _json(p, "live-drift")
    assert [x["key"] for x in drift["panels"]] == ["drift", "rotation"]
    for figure in ("live-residuals", "live-tracking", "live-drift"):
        assert_printed(p, figure)
    assert not w.problems, "\n".join(w.problems)


_NARROW_UNTIL_LOADED = """
window.__narrow = true;  // every panel reads 100 px wide until the document is parsed
const real = Object.getOwnPropertyDescriptor(Element.prototype, "clientWidth");
Object.defineProperty(Element.prototype, "clientWidth", { configurable: true, get() {
  return window.__narrow && this.classList && this.classList.contains("live-plot") ? 100 : real.get.call(this);
} });
document.addEventListener("DOMContentLoaded", () => { window.__narrow = false; });
"""

_FILLS = """() => [...document.querySelectorAll(".live-plot:not([hidden])")].filter(el => el.offsetParent !== null)
  .map(el => [el.closest(".live").id, el.clientWidth, el.querySelector(":scope > .uplot").getBoundingClientRect().width])"""


def test_a_plot_drawn_before_the_layout_was_final_takes_its_panels_width(live_site, browser):
    """A plot drawn while its panel read narrower than it ends up (the page not laid out yet: it
    happened at random to the first panel of the residual figure, 240 px beside a 608 px one)
    takes its panel's width once the page is laid out, not only when the window resizes. Forced
    here: every panel reads 100 px wide while the page's scripts run."""
    w = Watched(browser)
    p = w.page
    p.set_viewport_size({"width": 1400, "height": 900})
    p.add_init_script(_NARROW_UNTIL_LOADED)
    p.goto((live_site / "paper000_rpr3_idler_loop" / "index.html").as_uri(), wait_until="load")
    open_sections(p)
    p.wait_for_function(f"({_FILLS})().every(([, panel, plot]) => Math.abs(panel - plot) <= 1)", timeout=10_000)
    fills = p.evaluate(_FILLS)
    assert len(fills) >= 4 and all(plot > 300 for _, _, plot in fills), fills
    assert not w.problems, w.problems


def test_a_log_axis_over_many_decades_labels_every_kth_decade(tmp_path, browser):
    """The pick-and-place cycle's residuals span 14 decades (a balanced stage's round-off against
    the unbalanced peak): a label at every decade put them 10 px apart, overprinted; every k-th
    decade keeps them at least 14 px apart (the paper 3-RPR's prismatic forces, 11 decades in a
    shorter panel, were 13 px apart)."""
    spec = tmp_path / "custom_pick_and_place_cycle.yaml"
    spec.write_text((SPECS / "custom_pick_and_place_cycle.yaml").read_text())
    out = tmp_path / "site"
    outcomes = build([str(spec)], Options(out=out, simulate=True))
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    w, p, d = _open(browser, out, "custom_pick_and_place_cycle", "live-residuals")
    host = p.locator("#live-residuals")
    host.scroll_into_view_if_needed()
    spans = host.evaluate(_LABEL_GAPS)
    assert max(decades for decades, _ in spans) > 12, spans
    assert all(len(gaps) >= 3 and min(gaps) >= 13.5 for _, gaps in spans), spans


# per plot: its value axis's label, the label's width in the font it is drawn in, and the height
# of the plotting area it is centred along (CSS px)
_LABEL_FITS = """el => el.uplots.map(u => {
  const c = document.createElement('canvas').getContext('2d');
  const f = u.axes[1].labelFont;  // uPlot keeps [css font, size, size x ratio]
  c.font = Array.isArray(f) ? f[0] : f;
  const r = u.ctx.canvas.width / u.width;
  return [u.axes[1].label, c.measureText(u.axes[1].label).width, u.bbox.height / r];
})"""


def test_a_value_axis_label_fits_along_its_plot(live_site, browser):
    """Every front's value axis label is drawn whole: the plot is tall enough for it (the
    effort front's "peak actuator effort (N m or N)" lost its unit in a 240 px plot)."""
    w, p, _ = _open(browser, live_site, "partial_offset_slider_crank", "live-partial_effort_vs_force")
    checked = []
    for figure in ("live-partial_force_vs_mass", "live-partial_moment_vs_mass", "live-partial_effort_vs_force"):
        host = p.locator(f"#{figure}")
        host.scroll_into_view_if_needed()
        for label, width, height in host.evaluate(_LABEL_FITS):
            checked.append(label)
            assert width <= height, (figure, label, width, height)
    assert "peak actuator effort (N m or N)" in checked
    assert not w.problems, "\n".join(w.problems)


def test_the_plots_write_numbers_as_the_pages_do(live_site, browser):
    """The hover legend's values (window.balpipeLive.fmt, shared with the what-if) follow
    balpipe.display.numbers.num: fixed-point to 4 significant digits, never exponent notation; a
    magnitude below a millionth or from a thousand million as a written-out power of ten; round-off
    of the panel's floor as the tables write it. Every value checked against the Python function."""
    from balpipe.display.numbers import num

    w, p, _ = _open(browser, live_site, "paper000_rpr3_idler_loop", "live-loads")
    values = [1.23456e-5, -0.000321, 54.6213, 136300.0, 2.7531e-11, 5e10, -4.2e-8, 0.0, 1.0, 999999.0]
    got = p.evaluate("vs => vs.map(v => window.balpipeLive.fmt(v))", values)
    assert got == [num(v) for v in values]
    assert not any(re.search(r"\de[-+]?\d", g) for g in got)
    assert p.evaluate("() => window.balpipeLive.fmt(3e-12, 1e-6)") == "0 (< tolerance)"
    assert w.problems == []
    p.close()
