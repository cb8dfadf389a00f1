"""Jinja2 environment shared by the page and the site index."""

from __future__ import annotations

import math
import re
from functools import lru_cache
from importlib import resources

import jinja2

from .. import __version__


def num(x, digits: int = 4) -> str:
    """A number with ``digits`` significant digits; small and large ones in scientific form."""
    if x is None:
        return "—"
    x = float(x)
    if not math.isfinite(x):
        return str(x)
    if x == 0:
        return "0"
    if 1e-3 <= abs(x) < 1e6:
        return f"{x:.{digits}g}"
    return f"{x:.{max(1, digits - 1)}e}"


def ratio(x) -> str:
    """A ratio to the unbalanced peak: percent when readable, otherwise scientific."""
    if x is None:
        return "—"
    x = float(x)
    if x == 0:
        return "0"
    if abs(x) >= 10:
        return f"{x:.3g} ×"
    if abs(x) >= 1e-3:
        return f"{100 * x:.3g} %"
    return f"{x:.2e}"


_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x9f]")


def printable(text: str) -> str:
    """Text with its control characters shown as escapes (a file name may hold them): they never
    reach a page raw."""
    return _CONTROL.sub(lambda m: f"\\x{ord(m.group()):02x}", str(text))


def unit(u: str) -> str:
    """Display form of a unit: 'kg m^2' -> 'kg m²'."""
    return (u or "").replace("^2", "²").replace("^3", "³")


@lru_cache(maxsize=1)
def environment() -> jinja2.Environment:
    folder = resources.files("balpipe.templates")
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(folder)),
        autoescape=jinja2.select_autoescape(["html"]),
        undefined=jinja2.StrictUndefined,
        keep_trailing_newline=True,
    )
    env.filters["num"] = num
    env.filters["ratio"] = ratio
    env.filters["unit"] = unit
    env.filters["printable"] = printable
    env.globals["version"] = __version__
    return env
