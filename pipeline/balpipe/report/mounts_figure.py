"""The mounts' figure of a page, what balancing did to the floor: per mount, each stage's RMS
force on the floor, and per point, each stage's RMS vibration velocity (the larger of x and y,
mm/s) with the spec's limit, as grouped bars (from ``results.json``'s ``mounts``)."""

from __future__ import annotations

import numpy as np

from ..display.units import DisplayUnits
from ..draw import figures

_HATCHES = ("", "///", "...", "xxx", "\\\\\\")  # the stages' colours repeat: their bars differ by hatching


def _bars(ax, groups: list[str], rows: list[tuple[str, list[float]]]) -> None:
    """Grouped bars; values at round-off (at most 1e-9 of the largest) drawn as 0."""
    largest = max((v for _, values in rows for v in values), default=0.0)
    rows = [(label, [v if v > 1e-9 * largest else 0.0 for v in values]) for label, values in rows]
    width = 0.8 / len(rows)
    x = np.arange(len(groups))
    for j, (label, values) in enumerate(rows):
        ax.bar(x - 0.4 + (j + 0.5) * width, values, width, label=label, color=figures.style(j).get("color"),
               hatch=_HATCHES[j % len(_HATCHES)], edgecolor="white", linewidth=0.5)
    ax.set_xticks(x, groups)
    ax.grid(axis="y", alpha=0.3)
    positive = [v for _, values in rows for v in values if v > 0]
    if positive and max(positive) > 100 * min(positive):
        ax.set_yscale("log")


def mounts_svg(mounts: dict | None, stages: list[tuple[str, str]], units: DisplayUnits = DisplayUnits()) -> str:
    """An SVG of two bar charts from ``results.json``'s ``mounts`` for the (name, label) stages
    shown, the floor forces in the page's display ``units``; "" when the spec has no frame."""
    if not mounts or not stages:
        return ""
    fig, (left, right) = figures.plt.subplots(1, 2, figsize=(8.0, 3.0))
    names = [m["name"] for m in mounts["frame"]["mounts"]]
    per = units.factor("force")
    _bars(left, names, [(label, [m["rms"] / per for m in mounts["stages"][name]["mounts"]]) for name, label in stages])
    left.set_ylabel(f"RMS force on the floor ({units.unit('force')})")
    points = [p["name"] for p in mounts["stages"][stages[0][0]]["velocity"]]
    _bars(right, points, [(label, [1000 * max(p["rms_x"], p["rms_y"]) for p in mounts["stages"][name]["velocity"]])
                          for name, label in stages])
    right.set_ylabel("RMS velocity, larger of x, y (mm/s)")
    limit = mounts["limits"].get("velocity_rms")
    if limit is not None:
        right.axhline(1000 * limit, color="0.3", linestyle="--", linewidth=1)
    figures.legend_below(fig, left)
    return figures.to_svg(fig, "mounts")
