"""The counterweights made as parts, for ``results.json`` (``parts``), the page's table and the
bill of materials (``parts.csv``).

A part is listed once per design however many of its stages carry it (a moment balance's
counterweights are on its force stage and on its counter-rotation stage); ``stages`` names them.
Everything is SI: m, kg, kg/m^3, kg m^2, rad.
"""

from __future__ import annotations

import csv
import io
import json
import re
from typing import Any

from ..display.numbers import num

#: the dimensions' columns of the bill of materials, in its order, with their SI unit
DIMENSIONS = (("thickness", "m"), ("radius", "m"), ("inner_radius", "m"), ("outer_radius", "m"), ("angle", "rad"),
              ("length", "m"), ("width", "m"), ("plates", ""), ("plate_thickness", "m"), ("orientation", "rad"))


def drawing_name(design: str, name: str) -> str:
    """The file name (without extension) of a part's drawings: ``part-<design>-<name>``, the
    name's characters outside [A-Za-z0-9_-] replaced by '_'."""
    return "part-" + re.sub(r"[^A-Za-z0-9_\-]", "_", f"{design}-{name}")


def parts_of(study: Any) -> list[tuple[str, list[str], Any]]:
    """(design, stage names, :class:`balpipe.mechanics.part_shapes.MadePart`) of every part of
    the study's stages, each once per design, in the stages' order."""
    seen: dict[tuple[str, str], tuple[str, list[str], Any]] = {}
    for s in study.stages:
        design = s.stage.design or "main"
        for p in s.stage.parts:
            key = (design, json.dumps(p.to_json(), sort_keys=True))
            seen.setdefault(key, (design, [], p))[1].append(s.stage.name)
    return list(seen.values())


def parts_json(study: Any) -> list[dict]:
    """``results.json``'s ``parts``: per part its design, stages, shape, material, density,
    dimensions, mass, centroid (in its body's frame), centroidal inertia, whether it fits and why
    not (located by its spec path), and its drawings' file names."""
    out = []
    for design, stages, p in parts_of(study):
        name = drawing_name(design, p.name)
        out.append({"design": design, "stages": stages, **p.to_json(),
                    "drawings": {"dxf": f"{name}.dxf", "svg": f"{name}.svg"} if p.outline else None})
    return out


def bom_csv(parts: list[dict]) -> str:
    """The bill of materials: one row per part of ``parts`` (:func:`parts_json`), SI units in
    the column names, 12 significant digits, empty cells where a dimension does not apply."""
    header = (["part", "design", "body", "shape", "material", "density_kg_per_m3", "mass_kg"]
              + [f"{k}_{u.replace('/', '_per_')}" if u else k for k, u in DIMENSIONS]
              + ["centroid_x_m", "centroid_y_m", "inertia_kg_m2", "fits", "problems", "drawing_dxf"])
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    w.writerow(header)

    def num(x: Any) -> str:
        return "" if x is None else f"{float(x):.12g}"

    for p in parts:
        dims = p["dimensions"]
        w.writerow([p["name"], p["design"], p["body"], p["shape"], p["material"], num(p["density"]), num(p["mass"])]
                   + [num(dims.get(k)) for k, _ in DIMENSIONS]
                   + [num(p["centroid"][0]), num(p["centroid"][1]), num(p["inertia"]), "yes" if p["fits"] else "no",
                      "; ".join(p["problems"]), (p["drawings"] or {}).get("dxf", "")])
    return buf.getvalue()


#: the dimensions the page shows, by the name it gives them, with their quantity
_SHOWN = {"thickness": ("t", "length"), "radius": ("r", "length"), "inner_radius": ("r_i", "length"),
          "outer_radius": ("r_o", "length"), "angle": ("angle", "angle"), "length": ("length", "length"),
          "width": ("width", "length"), "plates": ("plates", ""), "plate_thickness": ("each", "length")}


def page_rows(parts: list[dict], units: Any = None) -> list[dict]:
    """The page's table of parts (templates/parts.html): ``results.json``'s ``parts`` with their
    numbers as text in the page's display ``units`` (:class:`balpipe.display.units.DisplayUnits`,
    SI when None)."""
    from ..display.units import display_units

    u = units if units is not None else display_units()

    def shown(value: float, quantity: str) -> str:
        return u.text(value, quantity) if quantity else num(value)

    rows = []
    for p in parts:
        dims = ", ".join(f"{label} {shown(p['dimensions'][k], q)}" for k, (label, q) in _SHOWN.items()
                         if k in p["dimensions"])
        rows.append({
            "name": p["name"], "body": p["body"], "design": p["design"], "shape": p["shape"].replace("_", " "),
            "material": p["material"], "density": f"{num(p['density'], 6)} kg/m³", "dimensions": dims,
            "mass": u.text(p["mass"], "mass", digits=6), "centroid": u.point(p["centroid"]),
            "inertia": u.text(p["inertia"], "inertia"), "fits": p["fits"], "problems": "; ".join(p["problems"]),
            "where": p["where"], "svg": (p["drawings"] or {}).get("svg"), "dxf": (p["drawings"] or {}).get("dxf"),
        })
    return rows
