"""A fixed layout for a grid of matplotlib axes, computed instead of searched: tight_layout's
margins without laying the figure out.

``fig.tight_layout()`` lays every tick label, axis label and title out and asks each for its
drawn box (about a second a figure here, as long as drawing it). :func:`fixed_layout` gives the
same margins from the texts themselves: the tick labels that the axis's locator and formatter
will draw, its labels and title, each measured in its font (:func:`text_size`,
matplotlib's metrics, without laying a figure out), and sets them with ``subplots_adjust``, with
tight_layout's padding (1.08 font sizes) around and between the panels of the grid.
"""

from __future__ import annotations

from functools import lru_cache
from typing import NamedTuple

import matplotlib as mpl
from matplotlib.font_manager import FontProperties

PAD = 1.08  # tight_layout's default pad, in font sizes


class Decor(NamedTuple):
    """What sticks out of an axes on each side (pt)."""

    left: float
    right: float
    bottom: float
    top: float


@lru_cache(maxsize=1)
def _renderer():
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(10, 10, 72)  # at 72 dpi a pixel is a point


@lru_cache(maxsize=4096)
def text_size(text: str, size: float, math: bool = False) -> tuple[float, float]:
    """Width and height (pt) of ``text`` in DejaVu Sans at ``size`` pt, as matplotlib lays it out
    (``math``: as mathtext)."""
    if not math:
        return text_metrics(text, size)[:2]
    prop = FontProperties(family="DejaVu Sans", size=size)
    w, h, _ = _renderer().get_text_width_height_descent(text, prop, ismath=True)
    return float(w), float(h)


@lru_cache(maxsize=8192)
def text_metrics(text: str, size: float, style: str = "normal", weight: str = "normal") -> tuple[float, float, float]:
    """Width, height and descent (pt) of one line of ``text`` shown literally (no mathtext) in
    DejaVu Sans at ``size`` pt, in ``style`` and ``weight``: what :mod:`.canvas` lays out."""
    prop = FontProperties(family="DejaVu Sans", size=size, style=style, weight=weight)
    w, h, d = _renderer().get_text_width_height_descent(text, prop, ismath=False)
    return float(w), float(h), float(d)


def _points(size) -> float:
    return float(FontProperties(size=size).get_size_in_points())


def lines_size(text: str, size: float) -> tuple[float, float]:
    """Width and height (pt) of a text of one or more lines shown literally: the widest line,
    the lines' heights and matplotlib's spacing of 0.2 font sizes between them."""
    lines = text.split("\n")
    sizes = [text_size(line or " ", size) for line in lines]
    return max(w for w, _ in sizes), sum(h for _, h in sizes) + 0.2 * size * (len(lines) - 1)


def _measure(text: str, size: float) -> tuple[float, float]:
    """Width and height (pt) of one text as drawn (mathtext between '$' measured as such)."""
    if text.count("$") - text.count("\\$") >= 2:
        return text_size(text, size, math=True)
    return lines_size(text, size)


def _tick_texts(axis) -> tuple[list[str], str]:
    """The labels the axis will draw at its ticks inside the view (major, then minor: a log axis
    over less than a few decades labels some minor ticks), and its offset text."""
    lo, hi = sorted(axis.get_view_interval())
    inside = [v for v in axis.get_majorticklocs() if lo - 1e-9 * (hi - lo) <= v <= hi + 1e-9 * (hi - lo)]
    fmt = axis.get_major_formatter()
    labels = [s for s in fmt.format_ticks(inside) if s]
    offset = fmt.get_offset()
    minor = [v for v in axis.get_minorticklocs() if lo <= v <= hi]
    labels += [s for s in axis.get_minor_formatter().format_ticks(minor) if s]
    return labels, offset


