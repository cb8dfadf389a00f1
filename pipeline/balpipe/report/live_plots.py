"""The curves of a page's generic time-series figures (shaking loads, actuator efforts, joint
loads) for the interactive plots of :mod:`balpipe.draw.live`: a builder per figure kind
(:func:`loads`, :func:`efforts`, :func:`joints`), each giving its :class:`~balpipe.draw.live.Curves`.
"""

from __future__ import annotations

import numpy as np

from ..draw import figures
from ..draw.live import Curves
from .results import joint_load_series


def loads(stages: list) -> Curves:
    """``stages``: (label, analysis). Panels |F| (N) and M (N m), from the analysis's shaking loads."""
    return Curves(stages[0][1].t, [(label, {"F": np.hypot(an.force[:, 0], an.force[:, 1]), "M": an.moment})
                                   for label, an in stages],
                  [{"key": "F", "title": "shaking force |F| (N)", "axis": "|F| (N)"},
                   {"key": "M", "title": "shaking moment M (N m)", "axis": "M (N m)"}], [])


def efforts(stages: list, units: dict, marks: list | None = None, shown: dict | None = None) -> Curves:
    """``stages``: (label, analysis); ``units``: driver -> 'N m' or 'N'; ``shown``: driver -> the
    name its panel shows (the paper's symbol). A panel per driver: its actuator's torque or force
    (as :func:`balpipe.draw.figures.efforts_figure`)."""
    names = sorted({n for _, an in stages for n in an.efforts})
    panels = [{"key": n, "title": f"actuator effort: {(shown or {}).get(n, n)}" + (f" ({units[n]})" if units.get(n) else ""),
               "axis": figures.effort_axis(units.get(n, ""))} for n in names]
    return Curves(stages[0][1].t, [(label, an.efforts) for label, an in stages], panels, list(marks or []))


def joints(stages: list) -> Curves:
    """``stages``: (label, analysis). A panel per joint load, as the rows of the joint-load table
    (:func:`balpipe.report.results.joint_load_series`: |F| of a revolute, |N| of a prismatic
    pair, |T|, |Ft|, Fr of a gear mesh)."""
    panels: dict[str, dict] = {}
    curves = []
    for label, an in stages:
        mine = {}
        for joint, comp, kind, unit, values in joint_load_series(an):
            key = f"{joint}.{comp}"
            mine[key] = values
            panels.setdefault(key, {"key": key, "title": f"{joint}, {kind} ({unit})",
                                    "axis": f"{comp if comp == 'Fr' else f'|{comp}|'} ({unit})"})
        curves.append((label, mine))
    return Curves(stages[0][1].t, curves, list(panels.values()), [])
