"""The mechanism drawings' SVG writer (:mod:`balpipe.draw.canvas`, issue 23): ticks as
matplotlib chooses them, numbers and names written literally and deterministically, equal
scales, paths simplified without moving what is drawn, and no matplotlib figure made."""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from balpipe.draw import canvas as cv

import drawn_svg

NS = "{http://www.w3.org/2000/svg}"


@pytest.mark.parametrize("lo,hi,length", [(-0.61, 0.62, 400.0), (0.0, 1e-3, 300.0), (-3.2, 17.0, 120.0),
                                          (0.4, 0.55, 250.0), (-250.0, 40.0, 500.0)])
def test_ticks_are_matplotlibs(lo, hi, length):
    """The ticks of an axis of ``length`` pt are those matplotlib's AutoLocator puts on an axes
    of that length (x: one per three font sizes, y: per two)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=(length / 72.0 / 0.5, length / 72.0 / 0.5))
    ax = fig.add_axes((0.25, 0.25, 0.5, 0.5))
    ax.set_xlim(lo, hi)
    ax.set_ylim(lo, hi)
    for axis, per in ((ax.xaxis, 3.0), (ax.yaxis, 2.0)):
        want = [v for v in axis.get_majorticklocs() if lo - 1e-9 * (hi - lo) <= v <= hi + 1e-9 * (hi - lo)]
        assert np.allclose(cv.ticks(lo, hi, length, 9.0, per), want, rtol=0, atol=1e-12 * (hi - lo))
    plt.close(fig)


def test_tick_labels_carry_the_decimals_of_their_step():
    assert [cv.tick_label(v, 0.2) for v in (-0.4, 0.0, 0.6)] == ["\u22120.4", "0.0", "0.6"]
    assert cv.tick_label(0.25, 0.25) == "0.25" and cv.tick_label(1e-17, 0.05) == "0.00"
    assert cv.tick_label(1500.0, 500.0) == "1500" and cv.tick_label(2e-4, 1e-4) == "0.0002"


def test_numbers_are_written_rounded_and_never_negative_zero():
    assert cv.num(-0.001) == "0" and cv.num(1.0) == "1" and cv.num(2.345678) == "2.35" and cv.num(-12.5) == "-12.5"


def _drawing(name: str = "B<1> & $x$") -> cv.Canvas:
    c = cv.Canvas(432, 331.2)
    p = c.panels[0]
    t = np.linspace(0.0, 2 * math.pi, 2001)
    p.line(0.3 * np.cos(t), 0.3 * np.sin(t), "tab:blue", width=0.5)  # a finely sampled circle
    p.line([0.0, 0.3], [0.0, 0.0], "black", width=2.2, cap="round", cls="link")
    p.circle((0.3, 0.0), 0.05, fill="tab:red", edge="tab:red", alpha=0.6)
    p.marker(0.0, 0.0, "^", 9.0)
    p.title = "a title"
    c.layout()
    p.name(cv.Label(name, tuple(p.to_px((0.1, 0.1))), tuple(p.to_px((0.0, 0.0))), 8.0))
    return c


def test_the_drawing_is_valid_svg_with_names_shown_literally_and_the_same_bytes_twice():
    svg = _drawing().svg("d")
    root = ET.fromstring(svg)  # well formed: names are escaped
    texts = [t.text for t in root.iter(f"{NS}text")]
    assert "B<1> & $x$" in texts and "a title" in texts and "x (m)" in texts and "y (m)" in texts
    assert svg == _drawing().svg("d")
    assert 'id="d-clip0"' in svg and "url(#d-clip0)" in svg  # ids carry the prefix


def test_equal_scales_and_the_view_holds_the_data_with_margins():
    c = _drawing()
    p = c.panels[0]
    x0, y0, x1, y1 = p.box
    vx0, vy0, vx1, vy1 = p.view
    assert (x1 - x0) / (vx1 - vx0) == pytest.approx((y1 - y0) / (vy1 - vy0), rel=1e-12)  # one scale
    assert vx0 < -0.3 and vx1 > 0.35 and vy0 < -0.3 and vy1 > 0.3  # the circle and the disc inside
    assert 0 <= x0 and x1 <= c.width and 0 <= y0 and y1 <= c.height


def test_paths_are_simplified_within_a_fraction_of_a_point():
    """2001 samples of a circle are written as far fewer points, none farther than 0.2 pt from
    the circle as laid out."""
    c = _drawing()
    p = c.panels[0]
    root = ET.fromstring(c.svg("d"))
    d = next(e.get("d") for e in root.iter(f"{NS}path") if e.get("stroke") == cv.colour("tab:blue"))
    pts = np.array([(float(x), c.height - float(y)) for x, y in
                    (seg.split(" ") for seg in d.replace("M", "L").split("L")[1:])])
    assert 20 < len(pts) < 1000
    centre = p.to_px((0.0, 0.0))
    r = np.hypot(*(pts - centre).T)
    assert np.max(np.abs(r - 0.3 * p.scale)) < 0.2


def test_a_displaced_name_has_a_leader_and_its_box_is_read_back():
    drawn = drawn_svg.read(_drawing().svg("d"))
    (text, box), = drawn["names"]
    assert text == "B<1> & $x$" and box[2] > box[0] and box[3] > box[1]
    assert drawn["links"] and drawn["discs"]


def test_drawing_makes_no_matplotlib_figure():
    import matplotlib.pyplot as plt

    before = plt.get_fignums()
    _drawing().svg("d")
    assert plt.get_fignums() == before