def decorations(ax) -> Decor:
    """How far the tick labels, ticks, axis labels and title of ``ax`` reach out of its box (pt)."""
    left = right = bottom = top = 0.0
    xp, yp = ax.xaxis.get_tick_params(which="major"), ax.yaxis.get_tick_params(which="major")
    xsize = _points(xp.get("labelsize", mpl.rcParams["xtick.labelsize"]))
    ysize = _points(yp.get("labelsize", mpl.rcParams["ytick.labelsize"]))
    tick = mpl.rcParams["xtick.major.size"] + mpl.rcParams["xtick.major.pad"]
    ax.get_xlim(), ax.get_ylim()  # autoscaled limits: the ticks the draw will show
    if yp.get("labelleft", True):
        labels, offset = _tick_texts(ax.yaxis)
        left = max([_measure(s, ysize)[0] for s in labels] + [0.0]) + tick
        if offset:
            top = max(top, _measure(offset, ysize)[1])
    if xp.get("labelbottom", True):
        labels, offset = _tick_texts(ax.xaxis)
        if labels:
            h = max(_measure(s, xsize)[1] for s in labels)
            bottom = h + tick + (_measure(offset, xsize)[1] if offset else 0.0)
            # the first and last labels, centred on their ticks, may reach past the axes' ends
            lo, hi = sorted(ax.get_xlim())
            width = ax.get_position().width * float(ax.figure.get_size_inches()[0]) * 72.0
            locs = [v for v in ax.xaxis.get_majorticklocs() if lo <= v <= hi] or [lo, hi]
            right = max(0.0, 0.5 * _measure(labels[-1], xsize)[0] - (hi - locs[-1]) / (hi - lo) * width)
            left = max(left, 0.5 * _measure(labels[0], xsize)[0] - (locs[0] - lo) / (hi - lo) * width)
    pos = ax.get_position()
    W, H = (float(v) * 72.0 for v in ax.figure.get_size_inches())
    over_x = over_y = 0.0  # a label longer than its side: the half of its excess on either end
    for label, side in ((ax.yaxis.label, "left"), (ax.xaxis.label, "bottom")):
        text = label.get_text()
        if text and label.get_visible():
            w, h = _measure(text, label.get_fontsize())
            if side == "left":
                left += h + ax.yaxis.labelpad
                over_y = max(over_y, 0.5 * (w - pos.height * H))
            else:
                bottom += h + ax.xaxis.labelpad
                over_x = max(over_x, 0.5 * (w - pos.width * W))
    titles = [ax.get_title(loc) for loc in ("center", "left", "right") if ax.get_title(loc)]
    if titles:
        size = ax.title.get_fontsize()
        top += max(_measure(t, size)[1] for t in titles) + mpl.rcParams["axes.titlepad"]
        if ax.get_title("center"):
            over_x = max(over_x, 0.5 * (_measure(ax.get_title("center"), size)[0] - pos.width * W))
    return Decor(max(left, over_x), max(right, over_x), max(bottom, over_y), max(top, over_y))


def fixed_layout(fig, rect: tuple[float, float, float, float] = (0.0, 0.0, 1.0, 1.0), pad: float = PAD) -> None:
    """Place the grid of ``fig``'s axes (from ``plt.subplots``) inside ``rect`` (figure fractions
    left, bottom, right, top) so that every axes' decorations (:func:`decorations`) fit, ``pad``
    font sizes from the edge and between panels, as ``fig.tight_layout(rect=rect)`` does, by
    ``subplots_adjust``: margins of the outer rows and columns, one spacing between them."""
    axes = [ax for ax in fig.axes if ax.get_visible() and ax.get_subplotspec() is not None]
    if not axes:
        return
    nrows, ncols = axes[0].get_subplotspec().get_gridspec().get_geometry()
    W, H = (float(v) * 72.0 for v in fig.get_size_inches())
    p = pad * _points(mpl.rcParams["font.size"])
    left, right = [0.0] * ncols, [0.0] * ncols
    bottom, top = [0.0] * nrows, [0.0] * nrows
    for ax in axes:
        d = decorations(ax)
        ss = ax.get_subplotspec()
        r0, r1 = ss.rowspan.start, ss.rowspan.stop - 1
        c0, c1 = ss.colspan.start, ss.colspan.stop - 1
        left[c0], right[c1] = max(left[c0], d.left), max(right[c1], d.right)
        top[r0], bottom[r1] = max(top[r0], d.top), max(bottom[r1], d.bottom)
    x0, y0, x1, y1 = rect
    lf = x0 + (left[0] + p) / W
    rf = x1 - (right[-1] + p) / W
    bf = y0 + (bottom[-1] + p) / H
    tf = y1 - (top[0] + p) / H
    wgap = max([(right[c] + left[c + 1] + p) / W for c in range(ncols - 1)] + [0.0])
    hgap = max([(bottom[r] + top[r + 1] + p) / H for r in range(nrows - 1)] + [0.0])
    axw = (rf - lf - (ncols - 1) * wgap) / ncols
    axh = (tf - bf - (nrows - 1) * hgap) / nrows
    fig.subplots_adjust(left=lf, right=rf, bottom=bf, top=tf,
                        wspace=wgap / axw if ncols > 1 and axw > 0 else None,
                        hspace=hgap / axh if nrows > 1 and axh > 0 else None)
