"""Can a stage be built? A generic check of a model's parts.

A balancing method may compute a part that no real object has: a counterweight of negative
centroidal inertia (paper 004's eq. 17 read with the balanced links' inertias), a gear whose
computed inertia is negative (eqs. 19-21), a negative mass. The engine can still analyse such a
model when every *body's* total stays non-negative, so the analysis alone does not reveal it.
This module inspects every body (the bare link and each attachment separately, gears included):
a stage with a negative mass or a negative centroidal inertia anywhere is not realisable, and
the report flags it instead of counting it as passing.
"""

from __future__ import annotations

from dataclasses import dataclass

from ..model import Model


@dataclass(frozen=True)
class Issue:
    """One part that cannot be built."""

    body: str
    part: str  # the body itself ("link") or the attachment's name
    quantity: str  # "mass" or "inertia"
    value: float

    def __str__(self) -> str:
        unit = "kg" if self.quantity == "mass" else "kg m^2"
        where = f"body {self.body!r}" if self.part == "" else f"{self.part!r} on {self.body!r}"
        what = "mass" if self.quantity == "mass" else "centroidal inertia"
        return f"{where}: {what} {self.value:.4g} {unit}"


def issues(model: Model) -> list[Issue]:
    """Every negative mass or centroidal inertia among the bodies and their attachments."""
    out = []
    for b in model.bodies:
        parts = [("", b.mass, b.inertia)] + [(a.name, a.mass, a.inertia) for a in b.attachments]
        for name, m, i in parts:
            if m < 0:
                out.append(Issue(b.name, name, "mass", float(m)))
            if i < 0:
                out.append(Issue(b.name, name, "inertia", float(i)))
    return out


def verdict(model: Model) -> str:
    """"" when every part can be built, else "not realisable: negative inertia" (or "mass", or
    "inertia and mass")."""
    kinds = sorted({i.quantity for i in issues(model)})
    return f"not realisable: negative {' and '.join(kinds)}" if kinds else ""


def details(model: Model) -> str:
    """The parts that cannot be built, e.g. "'counterweight 1' on 'link1': centroidal inertia
    -0.126 kg m^2; ...", or ""."""
    return "; ".join(str(i) for i in issues(model))


def unmade(parts: tuple) -> list[str]:
    """Why each of ``parts`` (:class:`balpipe.mechanics.part_shapes.MadePart`) that cannot be made
    cannot, located: "part 'cw' on 'crank' (balancing.counterweights[0].part): thickness 31 mm
    exceeds max_thickness 25 mm"."""
    return [f"part {p.name!r} on {p.body!r} ({p.where}): {'; '.join(p.problems)}" for p in parts if p.problems]
