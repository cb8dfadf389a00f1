"""The HTML page of one study: figures, tables and the spec's own text."""

from __future__ import annotations

import markupsafe
import numpy as np

from ..balancing.base import in_style_order, styled
from ..display import numbers
from ..display.units import display_units
from ..laws.drives import law_names
from ..study import Study
from ..draw import extremes, figures, labels, live, player, sleeves
from ..draw.stage_names import short_names
from . import citations, live_plots, paper_figures, partial_figures, present, sections, toc, whatif
from .design_card import design_card
from .effort_table import effort_table
from .notation_table import PageNames, names_for, notation_groups
from .render import environment
from .orders_figure import orders_svg
from .mounts_figure import mounts_svg
from .parts_table import page_rows
from .results import joint_load_table


def shown_stages(study: Study) -> list:
    """The stages drawn in the generic figures: all, or those of the first group when the spec
    runs several motions (the method's figures show the other groups); in the order of their
    line styles (:attr:`Stage.style` where a method gives it, else their place in the group), so
    that stage k of this list is drawn in ``figures.style(k)`` in every figure of the page."""
    return in_style_order([s for s in study.stages if s.stage.group == study.stages[0].stage.group])


def table_order(study: Study) -> list:
    """The shown stages (:func:`shown_stages`) in the order of the page's stage table: the
    drawings and the player list them as the table does (each keeps its line style elsewhere)."""
    shown = {id(s) for s in shown_stages(study)}
    return [s for s in study.stages if id(s) in shown]


def mechanism_player_stages(study: Study) -> list[dict]:
    """The player's stages of "The mechanism" (:func:`balpipe.draw.player.player_html`): each
    shown stage on the fixed frame along its motion, in table order, with the shaking force and
    moment (about the spec's moment point) that it passes to the frame."""
    out = []
    for s in table_order(study):
        a = s.analysis
        out.append({"label": s.stage.label, "model": s.stage.model, "t": a.t, "base": np.zeros((len(a.t), 3)),
                    "poses": a.frame_pose, "force": a.force, "moment": a.moment, "point": a.moment_point})
    return out


def drawn_instants(study: Study) -> list[int]:
    """The samples of the extreme poses that every mechanism drawing of the page shows as ghosts
    (:func:`extremes.extreme_instants`), from the first stage drawn: one set of instants for
    every panel, as the stages share their motion."""
    s = shown_stages(study)[0]
    return extremes.extreme_instants(s.stage.model, s.analysis.frame_pose)


def drawn_times(study: Study) -> tuple[float, list[float]]:
    """The time (s) of the solid pose (t = 0, where the player starts) and those of the ghosts."""
    t = shown_stages(study)[0].analysis.t
    return float(t[extremes.REFERENCE]), [float(t[k]) for k in drawn_instants(study)]


def drawing_times(study: Study) -> dict:
    """The caption's facts: ``solid`` (s, text), ``ghosts`` ('0.25 s', '0.1 s and 0.4 s'; empty when
    the mechanism barely moves) and their ``count``, and ``sleeves``: whether a drawing has a
    prismatic pair between two links (:mod:`balpipe.draw.sleeves`)."""
    solid, ghosts = drawn_times(study)
    texts = [f"{numbers.num(t, 4)} s" for t in ghosts]
    sleeved = any(sleeves.guided_sliders(s.stage.model) for s in shown_stages(study))
    return {"solid": numbers.num(solid, 4), "ghosts": " and ".join(texts), "count": len(texts), "sleeves": sleeved}


def stage_styles(study: Study) -> dict[str, tuple[int, str]]:
    """Every stage's line style on the page (the index of :func:`balpipe.draw.figures.style`) and
    its short name in legends and titles, by stage name: the shown stages in their order
    (:func:`shown_stages`, the page's key), then the others (stages of other motions) after
    them; so a stage looks the same in every figure drawn per stage, the simulation's included."""
    shown = shown_stages(study)
    rest = [s for s in study.stages if s not in shown]
    ordered = shown + rest
    shorts = short_names([s.stage.label for s in ordered], [s.stage.design for s in ordered])
    return {s.stage.name: (k, short) for k, (s, short) in enumerate(zip(ordered, shorts))}


