"""Small multiples of time series written straight as SVG, without matplotlib's figure machinery
(issue 23: a 30-panel figure took matplotlib ~15 s, its layout search and text layout; this
writes it in a few milliseconds).

It draws what :func:`balpipe.draw.figures.panels_figure` promises, in the house style of the
matplotlib figures (``figures.plt.rcParams``: DejaVu Sans 9 pt, light grid, no top or right
spine, the stage line styles of :func:`balpipe.draw.figures.style`): per panel its title, y
label, the curves, ticks at nice numbers (1, 2, 2.5, 5 × 10^k, matplotlib's
:class:`~matplotlib.ticker.MaxNLocator`), "time (s)" under the lowest panel of each column, the
dotted lines of ``marks``; the first panel's legend below the panels, in as many columns (at
most 3) as the width holds. The layout is computed, not searched: every margin is the measured
size of what it holds (text measured with matplotlib's font metrics of the same font).

Long curves are thinned for the drawing to what the panel's width can show (:func:`decimate`:
the first, smallest, largest and last sample of every column of :data:`COLUMNS_PER_PT` per
point), so every peak is drawn exactly. Sizes and coordinates are in points (1/72 inch), as
matplotlib's SVG; numbers are rounded to 2 decimals, so the output is deterministic.
"""

from __future__ import annotations

import math
import re
import zlib
from functools import lru_cache
from typing import NamedTuple
from xml.sax.saxutils import escape

import numpy as np

PANEL_W, PANEL_H = 4.6 * 72, 2.8 * 72  # a panel's cell (pt), as panels_figure's figsize per panel
FONT, TITLE_FONT, LEGEND_FONT, MARK_FONT, NOTE_FONT = 9.0, 9.0, 8.5, 7.0, 8.0
TICK, TICK_PAD, LABEL_PAD, TITLE_PAD, EDGE = 3.5, 3.5, 4.0, 6.0, 4.0  # matplotlib's rcParams (pt)
LINE_W = 0.8  # spines, ticks and grid lines
GRID = "#b0b0b0"
MARGIN = 0.05  # data margins (axes.xmargin, axes.ymargin)
COLUMNS_PER_PT = 2  # decimation: columns per point of panel width (a print at 144 dpi shows each)
DASHES = {"-": None, "--": (3.7, 1.6), "-.": (6.4, 1.6, 1.0, 1.6), ":": (1.0, 1.65)}  # × linewidth, as matplotlib
MINUS = "\u2212"


@lru_cache(maxsize=1)
def _renderer():
    from matplotlib.backends.backend_agg import RendererAgg

    return RendererAgg(10, 10, 72)  # at 72 dpi a pixel is a point


@lru_cache(maxsize=4096)
def text_size(text: str, size: float, math: bool = False) -> tuple[float, float]:
    """Width and height (pt) of ``text`` in DejaVu Sans at ``size`` pt, as matplotlib lays it out
    (``math``: as mathtext)."""
    from matplotlib.font_manager import FontProperties

    prop = FontProperties(family="DejaVu Sans", size=size)
    w, h, _ = _renderer().get_text_width_height_descent(text, prop, ismath=math)
    return float(w), float(h)


def _fmt(v: float) -> str:
    return f"{round(float(v), 2) + 0.0:g}"


def _colour(c: str) -> str:
    from matplotlib.colors import to_hex

    return to_hex(c)


def decimate(x: np.ndarray, y: np.ndarray, x0: float, x1: float, columns: int) -> tuple[np.ndarray, np.ndarray]:
    """The samples of a curve that a drawing ``columns`` wide over [x0, x1] can show: in every
    column the first, the smallest, the largest and the last sample, in their order (so every
    extreme value is drawn exactly and the line between columns is the same); the curve itself
    when it has fewer than four samples a column."""
    n = len(x)
    if n <= 4 * columns or not np.all(np.isfinite(y)):
        return x, y
    col = np.clip(((x - x0) / ((x1 - x0) or 1.0) * columns).astype(int), 0, columns - 1)
    starts = np.flatnonzero(np.r_[True, col[1:] != col[:-1]])
    ends = np.r_[starts[1:], n]
    keep = [starts, ends - 1]
    for fn in (np.minimum, np.maximum):
        # the index of the smallest / largest value of each run of equal columns
        best = np.array([s + int((np.argmin if fn is np.minimum else np.argmax)(y[s:e])) for s, e in zip(starts, ends)])
        keep.append(best)
    k = np.unique(np.concatenate(keep))
    return x[k], y[k]


