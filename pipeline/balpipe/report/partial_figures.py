"""Figures of an optimal partial balancing (:mod:`balpipe.balancing.partial.method`): its Pareto fronts,
with the chosen design, the least-mass complete balancing in the same regions and every analysed
stage of the study (the compared designs, e.g. the paper's complete balancing) marked."""

from __future__ import annotations

import numpy as np

from ..display.numbers import num_at
from ..draw import live

AXES = {
    "added_mass": "added mass (kg)",
    "shaking_force": "peak shaking force (N)",
    "shaking_moment": "peak shaking moment (N m)",
    "effort": "peak actuator effort (N m or N)",
}
STAGE_KEYS = {"added_mass": lambda s: s.added_mass, "shaking_force": lambda s: s.analysis.max_force,
              "shaking_moment": lambda s: s.analysis.max_moment, "effort": lambda s: s.max_effort}
FRONTS = (
    ("force_vs_mass", "added_mass", "shaking_force", "Shaking force against added mass",
     "the least peak shaking force for each mass budget"),
    ("moment_vs_mass", "added_mass", "shaking_moment", "Shaking moment against added mass",
     "the least peak shaking moment for each mass budget"),
    ("force_vs_moment", "shaking_moment", "shaking_force", "Shaking force against shaking moment",
     "the least peak shaking force for each cap on the peak moment, at the spec's mass budget"),
    ("effort_vs_force", "shaking_force", "effort", "Actuator effort against shaking force",
     "the least peak actuator effort for each cap on the peak shaking force, at the spec's mass budget"),
)


FRONT = "optimal front (cone programme)"


def front_curves(points: list[dict], x: str, y: str, marks: list[tuple[str, float, float]]) -> live.Curves:
    """A front and its marks for the interactive plot (:mod:`balpipe.draw.live`): over the
    budget ``x``, a row per design in order of ``x`` (the front's designs, then each marked one),
    the front's curve through its designs and each mark a marker alone; hovering a design shows
    its budget and objective. The front in stage style 0, each mark in ``style(k + 1)``."""
    rows = sorted([(float(p[x]), 0, float(p[y])) for p in points] +
                  [(float(vx), k + 1, float(vy)) for k, (_, vx, vy) in enumerate(marks)])
    ys = np.full((len(marks) + 1, len(rows)), np.nan)
    for i, (_, series, value) in enumerate(rows):
        ys[series, i] = value
    stages = [(FRONT, {"y": ys[0]})] + [(label, {"y": ys[k + 1]}) for k, (label, _, _) in enumerate(marks)]
    xlim, ylim, _ = limits(points, x, y, marks)
    panel = {"key": "y", "title": "", "axis": AXES[y], "range": ylim, "xrange": xlim}
    return live.Curves(np.array([r[0] for r in rows]), stages, [panel], [],
                       styles=list(range(len(stages))), x_axis=AXES[x], points=tuple(range(1, len(stages))))


#: a mark farther from the front than this many times the front's own span (along x or y) is
#: left off the plot's axes (and named in the caption): the front keeps most of its plot
OUTLIER_SPANS = 0.5
PAD = 0.05  # of an axis's span, each side


def limits(points: list[dict], x: str, y: str, marks: list[tuple[str, float, float]]
           ) -> tuple[list[float], list[float], list[tuple[str, float, float]]]:
    """The axes of a front's plot: x and y limits that hold the front's designs and every mark
    within :data:`OUTLIER_SPANS` of the front's span of it, padded by :data:`PAD`; and the marks
    left outside (the outliers, for the caption). A front's span of 0 counts as its largest
    |value| (or 1)."""
    fx = np.array([float(p[x]) for p in points])
    fy = np.array([float(p[y]) for p in points])

    def window(v: np.ndarray) -> tuple[float, float]:
        span = float(np.ptp(v)) or float(np.max(np.abs(v))) or 1.0
        return float(np.min(v)) - OUTLIER_SPANS * span, float(np.max(v)) + OUTLIER_SPANS * span

    (x0, x1), (y0, y1) = window(fx), window(fy)
    kept = [m for m in marks if x0 <= m[1] <= x1 and y0 <= m[2] <= y1]
    out = [m for m in marks if m not in kept]

    def axis(v: np.ndarray, extra: list[float]) -> list[float]:
        lo, hi = float(min([*v, *extra])), float(max([*v, *extra]))
        pad = PAD * ((hi - lo) or abs(hi) or 1.0)
        return [lo - pad, hi + pad]

    return axis(fx, [m[1] for m in kept]), axis(fy, [m[2] for m in kept]), out


