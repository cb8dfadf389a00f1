"""A drawing per part: DXF (written by ezdxf, for CAD and the workshop) and SVG (for the page).

Both draw the part in its body's frame, in millimetres, so that the body's axis (a crank's) is at
the origin: the outline (layer ``OUTLINE``: one closed LWPOLYLINE whose arcs are bulges, exactly
the part's shape, so that its area times the thickness and the density is the part's mass and
its centroid the design's), the axis the part is laid out about and the body's pivots (layer
``PIVOTS``: a cross at the axis, a small circle per pivot) and a title (layer ``TEXT``: name,
material, thickness, mass). The DXF has ``$INSUNITS`` = 4 (mm).

Byte-identical on rebuild: ezdxf's creation and update dates, GUIDs and its version stamp are
written fixed (``ezdxf.options.write_fixed_meta_data_for_testing``, set only while the document is
made and written), the entities are added in one order, so their handles repeat, and the CLASSES
section is sorted by name (ezdxf lists the classes in use in a set's order, which depends on the
process's hash seed).
"""

from __future__ import annotations

import io
import math
from typing import Any

MM = 1e3  # the drawings' unit: mm per m


def _title(p: Any) -> str:
    return (f"{p.name} on {p.body}: {p.shape.replace('_', ' ')}, {p.material} ({p.density:g} kg/m^3), "
            f"t = {p.thickness * MM:.4g} mm, {p.mass:.6g} kg")


def dxf_text(part: Any) -> str:
    """The part's drawing as DXF R2010 text (:mod:`module docs <balpipe.report.part_drawings>`)."""
    import ezdxf  # only when a part is drawn

    before = ezdxf.options.write_fixed_meta_data_for_testing
    ezdxf.options.write_fixed_meta_data_for_testing = True  # fixed dates, GUIDs and stamps: the same bytes every build
    try:
        return _dxf(ezdxf, part)
    finally:
        ezdxf.options.write_fixed_meta_data_for_testing = before


def _dxf(ezdxf: Any, part: Any) -> str:
    doc = ezdxf.new("R2010", setup=False)
    doc.header["$INSUNITS"] = 4
    doc.header["$MEASUREMENT"] = 1
    for layer, colour in (("OUTLINE", 7), ("PIVOTS", 1), ("TEXT", 3)):
        doc.layers.add(layer, color=colour)
    msp = doc.modelspace()
    msp.add_lwpolyline([(x * MM, y * MM, b) for x, y, b in part.outline], format="xyb", close=True,
                       dxfattribs={"layer": "OUTLINE"})
    ax, ay = part.axis[0] * MM, part.axis[1] * MM
    size = _extent(part) * MM * 0.05
    msp.add_line((ax - size, ay), (ax + size, ay), dxfattribs={"layer": "PIVOTS"})
    msp.add_line((ax, ay - size), (ax, ay + size), dxfattribs={"layer": "PIVOTS"})
    for _, (x, y) in part.pivots:
        msp.add_circle((x * MM, y * MM), size / 2, dxfattribs={"layer": "PIVOTS"})
    msp.add_text(_title(part), height=size, dxfattribs={"layer": "TEXT", "insert": (ax, ay - 4 * size)})
    # ezdxf registers the CLASS entries of the entity types in use in a set's order, which varies
    # with the process's string hash seed: write once (every object and class is made), put the
    # classes in their names' order, and write again
    doc.write(io.StringIO())
    doc.classes.classes = dict(sorted(doc.classes.classes.items()))
    buf = io.StringIO()
    doc.write(buf)
    return buf.getvalue()


def _f(x: float) -> str:
    """x (mm) with 4 decimals, never "-0.0000"."""
    text = f"{x:.4f}"
    return "0.0000" if text == "-0.0000" else text


