"""Drawings of mechanisms written straight to SVG, without a matplotlib figure: the look of the
report's other figures without the cost of building and serialising artists.

A report draws about a hundred mechanisms (the stages' poses, paper 001's topology panels); as
matplotlib figures each cost about 0.2 s, most of it in building and serialising artists. A
:class:`Canvas` holds equal-aspect :class:`Panel`\\ s of lines, discs, polygons, markers and named
labels in model coordinates and writes them as SVG in the look of the report's other figures:
DejaVu Sans text measured with matplotlib's font metrics (:func:`balpipe.draw.layout.text_metrics`),
ticks from matplotlib's locator (:class:`matplotlib.ticker.MaxNLocator`, as its ``AutoLocator``
chooses them), paths simplified by matplotlib's own path cleaner (what its SVG backend does),
grid, left and bottom spines, axis labels and a title. Units are points (1/72 in); a panel's
layout coordinates have y up (as matplotlib's display coordinates and :mod:`.labels`), flipped
only when written.

Same input, same bytes: every number is written rounded to 0.01 pt, elements in drawing order
(stable by z), ids prefixed so that several drawings can be inlined in one page.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass, field
from functools import lru_cache
from typing import Sequence

import numpy as np

from .layout import PAD, lines_size, text_metrics

FONT = "'DejaVu Sans', 'Bitstream Vera Sans', sans-serif"
TICK = 3.5  # tick length and label pad (pt), matplotlib's defaults
GRID = "#b0b0b0"
MARGIN = 0.05  # autoscaled view: the data and 5 % of its range on each side (matplotlib's margins)
DASHES = {"--": (3.7, 1.6), ":": (1.0, 1.65), "-.": (6.4, 1.6, 1.0, 1.6)}  # in line widths, as matplotlib scales them


@lru_cache(maxsize=256)
def colour(c: str) -> str:
    """A matplotlib colour ('tab:red', '0.85', 'black') as SVG hex."""
    from matplotlib.colors import to_hex

    return to_hex(c)


def num(v: float) -> str:
    """A coordinate as written: 0.01 pt, no trailing zeros, never '-0'."""
    s = f"{v:.2f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def tick_label(v: float, step: float) -> str:
    """A tick's label with the decimals its ``step`` needs (0.25 -> two), minus as U+2212."""
    decimals = max(0, -math.floor(math.log10(step) + 1e-9))
    mantissa = step / 10.0 ** math.floor(math.log10(step) + 1e-9)
    if abs(mantissa - 2.5) < 1e-6:
        decimals += 1
    s = f"{0.0 if abs(v) < 1e-9 * step else v:.{decimals}f}"
    return s.replace("-", "\u2212")


