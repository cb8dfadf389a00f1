"""The inputs of a study in the paper's notation: every scalar of the spec (as
:func:`balpipe.report.inputs.input_rows` reads it, in SI units) with the paper's symbol, a short
description, its value and unit, grouped (geometry, mass parameters, motion, balancing method,
analysis and validation) and keeping the spec's field path so the YAML can be searched for it.

The symbols come from the template's and the method's tables (:mod:`balpipe.notation`,
declared beside each template and method in the registry)."""

from __future__ import annotations

from typing import Any

from markupsafe import Markup, escape

from .. import notation as N
from .. import units
from ..plugins import resolved
from ..registry import METHODS, TEMPLATES
from .inputs import _walk, input_rows
from .render import num

_RATE_UNITS = {"angle": ("rad/s", "rad/s^2"), "length": ("m/s", "m/s^2"), "point": ("m/s", "m/s^2")}


def tables_for(mechanism: Any, balancing: Any) -> list[N.Table]:
    """The notation tables of a design, first match wins: method, template, common."""
    out = []
    method = METHODS.get(getattr(balancing, "method", ""))
    if method is not None:
        out.append(N.table_of(resolved(method.notation), balancing))
    template = TEMPLATES.get(mechanism.template)
    if template is not None:
        out.append(N.table_of(resolved(template.notation), mechanism))
    out.append(N.COMMON)
    return out


def names_for(spec: Any) -> "PageNames":
    """The names of a study's drivers, parts and joints on its pages, from its main design's
    tables (:class:`balpipe.notation.Names`): the paper's symbols where its family declares them."""
    return PageNames(N.Names(tuple(tables_for(spec.mechanism, spec.balancing))))


class PageNames:
    """:class:`balpipe.notation.Names` for the templates: ``driver(name)``, ``part(name)``,
    ``joint(name)``, ``param(name)`` give markup (the symbol, the model's name beside it); ``text(kind, name)``
    plain text for plots (``θ₁ [theta1]``)."""

    def __init__(self, names: N.Names):
        self.names = names

    def driver(self, name: str) -> Markup:
        return Markup(self.names.html("driver", name))

    def part(self, name: str) -> Markup:
        return Markup(self.names.html("part", name)) if isinstance(name, str) else name

    def param(self, name: str) -> Markup:
        return Markup(self.names.html("param", name))

    def joint(self, name: str) -> Markup:
        return Markup(self.names.html("joint", name)) if name else Markup("")

    def text(self, kind: str, name: str) -> str:
        return self.names.text(kind, name, spec_name=True)

    def link_texts(self, models: list) -> dict[str, str]:
        """Body name -> the text the mechanism drawings write for it: the paper's symbol of each
        link and disc whose symbol reads as plain text (``l₄₁``, ``link 11``, ``gear 1'``), so
        that a link has one name on the page (the card, the tables and every drawing)."""
        out = {}
        for model in models:
            for b in model.bodies:
                t = self.names.text("part", b.name)
                if t != b.name and "_" not in t:
                    out[b.name] = t
        return out


def _written_to_si(raw: Any, dimension: str | None) -> tuple[str, str] | None:
    """A drive's end value as written ("-80 deg", 0.2) converted to SI: (value, unit)."""
    if isinstance(raw, bool):
        return None
    if isinstance(raw, (int, float)):
        return num(raw), units.SI.get(dimension or "", "")
    if isinstance(raw, str):
        m = units.QUANTITY.match(raw)
        if m:
            kinds = units.kinds_of(m.group(2)) if units.normalise_unit(m.group(2)) else {}
            if kinds:
                dim, factor = next(iter(kinds.items()))  # the first table holding the unit, as before
                return num(float(m.group(1)) * factor), units.SI[dim]
    return None


