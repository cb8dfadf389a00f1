"""Jinja2 environment shared by the page and the site index."""

from __future__ import annotations

import re
from functools import lru_cache
from importlib import resources
from pathlib import Path

import jinja2
import markupsafe

from .. import __version__
from ..balancing.conditions import clarity_text
from ..display import numbers
from ..display.units import DisplayUnits
from ..display.numbers import num, tol  # noqa: F401  (the pages' filters, re-exported)
from . import template_build

#: the display units of a template rendered without a study's own (the index, the diff)
SI = DisplayUnits()


def ratio(x, tol: float | None = None) -> str:
    """A ratio to a reference, the site's one convention (:func:`balpipe.display.numbers.ratio`:
    percent below ten times, "×" from ten on). A ratio at or below ``tol`` (the stage's balance
    tolerance; the default floor 1e-9 without one) is round-off and shows as "0 (< 1e-9)"."""
    return numbers.ratio(x, numbers.FLOOR if tol is None else tol)


def _units(ctx) -> DisplayUnits:
    u = ctx.get("u")
    return u if isinstance(u, DisplayUnits) else SI


@jinja2.pass_context
def qty(ctx, x, quantity: str, scale=None, digits: int = 4) -> str:
    """``x`` (SI, of ``quantity``: 'force', 'N m', ...) as the page's display units show it (the
    template's ``u``, SI without one), without the unit; round-off of ``scale`` reads 0."""
    return _units(ctx).num(x, quantity, scale, digits)


@jinja2.pass_context
def qload(ctx, x, quantity: str, ref, tolerance, with_unit: bool = False, of: str = "reference") -> str:
    """A peak load in the page's display units (``with_unit``: and its unit), or "0 (< 1e-9 of
    reference)" at most ``tolerance`` times ``ref`` (:func:`load`; ``of`` names the reference)."""
    if x is not None and ref and tolerance is not None and abs(float(x)) <= float(tolerance) * abs(float(ref)):
        return load(x, ref, tolerance, of=of)
    u = _units(ctx)
    return u.text(x, quantity) if with_unit else u.num(x, quantity)


@jinja2.pass_context
def unit_of(ctx, quantity: str) -> str:
    """The page's display unit of ``quantity`` ('force', or an SI unit such as 'N m')."""
    return _units(ctx).unit(quantity) or unit(quantity)


def clarity(gap) -> str:
    """A singular-value gap in words: 'clear of round-off by a factor over 10¹⁴'."""
    return clarity_text(float(gap))


def load(x, ref, tolerance, unit_text: str = "", of: str = "reference") -> str:
    """A peak load: "0 (< 1e-9 of reference)" when it is at most ``tolerance`` times ``ref``
    (round-off of a balanced stage), otherwise :func:`num` with the unit."""
    if x is None:
        return "—"
    suffix = f" {unit_text}" if unit_text else ""
    if ref and tolerance is not None and abs(float(x)) <= float(tolerance) * abs(float(ref)):
        return f"0 (< {tol(tolerance)} of {of})"
    return num(x) + suffix


_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f]")


def printable(text: str) -> str:
    """Text with its control characters shown as escapes (a file name may hold them): they never
    reach a page raw."""
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", str(text))


def unit(u: str) -> str:
    """Display form of a unit: 'kg m^2' -> 'kg m²'."""
    return (u or "").replace("^2", "²").replace("^3", "³")


_UNIT_POWERS = (("kg m^2", "kg m²"), ("/s^2", "/s²"), ("m^2", "m²"))


def typeset(value):
    """Every value a template writes, with the units of free text (notes, captions, messages,
    which the balancing code writes in the specs' ASCII form 'kg m^2') in their display form,
    so one page never shows 'kg m^2' beside 'kg m²'. Only plain text:
    markup (drawings, scripts, data) passes unchanged, as does every other value."""
    if not isinstance(value, str) or isinstance(value, markupsafe.Markup) or "^2" not in value:
        return value
    for ascii_form, shown in _UNIT_POWERS:
        value = value.replace(ascii_form, shown)
    return value


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    """The pages' environment: the templates of ``balpipe/templates``, compiled when balpipe was
    built where they are (:func:`.template_build.loader`), the options and filters that
    :mod:`.template_build` names."""
    folder = resources.files("balpipe.templates")
    env = jinja2.Environment(loader=template_build.loader(Path(str(folder))), finalize=typeset,
                             **template_build.options())
    env.filters["num"] = num
    env.filters["ratio"] = ratio
    env.filters["tol"] = tol
    env.filters["num_at"] = numbers.num_at
    env.filters["qty"] = qty
    env.filters["qload"] = qload
    env.filters["unit_of"] = unit_of
    env.filters["clarity"] = clarity
    env.filters["load"] = load
    env.filters["unit"] = unit
    env.filters["printable"] = printable
    env.globals["version"] = __version__
    return env
