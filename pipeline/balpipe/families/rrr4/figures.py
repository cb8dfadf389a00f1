"""Report figures of the method ``rrr4_counter_masses`` (paper 001; :attr:`balpipe.plugins.Method.figures`):
eq. 17's conditions with their residuals per stage, and the balance topologies (Figs. 2a, 3, 4a,
4b, 6a-c) with their counter-masses drawn. Every number drawn comes from the study (its stages,
parameters and ``balance.details``); a design is rebuilt from the spec only to be drawn, never
analysed here."""

from __future__ import annotations

import html
import math
import re

import numpy as np

from ...balancing.conditions import clarity_text, scale_of
from ...display import numbers
from ...notation import Names
from . import counter_masses as recipe
from . import conditions as cond
from . import topologies as topo
from .template import NOTATION, mass_parameters, resolve_legs

FIGURE_OF_STAGE = {"leg_by_leg": "Fig. 2a", "least_mass": "least mass", "general": "Fig. 4a", "special": "Fig. 6"}
FIG3 = tuple(f"Fig. 3{c}" for c in "abcdef")
TOL = 1e-9


def conditions_table(study) -> str | None:
    """An HTML table: each printed condition and its residual (kg m) for every stage."""
    mech = study.spec.mechanism
    if len(resolve_legs(mech)) != 4:
        return None
    rows = cond.eq17(recipe.geometry(mech))
    if mech.kinematics != "general":
        rows = rows + cond.special(recipe.geometry(mech), mech.kinematics)
    params = [(s.stage.label, mass_parameters(s.stage.model), scale_of(s.stage.model)) for s in study.stages]
    head = "".join(f"<th>{html.escape(lbl)}</th>" for lbl, _, _ in params)
    body = []
    for r in rows:
        cells = []
        for _, p, size in params:  # round-off of the terms or of the mechanism's first moments
            res, scale = r.residual(p), max(r.scale(p), size)
            ok = abs(res) <= TOL * max(scale, 1e-300)
            cells.append(f'<td class="num">{numbers.num_at(res, scale, floor=TOL)}{" ✓" if ok else ""}</td>')
        body.append(f"<tr><td>{html.escape(r.name)}</td><td><code>{html.escape(r.text())}</code></td>{''.join(cells)}</tr>")
    return (f"<table><tr><th>Condition</th><th>Linear equation (kg m; masses in kg)</th>{head}</tr>"
            + "".join(body) + "</table>")


