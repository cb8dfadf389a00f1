"""A page's time-series figure (``balpipe.draw.live.Curves``, what the page plots
interactively) drawn as a matplotlib figure: a panel per quantity, a curve per stage in the
page's line styles (``balpipe.draw.figures.style``)."""

from __future__ import annotations

import re
from typing import TYPE_CHECKING

import numpy as np

from ..draw import figures
from ..draw.live import Curves

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def matplotlib_figure(c: Curves, title: str = ""):
    """The figure of ``c``: its panels stacked, each with its title and axis label, every stage's
    curve (at every sample, not thinned as on the page) and the marks as dotted vertical lines.
    Drawn with matplotlib's object API (no pyplot: no window and no global state)."""
    from matplotlib.figure import Figure

    n = len(c.panels)
    fig = Figure(figsize=(7.0, 1.9 * n + 0.8), layout="constrained")
    axes = fig.subplots(n, 1, sharex=True, squeeze=False)[:, 0]
    t = np.asarray(c.t, dtype=float)
    styles = c.styles if c.styles is not None else list(range(len(c.stages)))
    for ax, panel in zip(axes, c.panels):
        for (label, values), st in zip(c.stages, styles):
            if panel["key"] not in values:
                continue
            kw = figures.style(st) if isinstance(st, int) else dict(st)
            ax.plot(t, np.asarray(values[panel["key"]], dtype=float), label=label, **kw)
        for when, what in c.marks:
            ax.axvline(when, color="0.5", linestyle=":", linewidth=0.8)
        ax.set_title(panel["title"], fontsize=9, loc="left")
        ax.set_ylabel(panel.get("axis", ""), fontsize=8)
        ax.grid(True, linewidth=0.3)
    axes[-1].set_xlabel(c.x_axis or "time (s)")
    if c.stages:
        axes[0].legend(fontsize=7, loc="best")
    if title:
        fig.suptitle(title, fontsize=10)
    return fig


_ATTR = re.compile(r'([\w-]+)="([^"]*)"')


def _attrs(text: str) -> dict[str, str]:
    return dict(_ATTR.findall(text))


def _paint(a: dict[str, str]) -> dict:
    """matplotlib keywords of a patch from SVG paint attributes (:func:`balpipe.draw.canvas._paint`'s)."""
    fill, edge = a.get("fill", "none"), a.get("stroke")
    out: dict = {"facecolor": "none" if fill == "none" else fill, "edgecolor": edge or "none",
                 "linewidth": float(a.get("stroke-width", 0) or 0)}
    alpha = a.get("fill-opacity") or a.get("stroke-opacity")
    if alpha:
        out["alpha"] = float(alpha)
    return out


def draw_panel(ax, panel) -> None:
    """The items and names of a laid-out :class:`balpipe.draw.canvas.Panel` on the matplotlib
    axes ``ax``, in model coordinates and drawing order (lines, discs, polygons, markers; the
    names where the page places them), equal aspect, the panel's view."""
    from matplotlib.patches import Circle, Polygon

    for z, kind, p in sorted(panel.items, key=lambda item: item[0]):
        if kind == "line":
            xy, style, _ = p
            a = _attrs(style)
            width = float(a.get("stroke-width", 1.5))
            kw: dict = {"color": a.get("stroke", "black"), "linewidth": width, "zorder": z,
                        "alpha": float(a.get("stroke-opacity", 1.0)),
                        "solid_capstyle": "projecting" if a.get("stroke-linecap") == "square" else "butt"}
            if "stroke-dasharray" in a:
                kw["dashes"] = [float(d) / width for d in a["stroke-dasharray"].split(",")]
            ax.plot(xy[:, 0], xy[:, 1], **kw)
        elif kind == "circle":
            c, r, paint = p
            ax.add_patch(Circle(tuple(c), r, zorder=z, **_paint(_attrs(paint))))
        elif kind == "polygon":
            xy, paint = p
            ax.add_patch(Polygon(xy, closed=True, zorder=z, **_paint(_attrs(paint))))
        else:
            (x, y), shape, size, face, edge, width = p
            ax.plot([x], [y], marker=shape, markersize=size, markerfacecolor=face, markeredgecolor=edge,
                    markeredgewidth=width, linestyle="none", zorder=z)
    if panel.view is not None and panel.box is not None:
        x0, y0, x1, y1 = panel.view
        s = panel.scale
        for lb in panel.labels:  # layout points back to the model's coordinates
            x, y = x0 + (lb.centre[0] - panel.box[0]) / s, y0 + (lb.centre[1] - panel.box[1]) / s
            ax.text(x, y, str(lb.text), ha="center", va="center", fontsize=lb.size, color=lb.color,
                    style=lb.style, weight=lb.weight, zorder=10,
                    bbox={"facecolor": "white", "edgecolor": "none", "pad": 0.5, "alpha": 0.85})
        ax.set_xlim(x0, x1)
        ax.set_ylim(y0, y1)
    ax.set_aspect("equal")
    ax.set_title(panel.title, fontsize=9)
    ax.set_xlabel(panel.xlabel, fontsize=8)
    ax.set_ylabel(panel.ylabel, fontsize=8)


def mechanism_figure(study, names) -> "Figure":
    """The page's drawings of the mechanism (one panel per shown stage: the solid pose at t = 0,
    the extreme poses as ghosts, the points' paths, the parts' names), as a matplotlib figure:
    the very drawings of the page (:func:`balpipe.draw.figures.mechanism_drawing` with
    :func:`balpipe.report.page.drawing_settings`), drawn by matplotlib."""
    from matplotlib.figure import Figure

    from ..draw.figures import mechanism_drawing
    from ..report.page import drawing_settings, shown_stages

    shown = shown_stages(study)
    settings = drawing_settings(study, names)
    fig = Figure(figsize=(6.0, 4.6 * len(shown)), layout="constrained")
    axes = fig.subplots(len(shown), 1, squeeze=False)[:, 0]
    for ax, s in zip(axes, shown):
        canvas, _ = mechanism_drawing(s.stage.model, s.analysis, title=s.stage.label, **settings)
        draw_panel(ax, canvas.panels[0])
    return fig