def time_curves(study: Study, names: PageNames | None = None) -> dict[str, live.Curves]:
    """The curves of the page's time-series figures, by name: ``loads`` (the shaking force and
    moment of the shown stages, with their pymunk runs when simulated), ``efforts`` (the
    actuators') and ``joints`` (the joint loads; no panel when the mechanism has no joint load), in
    the spec's display units (``report.units``; their CSV files stay SI)."""
    names = names if names is not None else names_for(study.spec)
    sims = []
    for s in shown_stages(study):
        v = s.validation
        sims.append((v.t, v.force, v.moment) if v is not None else None)
    shown = [(s.stage.label, s.analysis) for s in shown_stages(study)]
    units = {d.name: present.driver_unit(s.stage.model, d.name)
             for s in shown_stages(study) for d in (*s.stage.model.drivers, *s.stage.model.actuators)}
    marks = [(w["time"], w["kind"].replace("_", " ")) for w in study.warnings]
    shown_names = {d: names.text("driver", d) for d in units}  # the paper's symbols in the panels' titles
    joint_names = {j: names.text("joint", j) for _, an in shown for j in an.reactions}  # the paper's symbols
    styles = stage_styles(study)
    short = [styles[s.stage.name][1] for s in shown_stages(study)]
    u = display_units(study.spec.report.units)  # the spec's display units
    return {"loads": live.shown_in(live_plots.loads(shown, sims, short), u),
            "efforts": live.shown_in(live_plots.efforts(shown, units, marks, shown_names, short), u),
            "joints": live.shown_in(live_plots.joints(shown, joint_names, short), u)}


def drawing_settings(study: Study, names: PageNames) -> dict:
    """What every mechanism drawing of the page shares (the keyword arguments of
    :func:`balpipe.draw.figures.mechanism_figure`): the ghosts' instants, one scale for every
    panel, the gears' numbers, and one name per link (the paper's symbols)."""
    shown = shown_stages(study)
    return {"ghosts": drawn_instants(study),
            "limits": figures.common_limits([(s.stage.model, s.analysis.frame_pose) for s in shown]),
            "numbers": labels.gear_numbers([s.stage.model for s in shown]),
            "texts": names.link_texts([s.stage.model for s in shown])}


def study_figures(study: Study, names: PageNames | None = None) -> dict:
    names = names if names is not None else names_for(study.spec)
    shown = [(s.stage.label, s.analysis) for s in shown_stages(study)]
    curves = time_curves(study, names)
    # each time-series figure interactive, on screen and in print (draw/live.py; curves: report/live_plots.py)
    loads = live.html("loads", curves["loads"]) + "".join(
        f'<p class="muted coincide">{markupsafe.escape(note)}</p>' for note in live_plots.coincide_notes(shown))
    efforts = live.html("efforts", curves["efforts"])
    joint_curves = curves["joints"]
    joints = live.html("joints", joint_curves) if joint_curves.panels else ""
    drawing = drawing_settings(study, names)
    styled_as = stage_styles(study)
    mech = [
        (s.stage.label, figures.mechanism_figure(s.stage.model, s.analysis, prefix=f"mech{k}", title=s.stage.label,
                                                 **drawing))
        for k, s in enumerate(table_order(study))
    ]
    moving, moving_note = player.player(mechanism_player_stages(study), "mechanism-player", floating=False,
                                        autoplay=False)
    extra = [(title, svg, caption) for title, svg, caption in study.extra_figures()]
    extra += partial_figures.figures(study)  # the fronts of an optimal partial balancing, if any
    extra += paper_figures.own_figures(study)  # the paper's panels as it numbers them
    residuals, drift = [], []
    vals = [s for s in shown_stages(study) if s.validation is not None]
    if vals:
        rows, caption = residual_rows(study, vals)
        res = live_plots.residuals(rows, [styled_as[s.stage.name][0] for s in vals],
                                   [styled_as[s.stage.name][1] for s in vals])
        residuals.append(("Residuals of the simulation", live.html("residuals", res, live_plots.SIMULATED) + "".join(
            f'<p class="muted coincide">{markupsafe.escape(note)}</p>' for note in live_plots.residual_notes(res)),
            caption))
    if study.reactionless is not None:
        r = study.reactionless
        # in the key's order, each stage in its style
        runs_in_order = sorted(zip(r.labels, r.runs, r.names), key=lambda run: styled_as[run[2]][0])
        drift.append(("Frame drift and rotation",
                      live.html("drift", live_plots.drift([(lab, x.t, x.drift, x.rotation) for lab, x, _ in runs_in_order],
                                                          [styled_as[n][0] for _, _, n in runs_in_order],
                                                          [styled_as[n][1] for _, _, n in runs_in_order]),
                                live_plots.SIMULATED),
                      "Displacement of the free frame's centre of mass and its rotation during the motion."))
    torque = []
    runs = [s for s in study.stages if s.torque is not None]
    if runs:
        curves = [(f"{s.stage.label}: {names.text('driver', d)}", np.abs(e) / (s.torque.travel[d] or 1.0))
                  for s in runs for d, e in sorted(s.torque.tracking.items())]
        # each stage in its style where a stage has one driver (several: told apart by colour order)
        tracking_styles = ([styled_as[s.stage.name][0] for s in runs]
                           if all(len(s.torque.tracking) == 1 for s in runs) else None)
        torque.append((
            "Tracking error of the torque-driven run",
            live.html("tracking", live_plots.tracking(runs[0].torque.t, curves, tracking_styles), live_plots.SIMULATED),
            "Each driven coordinate of the simulation driven by the engine's efforts (no position drive), "
            "minus its planned motion, relative to its travel (largest excursion from its start): "
            + travel_text(runs[0], names) + ".",
        ))
    key = "; ".join(f"{figures.style_text(k)}: {s.stage.label}" for k, s in enumerate(shown_stages(study)))
    swatches = [{"name": styled_as[s.stage.name][1], "label": s.stage.label, "words": figures.style_text(k),
                 **live.swatch(k)} for k, s in enumerate(shown_stages(study))]
    # a method that gives its stages the paper's line styles (Stage.style): said in the legend
    paper_styles = styled(shown_stages(study))
    return {"loads": loads, "joints": joints, "key": swatches, "joints_chosen": joint_curves.choose is not None, "loads_key": key[:1].upper() + key[1:],
            "styles_note": ("" if not paper_styles else
                            "These are the paper's line styles for the stages it plots, so the figures titled with the "
                            "paper's numbers draw each stage as every other figure does" if study.spec.paper else
                            "These are the line styles of the paper whose method balances this spec, so the figures "
                            "drawn as that paper's draw each stage as every other figure does"),
            "efforts": efforts, "mechanism": mech,
            "player": moving, "player_note": moving_note, "gear_key": labels.gear_key(drawing["numbers"]), "extra": extra,
            "residuals": residuals, "drift": drift, "torque": torque}