def finder_table(study) -> str | None:
    """An HTML table: the generic condition finder's counts beside the paper's, eq. 17's rows in
    its space, the leg-by-leg and least-mass counter-masses side by side."""
    det = study.balance.details
    if "finder" not in det:
        return None
    p = {x.name: x.value for x in study.balance.parameters}
    mech = study.spec.mechanism
    four = len(resolve_legs(mech)) == 4
    rows = [("force-balance conditions, every motion", f"{int(p['finder_conditions'])}",
             "12 (eq. 17)" if four else "", clarity_text(p['finder_gap']))]
    if four:
        rows.append(("eq. 17's printed rows: largest distance from the computed space", numbers.num_at(p['eq17_in_finder_space'], 1.0, 2),
                     "0", "relative, scaled columns; at most 1e-9: in the space"))
    rows.append(("leg-by-leg design (eqs. 8-11): largest residual", numbers.num_at(p['leg_by_leg_in_finder_space'], 1.0, 2), "0",
                 "/ (total mass x model size)"))
    if "translating_conditions" in p:
        eq = cond.SPECIAL_EQ[mech.kinematics]
        rows += [
            ("conditions, translating platform (Fig. 5" + mech.kinematics[-1] + ")", f"{int(p['translating_conditions'])}",
             f"8 ({eq})", clarity_text(p['translating_gap'])),
            ("computed translating conditions: largest distance from the span of the printed eight",
             numbers.num_at(p['translating_in_printed_span'], 1.0, 2), "", "the printed eight are sufficient"),
            (f"{eq}'s rows with m5 p5, m5 q5 eliminated: independent combinations", f"{int(p['printed_reduced_conditions'])}",
             "", f"largest distance from the computed space {numbers.num_at(p['printed_reduced_in_translating'], 1.0, 2)}"),
        ]
    body = "".join(f"<tr><td>{html.escape(a)}</td><td class=\"num\">{b}</td><td class=\"num\">{html.escape(c)}</td>"
                   f"<td>{html.escape(d)}</td></tr>" for a, b, c, d in rows)
    out = ("<table><tr><th>Generic condition finder</th><th>computed</th><th>paper</th><th></th></tr>" + body + "</table>")
    lm = det.get("least_mass")
    if lm:
        stage = next((s for s in study.stages if s.stage.name == "leg_by_leg"), None)
        lbl = {b.name: a for b in stage.stage.model.bodies for a in b.attachments if a.kind == "counterweight"} if stage else {}
        cells = []
        for c in lm["counter_masses"]:
            a = lbl.get(c["body"])
            lb = f"{numbers.num(a.mass)} kg at {numbers.point(a.position)} m" if a else "none"
            pos = f"{numbers.num(c['mass'])} kg at {numbers.point(c['position'])} m" if c["mass"] > 0 else "none"
            cells.append(f"<tr><td>l{c['body'][4:]}</td><td>{lb}</td><td>{pos}</td></tr>")
        out += ("<table><tr><th>Link</th><th>leg-by-leg counter-mass (eqs. 8-11)</th><th>least-mass counter-mass "
                "(linprog, same allowed positions)</th></tr>" + "".join(cells)
                + f"<tr><th>added mass</th><th>{lm['leg_by_leg_mass']:.6g} kg</th><th>{lm['total_mass']:.6g} kg</th></tr></table>")
    return out


#: what a design panel's ratio is (computed with the balancing: counter_masses.design_loads)
LOAD_TEXT = ("inertial shaking force over the spec's motion (engine, computed with the balancing, in results.json) "
             "relative to the reference force of the stage ratios (the unbalanced stage's peak)")
DISC = 0.05  # the heaviest counter-mass's disc radius / the span of the base pivots
NAMED = ("pivot", "link")  # the names a panel carries: base pivots A1-A4 and links, as the paper: l11 for link11


def _draw(panel, model, poses, span: float, max_cw: float, title: str) -> list:
    """One panel (:class:`balpipe.draw.canvas.Panel`): ``model`` at the body poses ``poses`` (the
    engine's frame poses at t = 0): links, joints, pivots, each body's centre of mass (cross),
    counter-masses as red discs of area proportional to mass (``max_cw`` has the largest), the
    total centre of mass (star). Returns the points marked (centres of mass) for :func:`_name`
    to keep clear."""
    total, weighted, marks = 0.0, np.zeros(2), []
    for k, b in enumerate(model.bodies):
        x, y, th = poses[k]
        R = np.array([[math.cos(th), -math.sin(th)], [math.sin(th), math.cos(th)]])
        g = lambda p: np.array([x, y]) + R @ np.asarray(p, dtype=float)  # noqa: E731
        pts = np.array([g(b.points[n]) for n in b.outline])
        if b.kind == "platform":
            panel.polygon(pts[:-1], fill="0.9", edge="black", width=1.5, z=1.0)
        else:
            panel.line(pts[:, 0], pts[:, 1], "black", width=2.0, cap="round", cls="link")
        panel.markers(pts, "o", 4.0, face="white", edge="black")
        for a in b.attachments:
            if a.kind != "counterweight":
                continue
            root = g(b.points[b.outline[0]])
            pos = g(a.position)
            panel.line([root[0], pos[0]], [root[1], pos[1]], "tab:red", width=1.2)
            panel.circle(pos, DISC * span * math.sqrt(a.mass / max_cw), fill="tab:red", edge="tab:red", alpha=0.6)
        m, c, _ = b.mass_properties()
        gc = g(c)
        total, weighted = total + m, weighted + m * gc
        panel.marker(gc[0], gc[1], "x", 5.0, face="tab:blue")
        marks.append(gc)
    for name, p in model.frame_points.items():
        panel.marker(p[0], p[1], "^", 8.0)
    com = weighted / max(total, 1e-300)
    marks.append(com)
    panel.marker(com[0], com[1], "*", 11.0, face="tab:purple")
    panel.title, panel.title_size = title, 8.0
    panel.label_size = panel.tick_size = 7.0
    return marks


