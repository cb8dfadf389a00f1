"""A study shown in a notebook (Jupyter, VS Code): ``study_html``, the HTML of
``balpipe.Study._repr_html_``. The verdict, the design card and the shaking loads as the
page's interactive plot (uPlot and the page's own ``live_plots.js``, inlined: no server, no
network), the plot isolated in an ``<iframe srcdoc>`` so that several studies in one notebook
keep their own plots."""

from __future__ import annotations

import html

import markupsafe
from functools import lru_cache
from importlib import resources

from ..draw import live
from ..report.design_card import design_card
from ..report.page import time_curves

#: the panels of the loads figure that the notebook shows: the force's magnitude and the moment
SHOWN = ("F", "M")
PANEL_HEIGHT = 300  # px a panel takes in the frame (live_plots.js draws it 240 px high), its legend aside
LEGEND_LINE = 28  # px a line of the legend takes (about two stages a line in a notebook's width)


@lru_cache(maxsize=None)
def _asset(name: str) -> str:
    return resources.files("balpipe.templates").joinpath(name).read_text(encoding="utf-8")


def loads_frame(st) -> str:
    """The shaking force |F| and moment M of every stage the page shows, as the page's live plot
    in a self-contained ``<iframe srcdoc>`` (hover for values, drag to zoom, click a legend
    entry to hide a curve)."""
    c = time_curves(st)["loads"]
    c = c._replace(panels=[p for p in c.panels if p["key"] in SHOWN])
    doc = ("<!doctype html><html><head><meta charset='utf-8'><style>"
           + _asset("uplot.min.css")
           + "body{margin:0;overflow-x:hidden;font:13px system-ui,sans-serif}.live-plot{margin:0 0 8px}</style></head><body>"
           + live.html("loads", c)
           + "<script id='uplot-js'>" + _asset("uplot.iife.min.js") + "</script><script>"
           + _asset("live_plots.js") + "</script></body></html>")
    height = (PANEL_HEIGHT + LEGEND_LINE * ((len(c.stages) + 1) // 2)) * len(c.panels) + 20
    return (f'<iframe srcdoc="{html.escape(doc, quote=True)}" title="shaking loads" '
            f'style="width:100%;height:{height}px;border:0" sandbox="allow-scripts"></iframe>')


def _e(value) -> str:
    """HTML text of ``value``; markup (a part's name in the paper's notation) kept as it is."""
    return str(markupsafe.escape(value))


def _card(st, results: dict) -> str:
    card = design_card(st, results)
    if card is None:
        return "<p>No balancing stage: the mechanism as given.</p>"
    rows = "".join(f"<tr><td>{_e(p['name'])}</td><td>{_e(p['kind'])}</td>"
                   f"<td>{p['mass']:.4g}</td><td>{_e(p['where'])}</td><td>{p['inertia']:.4g}</td></tr>"
                   for p in card["parts"])
    parts = (f"<table><tr><th>part</th><th>kind</th><th>mass (kg)</th><th>position</th><th>inertia (kg m²)</th></tr>"
             f"{rows}</table>" if rows else "<p>No parts added: the method changes the motion or the links only.</p>")
    costs = "; ".join(f"{_e(name)} {_e(f)}" + (f" ({_e(what)})" if what else "")
                      for name, f, what in card["factors"])
    return (f"<p><strong>Design summary: {_e(card['stage'])} against "
            f"{_e(card['reference'])}</strong></p>{parts}"
            f"<p>Cost against the unbalanced mechanism: {costs}.</p>")


def study_html(study) -> str:
    """The notebook's view of a ``balpipe.Study``: its name, the verdict, the stages' peak
    loads, the design card and the live plot of the shaking loads."""
    r = study._results_view()
    v = r["verdict"]
    colour = {"good": "#1a7f37", "warn": "#9a6700", "bad": "#cf222e"}.get(v.get("level"), "#57606a")
    stages = "".join(f"<tr><td>{html.escape(s['label'] or s['name'])}</td><td>{s['max_shaking_force']:.4g}</td>"
                     f"<td>{s['max_shaking_moment']:.4g}</td><td>{s['force_ratio']:.3g}</td><td>{s['moment_ratio']:.3g}</td></tr>"
                     for s in r["stages"])
    problems = "".join(f"<li>{html.escape(p)}</li>" for p in r["problems"])
    return (f'<div class="balpipe-study"><h3>{html.escape(r["spec"])}</h3>'
            f'<p style="color:{colour}"><strong>{html.escape(v["text"])}</strong></p>'
            + (f"<ul>{problems}</ul>" if problems else "")
            + "<table><tr><th>stage</th><th>peak force (N)</th><th>peak moment (N m)</th>"
              f"<th>force ratio</th><th>moment ratio</th></tr>{stages}</table>"
            + _card(study.engine_study, r) + loads_frame(study.engine_study) + "</div>")