class Axis(NamedTuple):
    lo: float  # the view limits
    hi: float
    ticks: list[float]
    labels: list[str]
    offset: str  # '1e−6' or '+1000' written at the axis's end, '' without


def _nonsingular(lo: float, hi: float) -> tuple[float, float]:
    """A range that can be drawn, as matplotlib widens one: a constant ``v`` becomes v ± 5 % of
    |v| (±0.05 for 0)."""
    if not (math.isfinite(lo) and math.isfinite(hi)):
        return -0.05, 0.05
    if hi - lo <= 1e-14 * max(abs(lo), abs(hi)) or hi == lo:
        if hi == 0.0:
            return -0.05, 0.05
        return lo - 0.05 * abs(lo), hi + 0.05 * abs(hi)
    return lo, hi


def axis(lo: float, hi: float, length: float, spacing: float) -> Axis:
    """The view limits (the data range with :data:`MARGIN` either side), ticks at nice numbers
    at least ``spacing`` pt apart (matplotlib's: 2 font sizes on a y axis, 3 on an x axis) on an axis ``length`` pt long, and their labels: the fewest
    decimals that tell them apart, a common factor (10^k, outside 1e-4 ... 1e6) or offset (a
    range tiny beside its values) written once at the axis's end."""
    from matplotlib.ticker import MaxNLocator

    lo, hi = _nonsingular(lo, hi)
    d = hi - lo
    lo, hi = lo - MARGIN * d, hi + MARGIN * d
    bins = max(1, min(9, int(length / spacing)))
    ticks = [float(t) for t in MaxNLocator(nbins=bins, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
             if lo - 1e-9 * (hi - lo) <= t <= hi + 1e-9 * (hi - lo)]
    return Axis(lo, hi, ticks, *tick_labels(ticks))


def tick_labels(ticks: list[float]) -> tuple[list[str], str]:
    """Labels of ``ticks`` (evenly spaced) and the axis's common factor or offset text."""
    if not ticks:
        return [], ""
    step = ticks[1] - ticks[0] if len(ticks) > 1 else abs(ticks[0]) or 1.0
    big = max(abs(t) for t in ticks)
    offset, text = 0.0, ""
    if big > 0 and step < 1e-4 * big:  # a range tiny beside its values: an offset
        unit = 10.0 ** math.ceil(math.log10(step * len(ticks)))
        offset = round(ticks[0] / unit) * unit
        text = "+" + _number(offset) if offset >= 0 else MINUS + _number(-offset)
        ticks = [t - offset for t in ticks]
        big = max(abs(t) for t in ticks)
    scale = 0
    if big > 0 and (big < 1e-4 or big >= 1e6) and not text:
        scale = math.floor(math.log10(big))
        text = "1e" + str(scale).replace("-", MINUS)
    vals = [t / 10.0 ** scale for t in ticks]
    step = abs(vals[1] - vals[0]) if len(vals) > 1 else 1.0
    decimals = 0
    while decimals < 12 and any(abs(v * 10 ** decimals - round(v * 10 ** decimals)) > 1e-6 * step * 10 ** decimals
                                for v in vals):
        decimals += 1
    labels = [f"{v + 0.0:.{decimals}f}" for v in vals]
    return [s.replace("-", MINUS) if s.strip("-0.") else s.lstrip("-") for s in labels], text


def _number(v: float) -> str:
    return f"{v:.12g}".replace("e+0", "e").replace("e+", "e").replace("-", MINUS)


class Panel(NamedTuple):
    """One panel as :func:`panels_svg` takes it: title, y label, curves (label, t, values or None)."""

    title: str
    ylabel: str
    curves: list


class Box(NamedTuple):
    x0: float
    y0: float  # top (SVG y grows downwards)
    x1: float
    y1: float


class Layout(NamedTuple):
    """Where everything goes (pt, y down): the figure's size, each panel's plotting area, its
    axes, the texts around it, the legend's box and its columns."""

    width: float
    height: float
    areas: list  # Box per panel
    axes: list  # (x Axis, y Axis) per panel
    texts: list  # Box of every title, axis label and tick label (for the tests: all inside the figure)
    legend: Box | None
    legend_cols: int
    entries: list  # (label, line style) of the legend
    legend_font: float = LEGEND_FONT
    notes: list = []  # (x, y, line) of the notes' lines, left aligned, between the panels and the legend


def _limits(curves: list) -> tuple[float, float, float, float]:
    xs = [np.asarray(c[1], dtype=float) for c in curves if c[2] is not None]
    ys = [np.asarray(c[2], dtype=float) for c in curves if c[2] is not None]
    xs = [a[np.isfinite(a)] for a in xs]
    ys = [a[np.isfinite(a)] for a in ys]
    if not any(a.size for a in ys):
        return 0.0, 1.0, 0.0, 1.0
    return (min(float(a.min()) for a in xs if a.size), max(float(a.max()) for a in xs if a.size),
            min(float(a.min()) for a in ys if a.size), max(float(a.max()) for a in ys if a.size))


def curve_style(curve: tuple, k: int, styles) -> dict:
    """A curve's line style: its own (a fourth item) or stage ``k``'s, ``styles(k)``."""
    return curve[3] if len(curve) > 3 else styles(k)


def layout(panels: list, columns: int, marks: list | None = None, styles=None, cell: tuple | None = None,
           legend_font: float = LEGEND_FONT, notes: list | tuple = ()) -> Layout:
    """The fixed layout of :func:`panels_svg`: panels in rows of ``columns``, each ``cell`` (w, h)
    pt (default: ``panels_figure``'s figure per panel); a cell's margins are the sizes of its
    title, y label and tick labels (each column's left margin the widest of the column, each
    row's top and bottom the same); below the last row the ``notes`` (lines wrapped to the
    width) and the legend's rows."""
    cw, ch = cell or (PANEL_W, PANEL_H)
    cols = max(1, min(columns, len(panels)))
    rows = max(1, math.ceil(len(panels) / cols))
    W = cw * cols
    fh = text_size("0", FONT)[1]
    th = text_size("0", TITLE_FONT)[1]
    # the axes first (ticks depend on the lengths, the margins on the ticks: one refinement)
    lows = [n + cols >= len(panels) for n in range(len(panels))]
    top = TITLE_PAD + th + 2 * EDGE
    bottom_low = TICK + TICK_PAD + fh + LABEL_PAD + fh + EDGE
    bottom = [bottom_low if any(lows[n] for n in range(r * cols, min(len(panels), (r + 1) * cols))) else EDGE + 2 * fh
              for r in range(rows)]
    limits = [_limits(p[2]) for p in panels] or [(0.0, 1.0, 0.0, 1.0)]
    height = [ch - top - bottom[r] for r in range(rows)]
    yaxes = [axis(lim[2], lim[3], height[n // cols], 2.0 * FONT) for n, lim in enumerate(limits)]
    left = []
    for c in range(cols):
        w = 0.0
        for n in range(c, len(limits), cols):
            w = max([w] + [text_size(s, FONT)[0] for s in yaxes[n].labels])
        labelled = any(panels[n][1] for n in range(c, len(panels), cols))
        left.append(2 * EDGE + (fh + LABEL_PAD if labelled else 0.0) + w + TICK_PAD + TICK)
    areas, axes_, texts = [], [], []
    for n, lim in enumerate(limits):
        r, c = divmod(n, cols)
        cx, cy = c * cw, r * ch
        xa = axis(lim[0], lim[1], cw - left[c] - 12.0, 3.0 * FONT)
        last = text_size(xa.labels[-1], FONT)[0] / 2 if xa.labels else 0.0
        right = max(12.0, last + EDGE)
        box = Box(cx + left[c], cy + top, cx + cw - right, cy + ch - bottom[r])
        areas.append(box)
        axes_.append((xa, yaxes[n]))
        if n < len(panels):
            texts += _text_boxes(panels[n], box, xa, yaxes[n], lows[n])
    top = rows * ch
    lines = []
    for note in notes:
        for line in _wrap(note, NOTE_FONT, W - 4 * EDGE):
            top += 1.25 * NOTE_FONT  # a line of the notes
            lines.append((2 * EDGE, top, line))
    styles = styles or (lambda k: {})
    leg, ncol, entries = _legend(panels[0][2] if panels else [], W, top, styles, legend_font)
    H = top + (leg.y1 - leg.y0 + EDGE if leg else EDGE if lines else 0.0)
    return Layout(W, H, areas, axes_, texts, leg, ncol, entries, legend_font, lines)


def _wrap(text: str, size: float, width: float) -> list[str]:
    """``text`` in lines no wider than ``width`` pt (at word breaks; a longer word alone)."""
    lines: list[str] = []
    for word in text.split(" "):
        if lines and text_size(lines[-1] + " " + word, size)[0] <= width:
            lines[-1] += " " + word
        else:
            lines.append(word)
    return lines


def _text_boxes(panel, box: Box, xa: Axis, ya: Axis, low: bool) -> list:
    """The boxes of a panel's texts: title, y label, y tick labels, and x ones when ``low``."""
    out = []
    tw, th = text_size(panel[0], TITLE_FONT)
    mid = 0.5 * (box.x0 + box.x1)
    out.append(Box(mid - tw / 2, box.y0 - TITLE_PAD - th, mid + tw / 2, box.y0 - TITLE_PAD))
    lw, lh = text_size(panel[1], FONT)
    ymid = 0.5 * (box.y0 + box.y1)
    wide = max([text_size(s, FONT)[0] for s in ya.labels] + [0.0])
    x = box.x0 - TICK - TICK_PAD - wide - LABEL_PAD
    out.append(Box(x - lh, ymid - lw / 2, x, ymid + lw / 2))
    if low:
        fh = text_size("0", FONT)[1]
        y = box.y1 + TICK + TICK_PAD + fh + LABEL_PAD
        w = text_size("time (s)", FONT)[0]
        out.append(Box(mid - w / 2, y, mid + w / 2, y + fh))
        for t, s in zip(xa.ticks, xa.labels):
            px = _px(t, xa, box.x0, box.x1)
            w = text_size(s, FONT)[0]
            out.append(Box(px - w / 2, box.y1 + TICK + TICK_PAD, px + w / 2, box.y1 + TICK + TICK_PAD + fh))
    return out


def _legend(curves: list, W: float, top: float, styles, fs: float = LEGEND_FONT) -> tuple[Box | None, int, list]:
    """The legend's box under the panels (``top``), centred, in as many columns (at most 3) as fit
    in 98 % of ``W``; the entries are the first panel's curves (one per stage that has one)."""
    entries = [(c[0], curve_style(c, k, styles)) for k, c in enumerate(curves) if c[2] is not None]
    if not entries:
        return None, 0, []
    for ncol in range(min(len(entries), 3), 0, -1):
        w = _legend_width(entries, ncol, fs)
        if ncol == 1 or w <= 0.98 * W:
            break
    rows = math.ceil(len(entries) / ncol)
    fh = text_size("0", fs)[1]
    h = rows * fh + (rows - 1) * 0.5 * fs + 2 * 0.4 * fs
    x0 = 0.5 * (W - w)
    return Box(x0, top + EDGE, x0 + w, top + EDGE + h), ncol, entries


def _legend_columns(entries: list, ncol: int) -> list:
    """The entries in ``ncol`` columns as matplotlib's legend fills them: in order, the first
    ``len % ncol`` columns one entry longer."""
    n, out, start = len(entries), [], 0
    for c in range(ncol):
        size = n // ncol + (1 if c < n % ncol else 0)
        if size:
            out.append(entries[start:start + size])
        start += size
    return out


def _legend_width(entries: list, ncol: int, fs: float = LEGEND_FONT) -> float:
    handle = (2.0 + 0.8) * fs
    cols = _legend_columns(entries, ncol)
    widths = [handle + max(text_size(label, fs)[0] for label, _ in col) for col in cols]
    return sum(widths) + 2.0 * fs * (len(cols) - 1) + 2 * 0.4 * fs


def _px(v: float, a: Axis, p0: float, p1: float) -> float:
    return p0 + (v - a.lo) / (a.hi - a.lo) * (p1 - p0)


def _text(x: float, y: float, s: str, size: float, anchor: str = "middle", extra: str = "") -> str:
    return (f'<text x="{_fmt(x)}" y="{_fmt(y)}" style="font-size:{_fmt(size)}px;font-family:\'DejaVu Sans\';'
            f'text-anchor:{anchor}"{extra}>{escape(s)}</text>')


def _line_attrs(st: dict) -> str:
    width = float(st["linewidth"])
    dash = DASHES.get(st["linestyle"])
    attrs = f'fill="none" stroke="{_colour(st["color"])}" stroke-width="{_fmt(width)}" stroke-linejoin="round"'
    if dash:
        attrs += ' stroke-dasharray="' + ",".join(_fmt(d * width) for d in dash) + '"'
    else:
        attrs += ' stroke-linecap="square"'
    return attrs


def _polyline(x: np.ndarray, y: np.ndarray, attrs: str) -> str:
    """A curve as one path, broken where a value is not finite: each run starts with an absolute
    move (``M``), then relative lines (``l``) between the points rounded to 0.1 pt (a thirtieth of
    a millimetre in print). The steps are differences of rounded values, so they add up to the
    rounded points exactly, and the path is about half the size of absolute coordinates."""
    xs = np.round(np.asarray(x, dtype=float) * 10)
    ys = np.round(np.asarray(y, dtype=float) * 10)
    parts: list[str] = []
    last = None
    for px, py in zip(xs.tolist(), ys.tolist()):
        if not (math.isfinite(px) and math.isfinite(py)):
            last = None
            continue
        if last is None:
            parts.append(f"M{_tenths(px)} {_tenths(py)}l")
        else:
            parts.append(f"{_tenths(px - last[0])} {_tenths(py - last[1])}")
        last = (px, py)
    d = " ".join(parts).replace("l ", "l").replace(" M", "M")
    d = re.sub(r"l(?=M|$)", "", d)
    return f'<path d="{d}" {attrs}/>' if parts else ""


def _tenths(v: float) -> str:
    """A coordinate in tenths of a point as a number of points: 1234 -> 123.4, -5 -> -0.5, 30 -> 3."""
    v = int(v)
    sign, v = ("-" if v < 0 else ""), abs(v)
    return f"{sign}{v // 10}" + (f".{v % 10}" if v % 10 else "")


def panels_svg(panels: list, prefix: str, styles, marks: list | None = None, columns: int = 3,
               cell: tuple | None = None, legend_font: float = LEGEND_FONT, notes: list | tuple = ()) -> str:
    """The SVG of :func:`balpipe.draw.figures.panels_figure`: ``panels`` (title, y label, curves),
    curves (label, t, values or None) one per stage, stage k drawn in ``styles(k)`` (a
    matplotlib line style dict: color, linestyle, linewidth); every element's id prefixed with
    ``prefix`` (several figures in one page), each panel a group ``{prefix}-axes_{n}``."""
    lay = layout(panels, columns, marks, styles, cell, legend_font, notes)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" width="{_fmt(lay.width)}pt" height="{_fmt(lay.height)}pt" '
           f'viewBox="0 0 {_fmt(lay.width)} {_fmt(lay.height)}" version="1.1">',
           f'<g id="{prefix}-figure_1">',
           f'<rect x="0" y="0" width="{_fmt(lay.width)}" height="{_fmt(lay.height)}" fill="#ffffff"/>']
    cols = max(1, min(columns, len(panels)))
    if not panels:
        out.append(_frame(Panel("", "", []), lay.areas[0], *lay.axes[0], True, prefix, 1, styles, []))
    for n, panel in enumerate(panels):
        low = n + cols >= len(panels)
        out.append(_frame(Panel(*panel), lay.areas[n], *lay.axes[n], low, prefix, n + 1, styles,
                          sorted(set(marks or []))))
    for x, y, line in lay.notes:
        out.append(_text(x, y, line, NOTE_FONT, "start", ' fill="#404040"'))
    if lay.legend is not None:
        out.append(_legend_svg(lay, prefix))
    out.append("</g>\n</svg>\n")
    return "\n".join(out)


def _frame(panel: Panel, box: Box, xa: Axis, ya: Axis, low: bool, prefix: str, n: int, styles,
           marks: list) -> str:
    """One panel: grid, curves, marks, spines, ticks and texts."""
    g = [f'<g id="{prefix}-axes_{n}">']
    grid = f'stroke="{GRID}" stroke-opacity="0.3" stroke-width="{LINE_W}"'
    tick = f'stroke="#000000" stroke-width="{LINE_W}"'
    for t in xa.ticks:
        px = _fmt(_px(t, xa, box.x0, box.x1))
        g.append(f'<path d="M{px} {_fmt(box.y1)}V{_fmt(box.y0)}" {grid}/>')
    for t in ya.ticks:
        py = _fmt(_px(t, ya, box.y1, box.y0))
        g.append(f'<path d="M{_fmt(box.x0)} {py}H{_fmt(box.x1)}" {grid}/>')
    columns = int(COLUMNS_PER_PT * (box.x1 - box.x0))
    drawn = [(k, c, curve_style(c, k, styles)) for k, c in enumerate(panel.curves) if c[2] is not None]
    for k, curve, st in sorted(drawn, key=lambda d: d[2].get("zorder", 2.0)):  # a wide line under the thin ones
        t0, y0 = np.asarray(curve[1], dtype=float), np.asarray(curve[2], dtype=float)
        t, y = decimate(t0, y0, xa.lo, xa.hi, columns)
        g.append(_polyline(_px(t, xa, box.x0, box.x1), _px(y, ya, box.y1, box.y0), _line_attrs(st)))
        if st.get("marker"):  # at matplotlib's markevery (start, every) of the samples
            start, every = st.get("markevery", (0, 1))
            g += _markers(_px(t0[start::every], xa, box.x0, box.x1), _px(y0[start::every], ya, box.y1, box.y0), st,
                          prefix)
    for tm, text in marks:
        px = _px(tm, xa, box.x0, box.x1)
        g.append(f'<path d="M{_fmt(px)} {_fmt(box.y1)}V{_fmt(box.y0)}" stroke="#666666" stroke-width="0.9" '
                 f'stroke-dasharray="0.9,1.49"/>')
        g.append(_text(0, 0, text, MARK_FONT, "end",
                       f' transform="translate({_fmt(px - 1.0)} {_fmt(box.y0)}) rotate(-90)"'))
    g.append(f'<path d="M{_fmt(box.x0)} {_fmt(box.y0)}V{_fmt(box.y1)}H{_fmt(box.x1)}" fill="none" {tick} '
             f'stroke-linecap="square"/>')
    fh = text_size("0", FONT)[1]
    for t, s in zip(ya.ticks, ya.labels):
        py = _px(t, ya, box.y1, box.y0)
        g.append(f'<path d="M{_fmt(box.x0 - TICK)} {_fmt(py)}H{_fmt(box.x0)}" {tick}/>')
        g.append(_text(box.x0 - TICK - TICK_PAD, py + 0.35 * fh, s, FONT, "end"))
    for t, s in zip(xa.ticks, xa.labels):
        px = _px(t, xa, box.x0, box.x1)
        g.append(f'<path d="M{_fmt(px)} {_fmt(box.y1)}V{_fmt(box.y1 + TICK)}" {tick}/>')
        if low:
            g.append(_text(px, box.y1 + TICK + TICK_PAD + 0.8 * fh, s, FONT))
    if ya.offset:
        g.append(_text(box.x0, box.y0 - 2.0, ya.offset, FONT, "start"))
    if xa.offset and low:
        g.append(_text(box.x1, box.y1 + TICK + TICK_PAD + 2.0 * fh, xa.offset, FONT, "end"))
    mid = 0.5 * (box.x0 + box.x1)
    if panel.title:
        g.append(_text(mid, box.y0 - TITLE_PAD - 0.25 * fh, panel.title, TITLE_FONT))
    if panel.ylabel:
        wide = max([text_size(s, FONT)[0] for s in ya.labels] + [0.0])
        x = box.x0 - TICK - TICK_PAD - wide - LABEL_PAD - 0.25 * fh
        g.append(_text(0, 0, panel.ylabel, FONT, "middle",
                       f' transform="translate({_fmt(x)} {_fmt(0.5 * (box.y0 + box.y1))}) rotate(-90)"'))
    if low and panel.title:
        g.append(_text(mid, box.y1 + TICK + TICK_PAD + fh + LABEL_PAD + 0.8 * fh, "time (s)", FONT))
    g.append("</g>")
    return "\n".join(x for x in g if x)


def _legend_svg(lay: Layout, prefix: str) -> str:
    """The legend: a line sample in the curve's style (with one marker, if it has markers) and the
    label, column by column."""
    box = lay.legend
    fs = lay.legend_font
    fh = text_size("0", fs)[1]
    g = [f'<g id="{prefix}-legend_1">']
    x = box.x0 + 0.4 * fs
    for col in _legend_columns(lay.entries, lay.legend_cols):
        y = box.y0 + 0.4 * fs
        for label, st in col:
            mid = y + 0.5 * fh
            g.append(f'<path d="M{_fmt(x)} {_fmt(mid)}H{_fmt(x + 2.0 * fs)}" {_line_attrs(st)}/>')
            if st.get("marker"):
                g += _markers(np.array([x + fs]), np.array([mid]), st, prefix)
            g.append(_text(x + 2.8 * fs, mid + 0.35 * fh, label, fs, "start"))
            y += fh + 0.5 * fs
        x += 2.8 * fs + max(text_size(label, fs)[0] for label, _ in col) + 2.0 * fs
    g.append("</g>")
    return "\n".join(g)


@lru_cache(maxsize=64)
def marker_path(marker: str, size: float) -> str:
    """SVG path data of a matplotlib marker ``size`` pt wide, centred on (0, 0), y down: the
    marker's own path (:class:`matplotlib.markers.MarkerStyle`), so every shape is matplotlib's."""
    from matplotlib.markers import MarkerStyle
    from matplotlib.path import Path
    from matplotlib.transforms import Affine2D

    ms = MarkerStyle(marker)
    path = ms.get_path().transformed(ms.get_transform() + Affine2D().scale(size, -size))
    out = []
    for verts, code in path.iter_segments(simplify=False, curves=True):
        pts = " ".join(f"{_fmt(v)}" for v in verts)
        out.append({Path.MOVETO: "M", Path.LINETO: "L", Path.CURVE3: "Q", Path.CURVE4: "C"}.get(code, "Z")
                   + ("" if code == Path.CLOSEPOLY else pts))
    return "".join(out)


def _markers(x: np.ndarray, y: np.ndarray, st: dict, prefix: str) -> list[str]:
    """Markers of style ``st`` (marker, markersize, hollow: facecolor none) at (x, y), each a
    ``<use>`` of one definition, as matplotlib writes them."""
    d = marker_path(st["marker"], float(st.get("markersize", 6.0)))
    colour = _colour(st["color"])
    face = st.get("markerfacecolor", st["color"])
    fill = "none" if face == "none" else _colour(face)
    ident = f"{prefix}-m{zlib.crc32((d + colour + fill).encode()):08x}"
    out = [f'<defs><path id="{ident}" d="{d}" fill="{fill}" stroke="{colour}" stroke-width="1"/></defs>']
    out += [f'<use xlink:href="#{ident}" href="#{ident}" x="{_fmt(a)}" y="{_fmt(b)}"/>'
            for a, b in zip(x.tolist(), y.tolist()) if math.isfinite(a) and math.isfinite(b)]
    return out