def _name(panel, model, poses, span: float, max_cw: float, marks: list) -> list:
    """The panel's names (:data:`NAMED`), placed by the report's label placer
    (:func:`balpipe.draw.figures.place_names`, :func:`balpipe.draw.labels.place`): no two
    overlap, and each keeps clear of the links, counter-mass discs, pivots, joints and the centres
    of mass ``marks`` where the panel leaves room. Call once the drawing is laid out."""
    from ...draw.figures import place_names

    # the paper's l_ij, as the page's tables and drawings write it (balpipe.notation.Names)
    paper = {b.name: Names((NOTATION,)).text("part", b.name) for b in model.bodies if b.name.startswith("link")}
    return place_names(panel, model, np.asarray(poses, dtype=float), span, max_cw, {}, disc=DISC, kinds=NAMED,
                       marks=marks, texts=paper)


def _span(model) -> float:
    return max(np.ptp([p[0] for p in model.frame_points.values()] + [0.0]),
               np.ptp([p[1] for p in model.frame_points.values()] + [0.0]), 0.1)


def _counter_masses(model) -> list[float]:
    return [a.mass for b in model.bodies for a in b.attachments if a.kind == "counterweight"]


def grid_columns(n: int) -> int:
    """Panels per row: at most three, two for four panels (2 x 2, not 3 + 1 or a row of four too
    small to read on a page)."""
    return 2 if n == 4 else min(3, n)


def panels_svg(panels: list[tuple], prefix: str) -> str:
    """One figure of ``panels`` (model, body poses, title), at most three a row (:func:`grid_columns`),
    drawn by :func:`draw_panels` through the figure cache (:mod:`balpipe.cache.figures`)."""
    from ...cache import figures as cache
    from ...draw.figures import drawn_model

    return cache.svg(draw_panels, [(drawn_model(model), poses, title) for model, poses, title in panels], prefix)


def draw_panels(panels: list[tuple], prefix: str) -> str:
    """:func:`panels_svg`, drawn by :func:`_draw` on one :class:`balpipe.draw.canvas.Canvas` with
    one disc scale for the whole figure, then named by :func:`_name`."""
    return panels_canvas(panels).svg(prefix)


def panels_canvas(panels: list[tuple]):
    """The laid-out and named :class:`balpipe.draw.canvas.Canvas` of :func:`draw_panels`: each
    panel 4.2 in square."""
    from ...draw.canvas import Canvas

    cols = grid_columns(len(panels))
    rows = (len(panels) + cols - 1) // cols
    canvas = Canvas(4.2 * 72 * cols, 4.2 * 72 * rows, rows, cols)
    max_cw = max([m for model, _, _ in panels for m in _counter_masses(model)] + [1e-12])
    for panel in canvas.panels[len(panels):]:
        panel.visible = False
    marks = [_draw(panel, model, poses, _span(model), max_cw, title)
             for panel, (model, poses, title) in zip(canvas.panels, panels)]
    canvas.layout()
    for panel, (model, poses, _), mk in zip(canvas.panels, panels, marks):
        _name(panel, model, poses, _span(model), max_cw, mk)
    return canvas


def topology_title(study) -> str:
    """The stage panels' title: the paper's figure numbers that the stage labels name (Fig. 2a, or
    2b-d with distal links kept as built; 4a; 6a, 6b or 6c), then "least mass" (ours) when drawn."""
    shown = [s.stage for s in study.stages if s.stage.name in FIGURE_OF_STAGE]
    figs = [m.group(1) for st in shown for m in [re.search(r"Fig\. (\d+[a-z])", st.label)] if m]
    ours = ["least mass"] if any(st.name == "least_mass" for st in shown) else []
    paper = [f"paper 001, Fig{'s' if len(figs) > 1 else ''}. {', '.join(figs)}"] if figs else []
    return f"Balance topologies ({'; '.join(paper + ours)})"


