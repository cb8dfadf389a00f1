"""Figures of a spec's history: its headline figures plotted against the commits that changed it,
as the pages' interactive plots (:mod:`balpipe.draw.live`: hover reads every stage's value at a
commit, drag zooms, a legend entry hides its curve).

The x axis is the commits' number, oldest first, as the history table numbers them (its rows
give each commit's hash, date, subject and the inputs it changed). A commit whose spec is invalid
or crashed has no value there (its marker is missing). Each stage keeps the line style and marker
it has on the study page's figures and key (its place in the stage table).
"""

from __future__ import annotations

import numpy as np

from ..draw.live import Curves

X_AXIS = "commit # (oldest first, as the table)"


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


def _commits_x(commits: list[dict]) -> np.ndarray:
    return np.arange(1, len(commits) + 1, dtype=float)


def _panels(commits: list[dict], stages: list[tuple[str, str]], panels: tuple[tuple[str, str, str], ...],
            first_style: int) -> Curves:
    """A panel per (results key, title, axis) of ``panels``: every stage's value per commit."""
    curves = [(label, {key: _series(commits, name, key) for key, _, _ in panels}) for name, label in stages]
    return Curves(_commits_x(commits), curves, [{"key": k, "title": t, "axis": ax} for k, t, ax in panels], [],
                  styles=[k + first_style for k in range(len(stages))], markers=True, x_axis=X_AXIS, grid=True)


def loads_history_figure(commits: list[dict]) -> Curves:
    """Peak shaking force |F| and moment |M| of every stage, per commit."""
    return _panels(commits, _stage_names(commits),
                   (("max_shaking_force", "peak shaking force |F| (N)", "|F| (N)"),
                    ("max_shaking_moment", "peak shaking moment |M| (N m)", "|M| (N m)")), 0)


def added_history_figure(commits: list[dict]) -> Curves:
    """Mass and rotating inertia that each balancing stage adds to the unbalanced mechanism."""
    names = _stage_names(commits)
    return _panels(commits, names[1:] or names,
                   (("added_mass", "added mass (kg)", "mass (kg)"), ("added_inertia", "added inertia (kg m²)",
                                                                      "inertia (kg m²)")), 1 if names[1:] else 0)


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


def parameters_history_figure(commits: list[dict]) -> Curves | None:
    """One panel per computed balancing parameter that changes along the history (its unit in
    the title); None when none changes."""
    params = changing_parameters(commits)[0]
    if not params:
        return None
    values = {}
    for name, _ in params:
        y = np.full(len(commits), np.nan)
        for i, c in enumerate(commits):
            for p in c.get("parameters") or []:
                if p["name"] == name and isinstance(p.get("value"), (int, float)):
                    y[i] = p["value"]
        values[name] = y
    panels = [{"key": name, "title": f"{name} ({unit.replace('^2', '²')})" if unit else name,
               "axis": f"{name} ({unit.replace('^2', '²')})" if unit else name} for name, unit in params]
    return Curves(_commits_x(commits), [("computed value", values)], panels, [], styles=[0], x_axis=X_AXIS,
                  grid=True)
