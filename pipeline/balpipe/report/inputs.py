"""The inputs of a spec as a table: every scalar as balpipe read it (SI units), with the unit
taken from the field's declared dimension (:func:`balpipe.units.quantity`)."""

from __future__ import annotations

import typing

from pydantic import BaseModel
from pydantic.functional_validators import BeforeValidator  # noqa: F401 - the kind of metadata read
from pydantic.json_schema import WithJsonSchema

from ..units import SI
from .render import num


def _unit_of(metadata) -> str | None:
    for m in metadata or ():
        if isinstance(m, WithJsonSchema):
            desc = (m.json_schema or {}).get("description", "")
            dim = desc.split(" in ", 1)[0]
            if dim in SI:
                return SI[dim]
    return None


def _annotated_unit(tp) -> str | None:
    """The unit of an ``Annotated`` quantity type, looking through Optional/list/dict."""
    if typing.get_origin(tp) is typing.Annotated:
        return _unit_of(typing.get_args(tp)[1:])
    for arg in typing.get_args(tp):
        u = _annotated_unit(arg)
        if u is not None:
            return u
    return None


def _tuple_units(tp) -> str | None:
    """"m, m, rad" for a fixed tuple whose elements have different units (a pose), else None."""
    for arg in (typing.get_args(tp) if typing.get_origin(tp) is not tuple else (tp,)):
        if typing.get_origin(arg) is tuple:
            units = [_annotated_unit(a) or "" for a in typing.get_args(arg)]
            if Ellipsis not in typing.get_args(arg) and len(set(units)) > 1:
                return ", ".join(units)
    return None


def _walk(value, path: str, unit: str | None, out: list[dict]) -> None:
    if isinstance(value, BaseModel):
        for name, info in type(value).model_fields.items():
            u = _unit_of(info.metadata)
            if u is None:
                u = _tuple_units(info.annotation) or _annotated_unit(info.annotation)
            _walk(getattr(value, name), f"{path}.{name}" if path else name, u, out)
    elif isinstance(value, dict):
        for k in value:
            _walk(value[k], f"{path}.{k}", unit, out)
    elif isinstance(value, (list, tuple)):
        if value and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value):
            out.append({"path": path, "value": "(" + ", ".join(num(v) for v in value) + ")", "unit": unit or ""})
        else:
            for k, v in enumerate(value):
                _walk(v, f"{path}[{k}]", unit, out)
    elif isinstance(value, bool):
        out.append({"path": path, "value": "yes" if value else "no", "unit": ""})
    elif isinstance(value, (int, float)):
        out.append({"path": path, "value": num(value) if isinstance(value, float) else str(value), "unit": unit or ""})
    elif isinstance(value, str) and path.rsplit(".", 1)[-1] not in ("description", "note", "name", "paper"):
        out.append({"path": path, "value": value, "unit": ""})


def input_rows(spec: BaseModel) -> list[dict]:
    """Rows (path, value, unit) of every scalar the spec sets, mechanism, motion and balancing
    first, then the analysis, the external loads and the frame on its mounts (the compared
    designs' inputs are :func:`balpipe.report.notation_table.notation_rows`'); descriptions and
    notes are left to the YAML below the table."""
    out: list[dict] = []
    for part in ("mechanism", "motion", "balancing", "analysis", "loads", "frame"):
        if hasattr(spec, part):
            _walk(getattr(spec, part), part, None, out)
    return out
