"""The curves of a page's generic time-series figures (shaking loads, actuator efforts, joint
loads, and the simulation's residuals, tracking errors and free-frame drift) for the interactive
plots of :mod:`balpipe.draw.live`: a builder per figure kind (:func:`loads`, :func:`efforts`,
:func:`joints`, :func:`residuals`, :func:`tracking`, :func:`drift`), each giving its
:class:`~balpipe.draw.live.Curves`. The browser draws them: no matplotlib (as matplotlib figures, the
three simulation figures were 13.5 s of a build of specs/).
"""

from __future__ import annotations

import numpy as np

from ..display import numbers
from ..draw import figures
from ..draw.live import Curves
from ..draw.stage_names import short_names
from .results import joint_load_series


#: the shaking loads' panels: key, title, axis, the values of a force (N, 2) and moment (N,)
LOADS = (("Fx", "shaking force Fx (N)", "Fx (N)", lambda F, M: F[:, 0]),
         ("Fy", "shaking force Fy (N)", "Fy (N)", lambda F, M: F[:, 1]),
         ("F", "shaking force |F| (N)", "|F| (N)", lambda F, M: np.hypot(F[:, 0], F[:, 1])),
         ("M", "shaking moment M (N m)", "M (N m)", lambda F, M: M))


def loads(stages: list, sims: list | None = None, names: list[str] | None = None) -> Curves:
    """``stages``: (label, analysis), stage k in line style k with its staggered markers
    (paper 000 Fig. 4 style), named ``names[k]`` in the legend (short names; default
    :func:`balpipe.draw.stage_names.short_names`); ``sims``: each stage's pymunk run (t, F, M)
    on the analysis's samples, or None: drawn dotted in :data:`balpipe.draw.figures.SIM_COLORS`,
    hidden until the figure's toggle shows them. Panels Fx, Fy, |F| (N) and M (N m)
    (:data:`LOADS`)."""
    names = list(names) if names else short_names([label for label, _ in stages])
    curves = [(label, {key: fn(an.force, an.moment) for key, _, _, fn in LOADS}) for label, an in stages]
    styles: list = list(range(len(stages)))
    shown = list(names)
    simulated = []
    for k, ((label, _), sim) in enumerate(zip(stages, sims or [])):
        if sim is not None:
            simulated.append(len(curves))
            curves.append((f"{label} (pymunk)", {key: fn(sim[1], sim[2]) for key, _, _, fn in LOADS}))
            shown.append(f"{names[k]} (pymunk)")
            styles.append({"color": figures.SIM_COLORS[k % len(figures.SIM_COLORS)], "linestyle": ":", "linewidth": 1.0})
    return Curves(stages[0][1].t, curves, [{"key": key, "title": title, "axis": axis} for key, title, axis, _ in LOADS],
                  [], styles=styles, markers=True, names=tuple(shown), simulated=tuple(simulated))


def coincide_notes(stages: list) -> list[str]:
    """'Coincide in force Fx, force |F|: a = b' per group of stages whose loads agree within 1e-6 of a
    panel's largest value (:func:`balpipe.draw.figures.coinciding`), with the panels where they
    do; ``stages``: (label, analysis)."""
    return coincide_in([(title.split(" (")[0].replace("shaking ", ""), [(label, fn(an.force, an.moment))
                                                                         for label, an in stages])
                        for _, title, _, fn in LOADS])


def coincide_in(panels: list[tuple[str, list[tuple[str, np.ndarray]]]], log: bool = False) -> list[str]:
    """'Coincide in a, b: x = y' per group of curves that agree (:func:`balpipe.draw.figures.coinciding`,
    ``log``: sample by sample, as on a logarithmic axis), with the panels where they do; ``panels``:
    (name, its curves as (label, values))."""
    notes: dict[str, list[str]] = {}
    for name, curves in panels:
        same = figures.coinciding(curves, log=log)
        if same:
            notes.setdefault("; ".join(same), []).append(name)
    return [f"Coincide in {', '.join(where)}: {groups}" for groups, where in notes.items()]


def residual_notes(c: Curves) -> list[str]:
    """:func:`coincide_in` for the residual figure (:func:`residuals`): stages whose residuals
    agree at every sample draw one curve over the other, and the page says which."""
    return coincide_in([(p["title"].split(" |")[0].lower(), [(label, curves[p["key"]]) for label, curves in c.stages])
                        for p in c.panels], log=True)


def efforts(stages: list, units: dict, marks: list | None = None, shown: dict | None = None,
            names: list[str] | None = None) -> Curves:
    """``stages``: (label, analysis), named ``names`` in the legend; ``units``: driver -> 'N m' or
    'N'; ``shown``: driver -> the name its panel shows (the paper's symbol). A panel per driver:
    its actuator's torque or force (its axis label: :func:`balpipe.draw.figures.effort_axis`)."""
    drivers = sorted({n for _, an in stages for n in an.efforts})
    panels = [{"key": n, "title": f"actuator effort: {(shown or {}).get(n, n)}" + (f" ({units[n]})" if units.get(n) else ""),
               "axis": figures.effort_axis(units.get(n, ""))} for n in drivers]
    return Curves(stages[0][1].t, [(label, an.efforts) for label, an in stages], panels, list(marks or []),
                  names=tuple(names or ()), markers=True)


#: a joint figure of more panels than this shows one joint at a time, with a selector
MANY_JOINTS = 6


