"""The design summary card at the top of a study page: the parts the spec's main design adds to
the unbalanced mechanism (name, mass, position, inertia) and what they cost, as factors
(:mod:`balpipe.report.costs`). A part with a negative mass or centroidal inertia cannot be built
(:mod:`balpipe.mechanics.realisable`): it is flagged, and its inertia is never counted as a cost.
"""

from __future__ import annotations

from markupsafe import Markup

from ..display.units import DisplayUnits
from ..model import Model
from ..study import Study
from .costs import drivers_text, factor_text
from .notation_table import PageNames, names_for

SI = DisplayUnits()


def _position(p, units: DisplayUnits = SI) -> str:
    """A part's position on its link, (x, y) in the page's length unit; a coordinate below 1e-9
    of the other is round-off of the computation and reads 0 (:func:`balpipe.display.numbers.point`)."""
    return units.point(p)


def added_parts(base: Model, final: Model, names: PageNames | None = None, units: DisplayUnits = SI) -> list[dict]:
    """Counterweights and discs of ``final`` that ``base`` lacks, and links whose own mass or
    inertia the method changed. Positions of attachments are in their link's frame (m). With
    ``names`` (:func:`names_for`), ``name`` and ``where`` are markup naming the parts in the
    paper's symbols (the model's name beside each); ``part`` keeps the model's name. ``units``: the
    page's display units of the positions and of a changed link's former mass and inertia."""
    def nm(name: str) -> str:
        return names.part(name) if names is not None else name

    rows = []
    old = {b.name: b for b in base.bodies}
    for b in final.bodies:
        before = old.get(b.name)
        if before is None:
            rows.append({"part": b.name, "name": nm(b.name), "kind": "counter-rotation" if b.kind == "gear" else f"added {b.kind}",
                         "mass": b.mass, "where": "a body of its own",
                         "inertia": b.inertia, "buildable": b.mass >= 0 and b.inertia >= 0})
            atts = b.attachments
        else:
            if abs(b.mass - before.mass) > 1e-12 or abs(b.inertia - before.inertia) > 1e-15:
                rows.append({"part": b.name, "name": nm(b.name), "kind": "link changed",
                             "mass": b.mass, "where": f"was {units.text(before.mass, 'mass')}, {units.text(before.inertia, 'inertia')}",
                             "inertia": b.inertia, "buildable": b.mass >= 0 and b.inertia >= 0})
            had = {a.name for a in before.attachments}
            atts = tuple(a for a in b.attachments if a.name not in had)
        for a in atts:
            rows.append({"part": a.name, "name": nm(a.name), "kind": a.kind, "mass": a.mass,
                         "where": Markup("on ") + nm(b.name) + f" at {_position(a.position, units)}",
                         "inertia": a.inertia, "buildable": a.mass >= 0 and a.inertia >= 0})
    return rows


def main_stages(study: Study, results: dict) -> tuple | None:
    """The main design's final stage of the first motion and the stage it is judged against
    (``results['verdict']``), as :class:`balpipe.study.StageResult`; None without a balancing
    stage."""
    motions = (results.get("verdict") or {}).get("motions") or []
    if not motions:
        return None
    by = {s.stage.name: s for s in study.stages}
    final, ref = by.get(motions[0]["final"]), by.get(motions[0]["reference"])
    return None if final is None or ref is None else (final, ref)


def design_card(study: Study, results: dict, units: DisplayUnits = SI) -> dict | None:
    """The card's content: the main design's final stage (first motion), its parts and cost
    factors from ``results['verdict']``, its numbers in the page's display ``units``; None
    without a balancing stage."""
    pair = main_stages(study, results)
    if pair is None:
        return None
    final, ref = pair
    motions = results["verdict"]["motions"]
    c = motions[0]["costs"]
    names = names_for(study.spec)
    factors = [
        ("moving mass", factor_text(c["moving_mass"]), "+" + units.text(c["added_mass"] or 0.0, "mass", results.get("moving_mass"))),
        ("peak actuator effort", factor_text(c["effort"]), drivers_text(c, "effort", names.driver)),
        ("RMS actuator effort", factor_text(c["rms"]), drivers_text(c, "rms", names.driver)),
        ("peak actuator power", factor_text(c["power"]), drivers_text(c, "power", names.driver)),
        ("largest joint load", factor_text(c["joint_load"]), names.joint(c["joint"])),
    ]
    parts = added_parts(ref.stage.model, final.stage.model, names, units)
    kinds: dict[str, list[float]] = {}
    for p in parts:
        kinds.setdefault(p["kind"], []).append(p["mass"])
    summary = "; ".join(f"{len(m)} {k}{'s' if len(m) != 1 and not k.endswith('changed') else ''} "
                        f"({units.text(sum(m), 'mass')})" for k, m in kinds.items())
    return {"stage": final.stage.label, "reference": ref.stage.label, "parts": parts, "summary": summary,
            "factors": factors, "unbuildable": [p for p in parts if not p["buildable"]],
            "added_inertia": c["added_inertia"], "motions": len(motions)}
