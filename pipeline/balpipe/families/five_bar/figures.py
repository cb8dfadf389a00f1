"""The five-bar's report figures (paper 004): the gripper path (Fig. 7) and the input angles
(Figs. 8-9), drawn from the study's analyses."""

from __future__ import annotations

import numpy as np

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
