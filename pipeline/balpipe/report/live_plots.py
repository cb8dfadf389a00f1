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


#: a joint figure of more panels than this shows one joint at a time, with a selector
MANY_JOINTS = 6


def joints(stages: list, shown: dict | None = None) -> Curves:
    """``stages``: (label, analysis); ``shown``: a joint's name in the panel titles (the paper's
    symbol, :class:`balpipe.notation.Names`), else the model's. A panel per joint load, as the rows of the joint-load table
    (:func:`balpipe.report.results.joint_load_series`: |F| of a revolute, |N| of a prismatic
    pair, |T|, |Ft|, Fr of a gear mesh). With more than :data:`MANY_JOINTS` panels (the 30 of
    the Scott-Russell 3-RPR legs) the plot shows one at a time, first the largest load
    (:func:`largest_load`)."""
    panels: dict[str, dict] = {}
    units: dict[str, str] = {}
    curves = []
    for label, an in stages:
        mine = {}
        for joint, comp, kind, unit, values in joint_load_series(an):
            key = f"{joint}.{comp}"
            mine[key] = values
            units[key] = unit
            panels.setdefault(key, {"key": key, "title": f"{(shown or {}).get(joint, joint)}, {kind} ({unit})",
                                    "axis": f"{comp if comp == 'Fr' else f'|{comp}|'} ({unit})"})
        curves.append((label, mine))
    ordered = list(panels.values())
    choose = largest_load(ordered, curves, units) if len(ordered) > MANY_JOINTS else None
    return Curves(stages[0][1].t, curves, ordered, [], choose=choose)


def largest_load(panels: list[dict], curves: list, units: dict[str, str]) -> int:
    """The panel of the largest peak over every stage among the forces (N: bearing loads, normal
    forces, tooth forces, the loads the joint-load table compares), else among every panel: the
    joint a reader looks at first. The first such panel on a tie."""
    def peak(key: str) -> float:
        return max((float(np.max(np.abs(c[key]))) for _, c in curves if key in c), default=0.0)

    forces = [i for i, p in enumerate(panels) if units[p["key"]] == "N"] or list(range(len(panels)))
    return max(forces, key=lambda i: (peak(panels[i]["key"]), -i))