def travel_text(s, names: PageNames | None = None) -> str:
    """'crank 2.793 rad' per driver of a stage's torque-driven run: the tracking error's reference
    (with ``names``, each driver in the paper's symbol: 'θ₁ [theta1] 0.61 rad')."""
    model = s.stage.model
    return ", ".join(f"{names.text('driver', d) if names else d} {numbers.num(v, 4)} {'m' if present.driver_unit(model, d) == 'N' else 'rad'}"
                     for d, v in sorted(s.torque.travel.items()))


def residual_rows(study: Study, stages: list) -> tuple[list, str]:
    """The residual figure's rows (:func:`figures.residual_figure`) for ``stages`` (simulated), each
    divided by its own reference: the loads of ``study.reference_stage`` (with several motions, the
    unbalanced stage of its own motion; results.json's ``stages[].reference``, whose loads are
    ``checks.reference`` for the first motion), as the validation table's residuals; and the
    caption naming each reference."""
    refs = {}
    rows = []
    for s in stages:
        rs = study.reference_stage(s)
        ref = s.metrics.reference_loads
        refs.setdefault(rs.stage.name, (rs.stage.label, ref, []))[2].append(s.stage.label)
        rows.append((s.stage.label, s.validation.t, s.validation.force_error, s.validation.moment_error,
                     ref.force, ref.moment))
    parts = []
    for name, (label, ref, of) in refs.items():
        whose = "" if len(refs) == 1 else f"for {', '.join(of)}, "
        parts.append(whose + _reference_phrase(ref, label, "force") + " and " + _reference_phrase(ref, label, "moment"))
    caption = ("Difference between the pymunk simulation and the analytic engine (force |F_sim − F_analytic|, "
               "moment |M_sim − M_analytic|), divided by the reference loads F_ref, M_ref of the ratios "
               "and of the validation table: " + "; ".join(parts) + ".")
    return rows, caption


def _reference_phrase(ref, label: str, which: str) -> str:
    """'F_ref = 237.7 N, the peak inertial force of the unbalanced stage 'unbalanced'' (or its floor)."""
    value, basis, peak, unit, sym = ((ref.force, ref.force_basis, ref.force_peak, "N", "F_ref") if which == "force"
                                     else (ref.moment, ref.moment_basis, ref.moment_peak, "N m", "M_ref"))
    if basis == "unbalanced peak":
        return f"{sym} = {numbers.num(value, 4)} {unit}, the peak inertial {which} of the unbalanced stage '{label}'"
    return (f"{sym} = {numbers.num(value, 4)} {unit}, {ref.floor_fraction:g} of the gross inertial {which} of the unbalanced "
            f"stage '{label}' (larger than its peak, {numbers.num(peak, 3)} {unit})")