def _drive_values(spec: Any) -> dict[str, tuple[str, str]]:
    """path -> (value, unit) of every drive's start and end (SI) and boundary rates."""
    out: dict[str, tuple[str, str]] = {}
    mech = spec.mechanism
    dims = mech.drives() if hasattr(mech, "drives") else {}
    for name, drive in spec.motion.drive.items():
        if not hasattr(drive, "start_velocity"):  # the laws of balpipe.laws: values and speed in SI
            for base, law, dim in ((name, drive, dims.get(name)), (f"{name}.timing", getattr(drive, "timing", None), "length")):
                for key in ("start", "end", "mean", "speed"):
                    raw = getattr(law, key, None)
                    conv = _written_to_si(raw, dim) if key != "speed" else (
                        (num(float(raw)), _RATE_UNITS.get(dim or "", ("SI",))[0]) if raw is not None else None)
                    if conv:
                        out[f"motion.drive.{base}.{key}"] = conv
            continue
        dim = dims.get(name)
        for key, raw in (("start", drive.start), ("end", drive.end)):
            path = f"motion.drive.{name}.{key}"
            if isinstance(raw, (list, tuple)):
                parts = [_written_to_si(r, "length" if dim == "point" else None) for r in raw]
                if all(parts):
                    us = [u for _, u in parts]
                    out[path] = ("(" + ", ".join(v for v, _ in parts) + ")",
                                 us[0] if len(set(us)) == 1 else ", ".join(us))
            else:
                conv = _written_to_si(raw, dim)
                if conv:
                    out[path] = conv
        rate = _RATE_UNITS.get(dim or "")
        for key, order in (("start_velocity", 0), ("end_velocity", 0), ("start_acceleration", 1), ("end_acceleration", 1)):
            out[f"motion.drive.{name}.{key}"] = (num(float(getattr(drive, key))),
                                                 rate[order] if rate else "SI per component")
    return out


def _idle_settings(spec: Any) -> set[str]:
    """Motion settings that have no effect with the laws in use (:func:`balpipe.motion.law_for`):
    the boundary rates of a drive whose law is not polynomial, the acceleration fraction when no
    law is trapezoidal. The table leaves them out (the YAML below still shows them)."""
    motion = spec.motion
    out, trapezoidal = set(), motion.law == "trapezoidal"
    for name, drive in motion.drive.items():
        law = drive.law or motion.law
        trapezoidal = trapezoidal or law == "trapezoidal"
        if law != "polynomial":
            out.update(f"motion.drive.{name}.{k}" for k in
                       ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration"))
    if not trapezoidal:
        out.add("motion.accel_fraction")
    return out


def _row(r: dict, sym: N.Sym | None, has_paper: bool) -> dict:
    leaf = r["path"].rsplit(".", 1)[-1]
    if sym is None:
        symbol, text, marked = Markup("<code>") + escape(leaf) + Markup("</code>"), "", False
    else:
        symbol, text = Markup(N.symbol_html(sym.symbol)), sym.text
        marked = has_paper and not sym.paper and not sym.setting
    unit = r["unit"] or (sym.unit if sym is not None and sym.unit else "")
    return {"path": r["path"], "symbol": symbol, "text": text, "text_html": Markup(N.text_html(text)),
            "not_in_paper": marked, "missing": sym is None, "value": r["value"], "unit": unit}


def notation_rows(spec: Any) -> list[dict]:
    """Every input of the spec with its symbol: dicts with path, symbol (HTML), text,
    not_in_paper, missing (no table has it), value, unit and group."""
    has_paper = bool(getattr(spec, "paper", None))
    tables = tables_for(spec.mechanism, spec.balancing)
    drives = _drive_values(spec)
    rows: list[dict] = []
    merged: set[str] = set()
    idle = _idle_settings(spec)
    for r in input_rows(spec):
        path = r["path"]
        base = path.split("[", 1)[0] if path.startswith("motion.drive.") else path
        if base in idle:
            continue
        if base in drives:
            if base in merged:
                continue
            merged.add(base)
            r = {"path": base, "value": drives[base][0], "unit": drives[base][1]}
        row = _row(r, N.lookup(tables, r["path"]), has_paper)
        row["group"] = N.group_of(r["path"], row["unit"])
        rows.append(row)
    extra: list[dict] = []
    if getattr(spec, "validation", None) is not None:
        _walk(spec.validation, "validation", None, extra)
    for r in extra:
        row = _row(r, N.lookup(tables, r["path"]), has_paper)
        row["group"] = N.group_of(r["path"], row["unit"])
        rows.append(row)
    for k, design in enumerate(getattr(spec, "compare", None) or []):
        design_rows: list[dict] = []
        _walk(design.balancing, "balancing", None, design_rows)
        dtables = tables_for(spec.mechanism, design.balancing)
        for r in design_rows:
            row = _row(r, N.lookup(dtables, r["path"]), has_paper)
            row["path"] = f"compare[{k}].{r['path']}"
            row["group"] = f"Compared design: {design.label or design.name}"
            rows.append(row)
    return rows


def notation_groups(spec: Any) -> list[dict]:
    """:func:`notation_rows` in groups, in the order of :data:`balpipe.notation.GROUPS` (then the
    compared designs): [{"name", "rows"}]."""
    rows = notation_rows(spec)
    names = list(N.GROUPS) + [r["group"] for r in rows if r["group"] not in N.GROUPS]
    out = []
    for name in dict.fromkeys(names):
        members = [r for r in rows if r["group"] == name]
        if members:
            out.append({"name": name, "rows": members})
    return out