def topology_figure(study):
    """The balanced stages at t = 0, one panel each: links, joints, pivots, each link's centre of
    mass (cross), counter-masses as red discs of area proportional to mass, and the fixed total
    centre of mass (star)."""
    shown = [s for s in study.stages if s.stage.name in FIGURE_OF_STAGE]
    if not shown:
        return None
    return panels_svg([(s.stage.model, s.analysis.frame_pose[0], f"{s.stage.label}\nadded {s.added_mass:.3g} kg")
                       for s in shown], "rrr4-topology")


def designs_drawn(study) -> list[tuple]:
    """Figs. 3 and 4b's designs (:mod:`.topologies`) rebuilt from the spec for drawing, each with
    the numbers the balancing computed (``details["topologies"]["designs"]``: added mass, peak
    inertial shaking force / the reference force): (design, its row). Nothing is analysed here."""
    top = study.balance.details.get("topologies")
    if not top:
        return []
    model = study.stages[0].stage.model
    cw = study.spec.balancing.counterweights
    designs = topo.designs(model, recipe.geometry(study.spec.mechanism), cw.proximal, cw.distal)
    rows = {r["figure"]: r for r in top["designs"]}
    return [(d, rows[d.figure]) for d in designs]


def designs_figure(study, drawn: list[tuple], figures: tuple[str, ...]):
    """The designs of ``figures`` (e.g. Fig. 3a..f), one panel each, at the unbalanced stage's
    pose at t = 0 (the kinematics are the same), titled with the balancing's numbers."""
    shown = [c for c in drawn if c[0].figure in figures]
    if not shown:
        return None
    poses = study.stages[0].analysis.frame_pose[0]
    titles = [f"{topo.whose(d.figure)}: {', '.join(row['kept'])} as built\nadded {numbers.num(row['added_mass'], 3)} kg, "
              f"peak |F| / reference {numbers.ratio(row['force_ratio'])}" for d, row in shown]
    return panels_svg([(d.model, poses, title) for (d, _), title in zip(shown, titles)], "rrr4-" + topo.tag(figures[0]))