def _marks(study, det: dict, x: str, y: str) -> list[tuple[str, float, float]]:
    out = []
    fr = det["fronts"]
    for key, label in (("complete_force", "least-mass complete force balance (these regions)"),
                       ("complete_force_moment", "least-mass complete force and moment balance (these regions)")):
        c = fr.get(key)
        if c is not None and x in c and y in c:
            out.append((label, c[x], c[y]))
    if len(det.get("motions") or [None]) > 1:
        # the fronts' peaks are over every motion, the stages' analyses over the spec's motion
        # alone: mark only what is measured as the fronts are, the unbalanced mechanism and the
        # chosen design (the method's own peaks over every motion)
        chosen = [s for s in study.stages if s.stage.design is None][-1]
        for label, peaks, mass in ((study.unbalanced.stage.label, det["unbalanced"], 0.0),
                                   (chosen.stage.label, det["peaks"], det["added_mass"])):
            values = {"added_mass": mass, **peaks}
            out.append((f"{label} (over every motion)", values[x], values[y]))
        return out
    for s in study.stages:
        out.append((s.stage.label, STAGE_KEYS[x](s), STAGE_KEYS[y](s)))
    return out


def headline(study, det: dict) -> str:
    """'removes 80 % of the peak force for 25 % of the complete balance's mass' for the chosen design."""
    c = det["fronts"].get("complete_force") if det.get("fronts") else None
    F, F0 = det["peaks"]["shaking_force"], det["unbalanced"]["shaking_force"]
    over = "" if len(det.get("motions") or [None]) == 1 else " over every motion"
    text = f"The chosen design removes {100 * (1 - F / F0):.0f} % of the unbalanced peak shaking force{over}"
    if c is not None and c["added_mass"] > 0:
        text += f" for {100 * det['added_mass'] / c['added_mass']:.0f} % of the mass of the complete force balance"
    return text + "."


def figures(study) -> list[tuple[str, str, str]]:
    """(title, svg, caption) of each front the study's partial balancing computed; [] otherwise."""
    det = study.balance.details.get("partial_balance")
    if not det or not det.get("fronts"):
        return []
    out = []
    n = len(det.get("motions") or [None])
    where = "at the analysed motion" if n == 1 else f"over {n} motions at once (each peak the largest over every motion)"
    marked = ("every analysed stage" if n == 1 else
              "the unbalanced mechanism and the chosen design, their peaks over every motion as the front's (the other "
              "stages are analysed on the spec's motion alone: see the stage table)")
    for key, x, y, title, what in FRONTS:
        pts = det["fronts"].get(key) or []
        if len(pts) < 2:
            continue
        marks = _marks(study, det, x, y)
        svg = live.html(f"partial_{key}", front_curves(pts, x, y, marks),
                        'its designs are in <a href="results.json">results.json</a> '
                        '(<code>balancing_details.partial_balance.fronts</code>)')
        spare = sum(1 for p in pts if "budget" in p and p["added_mass"] < p["budget"] * (1 - 1e-6) - 1e-9)
        lightest = (f" At {spare} of the budgets more mass would not lower it: there the point is the lightest of "
                    "the optimal designs, its added mass below the budget." if spare else "")
        off = limits(pts, x, y, marks)[2]
        # a value at round-off of its axis's largest (a balanced design's 1e-14 N) reads 0
        sx = max(abs(float(v)) for v in [*(p[x] for p in pts), *(m[1] for m in marks)])
        sy = max(abs(float(v)) for v in [*(p[y] for p in pts), *(m[2] for m in marks)])
        outside = ("" if not off else " Off the axes, which the front fills: " + "; ".join(
            f"{label} at {AXES[x].split(' (')[0]} {num_at(vx, sx)} {AXES[x].split('(')[-1].rstrip(')')}, "
            f"{AXES[y].split(' (')[0]} {num_at(vy, sy)} {AXES[y].split('(')[-1].rstrip(')')}" for label, vx, vy in off) + ".")
        caption = (f"{len(pts)} points, each {what}, in absolute values (not relative to the unbalanced mechanism), "
                   f"solved to global optimality {where}.{lightest} Markers: the least-mass complete balances in the same "
                   f"regions along {'this motion' if n == 1 else 'these motions'}, where they exist, and {marked}."
                   f"{outside} " + headline(study, det) + f" Hover a design for its {AXES[x].split(' (')[0]} and "
                   f"{AXES[y].split(' (')[0]}.")
        out.append((title, svg, caption))
    return out
