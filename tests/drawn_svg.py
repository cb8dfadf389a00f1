"""Read a drawing of :mod:`balpipe.draw.canvas` back from its SVG, as a browser draws it: the
placed names' boxes, the solid links, the discs. Coordinates are the SVG's (points, y down)."""

from __future__ import annotations

import re
import xml.etree.ElementTree as ET

NS = "{http://www.w3.org/2000/svg}"


def _segments(d: str) -> list[tuple[tuple[float, float], tuple[float, float]]]:
    """The straight segments of path data made of M and L commands."""
    segs, last = [], None
    for cmd, x, y in re.findall(r"([ML])(-?[\d.]+) (-?[\d.]+)", d):
        p = (float(x), float(y))
        if cmd == "L" and last is not None:
            segs.append((last, p))
        last = p
    return segs


def read(svg: str) -> dict:
    """``names``: (text, box (x0, y0, x1, y1)) of every placed name, its white box as drawn;
    ``links``: the segments of the solid links (class ``link``); ``outlines``: the edges of the
    filled polygons that are no markers (platforms, sleeves, slider blocks); ``discs``: (centre,
    radius) of the filled discs that are no markers (counterweights);
    ``panels``: the clip rectangles (x0, y0, x1, y1), one per panel drawn."""
    root = ET.fromstring(svg)
    names, links, outlines, discs, panels = [], [], [], [], []
    for g in root.iter(f"{NS}g"):
        if g.get("class") == "name":
            rect, text = g.find(f"{NS}rect"), g.find(f"{NS}text")
            x, y, w, h = (float(rect.get(k)) for k in ("x", "y", "width", "height"))
            names.append((text.text, (x, y, x + w, y + h)))
    for p in root.iter(f"{NS}path"):
        if p.get("class") == "link":
            links += _segments(p.get("d"))
    for poly in root.iter(f"{NS}polygon"):
        pts = [tuple(map(float, q.split(","))) for q in poly.get("points").split()]
        if poly.get("fill") not in (None, "none") and poly.get("class") != "marker":
            outlines += [(pts[k], pts[(k + 1) % len(pts)]) for k in range(len(pts))]
    for c in root.iter(f"{NS}circle"):
        if c.get("fill") not in (None, "none") and c.get("class") != "marker":
            discs.append(((float(c.get("cx")), float(c.get("cy"))), float(c.get("r"))))
    for clip in root.iter(f"{NS}clipPath"):
        r = clip.find(f"{NS}rect")
        x, y, w, h = (float(r.get(k)) for k in ("x", "y", "width", "height"))
        panels.append((x, y, x + w, y + h))
    return {"names": names, "links": links, "outlines": outlines, "discs": discs, "panels": panels}
