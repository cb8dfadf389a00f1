"""The serial arm's report figures, as its methods' hooks (:attr:`plugins.Method.figures`):

- gear decoupling (paper 002): Fig. 2 (shaking force F^sh, eq. 15, and moment M^sh, eq. 16, of
  the unbalanced arm), the mass matrix D before and after decoupling (eqs. 4-6, 17-18) and each
  joint's torque against its acceleration;
- centre-of-mass motion planning (paper 003): the peaks per trajectory (Sec. 3), Fig. 2 (the
  tested trajectories), Figs. 3 and 4 (shaking force and moment of cases 1-3 on the main
  trajectory, the paper's P15P7, in the paper's line styles), the other trajectories, and the
  optimised orientation phi.

Everything is drawn from the study: its analysed stages, its computed parameters and its spec
(paper 003's plans are rebuilt by :func:`com_planning.replan`); nothing is carried from the
balancing in a closure. Every stage is drawn in its line style of the page
(:func:`balancing.base.style_index`): one style means one stage on the whole page.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from ...balancing.base import style_index
from ...display import numbers
from ...spec_parts import paper_id
from .com_planning import CASES, STYLES, PhiPolynomial, replan
from .decoupling import mass_matrix_2r

#: colours of paper 003's trajectories in Fig. 2 and in the phi figure (no stage's colour: blue,
#: black and grey mean stages on that page)
TRAJECTORY_COLOURS = ("C1", "C2", "C3", "C4", "C5", "C6", "C8", "C9", "tab:olive", "tab:cyan")


def _titled(study, paper: str, figure: str, text: str) -> str:
    """A figure's title: "Fig. 2 of paper 003: the tested trajectories" on that paper's own page;
    on the page of another spec the same method balances (an engineer's own arm) the text alone,
    saying which figure of the paper it is drawn as (its page lists no figure of the paper)."""
    if _is_paper(study, paper):
        return f"{figure} of paper {paper}: {text}"
    return f"{text[0].upper()}{text[1:]} (drawn as {figure} of paper {paper})"


def _is_paper(study, paper: str) -> bool:
    return paper_id(study.spec.paper) == paper


def _main(study) -> dict:
    """The main design's stage results by name (not those of a ``compare`` design)."""
    return {s.stage.name: s for s in study.stages if s.stage.design is None}


def _params(study) -> dict:
    return {p.name: p.value for p in study.balance.parameters}


# --------------------------------------------------------------------------------------------
# Paper 002


def decoupling_figures(study):
    """Paper 002's figures: Fig. 2, the mass matrix before and after (its entries and along the
    motion), torque against acceleration."""
    from ...cache import figures as cache
    from ...engine.joint_space import mass_matrix

    by = _main(study)
    spec, method = study.spec, study.spec.balancing
    yield _paper002_fig2(study, by["unbalanced"])
    g1, l1 = method.gear_1p, spec.mechanism.links[0].length
    before = mass_matrix_2r(by["unbalanced"].stage.model, l1, None)
    after = mass_matrix_2r(by["decoupled"].stage.model, l1,
                           (g1.mass, g1.position, _params(study)["I_S1p"], g1.ratio))
    J = (after.M11[0], after.M22[0])
    entries = (("M11", "D₁₁"), ("M12", "D₁₂ = D₂₁"), ("M22", "D₂₂"))
    rows = "".join(f"<tr><td>{name}</td><td><code>{before.text(e)}</code></td><td><code>{after.text(e)}</code></td></tr>"
                   for e, name in entries)
    yield (
        "Mass matrix before and after decoupling (eqs. 4-6, 17-18)",
        "<table><tr><th>Entry (kg m²)</th><th>unbalanced</th><th>decoupled</th></tr>" + rows + "</table>",
        "D₁₁ = I_a + m_a|c_a|² + m₁′|AC|² + I_S1′ + I_b + m_b (l₁² + |c_b|² + 2 l₁ (c_bx cos θ₂ − c_by sin θ₂)); "
        "D₁₂ = ρ I_S1′ + I_b + m_b (|c_b|² + l₁ (c_bx cos θ₂ − c_by sin θ₂)); D₂₂ = ρ² I_S1′ + I_b + m_b |c_b|², "
        "with link 1's assembly (m_a, c_a, I_a), gear 1′ on C (m₁′, I_S1′, ratio ρ) and link 2's assembly "
        "(m_b, c_b from B, I_b); the numbers are computed from the stages' models.",
    )
    stages = [by["unbalanced"], by["decoupled"]]
    rows = [(s.stage.label, style_index(study.stages, s), mass_matrix(s.stage.model, s.analysis.t)[1]) for s in stages]
    yield ("Mass matrix along the motion", mass_matrix_html(stages[0].analysis.t, rows),
           "Entries of the joint-space mass matrix computed by the engine from each stage's model "
           "(D = Vᵀ diag(m, m, I) V, V the body velocities per unit joint rate): the decoupled arm's is "
           "constant and diagonal.")
    runs = []
    for s in stages:
        an = s.analysis
        qdd = [an.a[:, an.names.index(f"link{j + 1}"), 2] - (an.a[:, an.names.index("link1"), 2] if j else 0.0)
               for j in range(2)]
        runs.append((s.stage.label, style_index(study.stages, s), qdd, [an.efforts[f"q{j + 1}"] for j in range(2)]))
    yield ("Torque against acceleration (eqs. 17-18)", cache.svg(torque_acceleration_svg, runs, J),
           "Each joint's actuator torque τᵢ against its own acceleration θ̈ᵢ at every sample: coupled and "
           "nonlinear before, on the line τᵢ = Jᵢ θ̈ᵢ after decoupling (red)"
           + (" (with gravity on, the decoupled arm's total centre of mass is on A: no gravity torque)."
              if study.spec.analysis.gravity else "."))


#: the mass matrix's panels: key, entry (row, column), title
MASS_PANELS = (("D11", (0, 0), "D₁₁ (kg m²)"), ("D12", (0, 1), "D₁₂ (kg m²)"), ("D22", (1, 1), "D₂₂ (kg m²)"))


def mass_matrix_html(t: np.ndarray, rows: list[tuple]) -> str:
    """D11, D12, D22 over time ``t``, a panel each, a line per (stage label, style index, D (N, 2,
    2)) in its stage's style; drawn by the browser (:func:`balpipe.draw.live.html`, element
    ``#live-decoupling-mass``)."""
    from ...draw import live

    curves = live.Curves(t, [(label, {key: M[:, i, j] for key, (i, j), _ in MASS_PANELS}) for label, _, M in rows],
                         [{"key": key, "title": title, "axis": title} for key, _, title in MASS_PANELS], [],
                         styles=[k for _, k, _ in rows], grid=True)
    return live.html("decoupling-mass", curves)


def torque_acceleration_svg(runs: list[tuple], J: tuple[float, float]) -> str:
    """Each joint's torque against its acceleration, one marker style per (stage label, style
    index, [q1'', q2''], [tau1, tau2]), and the lines tau_i = J_i q_i''."""
    from ...draw.figures import MARKERS, plt, style, to_svg  # matplotlib only when a report is drawn
    from ...draw.layout import fixed_layout

    fig, axes = plt.subplots(1, 2, figsize=(9.0, 3.2))
    for label, k, qdd, tau in runs:
        for j, ax in enumerate(axes):
            ax.plot(qdd[j], tau[j], MARKERS[k % len(MARKERS)], markersize=2.5, color=style(k)["color"],
                    markerfacecolor="none", alpha=0.7, label=label)
    for j, (ax, Jj) in enumerate(zip(axes, J)):
        sub = "₁₂"[j]
        lim = np.array(ax.get_xlim())
        ax.plot(lim, Jj * lim, color="tab:red", linewidth=1.0, label=f"J{sub} θ̈{sub} (J{sub} = {Jj:.4g} kg m²)")
        ax.set_xlabel(f"θ̈{sub} (rad/s²)")
        ax.set_title(f"τ{sub} (N m)", fontsize=9)
        ax.legend(fontsize=7)
    fixed_layout(fig)
    return to_svg(fig, "decoupling-torque")


def _paper002_fig2(study, un):
    """Fig. 2 of paper 002: F^sh = |reaction force on the frame| (eq. 15) and M^sh = -tau1 (eq.
    16) of the unbalanced arm, in the stage's style; with gravity on, the weight is said apart."""
    from ...draw import live

    an = un.analysis
    weight = an.total_mass * float(np.hypot(*an.gravity))
    if weight:
        apart = (f" With gravity on, Fˢʰ includes the links' constant weight m g = {weight:.4g} N: its inertial part "
                 f"alone peaks at {an.max_inertial_force:.4g} N, the whole at {an.max_force:.4g} N.")
    else:
        apart = " Gravity is off: Fˢʰ is the inertial force alone."
    curves = live.Curves(an.t, [(un.stage.label, {"F": np.linalg.norm(an.force, axis=1), "M": an.moment})],
                         [{"key": "F", "title": "(a) Fˢʰ (N), eq. 15", "axis": "Fˢʰ (N)"},
                          {"key": "M", "title": "(b) Mˢʰ (N m), eq. 16", "axis": "Mˢʰ (N m)"}], [],
                         styles=[style_index(study.stages, un)])
    return (_titled(study, "002", "Fig. 2", "shaking force and shaking moment of the unbalanced manipulator"),
            live.html("p002fig2", curves),
            f"Stage '{un.stage.label}' in its line style of this page, from the analysis of this spec: Fˢʰ = "
            "√(F₁₀ₓ² + F₁₀ᵧ²), the reaction force on the frame, and Mˢʰ = −τ₁, about joint A." + apart)


# --------------------------------------------------------------------------------------------
# Paper 003


def _pct(x: float) -> str:
    return f"{100 * x:.1f} %"


def com_planning_figures(study):
    """Paper 003's figures: the peaks per trajectory, Figs. 2-4, the other trajectories, phi."""
    params = _params(study)
    planner, plans = replan(study.spec, params)
    by = _main(study)
    main = study.stages[0].stage.group  # the balancing lists the main trajectory first
    yield _peaks_table(study, plans, by, params)
    yield _square_figure(study, planner, plans, main)
    yield from _figs_3_4(study, main, by)
    others = [p for p in plans if p.name != main]
    if others:
        yield _other_trajectories(study, others, by)
    t = planner.t
    phis = [(p.name or "optimised", np.degrees(PhiPolynomial(p.start[2], p.end[2], planner.T, p.phi_coefficients)(t)[0]))
            for p in plans]
    phi5 = PhiPolynomial(plans[0].start[2], plans[0].end[2], planner.T)
    k345 = style_index(study.stages, by[_prefix(main) + "com_bang_bang"])
    method = study.spec.balancing
    yield ("Optimised end-effector orientation φ", phi_html(t, phis, np.degrees(phi5(t)[0]), k345),
           f"φ(t) of case 2 per trajectory (degree {method.phi.degree}, ends fixed), and the 3-4-5 law it starts "
           "from, in the line style of the stage that uses it.")


def phi_html(t: np.ndarray, phis: list[tuple[str, np.ndarray]], phi345: np.ndarray, k345: int) -> str:
    """φ (deg) over time per (trajectory, values), each in its colour (:data:`TRAJECTORY_COLOURS`),
    and the 3-4-5 law in the line style ``k345`` of the stage that uses it; drawn by the browser
    (:func:`balpipe.draw.live.html`, element ``#live-com-phi``)."""
    from ...draw import live

    curves = live.Curves(t, [(name, {"phi": phi}) for name, phi in phis] + [("3-4-5 law", {"phi": phi345})],
                         [{"key": "phi", "title": "", "axis": "φ (deg)"}], [],
                         styles=[{"color": TRAJECTORY_COLOURS[k % len(TRAJECTORY_COLOURS)], "linestyle": "-",
                                  "linewidth": 1.0} for k in range(len(phis))] + [k345])
    return live.html("com-phi", curves)


def _prefix(name: str) -> str:
    return f"{name}_" if name else ""


def _peaks_table(study, plans, by, params) -> tuple[str, str, str]:
    method = study.spec.balancing
    rows = []
    for p in plans:
        pre = _prefix(p.name)
        a1 = by[pre + "ee_quintic"].analysis
        rows.append(f'<tr><th colspan="7">{p.name or "trajectory"}: tip ({p.start[0]:.4g}, {p.start[1]:.4g}) → '
                    f'({p.end[0]:.4g}, {p.end[1]:.4g}) m, centre of mass moves {1000 * p.com_distance:.4g} mm</th></tr>')
        for key, _ in CASES:
            s = by[pre + key]
            an = s.analysis
            tau = max(float(np.max(np.abs(e))) for e in an.efforts.values())
            fr = 1 - an.max_inertial_force / a1.max_inertial_force
            mr = 1 - an.max_inertial_moment / a1.max_inertial_moment
            rows.append(
                f"<tr><td>{s.stage.label.split(' · ')[-1]}</td><td class=\"num\">{an.max_force:.4g}</td>"
                f"<td class=\"num\">{'—' if key == 'ee_quintic' else _pct(fr)}</td>"
                f"<td class=\"num\">{an.max_moment:.4g}</td><td class=\"num\">{'—' if key == 'ee_quintic' else _pct(mr)}</td>"
                f"<td class=\"num\">{tau:.4g}</td><td class=\"num\">{_rate_cell(key, an, p, method)}</td></tr>"
            )
    fmin, fmax = params["force_reduction_min"], params["force_reduction_max"]
    mmin, mmax = params["moment_reduction_min"], params["moment_reduction_max"]
    head = ("<table><tr><th>Case</th><th>Peak |F| (N)</th><th>|F| reduction vs case 1</th><th>Peak |M| (N m)</th>"
            "<th>|M| reduction vs case 1</th><th>Peak |τ| (N m)</th><th>Peak |dτ/dt| (N m/s)</th></tr>")
    paper = _is_paper(study, "003")
    summary = (f'<tr><th colspan="7">All trajectories, case 2 (CoM bang-bang + φ optimised) vs case 1: force '
               f'reduction {_pct(fmin)} to {_pct(fmax)}{" (published 48 % to 62.2 %)" if paper else ""}; moment '
               f'reduction {_pct(mmin)} to {_pct(mmax)}{" (published 37.2 % to 61 %)" if paper else ""}</th></tr>')
    return ("Peak loads per trajectory" + (" (the paper's Sec. 3 results)" if paper else ""),
            head + "".join(rows) + summary + "</table>",
            "Computed by the engine for every stage; reductions are 1 − peak / peak of the same trajectory's case 1 "
            "(end-effector quintic). " + ("The paper gives only the ranges over its eight trajectories; the duration "
                                         if paper else "The duration ")
            + f"({study.spec.motion.duration:g} s here) does not change the ratios (all loads scale with 1/T²) but does "
            "change case 3 (the torque-rate limit). In a horizontal plane the shaking moment about the base joint is "
            "minus joint 1's torque (paper 002, eq. 16), hence equal peaks. Torque rates: case 1 by central "
            f"differences on the analysis grid, case 3 on {method.rate_samples} samples and 64 in each ramp (the ramp search).")


def _rate_cell(key: str, an, plan, method) -> str:
    """Peak actuator torque rate: unbounded where the bang-bang law makes the torques jump; case
    3's as measured by the ramp search; case 1's by central differences on the analysis grid."""
    if key.startswith("com_bang_bang"):
        return "unbounded (torques jump)"
    if key == "com_trapezoidal":
        return f"{numbers.num(plan.ramp_rate)} (limit {numbers.num(method.torque_rate_limit, 3)})"
    return numbers.num(max(float(np.max(np.abs(np.gradient(e, an.t)))) for e in an.efforts.values()))


#: the paper's cases 1, 2, 3, which Figs. 3-4 draw (the stage with phi on the 3-4-5 law is not a case of the paper)
PAPER_CASES = ("ee_quintic", "com_bang_bang_phi_opt", "com_trapezoidal")


def _figs_3_4(study, main: str, by: dict):
    """Figs. 3 and 4 of paper 003: |F| and M of cases 1, 2, 3 on the main trajectory, in the
    paper's line styles (case 1 black full, case 2 black dashed, case 3 grey full), which are these
    stages' styles on the whole page (:data:`com_planning.STYLES`)."""
    from ...draw import live

    pre = _prefix(main)
    stages = [by[pre + key] for key in PAPER_CASES]
    for number, what, ylabel, fn, prefix in (
            ("3", "shaking forces", "|F| (N)", lambda an: np.linalg.norm(an.force, axis=1), "p003fig3"),
            ("4", "shaking moment", "M (N m)", lambda an: an.moment, "p003fig4")):
        curves = live.Curves(stages[0].analysis.t, [(s.stage.label.split(" · ")[-1], {"y": fn(s.analysis)}) for s in stages],
                             [{"key": "y", "title": "", "axis": ylabel}], [],
                             styles=[style_index(study.stages, s) for s in stages])
        paper = _is_paper(study, "003")
        yield (_titled(study, "003", f"Fig. {number}", f"variations of the {what}, trajectory {main}"),
               live.html(prefix, curves),
               f"Trajectory {main}, " + ("the one the paper's Figs. 3-4 show" if paper else "this spec's main trajectory")
               + "; case 1 (black full line), case 2 (black dashed line) and case 3 (grey full line), "
               + ("the paper's line styles" if paper else "the line styles of paper 003's Figs. 3-4")
               + " and these stages' styles on the whole page. "
               + ("Moment about the base joint, horizontal plane. " if number == "4" else "")
               + ("The stage the paper does not draw" if paper else "The fourth stage")
               + " (CoM bang-bang with φ on the 3-4-5 law) is in the table above and in the page's stage figures. "
               "Computed by the engine from this spec.")


def _other_trajectories(study, plans, by: dict) -> tuple[str, str, str]:
    """|F| and M of every stage on the trajectories that Figs. 3-4 do not show, a pair of panels
    each; a curve per case, in the case's line style of this page (the same on every trajectory);
    drawn by the browser (:func:`balpipe.draw.live.html`, element ``#live-com-loads``)."""
    from ...draw import live

    n = len(plans)
    cases = [key for key, _ in sorted(CASES, key=lambda kl: STYLES[kl[0]])]
    panels: list[Any] = []
    curves: dict[str, dict[str, Any]] = {key: {} for key in cases}
    for p in plans:
        pre = _prefix(p.name)
        panels += [{"key": f"F {p.name}", "title": f"{p.name}: shaking force |F| (N)", "axis": "|F| (N)"},
                   {"key": f"M {p.name}", "title": f"{p.name}: shaking moment M (N m)", "axis": "M (N m)"}]
        for key in cases:
            an = by[pre + key].analysis
            curves[key].update({f"F {p.name}": np.linalg.norm(an.force, axis=1), f"M {p.name}": an.moment})
    first = [by[_prefix(plans[0].name) + key] for key in cases]
    figure = live.Curves(first[0].analysis.t, [(s.stage.label.split(" · ")[-1], curves[key]) for key, s in zip(cases, first)],
                         panels, [], styles=[style_index(study.stages, s) for s in first], grid=True)
    return (f"Shaking force and moment on the other {n} trajectories", live.html("com-loads", figure),
            ("The same quantities as Figs. 3-4 on the trajectories the paper does not plot" if _is_paper(study, "003")
             else "The same quantities on the spec's other trajectories")
            + ", every stage in its line style of this page. Moment about the base joint, horizontal plane.")


def _square_figure(study, planner, plans, main: str) -> tuple[str, str, str]:
    """Fig. 2 of paper 003: the tested square, its points P_i, the tip's and the centre of mass'
    straight paths of every trajectory, and the arm at the start of the main trajectory."""
    from ...cache import figures as cache

    method = study.spec.balancing
    sq = method.test_square
    square = (sq.side, tuple(sq.centre), sq.points()) if sq is not None else None
    paths = [(p.name, p.start[:2], p.end[:2], p.com_start[:2], p.com_end[:2]) for p in plans]
    p0 = next(p for p in plans if p.name == main)
    pts = [np.asarray(planner.arm.base, dtype=float)]
    for L, a in zip(planner.arm.lengths, np.cumsum(p0.q_start)):
        pts.append(pts[-1] + L * np.array([math.cos(a), math.sin(a)]))
    svg = cache.svg(square_svg, square, paths, np.array(pts), tuple(planner.arm.base), p0.name)
    reading = " (our reading of the figure, which reproduces the paper's list of segments)" if _is_paper(study, "003") else ""
    zone = (f"side {sq.side:g} m, centre E = ({sq.centre[0]:g}, {sq.centre[1]:g}) m; points P1.. numbered "
            f"counter-clockwise from P1 at the {sq.first_corner} corner{reading}") if sq is not None else "no test square in the spec"
    return (_titled(study, "003", "Fig. 2", "the tested trajectories"), svg,
            f"Grey: the tested zone ({zone}). Arrows: the tip's straight paths of case 1; dashed: the centre of mass' "
            "straight paths of cases 2-3, each trajectory in a colour of its own. Base joint: triangle.")


def square_svg(square: tuple | None, paths: list[tuple], pts: np.ndarray, base: tuple, main: str) -> str:
    """:func:`_square_figure`'s drawing: ``square`` (side, centre, named points) or None, the
    ``paths`` (name, tip start, tip end, centre of mass start, end) of every trajectory, the arm's
    joints ``pts`` at the start of trajectory ``main``, its ``base``."""
    from ...draw.figures import legend_below, place_items, plt, to_svg  # matplotlib only when a report is drawn

    fig, ax = plt.subplots(figsize=(6.0, 5.4))
    names: list = []  # (text, point, kind): placed last, clear of the paths (draw.figures.place_items)
    segs: list = []
    if square is not None:
        side, (cx, cy), points = square
        h = side / 2
        ax.fill([cx - h, cx + h, cx + h, cx - h], [cy - h, cy - h, cy + h, cy + h], color="0.88", zorder=0)
        for name, (x, y) in points.items():
            ax.plot(x, y, "o", color="black", markersize=2.5)
            names.append((name, (x, y), "joint"))
        ax.plot([cx], [cy], "+", color="black")
        names.append(("E", (cx, cy), "joint"))
    for k, (name, start, end, com_start, com_end) in enumerate(paths):
        c = TRAJECTORY_COLOURS[k % len(TRAJECTORY_COLOURS)]
        ax.annotate("", xy=end, xytext=start, arrowprops={"arrowstyle": "->", "color": c, "lw": 1.2})
        ax.plot([com_start[0], com_end[0]], [com_start[1], com_end[1]], color=c, linestyle="--", linewidth=1.0,
                label=f"{name}: tip → (solid), centre of mass (dashed)")
        segs += [(tuple(start), tuple(end)), (tuple(com_start), tuple(com_end))]
    ax.plot(pts[:, 0], pts[:, 1], "-o", color="0.3", linewidth=2.0, markersize=3, label=f"arm at the start of {main}")
    segs += [(tuple(a), tuple(b)) for a, b in zip(pts[:-1], pts[1:])]
    ax.plot([base[0]], [base[1]], "^", color="black", markersize=8)
    ax.set_aspect("equal")
    ax.set_xlabel("x (m)")
    ax.set_ylabel("y (m)")
    legend_below(fig, ax, fontsize=7)  # under the drawing: never over the arm or the paths
    place_items(fig, ax, names, segs, [(np.asarray(q, dtype=float), None) for _, q, _ in names]
                + [(np.asarray(base, dtype=float), -1.0)])
    return to_svg(fig, "com-square")
