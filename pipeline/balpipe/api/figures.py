"""A page's time-series figure (``balpipe.draw.live.Curves``, what the page plots
interactively) drawn as a matplotlib figure: a panel per quantity, a curve per stage in the
page's line styles (``balpipe.draw.figures.style``)."""

from __future__ import annotations

import numpy as np

from ..draw import figures
from ..draw.live import Curves


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
