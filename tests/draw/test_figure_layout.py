"""The matplotlib figures at a fraction of the cost (issue 23): a layout computed from the
texts (balpipe.draw.layout.fixed_layout) instead of tight_layout's search, that still keeps every
tick label, axis label and title inside the figure and clear of the neighbouring panels; and
one draw per SVG instead of two."""

from __future__ import annotations

import io

import matplotlib.figure
import numpy as np
import pytest

from balpipe.draw import figures
from balpipe.draw.layout import fixed_layout


def _grid(yscale: str = "linear"):
    fig, axes = figures.plt.subplots(2, 3, figsize=(9.0, 5.0), sharex=True)
    t = np.linspace(0.0, 0.5, 201)
    values = [1e5 * np.sin(9 * t), -0.0025 * t, 1e-6 * (1 + t), 1000.0 + 1e-5 * t, np.exp(-30 * t), 42.0 + 0 * t]
    for n, (ax, y) in enumerate(zip(axes.flat, values)):
        ax.plot(t, np.abs(y) + 1e-9 if yscale == "log" else y)
        ax.set_yscale(yscale)
        ax.set_title(f"panel {n}: a title of some length (N m)", fontsize=9)
        ax.set_ylabel("|F_sim − F_analytic| / F_ref" if n % 3 == 0 else "M (N m)")
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    return fig


@pytest.mark.parametrize("yscale", ["linear", "log"])
def test_the_fixed_layout_keeps_every_text_inside_and_clear_of_the_other_panels(yscale):
    fig = _grid(yscale)
    fixed_layout(fig)
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    boxes = [ax.get_tightbbox(r) for ax in fig.axes]
    for ax, b in zip(fig.axes, boxes):
        assert b.x0 >= -0.5 and b.y0 >= -0.5 and b.x1 <= W + 0.5 and b.y1 <= H + 0.5, ax.get_title()
    for i in range(len(boxes)):
        for j in range(len(boxes)):
            if i != j:  # no panel's texts over another panel's plotting area
                assert not boxes[i].overlaps(fig.axes[j].get_window_extent(r)), (i, j)
    # and no space wasted: the outer texts within two pads of the figure's edges
    pad = 2 * 1.08 * 9 * fig.dpi / 72 + 2
    assert min(b.x0 for b in boxes) < pad and W - max(b.x1 for b in boxes) < pad + 20
    assert min(b.y0 for b in boxes) < pad and H - max(b.y1 for b in boxes) < pad
    figures.plt.close(fig)


def test_an_svg_is_drawn_once_and_is_the_same_bytes(monkeypatch):
    """After fig.tight_layout() matplotlib keeps a do-nothing layout engine, for which savefig
    draws the whole figure a second time; to_svg drops it, and the SVG is byte for byte what
    savefig writes with it."""
    def svg(fig, drop: bool) -> str:
        fig.tight_layout()
        if drop:
            return figures.to_svg(fig, "p")
        buf = io.StringIO()
        fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
        figures.plt.close(fig)
        text = buf.getvalue()
        return text[text.index("<svg"):]

    draws = []
    real = matplotlib.figure.Figure.draw
    monkeypatch.setattr(matplotlib.figure.Figure, "draw", lambda self, r: draws.append(1) or real(self, r))
    ours = svg(_grid(), True)
    assert len(draws) == 1
    theirs = svg(_grid(), False)
    assert len(draws) == 3  # matplotlib's own: twice
    import re

    plain = re.sub(r'(id="|url\(#|xlink:href="#)p-', r"\1", ours)
    assert plain == theirs