def ticks(lo: float, hi: float, length: float, size: float, per_label: float) -> list[float]:
    """The major ticks matplotlib's ``AutoLocator`` draws on an axis of ``length`` pt from ``lo`` to
    ``hi``: at most one per ``per_label`` font sizes (3 on x, 2 on y), at most 9 intervals, steps of
    1, 2, 2.5 or 5 times a power of ten; those inside the view."""
    from matplotlib.ticker import MaxNLocator

    nbins = max(1, min(int(length // (size * per_label)), 9))
    values = MaxNLocator(nbins=nbins, steps=[1, 2, 2.5, 5, 10]).tick_values(lo, hi)
    tol = 1e-9 * (hi - lo)
    return [float(v) for v in values if lo - tol <= v <= hi + tol]


def _style(color: str, width: float, alpha: float, dash: str | None, cap: str) -> str:
    out = f'fill="none" stroke="{colour(color)}" stroke-width="{num(width)}"'
    if alpha < 1.0:
        out += f' stroke-opacity="{alpha:.3g}"'
    if dash in DASHES:
        out += f' stroke-dasharray="{",".join(num(d * width) for d in DASHES[dash])}"'
    out += f' stroke-linecap="{cap}"' if cap != "butt" else ""
    return out + (' stroke-linejoin="round"' if cap == "round" else "")


def _paint(fill: str | None, edge: str | None, width: float, alpha: float) -> str:
    out = f'fill="{colour(fill)}"' if fill is not None else 'fill="none"'
    if fill is not None and alpha < 1.0:
        out += f' fill-opacity="{alpha:.3g}"'
    if edge is not None:
        out += f' stroke="{colour(edge)}" stroke-width="{num(width)}"'
        out += f' stroke-opacity="{alpha:.3g}"' if alpha < 1.0 else ""
    return out


@dataclass(frozen=True)
class Label:
    """A name drawn on a panel: its text centred on ``centre`` (layout pt), in a white box, with
    a grey leader line from ``anchor`` when displaced (:mod:`.labels`)."""

    text: str
    centre: tuple[float, float]
    anchor: tuple[float, float] | None
    size: float
    color: str = "black"
    style: str = "normal"
    weight: str = "normal"

    def box(self) -> tuple[float, float, float, float]:
        """The text's own box (layout pt), as measured."""
        w, h, _ = text_metrics(self.text, self.size, self.style, self.weight)
        return (self.centre[0] - 0.5 * w, self.centre[1] - 0.5 * h, self.centre[0] + 0.5 * w, self.centre[1] + 0.5 * h)


@dataclass
class Panel:
    """One equal-aspect drawing area: what is drawn on it, in model coordinates, then laid out
    by its :class:`Canvas` (:meth:`Canvas.layout`), which fixes :attr:`view` (model) and
    :attr:`box` (layout pt); :meth:`to_px` maps the one onto the other."""

    title: str = ""
    xlabel: str = "x (m)"
    ylabel: str = "y (m)"
    title_size: float = 9.0
    label_size: float = 9.0
    tick_size: float = 9.0
    limits: tuple[float, float, float, float] | None = None  # x0, y0, x1, y1; None: the data's
    items: list = field(default_factory=list)  # (z, kind, payload), in drawing order
    labels: list[Label] = field(default_factory=list)
    lo: list[float] = field(default_factory=lambda: [math.inf, math.inf])
    hi: list[float] = field(default_factory=lambda: [-math.inf, -math.inf])
    view: tuple[float, float, float, float] | None = None
    box: tuple[float, float, float, float] | None = None
    visible: bool = True

    # -- what is drawn (model coordinates) --------------------------------------------------

    def _extend(self, xy: np.ndarray, r: float = 0.0) -> None:
        if xy.size:
            self.lo = [min(self.lo[0], float(xy[:, 0].min()) - r), min(self.lo[1], float(xy[:, 1].min()) - r)]
            self.hi = [max(self.hi[0], float(xy[:, 0].max()) + r), max(self.hi[1], float(xy[:, 1].max()) + r)]

    def line(self, x: Sequence[float], y: Sequence[float], color: str, width: float = 1.5, alpha: float = 1.0,
             dash: str | None = None, cap: str = "square", z: float = 2.0, cls: str = "") -> None:
        """A polyline (matplotlib's ``plot``: 1.5 pt, projecting caps by default)."""
        xy = np.column_stack([np.asarray(x, dtype=float).ravel(), np.asarray(y, dtype=float).ravel()])
        self._extend(xy)
        self.items.append((z, "line", (xy, _style(color, width, alpha, dash, cap), cls)))

    def circle(self, centre: Sequence[float], r: float, fill: str | None = None, edge: str | None = None,
               width: float = 1.0, alpha: float = 1.0, z: float = 1.0) -> None:
        """A disc or circle of radius ``r`` in model units."""
        c = np.asarray(centre, dtype=float).reshape(1, 2)
        self._extend(c, r)
        self.items.append((z, "circle", (c[0], float(r), _paint(fill, edge, width, alpha))))

    def polygon(self, points: Sequence[Sequence[float]], fill: str | None = None, edge: str | None = None,
                width: float = 1.0, alpha: float = 1.0, z: float = 1.0) -> None:
        xy = np.asarray(points, dtype=float).reshape(-1, 2)
        self._extend(xy)
        self.items.append((z, "polygon", (xy, _paint(fill, edge, width, alpha))))

    def marker(self, x: float, y: float, shape: str, size: float, face: str = "black", edge: str | None = None,
               width: float = 1.0, z: float = 2.0) -> None:
        """A marker of ``size`` pt (matplotlib's ``markersize``) at a point: 'o', '^', 'x', '+' or '*'."""
        self.items.append((z, "marker", ((float(x), float(y)), shape, float(size), face, edge or face, width)))
        self._extend(np.array([[x, y]], dtype=float))

    def markers(self, xy: np.ndarray, shape: str, size: float, face: str = "black", edge: str | None = None,
                width: float = 1.0, z: float = 2.0) -> None:
        for x, y in np.asarray(xy, dtype=float).reshape(-1, 2):
            self.marker(x, y, shape, size, face, edge, width, z)

    # -- after layout -------------------------------------------------------------------------

    @property
    def scale(self) -> float:
        """Layout pt per model unit (the same on both axes)."""
        return (self.box[2] - self.box[0]) / (self.view[2] - self.view[0])

    def to_px(self, xy) -> np.ndarray:
        """Model coordinates -> layout pt (y up)."""
        a = np.asarray(xy, dtype=float)
        s = self.scale
        out = np.empty(a.shape[:-1] + (2,))  # np.stack's result without its overhead (23000 calls a build)
        out[..., 0] = self.box[0] + (a[..., 0] - self.view[0]) * s
        out[..., 1] = self.box[1] + (a[..., 1] - self.view[1]) * s
        return out

    def name(self, label: Label) -> None:
        """A name placed in layout pt (:func:`balpipe.draw.figures.place_items`)."""
        self.labels.append(label)

    # -- layout ---------------------------------------------------------------------------------

    def data_view(self) -> tuple[float, float, float, float]:
        if self.limits is not None:
            return tuple(float(v) for v in self.limits)
        lo, hi = self.lo, self.hi
        if not all(map(math.isfinite, lo + hi)):
            return (-1.0, -1.0, 1.0, 1.0)
        dx, dy = (hi[0] - lo[0]) or 1.0, (hi[1] - lo[1]) or 1.0
        return (lo[0] - MARGIN * dx, lo[1] - MARGIN * dy, hi[0] + MARGIN * dx, hi[1] + MARGIN * dy)

    def _margins(self, xt: list[float], yt: list[float], xstep: float, ystep: float) -> tuple[float, float, float, float]:
        """Left, right, bottom, top: what sticks out of the box (pt)."""
        yw = max([text_metrics(tick_label(v, ystep), self.tick_size)[0] for v in yt] + [0.0])
        xh = max([text_metrics(tick_label(v, xstep), self.tick_size)[1] for v in xt] + [0.0])
        left = yw + 2 * TICK + (lines_size(self.ylabel, self.label_size)[1] + 4.0 if self.ylabel else 0.0)
        bottom = xh + 2 * TICK + (lines_size(self.xlabel, self.label_size)[1] + 4.0 if self.xlabel else 0.0)
        top = lines_size(self.title, self.title_size)[1] + 6.0 if self.title else 0.0
        right = 0.5 * text_metrics(tick_label(xt[-1], xstep), self.tick_size)[0] if xt else 0.0
        return left, right, bottom, top

    def layout(self, cell: tuple[float, float, float, float], pad: float) -> None:
        """Fit the panel into ``cell`` (layout pt, y up) ``pad`` pt in from its edges: the largest
        equal-aspect box whose tick labels, axis labels and title fit, centred in what is left
        (matplotlib's adjustable 'box' with anchor 'C'); ticks chosen for the box's final size."""
        self.view = self.data_view()
        x0, y0, x1, y1 = self.view
        dx, dy = x1 - x0, y1 - y0
        cx0, cy0, cx1, cy1 = cell[0] + pad, cell[1] + pad, cell[2] - pad, cell[3] - pad
        w, h = cx1 - cx0, cy1 - cy0
        for _ in range(3):  # ticks -> margins -> box -> ticks: settles in two rounds
            xt, yt = self._ticks(w, h)
            left, right, bottom, top = self._margins(xt, yt, _step(xt), _step(yt))
            aw, ah = max(cx1 - cx0 - left - right, 1.0), max(cy1 - cy0 - bottom - top, 1.0)
            s = min(aw / dx, ah / dy)
            w, h = dx * s, dy * s
        bx = cx0 + left + 0.5 * (aw - w)
        by = cy0 + bottom + 0.5 * (ah - h)
        self.box = (bx, by, bx + w, by + h)

    def _ticks(self, w: float, h: float) -> tuple[list[float], list[float]]:
        x0, y0, x1, y1 = self.view
        return ticks(x0, x1, w, self.tick_size, 3.0), ticks(y0, y1, h, self.tick_size, 2.0)

    # -- writing ------------------------------------------------------------------------------

    def svg(self, height: float, clip: str) -> list[str]:
        """The panel's SVG elements (``height``: the canvas's, to flip y; ``clip``: the id of its
        clip path)."""
        if not self.visible:
            return []
        bx0, by0, bx1, by1 = self.box
        Y = lambda y: height - y  # noqa: E731
        xt, yt = self._ticks(bx1 - bx0, by1 - by0)
        xs, ys = _step(xt), _step(yt)
        out = [f'<clipPath id="{clip}"><rect x="{num(bx0)}" y="{num(Y(by1))}" width="{num(bx1 - bx0)}" '
               f'height="{num(by1 - by0)}"/></clipPath>']
        grid = [f"M{num(p[0])} {num(Y(by0))}V{num(Y(by1))}" for p in (self.to_px((v, self.view[1])) for v in xt)]
        grid += [f"M{num(bx0)} {num(Y(p[1]))}H{num(bx1)}" for p in (self.to_px((self.view[0], v)) for v in yt)]
        out.append(f'<path d="{"".join(grid)}" fill="none" stroke="{GRID}" stroke-width="0.8" stroke-opacity="0.3"/>')
        out.append(f'<g clip-path="url(#{clip})">')
        order = sorted(range(len(self.items)), key=lambda k: self.items[k][0])  # stable: drawing order within a z
        out += [self._item(self.items[k], Y) for k in order]
        out.append("</g>")
        # spines, ticks and their labels, axis labels, title
        out.append(f'<path d="M{num(bx0)} {num(Y(by1))}V{num(Y(by0))}H{num(bx1)}" fill="none" stroke="#000000" '
                   'stroke-width="0.8" stroke-linecap="square"/>')
        marks = [f"M{num(p[0])} {num(Y(by0))}v{num(TICK)}" for p in (self.to_px((v, self.view[1])) for v in xt)]
        marks += [f"M{num(bx0)} {num(Y(p[1]))}h{num(-TICK)}" for p in (self.to_px((self.view[0], v)) for v in yt)]
        out.append(f'<path d="{"".join(marks)}" stroke="#000000" stroke-width="0.8"/>')
        ts = self.tick_size
        for v in xt:
            x = self.to_px((v, self.view[1]))[0]
            _, th, d = text_metrics(tick_label(v, xs), ts)
            out.append(_text(tick_label(v, xs), x, Y(by0 - 2 * TICK - th + d), ts, "middle"))
        for v in yt:
            y = self.to_px((self.view[0], v))[1]
            _, th, d = text_metrics(tick_label(v, ys), ts)
            out.append(_text(tick_label(v, ys), bx0 - 2 * TICK, Y(y - 0.5 * th + d), ts, "end"))
        if self.xlabel:
            xh = max([text_metrics(tick_label(v, xs), ts)[1] for v in xt] + [0.0])
            _, lh, d = text_metrics(self.xlabel, self.label_size)
            out.append(_text(self.xlabel, 0.5 * (bx0 + bx1), Y(by0 - 2 * TICK - xh - 4.0 - lh + d), self.label_size,
                             "middle"))
        if self.ylabel:
            yw = max([text_metrics(tick_label(v, ys), ts)[0] for v in yt] + [0.0])
            _, lh, d = text_metrics(self.ylabel, self.label_size)
            x, y = bx0 - 2 * TICK - yw - 4.0 - lh + d, Y(0.5 * (by0 + by1))
            out.append(_text(self.ylabel, x, y, self.label_size, "middle", rotate=True))
        if self.title:
            lines = self.title.split("\n")
            base = by1 + 6.0
            for line in reversed(lines):
                _, lh, d = text_metrics(line or " ", self.title_size)
                out.append(_text(line, 0.5 * (bx0 + bx1), Y(base + d), self.title_size, "middle"))
                base += lh + 0.2 * self.title_size
        for lb in self.labels:
            out.append(_name(lb, Y))
        return out

    def _item(self, item: tuple, Y) -> str:
        _, kind, p = item
        if kind == "line":
            xy, style, cls = p
            d = _path(self.to_px(xy), Y)
            klass = f' class="{cls}"' if cls else ""
            return f'<path{klass} d="{d}" {style}/>' if d else ""
        if kind == "circle":
            c, r, paint = p
            q = self.to_px(c)
            return f'<circle cx="{num(q[0])}" cy="{num(Y(q[1]))}" r="{num(r * self.scale)}" {paint}/>'
        if kind == "polygon":
            xy, paint = p
            q = self.to_px(xy)
            pts = " ".join(f"{num(a)},{num(Y(b))}" for a, b in q)
            return f'<polygon points="{pts}" {paint}/>'
        (x, y), shape, size, face, edge, width = p
        q = self.to_px((x, y))
        return _marker(float(q[0]), float(Y(q[1])), shape, size, face, edge, width)


def _step(values: list[float]) -> float:
    return (values[1] - values[0]) if len(values) > 1 else (abs(values[0]) or 1.0) if values else 1.0


def _path(px: np.ndarray, Y) -> str:
    """A polyline in layout pt as SVG path data, simplified as matplotlib's backends simplify it
    (:meth:`matplotlib.path.Path.cleaned`: points within 1/9 pt of the line dropped)."""
    from matplotlib.path import Path

    if len(px) < 2:
        return ""
    cleaned = Path(px).cleaned(simplify=True)
    out = []
    for (x, y), code in zip(cleaned.vertices, cleaned.codes):
        if code == Path.STOP:
            break
        out.append(("M" if code == Path.MOVETO else "L") + f"{num(x)} {num(Y(y))}")
    return "".join(out)


def _marker(x: float, y: float, shape: str, size: float, face: str, edge: str, width: float) -> str:
    """A marker centred at SVG (x, y), ``size`` pt across as matplotlib draws it."""
    r = 0.5 * size
    paint = f'class="marker" fill="{colour(face)}" stroke="{colour(edge)}" stroke-width="{num(width)}"'
    if shape == "o":
        return f'<circle cx="{num(x)}" cy="{num(y)}" r="{num(r)}" {paint}/>'
    if shape == "^":
        pts = [(x, y - r), (x - r, y + r), (x + r, y + r)]
    elif shape == "*":
        pts = [(x + r * (1.0 if k % 2 == 0 else 0.381966) * math.sin(math.pi * k / 5),
                y - r * (1.0 if k % 2 == 0 else 0.381966) * math.cos(math.pi * k / 5)) for k in range(10)]
    else:  # 'x' and '+': strokes
        d = (f"M{num(x - r)} {num(y - r)}L{num(x + r)} {num(y + r)}M{num(x - r)} {num(y + r)}L{num(x + r)} {num(y - r)}"
             if shape == "x" else f"M{num(x - r)} {num(y)}H{num(x + r)}M{num(x)} {num(y - r)}V{num(y + r)}")
        return f'<path class="marker" d="{d}" fill="none" stroke="{colour(face)}" stroke-width="{num(width)}"/>'
    return f'<polygon points="{" ".join(f"{num(a)},{num(b)}" for a, b in pts)}" {paint}/>'


def _text(text: str, x: float, y: float, size: float, anchor: str, rotate: bool = False, extra: str = "") -> str:
    """Text whose baseline starts (anchor 'start'), centres ('middle') or ends ('end') at SVG (x, y)."""
    turn = f' transform="rotate(-90 {num(x)} {num(y)})"' if rotate else ""
    return (f'<text x="{num(x)}" y="{num(y)}" font-size="{num(size)}" text-anchor="{anchor}"{turn}{extra}>'
            f"{html.escape(text, quote=False)}</text>")


def _name(lb: Label, Y) -> str:
    """A placed name: its leader (when displaced), a white box a little larger than the text, the text."""
    x0, y0, x1, y1 = lb.box()
    out = ['<g class="name">']
    if lb.anchor is not None:
        out.append(f'<path d="M{num(lb.anchor[0])} {num(Y(lb.anchor[1]))}L{num(lb.centre[0])} {num(Y(lb.centre[1]))}" '
                   'stroke="#737373" stroke-width="0.6"/>')
    e = 0.05 * lb.size
    out.append(f'<rect x="{num(x0 - e)}" y="{num(Y(y1 + e))}" width="{num(x1 - x0 + 2 * e)}" height="{num(y1 - y0 + 2 * e)}" '
               'fill="#ffffff" fill-opacity="0.85"/>')
    _, h, d = text_metrics(lb.text, lb.size, lb.style, lb.weight)
    extra = (f' fill="{colour(lb.color)}"' + (' font-style="italic"' if lb.style == "italic" else "")
             + (' font-weight="bold"' if lb.weight == "bold" else ""))
    out.append(_text(lb.text, lb.centre[0], Y(lb.centre[1] - 0.5 * h + d), lb.size, "middle", extra=extra))
    out.append("</g>")
    return "".join(out)


class Canvas:
    """A drawing of ``width`` x ``height`` pt holding a grid of ``rows`` x ``cols`` panels."""

    def __init__(self, width: float, height: float, rows: int = 1, cols: int = 1):
        self.width, self.height, self.rows, self.cols = float(width), float(height), rows, cols
        self.panels = [Panel() for _ in range(rows * cols)]

    def layout(self, pad: float = PAD * 9.0) -> None:
        """Lay every panel out in its cell of the grid, ``pad`` pt in from the cell's edges."""
        cw, ch = self.width / self.cols, self.height / self.rows
        for k, p in enumerate(self.panels):
            r, c = divmod(k, self.cols)
            p.layout((c * cw, self.height - (r + 1) * ch, (c + 1) * cw, self.height - r * ch), pad)

    def svg(self, prefix: str) -> str:
        """The drawing as an SVG document (laid out first if it was not)."""
        if any(p.box is None for p in self.panels):
            self.layout()
        W, H = self.width, self.height
        out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{num(W)}pt" height="{num(H)}pt" '
               f'viewBox="0 0 {num(W)} {num(H)}" font-family="{FONT}" class="drawing">',
               f'<rect width="{num(W)}" height="{num(H)}" fill="#ffffff"/>']
        for k, p in enumerate(self.panels):
            out += p.svg(H, f"{prefix}-clip{k}")
        out.append("</svg>")
        return "\n".join(s for s in out if s) + "\n"
