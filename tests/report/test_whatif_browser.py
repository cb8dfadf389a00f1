"""The live what-if in a real browser (playwright and the system's Chromium, as
tests/report/test_site_browser.py; skipped with the reason when either is missing): sliders set
to random values recompute the loads in the page, which equal the engine's analysis of the model
with those parts to 1e-9 of each series' scale; the plots draw them; the reset restores the
computed design exactly; the panel is usable at 400 and 1400 px; a page in display units other
than SI (the V-twin's mm and kN) shows every slider, number box, peak and curve in them, each the
SI value over its unit's factor, while the page's state stays SI. Pages are opened from
``file://``: no server, no network."""

from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
import pytest

from test_site_browser import Watched, open_sections

from balpipe.report import whatif
from balpipe.report.results import results_dict

# on the worker of tests/report/test_site_browser.py, with its browser (one Chromium per run)
pytestmark = pytest.mark.xdist_group("site_browser")
WHATIF_SPECS = ["offset_slider_crank.yaml", "custom_four_bar_balancing.yaml", "partial_offset_slider_crank.yaml",
                "custom_v_twin_6000rpm.yaml"]
VTWIN = "custom_v_twin_6000rpm"  # report.units {length: mm, force: kN}


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


# the sliders set to ``values`` in the display units (the page's SI values over its factors)
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


def _factors(p) -> tuple[np.ndarray, dict[str, float]]:
    """The page's own conversion: each slider value's factor to SI (m, x, y, I) and each panel's."""
    params, factors = p.evaluate("[window.balpipeWhatif.params, window.balpipeWhatif.factors]")
    return np.array([q["factor"] for q in params]), factors


@pytest.mark.parametrize("slug", ["offset_slider_crank", "custom_four_bar_balancing", VTWIN])
def test_random_sliders_give_the_engines_loads_and_the_reset_the_design(whatif_site, browser, studies, slug):
    """The sliders set in the page's display units (SI values over the page's factors): the page's
    SI values are those values times the factors, and its SI series the engine's to 1e-9; the
    plots draw them over the panels' factors."""
    w, p = _open(browser, whatif_site, slug, 1400)
    st = studies(slug + ".yaml")
    ref = whatif.build(st, results_dict(st, slug + ".yaml", "h", simulated=False))
    assert isinstance(ref, whatif.WhatIf)
    start = p.evaluate(_STATE)
    assert np.array_equal(start["t"], ref.t) and np.allclose(start["values"], ref.values(), rtol=0, atol=0)
    f, factors = _factors(p)
    assert (slug == VTWIN) == (not np.all(f == 1.0))
    typed = p.evaluate("[...document.querySelectorAll('#whatif-panel input[type=number]')].map(e => e.value)")
    assert typed and all(PLAIN.match(v) for v in typed), typed  # fixed-point, never '2.75272e-11'
    rng = np.random.default_rng(7)
    lo = np.array([q.lo for q in ref.parts]).reshape(-1, 4)
    hi = np.array([q.hi for q in ref.parts]).reshape(-1, 4)
    for _ in range(2):
        shown = rng.uniform(lo, hi) / f
        p.evaluate(_SET, [shown.tolist(), start["updates"]])
        state = p.evaluate(_STATE)
        values = np.array(state["values"])
        # the page's SI value of what it shows (the range input keeps a value to about 16 digits)
        assert np.max(np.abs(values - np.clip(shown * f, lo, hi)) / (hi - lo)) <= 1e-14, values - shown * f
        assert np.all(values >= lo) and np.all(values <= hi) and not np.array_equal(values, ref.values())
        exact = whatif.engine_series(ref, values)  # the engine's analysis of the model with these parts
        assert set(state["series"]) == set(ref.keys) | {"F"}
        for k, y in state["series"].items():
            assert np.max(np.abs(np.array(y) - exact[k])) <= 1e-9 * _scale(k, exact), (slug, k)
        p.wait_for_function("() => window.balpipeWhatif.drawn === window.balpipeWhatif.updates")  # redrawn on the next frame
        plots = p.evaluate(_PLOTS)
        for plot in plots:  # the plot draws the design tried; the computed design stays (in the display units)
            k = plot["key"]
            assert plot["series"][2] == (np.array(state["series"][k]) / factors[k]).tolist(), k
            assert plot["series"][1] == (np.array(start["design"][k]) / factors[k]).tolist(), k
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