def joints(stages: list, shown: dict | None = None, names: list[str] | None = None) -> Curves:
    """``stages``: (label, analysis), named ``names`` in the legend; ``shown``: a joint's name in the panel titles (the paper's
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
    return Curves(stages[0][1].t, curves, ordered, [], choose=choose, names=tuple(names or ()), markers=True)


def largest_load(panels: list[dict], curves: list, units: dict[str, str]) -> int:
    """The panel of the largest peak over every stage among the forces (N: bearing loads, normal
    forces, tooth forces, the loads the joint-load table compares), else among every panel: the
    joint a reader looks at first. The first such panel on a tie."""
    def peak(key: str) -> float:
        return max((float(np.max(np.abs(c[key]))) for _, c in curves if key in c), default=0.0)

    forces = [i for i, p in enumerate(panels) if units[p["key"]] == "N"] or list(range(len(panels)))
    return max(forces, key=lambda i: (peak(panels[i]["key"]), -i))


#: where a reader without JavaScript finds the simulation figures' numbers
SIMULATED = 'its largest values are in the table above and in <a href="results.json">results.json</a>'


def residuals(rows: list, styles: list[int] | None = None, names: list[str] | None = None) -> Curves:
    """|F_sim − F_analytic| / F_ref and |M_sim − M_analytic| / M_ref over time, a curve per
    simulated stage on a log axis; ``rows``: (label, t, force error (N,), moment error (N,),
    F_ref, M_ref) of :func:`balpipe.report.page.residual_rows`, each stage divided by its own
    reference. One reference for every stage: the titles give it; several: each stage's legend
    entry does. A reference of 0 leaves the errors in N and N m. Each stage drawn in its line
    style on the page (``styles``: its index, :func:`balpipe.draw.figures.style`; default 0, 1,
    ...), named ``names`` (short names)."""
    one = len({(F0, M0) for *_, F0, M0 in rows}) == 1  # one reference for every stage: in the titles
    shorts = list(names) if names else short_names([r[0] for r in rows])
    curves, legend = [], []
    for k, (label, t, fe, me, F0, M0) in enumerate(rows):
        refs = "" if one else f" (F_ref {numbers.num(F0, 4)} N, M_ref {numbers.num(M0, 4)} N m)"
        curves.append((label + refs, {"force": fe / F0 if F0 > 0 else fe, "moment": me / M0 if M0 > 0 else me}))
        legend.append(shorts[k] + refs)
    F0, M0 = rows[0][4], rows[0][5]
    panels = [
        {"key": "force", "log": True,
         "title": "Force residual |F_sim − F_analytic|" + (f" / F_ref, F_ref = {numbers.num(F0, 4)} N" if F0 > 0 and one else
                                                            " / F_ref, F_ref per stage (legend)" if not one else " (N)"),
         "axis": "|ΔF| / F_ref" if F0 > 0 or not one else "|ΔF| (N)"},
        {"key": "moment", "log": True,
         "title": "Moment residual |M_sim − M_analytic|" + (f" / M_ref, M_ref = {numbers.num(M0, 4)} N m" if M0 > 0 and one else
                                                              " / M_ref, M_ref per stage (legend)" if not one else " (N m)"),
         "axis": "|ΔM| / M_ref" if M0 > 0 or not one else "|ΔM| (N m)"},
    ]
    return Curves(_common_t(r[1] for r in rows), curves, panels, [], styles=list(styles) if styles else None,
                  grid=True, names=tuple(legend), markers=True)


def tracking(t, curves: list[tuple[str, np.ndarray]], styles: list[int] | None = None) -> Curves:
    """The torque-driven runs' tracking errors: one curve per (stage: driver) of ``curves``
    (|q_sim − q_plan| / travel over ``t``), each in its stage's line style (``styles``: the
    index of :func:`balpipe.draw.figures.style`; default 0, 1, ...)."""
    return Curves(np.asarray(t, dtype=float), [(label, {"q": y}) for label, y in curves],
                  [{"key": "q", "title": "Tracking error of the torque-driven run", "axis": "|q_sim − q_plan| / travel"}], [],
                  styles=list(styles) if styles else None, markers=bool(styles))


def drift(runs: list, styles: list[int] | None = None, names: list[str] | None = None) -> Curves:
    """The free-floating frame: drift of its centre of mass (mm) and its rotation (deg) per
    stage; ``runs``: (label, t, drift (N, 2) in m, rotation (N,) in rad), each in its stage's
    line style on the page (``styles``: the index of :func:`balpipe.draw.figures.style`, as the
    page's key; default 0, 1, ...), named ``names`` (short names)."""
    curves = [(label, {"drift": 1000.0 * np.hypot(d[:, 0], d[:, 1]), "rotation": np.degrees(rot)})
              for label, _, d, rot in runs]
    panels = [{"key": "drift", "title": "Drift of the free frame (mm)", "axis": "drift (mm)"},
              {"key": "rotation", "title": "Rotation of the free frame (deg)", "axis": "rotation (deg)"}]
    return Curves(_common_t(r[1] for r in runs), curves, panels, [], grid=True,
                  styles=list(styles) if styles else None, names=tuple(names or ()), markers=True)


def _common_t(ts) -> np.ndarray:
    """The stages' common sample times: every simulation samples its stage's analysis grid, and
    a study's stages share one grid (the time column of timeseries.csv)."""
    ts = [np.asarray(t, dtype=float) for t in ts]
    if any(not np.array_equal(t, ts[0]) for t in ts[1:]):
        raise ValueError("the simulated stages do not share their sample times")
    return ts[0]
