"""The curves of a page's generic time-series figures (shaking loads, actuator efforts, joint
loads) for the interactive plots of :mod:`balpipe.draw.live`: a builder per figure kind
(:func:`loads`, :func:`efforts`, :func:`joints`), each giving its :class:`~balpipe.draw.live.Curves`.
"""

from __future__ import annotations

import numpy as np

from ..draw import figures
from ..draw.live import Curves
from .results import joint_load_series


#: the shaking loads' panels: key, title, axis, the values of a force (N, 2) and moment (N,)
LOADS = (("Fx", "shaking force Fx (N)", "Fx (N)", lambda F, M: F[:, 0]),
         ("Fy", "shaking force Fy (N)", "Fy (N)", lambda F, M: F[:, 1]),
         ("F", "shaking force |F| (N)", "|F| (N)", lambda F, M: np.hypot(F[:, 0], F[:, 1])),
         ("M", "shaking moment M (N m)", "M (N m)", lambda F, M: M))


def loads(stages: list, sims: list | None = None) -> Curves:
    """``stages``: (label, analysis), stage k in line style k with its staggered markers
    (paper 000 Fig. 4 style); ``sims``: each stage's pymunk run (t, F, M) on the analysis's
    samples, or None: drawn dotted in :data:`balpipe.draw.figures.SIM_COLORS`. Panels Fx, Fy,
    |F| (N) and M (N m) (:data:`LOADS`)."""
    curves = [(label, {key: fn(an.force, an.moment) for key, _, _, fn in LOADS}) for label, an in stages]
    styles: list = list(range(len(stages)))
    for k, ((label, _), sim) in enumerate(zip(stages, sims or [])):
        if sim is not None:
            curves.append((f"{label} (pymunk)", {key: fn(sim[1], sim[2]) for key, _, _, fn in LOADS}))
            styles.append({"color": figures.SIM_COLORS[k % len(figures.SIM_COLORS)], "linestyle": ":", "linewidth": 1.0})
    return Curves(stages[0][1].t, curves, [{"key": key, "title": title, "axis": axis} for key, title, axis, _ in LOADS],
                  [], styles=styles, markers=True)


def coincide_notes(stages: list) -> list[str]:
    """'Coincide in force Fx, force |F|: a = b' per group of stages whose loads agree within 1e-6 of a
    panel's largest value (:func:`balpipe.draw.figures.coinciding`), with the panels where they
    do; ``stages``: (label, analysis)."""
    notes: dict[str, list[str]] = {}
    for key, title, _, fn in LOADS:
        same = figures.coinciding([(label, fn(an.force, an.moment)) for label, an in stages])
        if same:
            notes.setdefault("; ".join(same), []).append(title.split(" (")[0].replace("shaking ", ""))
    return [f"Coincide in {', '.join(where)}: {groups}" for groups, where in notes.items()]


def efforts(stages: list, units: dict, marks: list | None = None, shown: dict | None = None) -> Curves:
    """``stages``: (label, analysis); ``units``: driver -> 'N m' or 'N'; ``shown``: driver -> the
    name its panel shows (the paper's symbol). A panel per driver: its actuator's torque or force
    (its axis label: :func:`balpipe.draw.figures.effort_axis`)."""
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
