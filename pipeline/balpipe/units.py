"""Quantities with units in specs: ``0.25 s``, ``30 deg``, ``12 g``, ``0.012 kg m^2``.

A bare number is taken in SI units. Strings are ``<number> <unit>``; the unit must belong to the
field's dimension, so ``"30 deg"`` in a length field is an error, not a silent 0.52 m, and a
string without a unit (``"0.2"``) is an error too (write ``0.2 m`` or the bare number 0.2).

Every numeric spec field is one of the types below (:func:`quantity`, :func:`number`,
:func:`count`, :data:`Sign`, :data:`Rate`): they refuse booleans, NaN and infinities, and
magnitudes beyond :data:`MAX_ABS` (stated limits: a 1e300 m link would overflow the engine), with
a message that names the field's kind and the limit.
Hand-written on purpose: a few dimensions and a dozen units do not justify a units library's
import time in a tool that loads hundreds of specs.
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Callable

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
    "acceleration": {"m/s^2": 1.0, "mm/s^2": 1e-3, "cm/s^2": 1e-2, "g0": 9.80665},
    "velocity": {"m/s": 1.0, "mm/s": 1e-3, "cm/s": 1e-2},
    "angular velocity": {"rad/s": 1.0, "deg/s": math.pi / 180, "rpm": math.pi / 30, "rev/s": 2 * math.pi},
    "angular acceleration": {"rad/s^2": 1.0, "deg/s^2": math.pi / 180},
    "force": {"N": 1.0, "kN": 1e3, "MN": 1e6, "lbf": 4.4482216152605},
    "torque": {"N m": 1.0, "kN m": 1e3, "N mm": 1e-3},
    "pressure": {"Pa": 1.0, "kPa": 1e3, "MPa": 1e6, "bar": 1e5, "psi": 6894.757293168},
    "area": {"m^2": 1.0, "cm^2": 1e-4, "mm^2": 1e-6},
    "stiffness": {"N/m": 1.0, "N/mm": 1e3, "kN/m": 1e3, "kN/mm": 1e6},
    "damping": {"N s/m": 1.0, "N s/mm": 1e3, "kN s/m": 1e3},
    "torsional stiffness": {"N m/rad": 1.0, "N m/deg": 180 / math.pi, "kN m/rad": 1e3},
    "torsional damping": {"N m s/rad": 1.0, "N m s/deg": 180 / math.pi},
    "density": {"kg/m^3": 1.0, "g/cm^3": 1e3, "kg/dm^3": 1e3},
    "dimensionless": {"": 1.0},
}
SI = {"length": "m", "angle": "rad", "time": "s", "mass": "kg", "inertia": "kg m^2",
      "acceleration": "m/s^2", "velocity": "m/s", "angular velocity": "rad/s",
      "angular acceleration": "rad/s^2", "force": "N", "torque": "N m", "pressure": "Pa", "area": "m^2",
      "stiffness": "N/m", "damping": "N s/m", "torsional stiffness": "N m/rad",
      "torsional damping": "N m s/rad", "density": "kg/m^3", "dimensionless": ""}

#: Largest magnitude accepted per dimension, in SI units: beyond these a planar mechanism is not
#: what the spec means, and products such as m L^2 w^2 approach float overflow.
MAX_ABS = {"length": 1e4, "angle": 1e5, "time": 1e5, "mass": 1e6, "inertia": 1e12,
           "acceleration": 1e7, "velocity": 1e6, "angular velocity": 1e6,
           "angular acceleration": 1e9, "force": 1e9, "torque": 1e9, "pressure": 1e10, "area": 1e4,
           "stiffness": 1e12, "damping": 1e12, "torsional stiffness": 1e12, "torsional damping": 1e12,
           "density": 1e5, "dimensionless": 1e12}

_NUM = r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?"
#: a quantity as written, "<number> <unit>": group 1 the number, group 2 the unit (may be empty)
QUANTITY = re.compile(rf"^\s*({_NUM})\s*(.*?)\s*$")


def normalise_unit(unit: str) -> str:
    """A unit written in one form: '·', '*' -> ' ', '²', '**2' -> '^2', spaces collapsed
    ('kg · m²' -> 'kg m^2'), as the unit tables key them."""
    u = unit.replace("·", " ").replace("*", " ").replace("²", "^2").replace("**2", "^2")
    u = re.sub(r"\s+", " ", u).strip()
    return u.replace(" ^2", "^2")


def kinds_of(unit: str) -> dict[str, float]:
    """The dimensions whose unit tables hold ``unit`` (after normalising its spelling), in the
    order of :data:`UNITS`, each with the unit's factor to SI ({} for an unknown unit)."""
    u = normalise_unit(unit)
    return {kind: table[u] for kind, table in UNITS.items() if u in table}


