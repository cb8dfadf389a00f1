"""The 3-RPR's report figures (paper 000): the shaking force and moment of every stage in the
paper's line styles (Figs. 4 and 8), the peaks and the moment factor, and the axial forces that
prismatic actuators would need."""

from __future__ import annotations

import numpy as np

from ...balancing.base import in_style_order, style_index
from ...display import numbers
from .template import pose_of, prismatic_equivalent


def _own(study) -> list:
    """The main design's stages (those of ``compare`` designs are shown in the generic "Designs
    side by side" table, not in the paper's figures)."""
    return [s for s in study.stages if s.stage.design is None]


def _stage(study, name: str):
    for s in _own(study):
        if s.stage.name == name:
            return s
    return None


def figures(study):
    """The template's figure: the axial forces that prismatic actuators would need, when the
    spec drives the revolutes."""
    if study.spec.mechanism.actuation == "revolute":
        yield _prismatic_forces_figure(study)


def paper_figures(number: str, linkage: str, published_factor: float):
    """The figures of one of the paper's methods (its :attr:`plugins.Method.figures`): the
    shaking force x, y and moment of every stage (``number``: Fig. 4 for the idler loop, Fig. 8
    for the Scott-Russell legs), in the paper's line styles, which are the stages' styles on the
    whole page (:data:`template.STYLES`: unbalanced solid, counterweights dashed, counter-rotations
    grey; the added-linkage stage ``linkage``, which the paper does not plot, blue dash-dot), and a
    table of the peaks and of the factor by which the counterweights raise the peak moment (the
    paper reports ``published_factor``)."""

    def figures(study):
        from ...draw import live

        panels = (("(a) shaking force along x (N)", lambda a: a.force[:, 0]),
                  ("(b) shaking force along y (N)", lambda a: a.force[:, 1]),
                  ("(c) shaking moment about O (N m)", lambda a: a.moment))
        own = in_style_order(_own(study))
        linkage_label = next((s.stage.label for s in own if s.stage.name == linkage), linkage)
        curves = live.Curves(own[0].analysis.t,
                             [(s.stage.label, {key: fn(s.analysis) for key, (_, fn) in zip("xyM", panels)}) for s in own],
                             [{"key": key, "title": title, "axis": axis}
                              for key, (title, _), axis in zip("xyM", panels, ("F_x (N)", "F_y (N)", "M (N m)"))], [],
                             styles=[style_index(study.stages, s) for s in own])
        yield (
            f"Shaking force and moment, every stage ({number} of paper 000)",
            live.html("rpr3-loads", curves),
            "The paper's line styles, which every figure of this page gives these stages: before (solid) and after "
            "(dashed) the counterweights, after the counter-rotations (grey); the stage with the "
            f"{linkage_label} but no counterweights, which the paper does not plot, is blue dash-dot. Moments about "
            "O, the base's circumcentre; loads that the moving links exert on the base.",
        )
        yield ("Peak loads and the moment factor", _factor_table(study, linkage), _factor_caption(published_factor))

    return figures


def _prismatic_forces_figure(study):
    mech = study.spec.mechanism
    pose = pose_of(study.unbalanced.stage.model)
    runs = []
    stages = (study.stages[0], _own(study)[-1])
    for s in stages:
        an = s.analysis
        tau = np.stack([an.efforts[f"theta{i}"] for i in (1, 2, 3)], axis=1)
        runs.append((s.stage.label, prismatic_equivalent(mech, pose, an.t, tau)))
    return (
        "Axial forces that prismatic actuators would need",
        prismatic_forces_html(study.stages[0].analysis.t, runs, [style_index(study.stages, s) for s in stages]),
        "The same motion driven by actuators at the prismatic pairs B_i instead of the revolutes A_i: "
        "J_p^T f = J_r^T tau (the same generalised force on the platform). Where the three leg lines meet "
        "in one point (a parallel singularity of prismatic actuation, at phi = 0 for a platform homothetic "
        "to the base) the forces are unbounded; samples there are left out.",
    )


def prismatic_forces_html(t: np.ndarray, runs: list[tuple[str, np.ndarray]], styles: list[int] | None = None) -> str:
    """|axial force| of each leg over time ``t`` on logarithmic axes, a panel per leg, a line per
    (stage label, forces (N, 3)), each in its stage's style on the page (``styles``: the index of
    :func:`balpipe.draw.figures.style`; default 0, 1, ...); drawn by the browser
    (:func:`balpipe.draw.live.html`, element ``#live-rpr3-prismatic``), no value where a force
    is unbounded (NaN) or zero."""
    from ...draw import live

    curves = live.Curves(t, [(label, {f"leg{i + 1}": np.abs(f[:, i]) for i in range(3)}) for label, f in runs],
                         [{"key": f"leg{i + 1}", "title": f"|axial force| of leg {i + 1} (N)",
                           "axis": f"|f{i + 1}| (N)", "log": True} for i in range(3)], [],
                         styles=list(styles) if styles else None, grid=True)
    return live.html("rpr3-prismatic", curves)


def _factor_table(study, linkage: str) -> str:
    rows = []
    unb = study.unbalanced.analysis
    for s in _own(study):
        an = s.analysis
        rows.append(
            f"<tr><td>{s.stage.label}</td><td>{numbers.num_at(an.max_force, unb.max_force, 6)}</td>"
            f"<td>{numbers.num_at(an.max_moment, unb.max_moment, 6)}</td>"
            f"<td>{numbers.num(s.max_effort, 6)}</td><td>{numbers.num(s.added_mass, 6)}</td><td>{numbers.num(s.added_inertia, 6)}</td></tr>"
        )
    from ...mechanics.drivers import driver_unit

    model = study.unbalanced.stage.model
    units = sorted({driver_unit(model, d.name) for d in model.drivers}) or ["N m or N"]
    head = ("<table><thead><tr><th>stage</th><th>max |F| (N)</th><th>max |M| (N m)</th>"
            f"<th>peak actuator effort ({' or '.join(units)})</th><th>added mass (kg)</th><th>added inertia (kg m²)</th>"
            "</tr></thead><tbody>")
    out = head + "".join(rows) + "</tbody></table>"
    cw, un, added = _stage(study, "counterweights"), study.unbalanced, _stage(study, linkage)
    if cw is not None:
        out += "<table><thead><tr><th>peak moment with counterweights relative to</th><th>factor</th></tr></thead><tbody>"
        for ref in (un, added):
            if ref is not None and ref.analysis.max_moment > 0:
                out += (f"<tr><td>{ref.stage.label} ({numbers.num(ref.analysis.max_moment, 6)} N m)</td>"
                        f"<td>{numbers.num(cw.analysis.max_moment / ref.analysis.max_moment)}</td></tr>")
        out += "</tbody></table>"
    return out


def _factor_caption(published_factor: float) -> str:
    return ("Peaks over the motion of every stage. The factor is the counterweights stage's peak shaking "
            f"moment divided by the reference stage's; the paper reports {published_factor:g} (the reference "
            "`counterweights.moment_ratio` compares it with the unbalanced 3-RPR).")


#: the figures of the two methods (their :attr:`plugins.Method.figures`, named by the family)
idler_loop_figures = paper_figures("Fig. 4", "idler_loop", 17)
scott_russell_figures = paper_figures("Fig. 8", "scott_russell", 28)
