"""The units a study's pages show: a spec's ``report: {units: ...}`` (a preset's name, or a
mapping from quantity to unit over a preset), SI by default.

Quantities and their units (the first is SI): length m, mm, cm; mass kg, g; force N, kN; moment
N m, kN m, N mm; speed (angular) rad/s, rpm; angle rad, deg; power W, kW. An inertia follows the
mass and length units (kg m², kg mm², g mm², ...). Presets: ``SI`` (the default: every page
number is the number in results.json) and ``engineering`` (mm, kg, kN, kN m, rpm, deg, kW).

Only the pages read these: ``results.json`` and the CSV files stay in SI units (results.json
says so in its ``units`` key, the CSV columns in their names), so a script never depends on
how its pages were shown.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Mapping

from . import numbers

#: per quantity, its units and each unit's factor to SI (the first is SI)
CHOICES: dict[str, dict[str, float]] = {
    "length": {"m": 1.0, "mm": 1e-3, "cm": 1e-2},
    "mass": {"kg": 1.0, "g": 1e-3},
    "force": {"N": 1.0, "kN": 1e3},
    "moment": {"N m": 1.0, "kN m": 1e3, "N mm": 1e-3},
    "speed": {"rad/s": 1.0, "rpm": 3.141592653589793 / 30},
    "angle": {"rad": 1.0, "deg": 3.141592653589793 / 180},
    "power": {"W": 1.0, "kW": 1e3},
}
PRESETS: dict[str, dict[str, str]] = {
    "SI": {q: next(iter(u)) for q, u in CHOICES.items()},
    "engineering": {"length": "mm", "mass": "kg", "force": "kN", "moment": "kN m", "speed": "rpm",
                    "angle": "deg", "power": "kW"},
}
#: an SI unit as results.json writes it -> the quantity it measures
OF_SI_UNIT = {"m": "length", "kg": "mass", "N": "force", "N m": "moment", "rad/s": "speed", "rad": "angle",
              "W": "power", "kg m^2": "inertia", "kg m²": "inertia"}


@dataclass(frozen=True)
class DisplayUnits:
    """The unit of each quantity on a page (:data:`CHOICES`); ``inertia`` follows mass and
    length. Build with :func:`display_units`."""

    units: Mapping[str, str] = field(default_factory=lambda: dict(PRESETS["SI"]))

    def unit(self, quantity: str) -> str:
        """The display unit of ``quantity`` (a :data:`CHOICES` key, 'inertia', or an SI unit as
        results.json writes it: 'N m' -> the moment's unit); '' for anything else."""
        q = OF_SI_UNIT.get(quantity, quantity)
        if q == "inertia":
            return f"{self.units['mass']} {self.units['length']}²"
        return self.units.get(q, "")

    def factor(self, quantity: str) -> float:
        """The SI value of one display unit of ``quantity`` (1 for unknown quantities)."""
        q = OF_SI_UNIT.get(quantity, quantity)
        if q == "inertia":
            return CHOICES["mass"][self.units["mass"]] * CHOICES["length"][self.units["length"]] ** 2
        return CHOICES[q][self.units[q]] if q in CHOICES else 1.0

    def value(self, x: float | None, quantity: str) -> float | None:
        """An SI value of ``quantity`` in its display unit."""
        return None if x is None else float(x) / self.factor(quantity)

    def num(self, x: float | None, quantity: str, scale: float | None = None, digits: int = 4) -> str:
        """The number shown for an SI value (no unit): :func:`balpipe.display.numbers.num_at` of
        the converted value (round-off of ``scale``, also SI, reads 0)."""
        return numbers.num_at(self.value(x, quantity), self.value(scale, quantity), digits)

    def text(self, x: float | None, quantity: str, scale: float | None = None, digits: int = 4) -> str:
        """The number and its unit: '21.14 kN'."""
        if x is None:
            return "—"
        return f"{self.num(x, quantity, scale, digits)} {self.unit(quantity)}".rstrip()

    def point(self, p, digits: int = 4) -> str:
        """A position (a pair of SI lengths) and its unit: '(-80, 0) mm'; a coordinate at most
        1e-9 of the other reads 0 (:func:`balpipe.display.numbers.point`)."""
        f = self.factor("length")
        return f"{numbers.point([float(c) / f for c in p[:2]], digits)} {self.unit('length')}"

    @property
    def is_si(self) -> bool:
        return dict(self.units) == PRESETS["SI"]


def display_units(choice: str | Mapping[str, str] | None = None) -> DisplayUnits:
    """The display units of a spec's ``report.units``: None (SI), a preset's name, or a mapping
    {quantity: unit} over SI, or over a preset named by its ``preset`` key. Raises ValueError
    naming the quantity or unit that is not known."""
    if choice is None:
        return DisplayUnits()
    if isinstance(choice, str):
        if choice not in PRESETS:
            raise ValueError(f"unknown units preset {choice!r} (use one of: {', '.join(PRESETS)}, or a mapping)")
        return DisplayUnits(dict(PRESETS[choice]))
    chosen = dict(choice)
    base = chosen.pop("preset", "SI")
    if base not in PRESETS:
        raise ValueError(f"unknown units preset {base!r} (use one of: {', '.join(PRESETS)})")
    units = dict(PRESETS[base])
    for q, u in chosen.items():
        if q not in CHOICES:
            raise ValueError(f"unknown quantity {q!r} (use one of: {', '.join(CHOICES)})")
        if u not in CHOICES[q]:
            raise ValueError(f"unit {u!r} is not a {q} unit (use one of: {', '.join(CHOICES[q])})")
        units[q] = u
    return DisplayUnits(units)