def parse(value: Any, dimension: str) -> float:
    """Convert a number or a ``"<number> <unit>"`` string of ``dimension`` to SI.

    Refuses booleans, NaN, infinities, strings without a unit (but for dimensionless values)
    and magnitudes above :data:`MAX_ABS`, with a message saying what is expected."""
    kind = "number" if dimension == "dimensionless" else dimension
    a = "an" if kind[0] in "aeiou" else "a"
    if isinstance(value, bool):
        raise ValueError(f"expected {a} {kind}, got a boolean ({str(value).lower()})")
    if isinstance(value, (int, float)):
        try:
            v = float(value)
        except OverflowError:
            raise ValueError(f"{kind} too large (got an integer of {len(str(abs(value)))} digits)") from None
    elif isinstance(value, str):
        m = QUANTITY.match(value)
        if not m:
            low = value.strip().lower().lstrip("+-.")
            if low in ("nan", "inf", "infinity"):
                raise ValueError(f"{kind} must be a finite number, got {value!r}")
            raise ValueError(f"expected {a} {kind} like '{_example(dimension)}', got {value!r}")
        unit = normalise_unit(m.group(2))
        table = UNITS[dimension]
        if unit == "" and dimension != "dimensionless":
            raise ValueError(
                f"{value.strip()!r} has no unit: write '{m.group(1)} {SI[dimension]}' or the bare number "
                f"{m.group(1)} (SI units)"
            )
        elif unit in table:
            factor = table[unit]
        else:
            known = ", ".join(sorted(k for k in table if k)) or "none"
            raise ValueError(f"unit {m.group(2)!r} is not {a} {kind} unit (use one of: {known})")
        v = float(m.group(1)) * factor
    else:
        what = {"dict": "a mapping", "list": "a list", "NoneType": "nothing (null)"}.get(
            type(value).__name__, type(value).__name__)
        raise ValueError(f"expected {a} {kind} (a number{'' if dimension == 'dimensionless' else ' or a string with a unit'}), got {what}")
    if not math.isfinite(v):
        raise ValueError(f"{kind} must be a finite number, got {value!r}")
    if abs(v) > MAX_ABS[dimension]:
        u = f" {SI[dimension]}" if SI[dimension] else ""
        raise ValueError(f"{kind} out of range: |{v:.4g}|{u} exceeds the limit {MAX_ABS[dimension]:g}{u}")
    return v


def _example(dimension: str) -> str:
    return {"length": "0.2 m", "angle": "30 deg", "time": "0.25 s", "mass": "12 g",
            "inertia": "0.01 kg m^2", "acceleration": "9.81 m/s^2", "velocity": "0.5 m/s",
            "angular velocity": "2 rad/s", "angular acceleration": "10 rad/s^2",
            "force": "250 N", "torque": "12 N m", "pressure": "6 bar", "area": "50 cm^2",
            "stiffness": "2 kN/m", "damping": "40 N s/m", "torsional stiffness": "5 N m/rad",
            "torsional damping": "0.2 N m s/rad", "density": "7850 kg/m^3", "dimensionless": "0.5"}[dimension]


def quantity(dimension: str, **field_kwargs: Any) -> Any:
    """An annotated float field of ``dimension`` (accepts numbers in SI or strings with units).

    The generic numeric field type of specs: finite, no booleans, units of its kind, bounded
    by :data:`MAX_ABS`; ``field_kwargs`` add pydantic bounds (``gt``, ``ge``, ``le``, ...).
    Use it bare (``x: Length``) or as ``x: quantity("time", gt=0) = Field(...)``; never nested
    inside another ``Annotated[float, ...]`` (pydantic would then skip the unit parser)."""
    schema: dict[str, Any]
    if dimension == "dimensionless":
        schema = {"type": "number", "description": "a finite number"}
    else:
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


def number(**field_kwargs: Any) -> Any:
    """A finite dimensionless number field (no booleans, no NaN or infinities)."""
    return quantity("dimensionless", **field_kwargs)


def _parse_count(value: Any) -> int:
    if isinstance(value, bool):
        raise ValueError(f"expected a whole number, got a boolean ({str(value).lower()})")
    if isinstance(value, int):
        return value
    if isinstance(value, str):
        try:
            value = float(value.strip())
        except ValueError:
            raise ValueError(f"expected a whole number, got {value!r}") from None
    if isinstance(value, float):
        if math.isfinite(value) and value == int(value) and abs(value) < 2**53:
            return int(value)
        raise ValueError(f"expected a whole number, got {value!r}")
    raise ValueError(f"expected a whole number, got {type(value).__name__}")


