"""The five-bar's report figures (paper 004): the gripper path (Fig. 7) and the input angles
(Figs. 8-9), drawn from the study's analyses; and paper 004's own panels on the page of every
spec that names the paper (:func:`paper_figures`, its :attr:`balpipe.plugins.Paper.own_figures`):
Figs. 10a, 10b, 11, 12, the shaking force along x and along y and the shaking moment (N m) of the
unbalanced manipulator, and the shaking moment after shaking force balancing."""

from __future__ import annotations

import numpy as np

from ...balancing.base import style_index
from ...draw import live
from .template import gripper_path, input_angles, segment_distance


def figures(study):
    """Report figures of the template: the gripper path (Fig. 7, drawn through the figure cache,
    :mod:`balpipe.cache.figures`) and the input angles (Figs. 8-9, drawn by the browser)."""
    from ...cache import figures as cache

    first = study.stages[0]
    an, model = first.analysis, first.stage.model
    C = gripper_path(an, model)
    S, E = C[0], C[-1]
    on_path = getattr(study.spec.motion.drive.get("gripper"), "law", None) == "path"  # balpipe.laws.paths
    dev = float(np.max(segment_distance(C, S, E)))
    coupled = model.name.startswith("fixed-sequence")
    yield (
        "Gripper path (Fig. 7)",
        cache.svg(path_svg, C, on_path),
        f"C(t) from the analysis, from ({S[0]:.4g}, {S[1]:.4g}) to ({E[0]:.4g}, {E[1]:.4g}) m; " + (
            "the path of motion.drive.gripper." if on_path else f"largest distance from the straight segment {1000 * dev:.3g} mm"
            + (" (the gear-coupled inputs do not keep the gripper on the segment)." if coupled else ".")),
    )
    th1, th2 = input_angles(an)
    yield (
        "Input angles (Figs. 8-9)",
        angles_html(an.t, th1, th2),
        "theta1 follows the motion law; theta2 follows it through gears 1', 5, 2' (theta2 - theta2i = "
        "U21 (theta1 - theta1i))." if coupled
        else f"Both inputs follow the inverse kinematics of the {'given' if on_path else 'straight'} path.",
    )


def path_svg(C: np.ndarray, on_path: bool) -> str:
    """The gripper path C (N, 2), its start (circle) and end (square), and the straight segment
    between them unless the motion is a path of its own (``on_path``)."""
    from ...draw.figures import plt, to_svg  # matplotlib only when a report is drawn
    from ...draw.layout import fixed_layout

    S, E = C[0], C[-1]
    fig, ax = plt.subplots(figsize=(5.6, 3.6))
    ax.plot(C[:, 0], C[:, 1], color="black", linewidth=1.4, label="gripper path")
    if not on_path:
        ax.plot([S[0], E[0]], [S[1], E[1]], color="0.6", linestyle="--", linewidth=1.0, label="straight segment")
    ax.plot([S[0]], [S[1]], "o", color="black", markersize=4)
    ax.plot([E[0]], [E[1]], "s", color="black", markersize=4)
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    ax.set_aspect("equal", adjustable="datalim")
    ax.legend(fontsize=7, loc="best")
    fixed_layout(fig)
    return to_svg(fig, "fivebar-path")


def angles_html(t: np.ndarray, th1: np.ndarray, th2: np.ndarray) -> str:
    """The two input angles over time ``t``, a panel each, in a black line; drawn by the browser
    (:func:`balpipe.draw.live.html`, element ``#live-fivebar-angles``)."""
    from ...draw import live

    curves = live.Curves(t, [("input angles", {"theta1": th1, "theta2": th2})],
                         [{"key": k, "title": f"{k} (rad)", "axis": f"{k} (rad)"} for k in ("theta1", "theta2")], [],
                         styles=[{"color": "black", "linestyle": "-", "linewidth": 1.4}], grid=True)
    return live.html("fivebar-angles", curves)


def series(t, curves: list[tuple[str, np.ndarray, int]], ylabel: str, prefix: str) -> str:
    """A time series in the page's stage styles: each curve (label, values, k) drawn in
    ``figures.style(k)``, k the stage's place in the page's stage table, so that one line style
    means one stage on the whole page; interactive, on screen and in print
    (:func:`balpipe.draw.live.html`, element ``#live-<prefix>``)."""
    curves_of = live.Curves(t, [(label, {"y": y}) for label, y, _ in curves],
                            [{"key": "y", "title": "", "axis": ylabel}], [], styles=[k for _, _, k in curves])
    return live.html(prefix, curves_of)


def style_of(study, stage) -> int:
    """The stage's style index on the page (:func:`balpipe.balancing.base.style_index`)."""
    return style_index(study.stages, stage)


def paper_figures(study) -> list[tuple[str, str, str]]:
    """Paper 004's Figs. 10a, 10b, 11 (the unbalanced manipulator) and 12 (the main design's
    force-balanced stage, when there is one), (title, html, caption), from the study's analyses."""
    un = study.unbalanced
    an = un.analysis
    force_only = next((s for s in study.stages if s.stage.balances == "force" and s.stage.design is None), None)
    k0 = style_of(study, un)
    out = [
        ("Fig. 10a of paper 004: shaking force along x (N)",
         series(an.t, [(un.stage.label, an.force[:, 0], k0)], "F_x (N)", "p004fig10a"),
         "The unbalanced manipulator, from the analysis of this spec."),
        ("Fig. 10b of paper 004: shaking force along y (N)",
         series(an.t, [(un.stage.label, an.force[:, 1], k0)], "F_y (N)", "p004fig10b"),
         "The unbalanced manipulator, from the analysis of this spec."),
        ("Fig. 11 of paper 004: shaking moment (N m)",
         series(an.t, [(un.stage.label, an.moment, k0)], "M (N m)", "p004fig11"),
         "The unbalanced manipulator, about the moment point of the spec."),
    ]
    if force_only is not None:
        a2 = force_only.analysis
        out.append(("Fig. 12 of paper 004: shaking moment after shaking force balancing (N m)",
                    series(a2.t, [(force_only.stage.label, a2.moment, style_of(study, force_only))], "M (N m)",
                           "p004fig12"),
                    f"Stage '{force_only.stage.label}' (force balanced by counterweights), in its line style of this "
                    "page: the moment grows, as the paper says."))
    return out
