"""The small multiples written without matplotlib (balpipe.draw.svgplot, issue 23): the printed
figure of the efforts and joint loads keeps every curve's extremes, nice ticks, every label, and
the same bytes for the same curves."""

from __future__ import annotations

import re

import numpy as np

from balpipe.draw import figures, svgplot


def test_decimation_keeps_every_extreme_exactly_and_the_ends():
    t = np.linspace(0.0, 1.0, 20_001)
    y = np.sin(40 * t) + 0.3 * np.sin(997 * t)
    y[12_345] = 5.0  # a one-sample spike
    x2, y2 = svgplot.decimate(t, y, 0.0, 1.0, 300)
    assert len(x2) <= 4 * 300 and len(x2) < len(t) / 10
    assert y2.max() == 5.0 and y2.min() == y.min()
    assert (x2[0], y2[0], x2[-1], y2[-1]) == (t[0], y[0], t[-1], y[-1])
    assert np.all(np.diff(x2) > 0)  # in time order
    # per column, the drawn range is the curve's range
    col = np.clip((t * 300).astype(int), 0, 299)
    col2 = np.clip((x2 * 300).astype(int), 0, 299)
    for c in (0, 17, 123, 299):
        assert y[col == c].max() == y2[col2 == c].max() and y[col == c].min() == y2[col2 == c].min()
    short = np.linspace(0.0, 1.0, 50)
    assert svgplot.decimate(short, short, 0.0, 1.0, 300)[0] is short  # short curves as they are


def test_ticks_are_nice_numbers_inside_the_view_with_distinct_labels():
    a = svgplot.axis(0.0, 0.5, 300.0, 27.0)
    assert a.lo < 0.0 and a.hi > 0.5 and a.labels[0] == "0.0" and a.labels[-1] == "0.5"
    steps = np.diff(a.ticks)
    assert np.allclose(steps, steps[0]) and round(steps[0] / 10 ** np.floor(np.log10(steps[0])), 6) in (1, 2, 2.5, 5)
    neg = svgplot.axis(-43.0, 41.0, 160.0, 18.0)
    assert "\u221240" in neg.labels and "0" in neg.labels and len(set(neg.labels)) == len(neg.labels)
    tiny = svgplot.axis(0.0, 3e-7, 160.0, 18.0)
    assert tiny.offset == "1e\u22127" and len(set(tiny.labels)) == len(tiny.labels)
    flat = svgplot.axis(1000.0, 1000.0 + 1e-6, 160.0, 18.0)  # a range tiny beside its values: an offset
    assert flat.offset.startswith("+") and len(set(flat.labels)) == len(flat.labels)
    zero = svgplot.axis(0.0, 0.0, 160.0, 18.0)  # a constant curve: a range around it, as matplotlib
    assert zero.lo < 0.0 < zero.hi


def test_the_figure_has_every_panel_label_curve_and_legend_entry_and_is_deterministic():
    t = np.linspace(0.0, 0.5, 3001)
    names = ["unbalanced", "counterweights <&>"]
    panels = [(f"J{j}, revolute: |F| (N)", "|F| (N)", [(n, t, (k + 1) * np.abs(np.sin(9 * t + j))) for k, n in
                                                     enumerate(names)]) for j in range(4)]
    panels[3][2][1] = (names[1], t, None)  # a stage without this curve
    svg = figures.panels_figure(panels, "joints", marks=[(0.2, "dead centre")])
    assert svg == figures.panels_figure(panels, "joints", marks=[(0.2, "dead centre")])
    assert svg.count('<g id="joints-axes_') == 4 and svg.count('<g id="joints-legend_1">') == 1
    for j in range(4):
        assert f">J{j}, revolute: |F| (N)</text>" in svg
    assert svg.count(">|F| (N)</text>") == 4 and svg.count(">time (s)</text>") == 3  # under each column's lowest
    assert svg.count(">dead centre</text>") == 4
    assert "counterweights &lt;&amp;&gt;</text>" in svg  # user text escaped
    assert svg.count("<path d=\"M") >= 7  # 7 curves at least
    # the dashed stage in matplotlib's dash pattern, scaled by its width
    assert 'stroke-dasharray="5.18,2.24"' in svg
    # every coordinate inside the figure
    w, h = map(float, re.search(r'viewBox="0 0 ([\d.]+) ([\d.]+)"', svg).groups())
    xs = [float(v) for v in re.findall(r'x="([-\d.]+)"', svg)]
    assert min(xs) >= 0 and max(xs) <= w


