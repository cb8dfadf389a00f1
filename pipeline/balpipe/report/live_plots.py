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

from ..draw import figures

POINTS = 400
DASHES = {"-": [], "--": [6, 3], "-.": [8, 3, 2, 3], ":": [2, 2]}  # matplotlib's line styles as canvas dashes


def _thin(n: int) -> np.ndarray:
    return np.unique(np.linspace(0, n - 1, min(n, POINTS)).round().astype(int))


def _round(values) -> list[float]:
    return [float(f"{v + 0.0:.6g}") for v in np.asarray(values, dtype=float)]


def line_style(k: int) -> dict:
    """Stage ``k``'s line as the static figures draw it (:func:`balpipe.draw.figures.style`): its
    colour, dashes and width, so a style means the same stage in every figure of the page."""
    from matplotlib.colors import to_hex

    st = figures.style(k)
    return {"stroke": to_hex(st["color"]), "dash": DASHES.get(st["linestyle"], []), "width": st["linewidth"]}


def loads_data(stages: list) -> dict:
    """``stages``: (label, analysis). Panels |F| (N) and M (N m) over time, one series per stage,
    each in its stage's line style."""
    t = np.asarray(stages[0][1].t, dtype=float)
    k = _thin(len(t))
    series = []
    for n, (label, an) in enumerate(stages):
        series.append({"label": label, "F": _round(np.hypot(an.force[k, 0], an.force[k, 1])),
                       "M": _round(an.moment[k]), **line_style(n)})
    return {"t": _round(t[k]), "series": series,
            "panels": [{"key": "F", "title": "shaking force |F|", "unit": "N"},
                       {"key": "M", "title": "shaking moment M", "unit": "N m"}]}


def as_script(data: dict) -> str:
    """JSON safe inside a ``<script type="application/json">`` element."""
    text = json.dumps(data, separators=(",", ":"), sort_keys=True, ensure_ascii=False)
    return text.replace("</", "<\\/").replace("<!--", "<\\!--")