def _points(part: Any) -> list[tuple[float, float]]:
    """Points that bound the part's outline (its vertices and 16 points along each arc), its
    axis and its body's pivots (m)."""
    out = [(part.axis[0], part.axis[1])] + [p for _, p in part.pivots]
    n = len(part.outline)
    for k, (x0, y0, b) in enumerate(part.outline):
        x1, y1, _ = part.outline[(k + 1) % n]
        out.append((x0, y0))
        if b:  # the arc through its chord's ends, bulging by b = tan(sweep / 4)
            s = 4 * math.atan(b)
            chord = math.hypot(x1 - x0, y1 - y0)
            r = chord / (2 * math.sin(abs(s) / 2))
            h = r * math.cos(s / 2) * (1 if s > 0 else -1)  # centre left of the chord for a ccw arc
            cx, cy = (x0 + x1) / 2 - (y1 - y0) / chord * h, (y0 + y1) / 2 + (x1 - x0) / chord * h
            a0 = math.atan2(y0 - cy, x0 - cx)
            out += [(cx + r * math.cos(a0 + s * i / 16), cy + r * math.sin(a0 + s * i / 16)) for i in range(1, 16)]
    return out


def _extent(part: Any) -> float:
    pts = _points(part)
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    return max(max(xs) - min(xs), max(ys) - min(ys), 1e-6)


def svg_path(outline: tuple) -> str:
    """The outline as an SVG path in mm, y up turned y down (arcs from their bulges)."""
    n = len(outline)
    out = [f"M{_f(outline[0][0] * MM)},{_f(-outline[0][1] * MM)}"]
    for k in range(n):
        x0, y0, b = outline[k]
        x1, y1, _ = outline[(k + 1) % n]
        if b:
            s = 4 * math.atan(b)
            r = math.hypot(x1 - x0, y1 - y0) / (2 * math.sin(abs(s) / 2)) * MM
            # a ccw arc (y up) is clockwise once y points down: SVG's sweep flag 0
            out.append(f"A{_f(r)},{_f(r)} 0 {int(abs(s) > math.pi)} {0 if s > 0 else 1} {_f(x1 * MM)},{_f(-y1 * MM)}")
        else:
            out.append(f"L{_f(x1 * MM)},{_f(-y1 * MM)}")
    return " ".join(out) + " Z"


def svg_text(part: Any) -> str:
    """The part's drawing as a standalone SVG, in mm (the page shows it)."""
    pts = _points(part)
    xs, ys = [p[0] for p in pts], [p[1] for p in pts]
    pad = 0.08 * _extent(part)
    x0, x1 = (min(xs) - pad) * MM, (max(xs) + pad) * MM
    y0, y1 = (-max(ys) - pad) * MM, (-min(ys) + pad) * MM
    size = _extent(part) * MM * 0.05
    ax, ay = part.axis[0] * MM, -part.axis[1] * MM
    marks = [f'<path d="M{_f(ax - size)},{_f(ay)}H{_f(ax + size)}M{_f(ax)},{_f(ay - size)}V{_f(ay + size)}" '
             f'stroke="#c0392b" stroke-width="{_f(size / 5)}"/>']
    marks += [f'<circle cx="{_f(x * MM)}" cy="{_f(-y * MM)}" r="{_f(size / 2)}" fill="none" stroke="#c0392b" '
              f'stroke-width="{_f(size / 5)}"><title>pivot {name}</title></circle>' for name, (x, y) in part.pivots]
    w, h = x1 - x0, y1 - y0
    return (f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="{_f(x0)} {_f(y0)} {_f(w)} {_f(h)}" '
            f'width="240" height="{240 * h / w:.1f}" role="img" aria-label="{_esc(_title(part))}">'
            f"<title>{_esc(_title(part))} (mm, in the body's frame)</title>"
            f'<path d="{svg_path(part.outline)}" fill="#7f8c8d" fill-opacity="0.35" stroke="#2c3e50" '
            f'stroke-width="{_f(size / 4)}"/>' + "".join(marks) + "</svg>\n")


def _esc(text: str) -> str:
    return text.replace("&", "&amp;").replace("<", "&lt;").replace(">", "&gt;").replace('"', "&quot;")


def drawing_files(study: Any) -> dict[str, str]:
    """The drawings (DXF and SVG) of every part of the study that could be sized, by file name
    (:func:`balpipe.report.parts_table.drawing_name`)."""
    from .parts_table import drawing_name, parts_of

    out = {}
    for design, _, part in parts_of(study):
        if part.outline:
            name = drawing_name(design, part.name)
            out[f"{name}.dxf"] = dxf_text(part)
            out[f"{name}.svg"] = svg_text(part)
    return out