def count(**field_kwargs: Any) -> Any:
    """A whole-number field (samples, iterations): no booleans, no fractions; bounds as kwargs."""
    return Annotated[int, BeforeValidator(_parse_count), Field(**field_kwargs)]


def _parse_sign(value: Any) -> int:
    if isinstance(value, bool) or value not in (1, -1) or not isinstance(value, (int, float)):
        raise ValueError(f"expected +1 or -1, got {value!r}")
    return int(value)


#: +1 or -1 (working and assembly modes, branches); booleans and other numbers refused.
Sign = Annotated[int, BeforeValidator(_parse_sign), WithJsonSchema({"enum": [1, -1]})]


class RateValue(float):
    """A boundary velocity or acceleration in SI, remembering whether its unit was linear
    (``m/s``), angular (``rad/s``) or absent (a bare SI number), so that the drive it belongs to
    can refuse ``rad/s`` on a slider (:func:`check_rate`)."""

    kind: str | None = None

    def __new__(cls, value: float, kind: str | None) -> "RateValue":
        obj = super().__new__(cls, value)
        obj.kind = kind
        return obj

    def __reduce__(self) -> tuple[type["RateValue"], tuple[float, str | None]]:  # pickled into build workers
        return (RateValue, (float(self), self.kind))


def _rate_parser(order: int) -> Callable[[Any], RateValue]:
    dims = ("velocity", "angular velocity") if order == 1 else ("acceleration", "angular acceleration")

    def parse_rate(value: Any) -> RateValue:
        if isinstance(value, RateValue):
            return value
        if isinstance(value, str):
            m = QUANTITY.match(value)
            unit = normalise_unit(m.group(2)) if m else ""
            for dim in dims:
                if unit and unit in UNITS[dim]:
                    return RateValue(parse(value, dim), dim)
            if m and unit:
                known = ", ".join(k for d in dims for k in UNITS[d])
                raise ValueError(f"unit {m.group(2)!r} is not a {dims[0]} unit (use one of: {known})")
        return RateValue(parse(value, dims[0]) if isinstance(value, str) else parse(value, "dimensionless"), None)

    return parse_rate


def _rate(order: int) -> Any:
    what = "velocity" if order == 1 else "acceleration"
    units = ", ".join(k for d in (("velocity", "angular velocity") if order == 1 else ("acceleration", "angular acceleration")) for k in UNITS[d])
    schema = {"anyOf": [{"type": "number"}, {"type": "string", "pattern": rf"^\s*{_NUM}\s*[^\s].*$"}],
              "description": f"{what} of the driven coordinate in SI (rad or m based), or a string with a unit ({units})"}
    # Any, not float: pydantic's float validator would drop the RateValue's unit kind
    return Annotated[Any, BeforeValidator(_rate_parser(order)), WithJsonSchema(schema)]


#: Boundary velocity / acceleration of a drive: SI number, or a linear or angular unit.
Rate = _rate(1)
RateRate = _rate(2)


def check_rate(value: float, coordinate: str) -> None:
    """Raise ValueError when ``value`` (a :class:`RateValue`) has a unit of the wrong kind for a
    coordinate of dimension ``coordinate`` ("angle" or "length")."""
    kind = getattr(value, "kind", None)
    if kind is None:
        return
    angular = kind.startswith("angular")
    if angular != (coordinate == "angle"):
        raise ValueError(f"a {'angular' if angular else 'linear'} unit on a coordinate that is a {coordinate}")


Length = quantity("length")
PositiveLength = quantity("length", gt=0)
NonNegativeLength = quantity("length", ge=0)
Angle = quantity("angle")
Duration = quantity("time", gt=0)
Mass = quantity("mass", ge=0)
PositiveMass = quantity("mass", gt=0)
Inertia = quantity("inertia", ge=0)
Acceleration = quantity("acceleration")
Number = number()
PositiveNumber = number(gt=0)
AccelFraction = number(gt=0, le=0.5)  # a trapezoidal law's acceleration time, of the segment's
Cycles = number(gt=0, le=10_000)  # a motion's number of periods
Stiffness = quantity("stiffness", ge=0)  # a mount's, along one axis
Damping = quantity("damping", ge=0)
PositiveInertia = quantity("inertia", gt=0)
PositiveVelocity = quantity("velocity", gt=0)
PositiveForce = quantity("force", gt=0)
OpenFraction = number(gt=0, lt=1)  # strictly between 0 and 1
Density = quantity("density", gt=0)  # a part's material
PlateCount = count(ge=1, le=1000)  # the plates of a bolted stack
