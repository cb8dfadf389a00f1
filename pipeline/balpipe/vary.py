"""What a sweep varies: ``--vary PATH=RANGE`` parsed into a :class:`Vary`, and the helpers that
read and set a field of a spec's data by its path (the sweep and the spec's ``sweep:`` block use
them)."""

from __future__ import annotations

import re

import numpy as np
from dataclasses import dataclass
from typing import Any

from .units import kinds_of

#: most values along one field (as many as a random sample's designs may have)
MAX_VALUES = 10_000_000

_NUM = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)\s*(.*?)\s*$")


class SweepError(Exception):
    """Bad sweep input, located (spec file, line, field, and the --vary argument)."""


@dataclass(frozen=True)
class Vary:
    """One ``--vary PATH=RANGE``: ``values`` for a grid, or ``lo``/``hi`` (numbers in ``unit``)."""

    arg: str
    path: tuple[str | int, ...]
    values: tuple = ()
    lo: float | None = None
    hi: float | None = None
    unit: str = ""
    origin: str = "--vary"  # or "sweep.vary": the spec's sweep block

    @property
    def where(self) -> str:
        """How messages name this vary: ``--vary PATH=RANGE``, or ``sweep.vary`` (the spec's block)."""
        return f"{self.origin} {self.arg}" if self.origin == "--vary" else self.origin

    @property
    def name(self) -> str:
        return ".".join(map(str, self.path))

    def raw(self, x: float) -> Any:
        """The spec value for the number x in this vary's unit."""
        return f"{float(x)!r} {self.unit}" if self.unit else float(x)

    def extremes(self) -> list:
        return list(self.values) if self.values else [self.raw(self.lo), self.raw(self.hi)]


def _number(text: str, arg: str) -> tuple[float, str]:
    m = _NUM.match(text)
    if not m:
        raise SweepError(f"{arg}: {text.strip()!r} is not a number with an optional unit")
    return float(m.group(1)), m.group(2)


def _conversion(frm: str, to: str, arg: str) -> float:
    """Factor from unit ``frm`` to unit ``to`` of the same dimension (HI given in another unit)."""
    a, b = kinds_of(frm), kinds_of(to)
    for kind in a:
        if kind in b:
            return a[kind] / b[kind]
    raise SweepError(f"{arg}: LO and HI have units of different kinds ({to!r}, {frm!r})")


def vary_count(arg: str) -> int | None:
    """How many values ``PATH=RANGE`` gives a grid, read without parsing a value (so a sweep's
    size is checked before any work): N of LO:HI:N, the number of a,b,c; None for LO:HI or a
    range that :func:`parse_vary` will refuse."""
    rng = arg.split("=", 1)[1] if "=" in arg else ""
    if "," in rng:
        return rng.count(",") + 1
    parts = rng.split(":")
    if len(parts) == 3 and parts[2].strip().isdigit() and len(parts[2].strip()) <= 30:
        return int(parts[2])
    return None


def parse_vary(arg: str, origin: str = "--vary", syntax_only: bool = False) -> Vary:
    """``PATH=RANGE`` -> :class:`Vary` (syntax only; :func:`plan` validates against the spec).
    Messages start with ``origin arg`` (``--vary PATH=RANGE``). N above :data:`MAX_VALUES` is
    refused before a value is made; ``syntax_only``: LO:HI:N is checked, its values not made."""
    tag = f"{origin} {arg}" if origin else arg
    if "=" not in arg:
        raise SweepError(f"{tag}: expected PATH=RANGE, e.g. mechanism.crank.mass=0.5kg:2kg:7")
    path_text, rng = arg.split("=", 1)
    path = tuple(int(p) if p.isdigit() else p for p in path_text.strip().split("."))
    if not path or any(p == "" for p in path):
        raise SweepError(f"{tag}: empty field in the path {path_text!r}")
    if "," in rng:
        vals = []
        unit0 = ""
        for part in rng.split(","):
            x, u = _number(part, tag)
            unit0 = u or unit0
            vals.append(x)
        return Vary(arg, path, tuple(f"{x!r} {unit0}" if unit0 else x for x in vals), unit=unit0, origin=origin)
    parts = rng.split(":")
    if len(parts) not in (2, 3):
        raise SweepError(f"{tag}: the range must be LO:HI:N, LO:HI or a,b,c")
    lo, ulo = _number(parts[0], tag)
    hi, uhi = _number(parts[1], tag)
    if ulo and uhi and ulo != uhi:
        hi = hi * _conversion(uhi, ulo, tag)
    unit = ulo or uhi
    if len(parts) == 3:
        try:
            n = int(parts[2])
        except ValueError:
            raise SweepError(f"{tag}: N must be an integer (got {parts[2]!r})") from None
        if n < 1:
            raise SweepError(f"{tag}: N must be at least 1")
        if n > MAX_VALUES:
            raise SweepError(f"{tag}: N = {n} is above the limit of {MAX_VALUES} values along one field")
        if syntax_only:
            return Vary(arg, path, (), lo, hi, unit, origin)
        xs = np.linspace(lo, hi, n) if n > 1 else np.array([lo])
        return Vary(arg, path, tuple(f"{float(x)!r} {unit}" if unit else float(x) for x in xs), unit=unit, origin=origin)
    return Vary(arg, path, (), lo, hi, unit, origin)


def set_path(data: Any, path: tuple, value: Any) -> None:
    """Set ``data[p0][p1]...`` = value; the last key may be new (an optional field)."""
    cur = data
    for k, p in enumerate(path[:-1]):
        try:
            cur = cur[p]
        except (KeyError, IndexError, TypeError):
            raise KeyError(path[: k + 1]) from None
    if isinstance(cur, dict):
        cur[path[-1]] = value
    elif isinstance(cur, list) and isinstance(path[-1], int) and path[-1] < len(cur):
        cur[path[-1]] = value
    else:
        raise KeyError(path)


def with_values(data: dict, paths: list[tuple], values: tuple) -> dict:
    """A copy of ``data`` with the values set, copying only the containers along the paths (the
    rest is shared with ``data``, which is never modified)."""
    d = dict(data)
    for path, value in zip(paths, values):
        cur = d
        for p in path[:-1]:
            try:
                nxt = cur[p]
            except (KeyError, IndexError, TypeError):
                break  # set_path reports it
            nxt = dict(nxt) if isinstance(nxt, dict) else list(nxt) if isinstance(nxt, list) else nxt
            cur[p] = nxt
            cur = nxt
        set_path(d, path, value)
    return d


def get_attr_path(obj: Any, path: tuple) -> Any:
    for p in path:
        obj = obj[p] if isinstance(p, int) or isinstance(obj, dict) else getattr(obj, p)
    return obj