_SHOWN = """() => {
  const panel = document.getElementById('whatif-panel'), host = document.getElementById('live-whatif');
  const all = sel => [...panel.querySelectorAll(sel)];
  return { labels: all('.whatif-row label').map(e => e.textContent),
    ranges: all('input[type=range]').map(e => [+e.min, +e.max, +e.value]),
    numbers: all('input[type=number]').map(e => [+e.min, +e.max, e.value]),
    computed: all('.whatif-was').map(e => e.textContent), marks: all('.whatif-mark').map(e => e.title),
    added: panel.querySelector('.whatif-added').textContent,
    peaks: [...document.querySelectorAll('#whatif-peaks tr')].map(r => [...r.cells].map(c => c.textContent)),
    axes: host.uplots.map(u => [u.axes[1].label, u.root.querySelector('.u-title').textContent]) };
}"""
#: a number box's value as the pages write numbers: fixed-point decimals, no exponent
PLAIN = re.compile(r"^-?\d+(\.\d+)?$")


def _near(text: str, value: float, digits: int) -> bool:
    """``text`` is ``value`` to ``digits`` significant digits."""
    return abs(float(text) - value) <= 0.51 * 10.0 ** (math.floor(math.log10(abs(value))) - digits + 1) if value else float(text) == 0


def test_the_v_twins_what_if_is_in_its_display_units(whatif_site, browser, studies):
    """report.units {length: mm, force: kN}: the sliders read kg, mm, mm and kg mm², their ranges,
    number boxes (fixed-point, six digits), computed notes and marks are the SI values over the
    unit's factor; the peaks table and the plots' titles and axes read kN (the moment stays N m, as
    on the rest of the page), the peaks are the SI peaks over 1000; the mass line reads kg."""
    w, p = _open(browser, whatif_site, VTWIN, 1400)
    st = studies(VTWIN + ".yaml")
    ref = whatif.build(st, results_dict(st, VTWIN + ".yaml", "h", simulated=False))
    assert isinstance(ref, whatif.WhatIf)
    f, factors = _factors(p)
    assert f.tolist() == [1.0, 1e-3, 1e-3, 1e-3 ** 2]
    assert factors == {**{k: 1e3 for k in ("Fx", "Fy", "F")}, **{k: 1.0 for k in factors if k not in ("Fx", "Fy", "F")}}
    got = p.evaluate(_SHOWN)
    units = ["kg", "mm", "mm", "kg mm²"]
    assert got["labels"] == [f"{n} ({u})" for _ in ref.parts for n, u in zip(["mass", "x", "y", "inertia"], units)]
    for k, part in enumerate(ref.parts):
        for j in range(4):
            (lo, hi, value), (nlo, nhi, typed) = got["ranges"][4 * k + j], got["numbers"][4 * k + j]
            # the range input keeps its value to 15 digits (its own decimal arithmetic)
            assert np.allclose([lo, hi, value], [part.lo[j] / f[j], part.hi[j] / f[j], part.design[j] / f[j]],
                               rtol=1e-14, atol=1e-14 * (hi - lo))
            assert (nlo, nhi) == (lo, hi) and PLAIN.match(typed), typed
            # a value within 1e-9 of its range of 0 is round-off (y = 7e-13 m) and reads 0
            shown = 0.0 if abs(part.design[j]) <= 1e-9 * (part.hi[j] - part.lo[j]) else part.design[j] / f[j]
            assert _near(typed, shown, 6), (typed, part.design[j])
            assert _near(got["computed"][4 * k + j].split()[1], shown, 4)
            assert got["marks"][4 * k + j].endswith(" " + units[j])
    mass = sum(q.design[0] for q in ref.parts)
    m = re.fullmatch(r"Mass of the parts tried: (\S+) kg \(computed design: (\S+) kg\)\.", got["added"])
    assert m and m.group(1) == m.group(2) and _near(m.group(1), mass, 4), got["added"]
    head, *rows = got["peaks"]
    titles = {q["key"]: q["title"] for q in ref.panels}
    for (title, _, computed, tried), key in zip(rows, [q["key"] for q in ref.panels]):
        unit = "kN" if key in ("Fx", "Fy", "F") else "N m"
        assert title == re.sub(r"\(N( m)?\)$", f"({unit})", titles[key]) and title.endswith(f"({unit})"), title
        assert computed == tried and _near(computed, float(np.max(np.abs(ref.design[key]))) / factors[key], 4)
    assert [a for a, _ in got["axes"]][:4] == ["Fx (kN)", "Fy (kN)", "|F| (kN)", "M (N m)"]
    assert all(a[a.rindex("("):] == t[t.rindex("("):] for a, t in got["axes"])
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
