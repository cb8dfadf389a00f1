"""The HTML page of one study: figures, tables and the spec's own text."""

from __future__ import annotations

from ..study import Study
from . import figures
from .render import environment

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
    validation = []
    if study.reactionless is not None:
        validation = list(study.reactionless.figures())
    return {"loads": loads, "efforts": efforts, "mechanism": mech, "extra": extra, "validation": validation}


def render_page(study: Study, results: dict, spec_text: str) -> str:
    spec = study.spec
    validation_rows = []
    note = ""
    for s in study.stages:
        if s.validation is not None:
            validation_rows.append(s.validation.row(s.stage.label))
            note = s.validation.settings_note()
    return environment().get_template("spec.html").render(
        r=results,
        paper=spec.paper,
        description=spec.description,
        law=spec.motion.law,
        figures=study_figures(study),
        validation=validation_rows,
        validation_note=note,
        instants=INSTANTS,
        spec_text=spec_text,
    )