def test_the_loads_figure_has_four_panels_markers_pymunk_curves_and_the_coincidence_note():
    from types import SimpleNamespace

    t = np.linspace(0.0, 0.5, 101)
    F = np.stack([np.sin(9 * t), np.cos(9 * t)], axis=1)
    stages = [("unbalanced", SimpleNamespace(t=t, force=F, moment=np.sin(5 * t)), (t, F * 1.001, np.sin(5 * t))),
              ("counterweights", SimpleNamespace(t=t, force=0 * F, moment=2 * np.sin(5 * t)), None),
              ("counter-rotations", SimpleNamespace(t=t, force=0 * F, moment=0 * t), None)]
    svg = figures.loads_figure(stages)
    assert svg == figures.loads_figure(stages)  # the same bytes again
    assert svg.count('<g id="loads-axes_') == 4 and ">time (s)</text>" in svg
    for title in ("Shaking force Fx (N)", "Shaking force Fy (N)", "Shaking force |F| (N)", "Shaking moment M (N m)"):
        assert f">{title}</text>" in svg
    assert ">unbalanced (pymunk)</text>" in svg  # in the legend
    assert "Coincide in force Fx, force Fy, force |F|: counterweights = counter-rotations" in svg
    # markers at matplotlib's markevery samples of each stage: 12 + 1 in the legend, per stage and panel
    for k in range(3):
        start, every = figures.marked(k, len(t))["markevery"]
        n = len(t[start::every])
        d = svgplot.marker_path(figures.marker(k), 4.5)
        ident = re.search(rf'<path id="(loads-m[0-9a-f]+)" d="{re.escape(d)}"', svg).group(1)
        assert svg.count(f'href="#{ident}"') == 2 * (4 * n + 1)  # xlink:href and href


def test_a_wide_line_is_drawn_under_the_thin_ones():
    """Paper 000 Fig. 4: the dashed stage's zero line stays visible over the grey stage's (style
    2, wide), as matplotlib's zorder draws it."""
    t = np.linspace(0.0, 1.0, 50)
    panels = [("F (N)", "F (N)", [(n, t, 0 * t) for n in ("unbalanced", "counterweights", "counter-rotations")])]
    svg = figures.panels_figure(panels, "z")
    grey, dashed = svgplot._line_attrs(figures.style(2)), svgplot._line_attrs(figures.style(1))
    axes = svg[svg.index('<g id="z-axes_1">'):svg.index('<g id="z-legend_1">')]
    assert axes.index(grey) < axes.index(dashed)


def test_a_curve_is_written_in_relative_steps_that_add_up_to_its_rounded_points():
    """The path's relative steps (0.1 pt) sum to each point rounded to 0.1 pt, with no drift over
    a long curve; a gap (NaN) starts a new absolute move."""
    rng = np.random.default_rng(3)
    x = np.cumsum(rng.uniform(0.05, 0.9, 2000))
    y = 100 + np.cumsum(rng.normal(0, 3, 2000))
    y[700] = np.nan
    d = re.search(r'd="([^"]*)"', svgplot._polyline(x, y, "")).group(1)
    runs = [r for r in re.split(r"(?=M)", d) if r]
    assert len(runs) == 2
    got = []
    for r in runs:
        head, _, rest = r[1:].partition("l")
        px, py = map(float, head.split())
        got.append((px, py))
        nums = list(map(float, rest.split()))
        for dx, dy in zip(nums[::2], nums[1::2]):
            px, py = px + dx, py + dy
            got.append((px, py))
    ok = np.isfinite(y)
    want = np.c_[np.round(x[ok] * 10) / 10, np.round(y[ok] * 10) / 10]
    assert np.allclose(np.array(got), want, atol=1e-6)
