"""Quantities with units in specs: ``0.25 s``, ``30 deg``, ``12 g``, ``0.012 kg m^2``.

A bare number is taken in SI units. Strings are ``<number> <unit>``; the unit must belong to the
field's dimension, so ``"30 deg"`` in a length field is an error, not a silent 0.52 m.
Hand-written on purpose: six dimensions and a dozen units do not justify a units library's
import time in a tool that loads hundreds of specs.
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any

from pydantic import BeforeValidator, Field, WithJsonSchema

_LENGTH = {"m": 1.0, "mm": 1e-3, "cm": 1e-2, "km": 1e3}
_MASS = {"kg": 1.0, "g": 1e-3, "t": 1e3}
UNITS: dict[str, dict[str, float]] = {
    "length": _LENGTH,
    "angle": {"rad": 1.0, "deg": math.pi / 180, "°": math.pi / 180, "rev": 2 * math.pi, "turn": 2 * math.pi},
    "time": {"s": 1.0, "ms": 1e-3, "min": 60.0},
    "mass": _MASS,
    "inertia": {
        f"{mu} {lu}^2": mf * lf**2
        for mu, mf in _MASS.items()
        for lu, lf in _LENGTH.items()
        if lu != "km"
    },
    "acceleration": {"m/s^2": 1.0, "g0": 9.80665},
    "dimensionless": {"": 1.0},
}
SI = {"length": "m", "angle": "rad", "time": "s", "mass": "kg", "inertia": "kg m^2",
      "acceleration": "m/s^2", "dimensionless": ""}

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
_QTY = re.compile(rf"^\s*({_NUM})\s*(.*?)\s*$")


def _normalise_unit(unit: str) -> str:
    u = unit.replace("·", " ").replace("*", " ").replace("²", "^2").replace("**2", "^2")
    u = re.sub(r"\s+", " ", u).strip()
    return u.replace(" ^2", "^2")


def parse(value: Any, dimension: str) -> float:
    """Convert a number or a ``"<number> <unit>"`` string of ``dimension`` to SI."""
    if isinstance(value, bool):
        raise ValueError(f"expected a {dimension}, got a boolean")
    if isinstance(value, (int, float)):
        v = float(value)
    elif isinstance(value, str):
        m = _QTY.match(value)
        if not m:
            raise ValueError(f"expected a {dimension} like '{_example(dimension)}', got {value!r}")
        unit = _normalise_unit(m.group(2))
        table = UNITS[dimension]
        if unit == "" and dimension != "dimensionless":
            factor = 1.0
        elif unit in table:
            factor = table[unit]
        else:
            known = ", ".join(sorted(k for k in table if k)) or "none"
            raise ValueError(f"unit {m.group(2)!r} is not a {dimension} unit (use one of: {known})")
        v = float(m.group(1)) * factor
    else:
        raise ValueError(f"expected a {dimension} (number or string with a unit), got {type(value).__name__}")
    if not math.isfinite(v):
        raise ValueError(f"{dimension} must be finite")
    return v


def _example(dimension: str) -> str:
    return {"length": "0.2 m", "angle": "30 deg", "time": "0.25 s", "mass": "12 g",
            "inertia": "0.01 kg m^2", "acceleration": "9.81 m/s^2", "dimensionless": "0.5"}[dimension]


def quantity(dimension: str, **field_kwargs: Any) -> Any:
    """An annotated float field of ``dimension`` (accepts numbers in SI or strings with units)."""
    units = ", ".join(k for k in UNITS[dimension] if k)
    schema = {
        "anyOf": [
            {"type": "number"},
            {"type": "string", "pattern": rf"^\s*{_NUM}\s*[^\s].*$", "examples": [_example(dimension)]},
        ],
        "description": f"{dimension} in {SI[dimension] or 'SI'}, or a string with a unit ({units})",
    }
    return Annotated[
        float,
        BeforeValidator(lambda v: parse(v, dimension)),
        WithJsonSchema(schema),
        Field(**field_kwargs),
    ]


Length = quantity("length")
PositiveLength = quantity("length", gt=0)
NonNegativeLength = quantity("length", ge=0)
Angle = quantity("angle")
Duration = quantity("time", gt=0)
Mass = quantity("mass", ge=0)
PositiveMass = quantity("mass", gt=0)
Inertia = quantity("inertia", ge=0)