def base_scales(results: dict) -> dict[str, float]:
    """The mechanism's own scale of each unit of its computed parameters (a value at most 1e-9
    of it is round-off): its moving mass (kg), size (m), their product (kg m), its inertia
    scale (kg m²) and the inverse mass (1/kg, a sensitivity to the mass budget)."""
    m, size = results.get("moving_mass") or 0.0, results.get("length_scale") or 0.0
    return {"kg": m, "m": size, "kg m": m * size, "kg m^2": results.get("inertia_scale") or 0.0,
            "1/kg": 1.0 / m if m else 0.0}


def render_page(study: Study, results: dict, spec_text: str, history: dict | None = None,
                nav: dict | None = None) -> str:
    spec = study.spec
    names = names_for(spec)
    units = display_units(spec.report.units)  # the spec's display units (results.json stays SI)
    validation_rows = []
    for s in study.stages:
        v = s.validation
        if v is not None:
            validation_rows.append({
                "name": s.stage.name, "label": s.stage.label, "force_residual": v.force_residual,
                "moment_residual": v.moment_residual, "sim_force_ratio": v.force_peak,
                "sim_moment_ratio": v.moment_peak, "tracking": v.tracking_error_max, "passed": v.passed,
                "status": v.status, "remedy": v.remedy,
                "dt": v.dt, "steps": v.steps, "iterations": v.iterations, "tolerance": v.tolerance,
                "reasons": "; ".join(v.reasons), "notes": "; ".join(v.notes),
                "excluded": v.excluded_samples, "version": v.pymunk_version,
                "not_realisable": s.metrics.not_realisable,
            })
    torque_rows = []
    for s in study.stages:
        q = s.torque
        if q is not None:
            torque_rows.append({
                "label": s.stage.label, "tracking": q.tracking_error_max, "calibration": q.calibration_error,
                "resolution": q.resolution, "at_least": "≥ " if getattr(q, "calibration_stopped", False) else "",
                "force_residual": q.force_residual, "moment_residual": q.moment_residual,
                "force_peak": q.force_peak, "moment_peak": q.moment_peak,
                "dt": q.dt, "steps": q.steps, "iterations": q.iterations, "tolerance": q.tracking_tolerance,
                "passed": q.passed, "status": q.status, "remedy": q.remedy, "reasons": "; ".join(q.reasons),
                "notes": "; ".join(q.notes),
                "per_driver": markupsafe.Markup(", ").join(names.driver(k) + f" {numbers.num_at(v, 1.0, 2)}"
                                                           for k, v in sorted(q.tracking_error.items())),
            })
    rl = study.reactionless
    drawn = study_figures(study, names)
    floating = rl.player() if rl is not None else ("", "")  # the free-floating runs' player and its note
    return toc.add_toc(sections.collapse(environment().get_template("spec.html").render(
        r=results,
        paper=spec.paper,
        description=spec.description,
        law=law_names(spec.motion),  # the drives' own laws (balpipe.laws)
        figures=drawn,
        paper_figs=paper_figures.listed([title for title, _, _ in drawn["extra"]]) if spec.paper else [],
        validation=validation_rows,
        torque=torque_rows,
        reactionless={"base_mass": rl.base_mass, "base_inertia": rl.base_inertia, "rows": rl.rows(),
                      "same_base": rl.same_base,
                      "player": floating[0], "player_note": floating[1]} if rl is not None else None,
        drawn=drawing_times(study),
        joint_loads=joint_load_table(study),
        parts=page_rows(results.get("parts") or [], units),
        orders_figure=orders_svg(units, [(s.stage.name, results["orders"][s.stage.name]) for s in shown_stages(study)
                                  if (results.get("orders") or {}).get(s.stage.name)]),
        mounts_figure=mounts_svg(results.get("mounts"), [(s.stage.name, s.stage.label) for s in shown_stages(study)], units),
        stage_names=[(s.stage.name, s.stage.label) for s in shown_stages(study)],
        group=study.stages[0].stage.group if len(shown_stages(study)) < len(study.stages) else "",
        reference={"force": study.reference.describe("force", units), "moment": study.reference.describe("moment", units),
                   "floored": study.reference.floored},
        spec_text=markupsafe.escape(spec_text),  # verbatim: markup, so render.typeset leaves its units as written
        history=history,
        actuators=results.get("actuators") or [],
        effort_table=effort_table(results.get("actuators") or []),
        nav=nav or {},
        inputs=notation_groups(spec),
        verdict=results.get("verdict"),
        card=design_card(study, results, units),
        u=units,
        whatif=whatif.section(study, results, stage_styles(study), units),
        citation=citations.cite(spec.paper),
        names=names,
        param_scale=numbers.scales_by_unit(((p["value"], p["unit"]) for p in results.get("parameters") or []),
                                           base_scales(results)),
    )))
