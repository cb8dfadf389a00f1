"""Interactive plots (issue 22): the data of a page's shaking-load curves as JSON, drawn in the
browser by uPlot (MIT, https://github.com/leeoniya/uPlot, shipped inside the page as
``templates/uplot.iife.min.js``, about 50 KB: no network, works from ``file://``): hover shows
the time and every curve's value, drag to zoom (double-click resets), a click on a legend entry
hides its curve, and the cursor follows the player's time. The static SVG of the same curves
stays in the page for printing and for readers without JavaScript.

The curves are thinned to at most :data:`POINTS` samples (evenly spaced, first and last kept)
and rounded to 6 significant digits: deterministic, and light (a page stays far below 2 MB).
"""

from __future__ import annotations

import json

import numpy as np

POINTS = 400


def _thin(n: int) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, POINTS)).round().astype(int))


def _round(values) -> list[float]:
    return [float(f"{v + 0.0:.6g}") for v in np.asarray(values, dtype=float)]


def loads_data(stages: list) -> dict:
    """``stages``: (label, analysis). Panels |F| (N) and M (N m) over time, one series per stage."""
    t = np.asarray(stages[0][1].t, dtype=float)
    k = _thin(len(t))
    series = []
    for label, an in stages:
        series.append({"label": label, "F": _round(np.hypot(an.force[k, 0], an.force[k, 1])),
                       "M": _round(an.moment[k])})
    return {"t": _round(t[k]), "series": series,
            "panels": [{"key": "F", "title": "shaking force |F|", "unit": "N"},
                       {"key": "M", "title": "shaking moment M", "unit": "N m"}]}


def as_script(data: dict) -> str:
    """JSON safe inside a ``<script type="application/json">`` element."""
    text = json.dumps(data, separators=(",", ":"), sort_keys=True, ensure_ascii=False)
    return text.replace("</", "<\\/").replace("<!--", "<\\!--")
