"""Interactive plots: the curves of a time-series figure as JSON, drawn in the browser
by uPlot (MIT, https://github.com/leeoniya/uPlot, shipped inside the page as
``templates/uplot.iife.min.js``, about 50 KB: no network, works from ``file://``) with one
script for every figure (``templates/live_plots.js``): hover shows the time and every curve's
value, drag to zoom (double-click resets), a click on a legend entry hides its curve; where the
page has a player, its time moves every plot's cursor and a click in a plot sets the player's
time. Printing prints these plots themselves, redrawn at the printed width and a pixel ratio that
prints sharply (``live_plots.js``); no static figure of the same curves is written (it would
double a page's weight and its build time). Without JavaScript a line in the plot's place says
where the numbers are (:data:`NUMBERS`).

A figure's curves are a :class:`Curves`; :func:`data` thins them to at most :data:`POINTS`
samples (evenly spaced, first and last kept; fewer for a figure of many curves, :data:`VALUES`)
and rounds them to 6 significant digits (round-off, below 1e-9 of a panel's largest value, to 0): deterministic, and light (a page stays below 2 MB).
:func:`html` writes the live element and the JSON together. Here, below the
report, so that a family's own figures (a paper's time series) are interactive too; the page's
generic figures build their curves in :mod:`balpipe.report.live_plots`.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
from contextlib import contextmanager
from contextvars import ContextVar
from typing import Iterator, NamedTuple

import numpy as np

from ..display import csv_numbers
from ..display.units import CHOICES, OF_SI_UNIT, DisplayUnits
from ..mechanics.sampling import spread_indices
from . import figures
from .stage_names import short_names

POINTS = 400  # samples a curve keeps at most
VALUES = 20_000  # values a figure keeps at most (curves x samples): fewer samples for a figure of many curves
MIN_POINTS = 100
DASHES = {"-": [], "--": [6, 3], "-.": [8, 3, 2, 3], ":": [2, 2]}  # matplotlib's line styles as canvas dashes


def _thin(n: int, curves: int = 1) -> np.ndarray:
    """The kept samples of ``n``, evenly spaced, first and last kept: :data:`POINTS` at most, fewer
    (not below :data:`MIN_POINTS`) when a figure's ``curves`` would exceed :data:`VALUES`."""
    keep = max(MIN_POINTS, min(POINTS, VALUES // max(1, curves)))
    return spread_indices(n, keep)


def _round(values, floor: float = 0.0) -> list[float | None]:
    """6 significant digits; a missing value (NaN) as null, the one JSON has; a value within the
    panel's round-off ``floor`` (:func:`_floor`) as 0: the plot cannot tell it from 0 and the
    hover reads "0 (< tolerance)" either way, and a balanced stage's 1.23457e-13 costs 12 bytes
    a sample."""
    a = np.asarray(values, dtype=float).ravel() + 0.0  # + 0.0: no "-0"
    finite = np.isfinite(a)
    out = np.zeros(a.shape)
    kept = finite & (np.abs(a) > floor)
    if kept.any():  # one format string for all, each value parsed (both correctly rounded): as float(f"{v:.6g}") each
        # (float() on the words: a third of numpy's parse of the same strings, the same floats)
        out[kept] = list(map(float, (("%.6g " * int(kept.sum())) % tuple(a[kept].tolist())).split()))
    shown = out.tolist()
    return shown if finite.all() else [v if ok else None for v, ok in zip(shown, finite.tolist())]


ROUND_OFF = 1e-9  # of a panel's largest value: what the hover shows as 0 (< tolerance), as the tables do


#: a log panel's values down to this fraction of its largest (the round-off of a double below it:
#: a residual of 8e-322 is a zero's), below which it has none; uPlot drew no plot at all on the
#: 318 decades that one such value gave a residual panel of custom_pick_and_place_cycle.yaml
LOG_RANGE = 1e-16


def _peak(c: Curves, key: str) -> float:
    """The panel's largest |value| over every stage (0 when it has none)."""
    return max((float(np.nanmax(np.abs(np.asarray(curves[key], dtype=float)), initial=0.0))
                for _, curves in c.stages if key in curves), default=0.0)


def _floor(c: Curves, key: str) -> float:
    """The panel's round-off floor: :data:`ROUND_OFF` of its largest |value| over every stage
    (0 when it has none), below which the hover reads "0 (< tolerance)" instead of a number
    such as 1.9e-13 N m (a balanced stage's residual)."""
    return float(f"{ROUND_OFF * _peak(c, key):.3g}")


def line_style(k: int | dict) -> dict:
    """Stage ``k``'s line as the page's other figures draw it (:func:`balpipe.draw.figures.style`):
    its colour, dashes and width, so a style means the same stage in every figure of the page; or
    ``k`` a line style of its own (matplotlib's ``color``, ``linestyle``, ``linewidth``: a
    stage's pymunk run)."""
    from matplotlib.colors import to_hex

    st = k if isinstance(k, dict) else figures.style(k)
    return {"stroke": to_hex(st["color"]), "dash": DASHES.get(st["linestyle"], []), "width": st["linewidth"]}


def markers(k: int, n: int) -> dict:
    """Stage ``k``'s markers over ``n`` drawn samples (:func:`balpipe.draw.figures.marked`): its
    symbol (matplotlib's letter, which ``live_plots.js`` draws) at every ``every`` sample from
    ``start``, staggered per stage so that curves that coincide stay apart."""
    st = figures.marked(k, n)
    start, every = st["markevery"]
    return {"marker": [st["marker"], int(start), int(every)]}


def swatch(k: int) -> dict:
    """Stage ``k``'s legend swatch as the page's key and every plot's legend draw it
    (``live_plots.js``): ``stroke`` (hex), ``dash`` (canvas dashes, comma-separated), ``width``
    and ``marker`` (matplotlib's letter), the same as its curves (:func:`line_style`,
    :func:`markers`)."""
    st = line_style(k)
    return {"stroke": st["stroke"], "dash": ",".join(f"{d:g}" for d in st["dash"]), "width": st["width"],
            "marker": figures.marker(k)}


class Curves(NamedTuple):
    """The curves of one figure, before thinning: a panel per dict of ``panels`` (``key``,
    ``title`` and ``axis`` label, each with its unit), a curve per stage and panel."""

    t: np.ndarray  # the stages' common sample times (s)
    stages: list  # (label, key -> values over t); a stage without a panel's key has no curve there
    panels: list
    marks: list  # (time, label): kinematic warnings, dotted vertical lines
    styles: list | None = None  # each stage's line style index (its place in the page's stage table); None: 0, 1, ...
    # a figure of many panels (a joint per panel): shown one panel at a time, a selector above
    # choosing which (or every one), this panel first; None: every panel shown
    choose: int | None = None
    # each stage's markers (:func:`markers`) on its curve: always on a plot over time (a stage keeps
    # its marker in every figure, as the page's key says); a series of an explicit style (a dict) has none
    markers: bool = True
    # a figure over another quantity than time (a Pareto front over its budget): the x axis's
    # label with its unit; such a figure is not linked to the player, keeps every sample, draws a
    # marker at every value (a curve across the samples where it has none) and the stages of
    # ``points`` (each a single design) as markers alone
    x_axis: str = ""
    points: tuple = ()
    # the panels side by side where the page is wide enough (as a figure of more than two panels)
    grid: bool = False
    # each stage's name in the legend (:func:`balpipe.draw.stage_names.short_names` of the labels
    # when empty); the label itself is the legend entry's tooltip
    names: tuple = ()
    # the stages that are simulation runs (pymunk): hidden until the figure's toggle shows them
    simulated: tuple = ()


def data(c: Curves) -> dict:
    """The JSON of one interactive figure: a plot per panel, one series per stage in its stage's
    line style (:func:`line_style`; null where the stage has no such curve), named by its short
    name (``label``) with its long label (``long``) where they differ, a simulation run marked
    ``sim`` (hidden until shown); every curve thinned to the same samples (:func:`_thin`) and
    rounded to 6 significant digits."""
    t = np.asarray(c.t, dtype=float)
    k = (np.arange(len(t)) if c.x_axis else
         _thin(len(t), sum(p["key"] in curves for _, curves in c.stages for p in c.panels)))
    # a panel on a log axis (``"log": True``: residuals) keeps its small values, which are what it
    # shows, down to :data:`LOG_RANGE` of its largest; none at or below that (null: a gap)
    floors = {p["key"]: 0.0 if p.get("log") else _floor(c, p["key"]) for p in c.panels}
    cuts = {p["key"]: LOG_RANGE * _peak(c, p["key"]) for p in c.panels if p.get("log")}

    def values(p: dict, y) -> list:
        out = _round(np.asarray(y, dtype=float)[k], floors[p["key"]])
        return [v if v is not None and v > cuts[p["key"]] else None for v in out] if p.get("log") else out

    labels = [label for label, _ in c.stages]
    names = list(c.names) if c.names else short_names(labels)
    series = [{"label": names[n], "y": {p["key"]: values(p, curves[p["key"]]) for p in c.panels if p["key"] in curves},
               **line_style(n), **({"long": label} if label != names[n] else {}),
               **({"sim": True} if n in c.simulated else {})}
              for n, (label, curves) in enumerate(c.stages)]
    if c.styles is not None:
        for one, style in zip(series, c.styles):
            one.update(line_style(style))
    if c.markers:  # over another quantity too (the history's commits): the stage's marker, as the page's key
        for n, one in enumerate(series):
            style = n if c.styles is None else c.styles[n]
            if not isinstance(style, dict):
                # over time at staggered samples; over another quantity (a front, commits) at every value
                one.update(markers(style, len(k)) if not c.x_axis else {"marker": [figures.marker(style), 0, 1]})
    out = {"t": _round(t[k]), "series": series, "panels": [{**p, "floor": floors[p["key"]]} for p in c.panels],
           "draw": draw_order(series),
           "marks": [[_round([tm])[0], text] for tm, text in sorted(set(c.marks))]}
    if c.choose is not None:
        out["choose"] = c.choose
    if c.grid:
        out["grid"] = True
    if c.x_axis:
        out["x"] = c.x_axis
        for n in c.points:
            series[n]["points"] = True
    return out


def draw_order(series: list[dict]) -> list[int]:
    """The order in which the plot draws ``series`` (the legend keeps theirs): the wide lines
    first, under the thin ones (:func:`balpipe.draw.figures.wide`, as the matplotlib figures' zorder),
    each group in its own order."""
    return sorted(range(len(series)), key=lambda i: not figures.wide(series[i]["width"]))


#: where a reader without JavaScript finds a time series' numbers (files beside the page)
NUMBERS = ('its samples are in <a href="timeseries.csv">timeseries.csv</a>, its peaks in the tables '
           'and in <a href="results.json">results.json</a>')


#: the figure CSVs of the page being rendered (:func:`collecting`), by file name; None: not kept
_FILES: ContextVar[dict[str, str] | None] = ContextVar("balpipe_live_files", default=None)


@contextmanager
def collecting() -> Iterator[dict[str, str]]:
    """While active, every figure :func:`html` writes adds its data file (:func:`csv_name`:
    :func:`csv_text`) to the dict yielded, and its markup links it: the page's folder gets one
    CSV per interactive figure (``balpipe build``'s page files)."""
    files: dict[str, str] = {}
    token = _FILES.set(files)
    try:
        yield files
    finally:
        _FILES.reset(token)


def csv_name(name: str) -> str:
    """The data file of figure ``name`` beside the page."""
    return f"figure-{name}.csv"


#: a figure's unit as its CSV column names it, in SI: (SI unit, factor from the shown unit); the
#: display units a spec may choose (:mod:`balpipe.display.units`) included
TO_SI = {"mm": ("m", 1e-3), "deg": ("rad", math.pi / 180.0),
         **{u: (next(iter(us)), f) for us in CHOICES.values() for u, f in us.items() if f != 1.0}}
_UNIT = re.compile(r"\(([^()]*)\)\s*$")


def column_unit(axis: str) -> tuple[str, str, float]:
    """An axis label split into (quantity, SI unit, factor from the plotted values to SI): 'Fx
    (N)' -> ('Fx', 'N', 1); 'drift (mm)' -> ('drift', 'm', 0.001); a label without a unit is a
    ratio: ('|ΔF| / F_ref', '1', 1)."""
    m = _UNIT.search(axis)
    if not m:
        return axis.strip(), "1", 1.0
    unit = m.group(1).strip()
    si, factor = TO_SI.get(unit, (unit, 1.0))
    return axis[:m.start()].strip(), si, factor


def panel_units(panels: list, units: DisplayUnits) -> dict[str, tuple[str, float]]:
    """Per panel key whose axis ends in an SI unit that ``units`` show otherwise ('Fx (N)' with
    forces in kN): its shown unit and that unit's factor to SI ('kN', 1000); panels shown in
    their SI unit (or without one) are absent. The one conversion of :func:`shown_in` and of the
    what-if's script (:mod:`balpipe.report.whatif`)."""
    out = {}
    for p in panels:
        m = _UNIT.search(p["axis"])
        si = m.group(1).strip() if m else ""
        shown = units.unit(si) if si in OF_SI_UNIT else ""
        if shown and shown != si:
            out[p["key"]] = (shown, units.factor(si))
    return out


def shown_in(c: Curves, units: DisplayUnits) -> Curves:
    """The figure in the page's display ``units``: each panel of :func:`panel_units` has its
    curves divided by the unit's factor and its title and axis in the shown unit ('Fx (kN)');
    its CSV (:func:`csv_text`) is converted back to SI by the unit's name."""
    shown = panel_units(c.panels, units)
    if not shown:
        return c
    panels = [p if p["key"] not in shown else
              {**p, "axis": _UNIT.sub(f"({shown[p['key']][0]})", p["axis"]),
               "title": _UNIT.sub(f"({shown[p['key']][0]})", p["title"])} for p in c.panels]
    scale = {k: f for k, (_, f) in shown.items()}
    stages = [(label, {k: (np.asarray(v, dtype=float) / scale[k] if k in scale else v) for k, v in curves.items()})
              for label, curves in c.stages]
    return c._replace(stages=stages, panels=panels)


def csv_text(c: Curves) -> str:
    """The figure's data as CSV: the samples it plots (:func:`data`'s, every sample of a figure
    over another quantity) at their exact values (12 significant digits, as timeseries.csv, not
    the plot's 6), in SI units; a column per curve and panel, each name ending in its unit in
    parentheses ('t (s)', 'unbalanced: Fx (N)'); an empty cell where a curve has no value.
    Deterministic."""
    t = np.asarray(c.t, dtype=float)
    k = (np.arange(len(t)) if c.x_axis else
         _thin(len(t), sum(p["key"] in curves for _, curves in c.stages for p in c.panels)))
    x_name, x_unit, x_factor = column_unit(c.x_axis) if c.x_axis else ("t", "s", 1.0)
    header = [f"{x_name} ({x_unit})"]
    columns = [t[k] * x_factor]
    names = list(c.names) if c.names else short_names([label for label, _ in c.stages])
    for p in c.panels:
        quantity, unit, factor = column_unit(p["axis"])
        for (label, curves), name in zip(c.stages, names):
            if p["key"] in curves:
                header.append(f"{name}: {quantity} ({unit})")
                columns.append(np.asarray(curves[p["key"]], dtype=float)[k] * factor)
    out = io.StringIO()
    csv.writer(out, lineterminator="\n").writerow(header)
    return out.getvalue() + csv_numbers.rows(columns, missing="")


def html(name: str, c: Curves, numbers: str = NUMBERS) -> str:
    """The page's markup of one figure: the element ``#live-<name>`` that ``live_plots.js`` fills
    (on screen and in print), holding a ``<noscript>`` line that says the plot needs JavaScript
    and where its ``numbers`` are (HTML), and the curves' JSON (:func:`data`); while
    :func:`collecting`, its data file too, linked under the plot (where ``live_plots.js`` adds
    the PNG of the figure as drawn)."""
    files = _FILES.get()
    link = ""
    if files is not None:
        files[csv_name(name)] = csv_text(c)
        link = (f'\n<p class="downloads" data-for="live-{name}">Download: <a href="{csv_name(name)}" download>'
                f'data (CSV, SI)</a></p>')
    return (f'<div class="live" id="live-{name}"><noscript><p class="muted">This plot is drawn by JavaScript, '
            f'which is off: {numbers}.</p></noscript></div>\n'
            f'<script type="application/json" data-live="live-{name}">{as_script(data(c))}</script>' + link)


def as_script(data: dict) -> str:
    """JSON safe inside a ``<script type="application/json">`` element: every ``<`` (in a label;
    nowhere else in JSON) written as its escape ``\\u003c``, which JSON.parse reads back."""
    text = json.dumps(data, separators=(",", ":"), sort_keys=True, ensure_ascii=False)
    return text.replace("<", "\\u003c")  # no '</script>' or '<!--' ends the element early; still valid JSON
