"""Figures of a spec's history: its headline figures plotted against the commits that changed it.

The x axis is the sequence of commits, oldest left, labelled with their short hashes; the
history table of the page gives each commit's date and subject. A commit whose spec is invalid
or crashed has no point (a gap), and its label is red, as is the label of a commit whose spec
fails a check or the pymunk validation. The figures are drawn through the figure cache
(:mod:`balpipe.cache.figures`): a build re-renders a page's history section without redrawing them.
"""

from __future__ import annotations

import math

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from ..cache import figures as cache  # noqa: E402
from ..draw.figures import style, to_svg  # noqa: E402

MAX_LABELS = 16


def _stage_names(commits: list[dict]) -> list[tuple[str, str]]:
    """Every stage seen in the history, in order of first appearance: (name, label)."""
    out: dict[str, str] = {}
    for c in commits:
        for s in c.get("stages") or []:
            out.setdefault(s["name"], s["label"])
    return list(out.items())


def _series(commits: list[dict], stage: str, key: str) -> np.ndarray:
    y = np.full(len(commits), np.nan)
    for i, c in enumerate(commits):
        for s in c.get("stages") or []:
            if s["name"] == stage and isinstance(s.get(key), (int, float)):
                y[i] = s[key]
    return y


def flagged(commit: dict) -> bool:
    """A commit whose spec is invalid, crashed, fails a check or fails the validation."""
    return commit.get("status") != "ok" or commit.get("validation") == "fail"


def _commit_axis(ax, commits: list[dict]) -> None:
    n = len(commits)
    step = max(1, math.ceil(n / MAX_LABELS))
    ticks = list(range(0, n, step))
    if ticks[-1] != n - 1:
        ticks.append(n - 1)
    ax.set_xticks(ticks)
    ax.set_xticklabels([commits[i]["short"] for i in ticks], rotation=45, ha="right", fontsize=7,
                       fontfamily="DejaVu Sans Mono")
    for lab, i in zip(ax.get_xticklabels(), ticks):
        if flagged(commits[i]):
            lab.set_color("tab:red")
    ax.set_xlim(-0.5, n - 0.5)
    ax.set_xlabel("commit (oldest left)")
    for i, c in enumerate(commits):
        if c.get("status") in ("invalid", "crash"):
            ax.axvline(i, color="tab:red", linestyle=":", linewidth=0.8)


def _plot(ax, x, y, k: int, label: str) -> None:
    st = dict(style(k))
    st["linewidth"] = min(st["linewidth"], 1.6)
    ax.plot(x, y, marker="o", markersize=3.5, label=label, **st)


def _panels_figure(commits: list[dict], stages: list[tuple[str, str]], panels: tuple[tuple[str, str], ...],
                   height: float, first_style: int, prefix: str) -> str:
    """Two panels, one per (results key, title) in ``panels``: every stage's value per commit,
    one legend under both."""
    x = np.arange(len(commits))
    fig, axes = plt.subplots(1, 2, figsize=(9.0, height))
    for ax, (key, title) in zip(axes, panels):
        for k, (name, label) in enumerate(stages):
            _plot(ax, x, _series(commits, name, key), k + first_style, label)
        ax.set_title(title, fontsize=9)
        _commit_axis(ax, commits)
    handles, labels = axes[0].get_legend_handles_labels()
    if labels:
        fig.legend(handles, labels, loc="lower center", ncol=min(len(labels), 4), fontsize=8, frameon=False)
    fig.tight_layout(rect=(0, 0.08, 1, 1))
    return to_svg(fig, prefix)


def loads_history_figure(commits: list[dict], prefix: str = "hist-loads") -> str:
    """Peak shaking force |F| and moment |M| of every stage, per commit."""
    return cache.svg(_panels_figure, commits, _stage_names(commits),
                     (("max_shaking_force", "Peak shaking force |F| (N)"),
                      ("max_shaking_moment", "Peak shaking moment |M| (N m)")), 3.4, 0, prefix)


def added_history_figure(commits: list[dict], prefix: str = "hist-added") -> str:
    """Mass and rotating inertia that each balancing stage adds to the unbalanced mechanism."""
    return cache.svg(_panels_figure, commits, _stage_names(commits)[1:] or _stage_names(commits),
                     (("added_mass", "Added mass (kg)"), ("added_inertia", "Added inertia (kg m²)")),
                     3.2, 1, prefix)


def _parameters(commits: list[dict]) -> list[tuple[str, str]]:
    out: dict[str, str] = {}
    for c in commits:
        for p in c.get("parameters") or []:
            out.setdefault(p["name"], p.get("unit") or "")
    return list(out.items())


def changing_parameters(commits: list[dict]) -> tuple[list[tuple[str, str]], list[tuple[str, str, float]]]:
    """The computed parameters whose value differs between the commits that have figures
    (name, unit), and those that keep one value throughout (name, unit, value)."""
    changing, constant = [], []
    valid = [c for c in commits if c.get("parameters")]
    for name, unit in _parameters(commits):
        values = [next((p["value"] for p in c["parameters"] if p["name"] == name), None) for c in valid]
        if len(set(values)) > 1:
            changing.append((name, unit))
        elif values:
            constant.append((name, unit, values[0]))
    return changing, constant


def parameters_history_figure(commits: list[dict], prefix: str = "hist-params") -> str | None:
    """One small panel per computed balancing parameter that changes along the history (its
    unit in the title); None when none changes."""
    params = changing_parameters(commits)[0]
    if not params:
        return None
    return cache.svg(_parameters_figure, commits, params, prefix)


def _parameters_figure(commits: list[dict], params: list[tuple[str, str]], prefix: str) -> str:
    """:func:`parameters_history_figure` of the changing ``params`` (name, unit), drawn."""
    ncol = min(3, len(params))
    nrow = math.ceil(len(params) / ncol)
    fig, axes = plt.subplots(nrow, ncol, figsize=(3.0 * ncol + 0.4, 2.5 * nrow), squeeze=False)
    x = np.arange(len(commits))
    for ax, (name, unit) in zip(axes.flat, params):
        y = np.full(len(commits), np.nan)
        for i, c in enumerate(commits):
            for p in c.get("parameters") or []:
                if p["name"] == name and isinstance(p.get("value"), (int, float)):
                    y[i] = p["value"]
        ax.plot(x, y, marker="o", markersize=3.5, color="black", linewidth=1.2)
        ax.set_title(f"{name} ({unit.replace('^2', '²')})" if unit else name, fontsize=9)
        _commit_axis(ax, commits)
        ax.set_xlabel("")
    for ax in list(axes.flat)[len(params):]:
        ax.set_visible(False)
    fig.tight_layout()
    return to_svg(fig, prefix)
