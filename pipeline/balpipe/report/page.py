"""The HTML page of one study: figures, tables and the spec's own text."""

from __future__ import annotations

from ..study import Study
from . import figures
from .render import environment
from .results import joint_load_table

INSTANTS = 5


def study_figures(study: Study) -> dict:
    sims = []
    for s in study.stages:
        v = s.validation
        sims.append((v.t, v.force, v.moment) if v is not None else None)
    loads = figures.loads_figure(
        [(s.stage.label, s.analysis, sim) for s, sim in zip(study.stages, sims)], prefix="loads"
    )
    efforts = figures.efforts_figure([(s.stage.label, s.analysis) for s in study.stages], prefix="efforts")
    mech = [
        (s.stage.label, figures.mechanism_figure(s.stage.model, s.analysis, INSTANTS, prefix=f"mech{k}", title=s.stage.label))
        for k, s in enumerate(study.stages)
    ]
    extra = [(title, svg, caption) for title, svg, caption in study.extra_figures()]
    residuals, drift = [], []
    vals = [s for s in study.stages if s.validation is not None]
    if vals:
        F0, M0 = study.unbalanced.analysis.max_force, study.unbalanced.analysis.max_moment
        residuals.append((
            "Residuals of the simulation",
            figures.residual_figure([(s.stage.label, s.validation.t, s.validation.force_error,
                                      s.validation.moment_error, F0, M0) for s in vals]),
            "Difference between the pymunk simulation and the analytic engine, relative to the unbalanced peaks.",
        ))
    if study.reactionless is not None:
        drift = list(study.reactionless.figures())
    return {"loads": loads, "efforts": efforts, "mechanism": mech, "extra": extra,
            "residuals": residuals, "drift": drift}


def render_page(study: Study, results: dict, spec_text: str, history: dict | None = None) -> str:
    spec = study.spec
    validation_rows = []
    for s in study.stages:
        v = s.validation
        if v is not None:
            validation_rows.append({
                "name": s.stage.name, "label": s.stage.label, "force_residual": v.force_residual,
                "moment_residual": v.moment_residual, "sim_force_ratio": v.force_peak,
                "sim_moment_ratio": v.moment_peak, "tracking": v.tracking_error_max, "passed": v.passed,
                "dt": v.dt, "steps": v.steps, "iterations": v.iterations, "tolerance": v.tolerance,
                "reasons": "; ".join(v.reasons), "notes": "; ".join(v.notes),
                "excluded": v.excluded_samples, "version": v.pymunk_version,
            })
    rl = study.reactionless
    return environment().get_template("spec.html").render(
        r=results,
        paper=spec.paper,
        description=spec.description,
        law=spec.motion.law,
        figures=study_figures(study),
        validation=validation_rows,
        reactionless={"base_mass": rl.base_mass, "base_inertia": rl.base_inertia, "rows": rl.rows(),
                      "player": rl.player()} if rl is not None else None,
        instants=INSTANTS,
        joint_loads=joint_load_table(study),
        stage_names=[(s.stage.name, s.stage.label) for s in study.stages],
        spec_text=spec_text,
        history=history,
    )