def figures(study):
    """(title, html or svg, caption) for the page: the figures of the method
    ``rrr4_counter_masses`` (:attr:`balpipe.plugins.Method.figures`), drawn from its stages and
    ``study.balance.details``."""
    table = conditions_table(study)
    if table is not None:
        mech = study.spec.mechanism
        n_special = 0 if mech.kinematics == "general" else 8
        yield (
            "Force-balance conditions (paper 001, eq. 17" + (", " + cond.SPECIAL_EQ[mech.kinematics] if n_special else "") + ")",
            table,
            f"The twelve general conditions of eq. 17" + (f" and the eight of {cond.SPECIAL_EQ[mech.kinematics]} "
                                                          "(non-rotating platform)" if n_special else "")
            + " as printed, as linear equations in the named mass parameters (m_ij p_ij and m_ij q_ij: first "
            "moments of link l_ij in its frame, origin at its proximal joint, x along the link; m5 p5, m5 q5: the "
            "platform's about its centre). Residual per stage in kg m; ✓ where it is at most 1e-9 of the "
            "condition's largest term. Count: 12 printed conditions, independent (each holds one dependent "
            "first moment with coefficient 1).",
        )
    finder = finder_table(study)
    if finder is not None:
        yield (
            "Generic condition finder against the printed conditions; least-mass counter-masses",
            finder,
            "The force-balance conditions computed numerically from the model's linear momentum at states it can "
            "reach (any mechanism's route, no loop algebra), against the paper's "
            "printed ones mapped onto the finder's parameters (m_ij p_ij = mx[link ij], m_ij q_ij = my[link ij], "
            "m5 p5 = mx[platform]: the body frames are the paper's). A printed row lies in the computed space when "
            "its distance from it (relative, in columns scaled to one unit) is at most 1e-9. With special kinematics "
            "the finder is also run on states of translating-platform motions only (eight random straight moves at "
            "the start angle). Second table: the counter-masses of the leg-by-leg design and of least total mass "
            "(linear programme over the same allowed positions: within the leg-by-leg distance of each link's "
            "proximal joint), link frames as in the paper (x along the link from its proximal joint).",
        )
    svg = topology_figure(study)
    if svg is not None:
        yield (
            topology_title(study),
            svg,
            "Whose designs: the figure numbers name the paper's topologies (which links carry counter-masses and the "
            "equations that size them), here on this spec's geometry and masses, which the paper does not give; the "
            "least-mass design is ours. "
            "Each force-balanced stage at t = 0: links (black; named l11 to l42 as in the paper, the spec's link11 to "
            "link42), joints (circles), base pivots (triangles, A1 to A4), each "
            "body's centre of mass (blue cross), counter-masses as red discs (area proportional to mass, the "
            "largest over the panels has the largest disc) on a line from the link's proximal joint, and the "
            "total centre of mass (purple star), which stays fixed during the motion in every panel.",
        )
    drawn = designs_drawn(study)
    if drawn:
        top = study.balance.details["topologies"]
        fr = top["freedoms"]
        worst = max(row["force_ratio"] for d, row in drawn if d.figure in FIG3)
        svg = designs_figure(study, drawn, FIG3)
        if svg is not None:
            yield (
                "Force balance topologies from the general conditions, of the kind of paper 001's Fig. 3 "
                "(a selection of ours, not the paper's panels)",
                svg,
                "Designs from eq. 17 whose link centres of mass may leave the lines through the joints. What the "
                f"paper's text fixes: with the masses given, eq. 17 leaves {fr['eq17']} mass-position parameters free "
                f"(the paper's six, two per loop equation) where the leg-by-leg conditions of Fig. 2 leave {fr['leg_by_leg']}; "
                f"keeping three bodies as built fixes the other twelve first moments for {top['admissible_kept']} of the "
                "84 triples (computed: exactly those with no two links of one leg). The paper's six panels cannot be read "
                "from its text, so the six drawn here are our selection, not the paper's: for each pair of legs (i, j) "
                "the distal links l_i2, l_j2 and the platform as built, one counter-mass on each of the six other links "
                "at the spec's distance from its proximal joint, in the direction eq. 17 needs (our design b is the design "
                "of Fig. 4a; its panel letters are ours, not the paper's). Each panel: added mass, and the peak "
                f"{LOAD_TEXT}; largest over the panels {worst:.1e}. Drawn as the stage "
                "panels above (red discs: counter-masses, area proportional to mass, the largest in this figure has "
                "the largest disc; blue crosses: body centres of mass; purple star: total centre of mass).",
            )
        svg = designs_figure(study, drawn, ("Fig. 4b",))
        if svg is not None:
            ranks = top["same_kind_per_leg_ranks"]
            yield (
                "Symmetric balance topology (paper 001, Fig. 4b: reconstructed by us from its text)",
                svg,
                "The paper's text says Fig. 4b is fully symmetric and has more design freedom than Fig. 2a. Read here "
                "as: a counter-mass on every link, as in Fig. 2a, but from eq. 17 instead of eqs. 8-11, the platform "
                f"as built. That family has {fr['eq17_links']} free first moments where the leg-by-leg family has "
                f"{fr['leg_by_leg_links']} (mu_54), and its link centres of mass may leave the link lines. No leg may "
                "be privileged, but keeping the same first moment in every leg (all p_i1, q_i1, p_i2 or q_i2) never "
                "fixes the design (eq. 17's 12 x 12 system then has rank "
                + ", ".join(f"{ranks[k]}" for k in ("p1", "q1", "p2", "q2"))
                + "), so the free parameters are fixed by the least Euclidean norm of the sixteen first-moment "
                "changes (every link treated alike; when that least-norm design is unique it has every symmetry of the "
                "mechanism and its mass data). That "
                "choice is ours: the paper's drawing is not in its text. Counter-masses at the spec's distances from "
                f"the proximal joints; the panel gives the added mass and the peak {LOAD_TEXT}.",
            )
