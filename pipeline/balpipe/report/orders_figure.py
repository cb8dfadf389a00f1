"""The orders' figure of a page: per order, each stage's peak shaking force of that order,
|F+| + |F-| (the largest magnitude of the order's force vector over a cycle, forward and
backward rotating components in phase), as grouped bars."""

from __future__ import annotations

import numpy as np

from ..display.units import DisplayUnits
from ..draw import figures

_HATCHES = ("", "///", "...", "xxx", "\\\\\\")  # the stages' colours repeat: their bars differ by hatching


def orders_svg(units: DisplayUnits, rows: list[tuple[str, dict]]) -> str:
    """An SVG bar chart of (stage label, the stage's ``orders`` entry of results.json) rows, its
    forces in the page's display ``units``; "" when there is nothing to draw."""
    if not rows:
        return ""
    fig, ax = figures.plt.subplots(figsize=(6.4, 2.8))
    n = max(len(o["orders"]) for _, o in rows)
    width = 0.8 / len(rows)
    for j, (label, o) in enumerate(rows):
        k = np.array([h["order"] for h in o["orders"]])
        peak = np.array([h["forward"]["amplitude"] + h["backward"]["amplitude"] for h in o["orders"]]) / units.factor("force")
        ax.bar(k - 0.4 + (j + 0.5) * width, peak, width, label=label, color=figures.style(j).get("color"),
               hatch=_HATCHES[j % len(_HATCHES)], edgecolor="white", linewidth=0.5)
    ax.set_xticks(range(1, n + 1))
    ax.set_xlabel("order (multiple of the cycle frequency)")
    ax.set_ylabel(f"peak force of the order ({units.unit('force')})")
    ax.grid(axis="y", alpha=0.3)
    figures.legend_below(fig, ax)
    return figures.to_svg(fig, "orders")
