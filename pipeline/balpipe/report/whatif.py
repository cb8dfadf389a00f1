"""The live what-if of a study page: a slider for each part's mass, position (x, y in its body's
frame) and centroidal inertia, and the shaking force, the shaking moment and the actuators'
efforts recomputed in the browser from affine maps the page ships (no server).

At fixed geometry and prescribed motion each of these loads is linear in every body's parameters
p = (m, mx, my, J) (mass, first moments in the body frame, inertia about the frame's origin;
:class:`balpipe.balancing.mass_sweep.MassSweep`: the momentum regressors for the shaking loads,
the dynamics regressor for the efforts, the model's own loads a constant term). A part (a
counterweight, a counter-rotating disc, an added or changed link) of mass m, centre (x, y) in its
body's frame and centroidal inertia I adds

    q = (m, m x, m y, I + m (x² + y²))

to its body's p (the parallel-axis theorem), so, with Y_b the columns of p of body b,

    load(values) = load(design) + sum over the parts of Y_b (q(values) - q(design))

exactly, a nonlinear map of the sliders made of affine maps in q. The page ships load(design) (the
engine's own series) and the columns Y_b of the bodies that carry parts at the samples its charts
draw, as base64 float64 arrays (little-endian; the maps are computed at those samples only, never
at every sample of a long grid), and ``templates/whatif.js`` turns the slider values into q and
sums; |F| is the norm of (Fx, Fy). :func:`series` is the same sum in numpy,
:func:`engine_series` the engine's analysis of the model with those parts (the browser test's
reference, to 1e-9 of each series' scale). The page shows the sliders, the peaks and the curves in
the spec's display units (:func:`data`'s ``params`` and ``factors``); the maps, the values and the
series stay SI.

Affinity is checked, not assumed: before shipping, the maps' prediction at a design away from the
computed one (every slider at a value drawn from its range with a fixed seed) must equal the
engine's analysis to :data:`TOL` of the series' scale. Coulomb friction makes the efforts follow
the joint reactions, not the parts: such a page gets sliders for the shaking loads alone and says
why; a stage whose shaking loads fail the check gets no sliders, and the page says why.
"""

from __future__ import annotations

import base64
import math
from dataclasses import dataclass, field, replace

import numpy as np

from ..balancing.mass_sweep import MassSweep
from ..balancing.partial.maps import coulomb_friction
from ..balancing.regressor import model_size, shaking_regressor, states_from_analysis
from ..display.units import DisplayUnits
from ..draw import figures, live
from ..engine import AnalysisError, analyse
from ..mechanics.sampling import spread_indices
from ..model import Model
from . import present
from .design_card import added_parts, main_stages
from .live_plots import LOADS
from .notation_table import PageNames, names_for

TOL = 1e-9  # of a series' scale: the maps against the engine at the check design
SEED = 0  # of the check design's slider values
#: float64 values the maps of one page hold at most (the design's series and the columns, over the
#: kept samples): a design of many parts keeps fewer samples than the charts, not below
#: :data:`balpipe.draw.live.MIN_POINTS`
VALUES = 24_000
#: the line of the design tried, beside the stages' own styles
STYLE = {"color": "tab:purple", "linestyle": "-", "linewidth": 2.0}
FIGURE = "whatif"  # the live figure's name: its element is #live-whatif
#: parts whose kind is a body of their own (its bare link's mass, centre and inertia move)
BODY_KINDS = ("counter-rotation", "link changed")
#: a part's four slider values (m, x, y, I): their names and quantities (balpipe.display.units)
PARAMS = (("mass", "mass"), ("x", "length"), ("y", "length"), ("inertia", "inertia"))


@dataclass(frozen=True)
class Part:
    """A part the sliders move: ``design`` = (m, x, y, I) as computed (kg, m, m, kg m²), ``lo`` and
    ``hi`` the sliders' ranges; ``body`` the body whose parameters it adds to; ``own``: the body's
    bare link (its own mass, centre and inertia), else the attachment ``name`` on ``body``."""

    name: str
    label: str
    kind: str
    body: str
    own: bool
    design: tuple[float, float, float, float]
    lo: tuple[float, float, float, float]
    hi: tuple[float, float, float, float]


@dataclass
class WhatIf:
    """The maps of one stage (see the module docstring): ``design`` and ``reference`` the engine's
    series of the computed design and of the stage it is judged against at the samples ``index``
    of the grid; ``columns[key][body]`` (n, 4) the columns of that body's p, None where a column
    is zero at every sample; ``keys`` the linear quantities (Fx, Fy, M, ``effort:<driver>``)."""

    stage: str
    label: str
    reference_label: str
    model: Model
    grid: np.ndarray
    gravity: tuple[float, float]
    moment_point: tuple[float, float]
    index: np.ndarray
    keys: list[str]
    panels: list[dict]
    design: dict[str, np.ndarray]
    reference: dict[str, np.ndarray]
    bodies: list[str]
    columns: dict[str, dict[str, list[np.ndarray | None]]]
    parts: list[Part]
    notes: list[str] = field(default_factory=list)
    styles: tuple[int, int] = (1, 0)  # line styles of the design and of its reference stage
    names: tuple[str, str] = ("", "")  # their short names in legends (the labels when empty)

    @property
    def t(self) -> np.ndarray:
        return self.grid[self.index]

    def values(self) -> np.ndarray:
        """The computed design's slider values, (parts, 4)."""
        return np.array([p.design for p in self.parts], dtype=float).reshape(len(self.parts), 4)


def momentum(values: np.ndarray) -> np.ndarray:
    """(m, x, y, I) -> (m, m x, m y, I + m (x² + y²)), along the last axis (what ``whatif.js``
    computes, in the same order of operations)."""
    v = np.asarray(values, dtype=float)
    m, x, y, inertia = v[..., 0], v[..., 1], v[..., 2], v[..., 3]
    return np.stack([m, m * x, m * y, inertia + m * (x * x + y * y)], axis=-1)


def series(w: WhatIf, values: np.ndarray) -> dict[str, np.ndarray]:
    """The loads of the design with the parts at ``values`` (parts, 4) from the maps, as the page's
    script computes them: every key of ``w.keys``, and ``F`` = |(Fx, Fy)|."""
    dq = momentum(values) - momentum(w.values())
    per_body = {b: np.zeros(4) for b in w.bodies}
    for p, d in zip(w.parts, dq):
        per_body[p.body] += d
    out = {}
    for key in w.keys:
        y = w.design[key].copy()
        for b in w.bodies:
            for j, col in enumerate(w.columns[key][b]):
                if col is not None:
                    y += col * per_body[b][j]
        out[key] = y
    out["F"] = np.hypot(out["Fx"], out["Fy"])
    return out


def with_parts(model: Model, parts: list[Part], values: np.ndarray) -> Model:
    """``model`` with each part at its ``values`` row (m, x, y, I)."""
    out = model
    for p, (m, x, y, inertia) in zip(parts, np.asarray(values, dtype=float).tolist()):
        b = out.body(p.body)
        if p.own:
            b = replace(b, mass=m, com=(x, y), inertia=inertia)
        else:
            b = replace(b, attachments=tuple(replace(a, mass=m, position=(x, y), inertia=inertia) if a.name == p.name
                                             else a for a in b.attachments))
        out = out.replace_body(b)
    return out


def _quantities(an, keys: list[str], index: np.ndarray) -> dict[str, np.ndarray]:
    out = {"Fx": an.force[index, 0], "Fy": an.force[index, 1], "M": an.moment[index]}
    out.update({k: an.efforts[k.split(":", 1)[1]][index] for k in keys if k.startswith("effort:")})
    out["F"] = np.hypot(out["Fx"], out["Fy"])
    return {k: np.array(v, dtype=float) for k, v in out.items()}


def engine_series(w: WhatIf, values: np.ndarray) -> dict[str, np.ndarray]:
    """The engine's analysis of the model with the parts at ``values``, at the page's samples: the
    reference of :func:`series` (raises :class:`balpipe.engine.AnalysisError` as the engine does)."""
    an = analyse(with_parts(w.model, w.parts, values), w.grid, w.gravity, w.moment_point)
    return _quantities(an, w.keys, w.index)


def _extent(model: Model, body: str, design: tuple[float, float, float, float]) -> float:
    """How far from its body's origin a part's sliders reach: 1.5 x the body's size (its points
    and parts) or the part's own distance, the model's size for a body without points."""
    b = model.body(body)
    r = [math.hypot(*p) for p in b.points.values()] + [math.hypot(*a.position) for a in b.attachments]
    r.append(math.hypot(design[1], design[2]))
    size = max(r) if max(r) > 0 else model_size(model)
    return 1.5 * size


def parts_of(base: Model, final: Model, names: PageNames | None = None) -> list[Part]:
    """The parts of ``final`` that ``base`` lacks (:func:`balpipe.report.design_card.added_parts`,
    in its order), with the sliders' ranges: mass from 0 (or the design's, if negative) to twice
    the design's, position within 1.5 x the body's size of its origin, inertia from 0 to the
    larger of twice the design's and the largest mass at a quarter of that reach."""
    moving = sum(b.mass_properties()[0] for b in base.bodies) or 1.0
    had = {b.name: {a.name for a in b.attachments} for b in base.bodies}
    used: set[tuple[str, str]] = set()
    out = []
    for row in added_parts(base, final):
        if row["kind"] in BODY_KINDS or row["kind"].startswith("added "):
            b = final.body(row["part"])
            own, body, design = True, b.name, (b.mass, b.com[0], b.com[1], b.inertia)
        else:
            b, a = next((b, a) for b in final.bodies for a in b.attachments  # in added_parts' order
                        if a.name == row["part"] and a.name not in had.get(b.name, ()) and (b.name, a.name) not in used)
            used.add((b.name, a.name))
            own, body, design = False, b.name, (a.mass, a.position[0], a.position[1], a.inertia)
        m, x, y, inertia = (float(v) for v in design)
        reach = _extent(final, body, (m, x, y, inertia))
        m_hi = 2.0 * abs(m) if m != 0 else 0.1 * moving
        i_hi = max(2.0 * abs(inertia), m_hi * (reach / 4) ** 2)
        label = names.text("part", row["part"]) if names is not None else row["part"]
        out.append(Part(row["part"], label, row["kind"], body, own, (m, x, y, inertia),
                        (min(0.0, m), -reach, -reach, min(0.0, inertia)), (max(m_hi, m), reach, reach, i_hi)))
    return out


#: what :func:`_maps` gives: YF, YM, G (None with Coulomb friction), the efforts' drivers, the frictions
Maps = tuple[np.ndarray, np.ndarray, "np.ndarray | None", list[str], list[str]]


def _maps(model: Model, an, samples: np.ndarray) -> Maps:
    """YF (n, 2, np), YM (n, np) and the efforts' G (n, nd, np) with their drivers (None and the
    Coulomb frictions' names when the efforts are not affine in the masses), at the ``samples``
    (n indices of the analysis's grid) only: a long grid's maps would hold its every sample's
    Jacobian and multipliers (:meth:`balpipe.balancing.mass_sweep.MassSweep.build`: each sample's
    numbers are the same as in the maps of every sample)."""
    friction = coulomb_friction(model)
    if friction:
        YF, YM = shaking_regressor(states_from_analysis(model, an, samples=samples), an.gravity, an.moment_point)
        return YF, YM, None, [], friction
    sweep = MassSweep.build(model, an.t, an.gravity, an.moment_point, analysis=an, samples=samples)
    return sweep.YF, sweep.YM, sweep.G, [d for d in sweep.drivers if d in an.efforts], []


MAP_ERRORS = (AnalysisError, ValueError, np.linalg.LinAlgError)  # why a stage's loads have no maps


def _unmapped(label: str, exc: Exception) -> str:
    """The page's sentence for a stage whose maps failed with ``exc``."""
    return f"The loads of {label} could not be mapped onto its parts ({exc}), so the page offers no sliders."


def _columns(maps: Maps, keys: list[str], at: dict[str, int], bodies: list[str]) -> dict[str, dict[str, list[np.ndarray]]]:
    """``out[key][body]``: the 4 columns (m, mx, my, J) of that body's p in the map of ``key``, at
    the maps' samples (the bodies' order in the model is ``at``)."""
    YF, YM, G, drivers, _ = maps

    def cols(key: str) -> np.ndarray:  # (n, np)
        if key in ("Fx", "Fy"):
            return YF[:, 0 if key == "Fx" else 1, :]
        if key == "M":
            return YM
        assert G is not None
        return G[:, drivers.index(key.split(":", 1)[1]), :]

    return {k: {b: [cols(k)[:, 4 * at[b] + j].copy() for j in range(4)] for b in bodies} for k in keys}


def _samples(N: int, panels: int, per_sample: int) -> np.ndarray:
    """The kept samples: as many as the page's charts keep for a figure of ``panels`` x 3 curves
    (:func:`balpipe.draw.live.data`), fewer when the maps would exceed :data:`VALUES`."""
    charts = max(live.MIN_POINTS, min(live.POINTS, live.VALUES // max(1, 3 * panels)))
    return spread_indices(N, max(live.MIN_POINTS, min(charts, VALUES // max(1, per_sample))))


def _scale(key: str, *series: dict[str, np.ndarray]) -> float:
    """A series' scale: its largest |value| over ``series`` (a force component's: |F|'s)."""
    k = "F" if key in ("Fx", "Fy") else key
    return max(float(np.max(np.abs(s[k]), initial=0.0)) for s in series)


def check(w: WhatIf) -> list[str]:
    """The keys whose maps miss the engine by more than :data:`TOL` of their scale at the check
    design (each slider drawn from its range, seed :data:`SEED`)."""
    lo = np.array([p.lo for p in w.parts], dtype=float).reshape(-1, 4)
    hi = np.array([p.hi for p in w.parts], dtype=float).reshape(-1, 4)
    values = np.random.default_rng(SEED).uniform(lo, hi)
    try:
        exact = engine_series(w, values)
    except AnalysisError:
        return list(w.keys)
    got = series(w, values)
    return [k for k in w.keys
            if np.max(np.abs(got[k] - exact[k]), initial=0.0) > TOL * max(_scale(k, exact, w.reference), 1e-300)]


def build(study, results: dict, styles: dict[str, tuple[int, str]] | None = None) -> WhatIf | str | None:
    """The what-if of the study's main design (:func:`balpipe.report.design_card.main_stages`):
    None when it adds no part; a sentence saying why when its loads are not affine in the parts;
    else its checked maps. ``styles``: each stage's line style and short name on the page, by
    stage name (:func:`balpipe.report.page.stage_styles`)."""
    pair = main_stages(study, results)
    if pair is None:
        return None
    final, ref = pair
    names = names_for(study.spec)
    parts = parts_of(ref.stage.model, final.stage.model, names)
    if not parts:
        return None
    model, an = final.stage.model, final.analysis
    N = len(an.t)
    first = spread_indices(N, live.POINTS)  # the most samples the page keeps (every one of a short grid)
    try:
        maps = _maps(model, an, first)
    except MAP_ERRORS as exc:
        return _unmapped(final.stage.label, exc)
    drivers, friction = maps[3], maps[4]
    notes = []
    if friction:
        notes.append(f"Coulomb friction ({', '.join(friction)}) makes the actuators' efforts follow the joint "
                     "reactions, not the parts' masses: they are not affine in the sliders, so only the shaking "
                     "force and moment move (friction acts between parts of the machine and leaves them unchanged).")
    keys = ["Fx", "Fy", "M"] + [f"effort:{d}" for d in drivers]
    bodies = [b.name for b in model.bodies if any(p.body == b.name for p in parts)]
    at = {b.name: k for k, b in enumerate(model.bodies)}
    units = {d: present.driver_unit(model, d) for d in drivers}
    panels = [{"key": key, "title": title, "axis": axis} for key, title, axis, _ in LOADS]
    panels += [{"key": f"effort:{d}", "title": f"actuator effort: {names.text('driver', d)}"
                + (f" ({units[d]})" if units[d] else ""), "axis": figures.effort_axis(units[d])} for d in drivers]
    # the maps' size per sample counts the columns not zero at the samples ``first``; when that keeps
    # fewer samples, those are mapped again (a sample's maps are the same numbers whatever the others)
    found = _columns(maps, keys, at, bodies)
    per_sample = len(keys) + sum(bool(np.any(c != 0)) for k in keys for b in bodies for c in found[k][b])
    index = _samples(N, len(panels), per_sample)
    if not np.array_equal(index, first):
        try:
            found = _columns(_maps(model, an, index), keys, at, bodies)
        except MAP_ERRORS as exc:
            return _unmapped(final.stage.label, exc)
    columns: dict[str, dict[str, list[np.ndarray | None]]] = {
        k: {b: [c if np.any(c != 0) else None for c in found[k][b]] for b in bodies} for k in keys}
    styles = styles or {}
    design_style, design_name = styles.get(final.stage.name, (1, final.stage.label))
    reference_style, reference_name = styles.get(ref.stage.name, (0, ref.stage.label))
    w = WhatIf(final.stage.name, final.stage.label, ref.stage.label, model, np.asarray(an.t, dtype=float),
               an.gravity, an.moment_point, index, keys, panels, _quantities(an, keys, index),
               _quantities(ref.analysis, [k for k in keys if k.split(":", 1)[-1] in ref.analysis.efforts], index), bodies, columns, parts, notes,
               (design_style, reference_style), (design_name, reference_name))
    for k in keys:
        w.reference.setdefault(k, np.zeros(len(index)))
    missed = check(w)
    if any(k in missed for k in ("Fx", "Fy", "M")):
        return (f"The shaking loads of {final.stage.label} are not affine in its parts' masses, positions and "
                "inertias here (the maps missed the engine at a check design), so the page offers no sliders.")
    if missed:
        w.notes.append("The efforts of " + ", ".join(names.text("driver", k.split(":", 1)[1]) for k in missed)
                       + " are not affine in the parts (the maps missed the engine at a check design): left out.")
        w.keys = [k for k in keys if k not in missed]
        w.panels = [p for p in panels if p["key"] not in missed]
    return w


def _b64(a: np.ndarray) -> str:
    """A float64 array as base64 of its little-endian bytes (``Float64Array`` in the browser)."""
    return base64.b64encode(np.ascontiguousarray(a, dtype="<f8").tobytes()).decode("ascii")


def curves(w: WhatIf, units: DisplayUnits | None = None) -> live.Curves:
    """The live figure in the page's display ``units`` (SI when None; :func:`balpipe.draw.live.shown_in`):
    per panel the reference stage, the computed design and the design tried, in that order; the
    design tried has no samples here (``whatif.js`` draws it, the computed design's until a
    slider moves)."""
    c = live.Curves(w.t, [(w.reference_label, {k: w.reference[k] for k in ["F", *w.keys] if k in w.reference}),
                          (w.label, dict(w.design)), ("design tried", {})],
                    w.panels, [], styles=[w.styles[1], w.styles[0], STYLE], grid=True,
                    names=(w.names[1] or w.reference_label, w.names[0] or w.label, "design tried"))
    return c if units is None else live.shown_in(c, units)


def data(w: WhatIf, units: DisplayUnits | None = None) -> dict:
    """What ``whatif.js`` reads: the samples' times, the design's series and the columns (base64
    float64, None for a zero column), the parts with their design values and ranges, and which
    series of the live figure is the design tried; all in SI. How the script shows them, in the
    page's display ``units`` (SI when None): ``params``, per slider value of a part its name, unit
    and the unit's factor to SI (a value shown is the SI value over it, a value typed or slid is
    multiplied by it), and ``factors``, per panel key of the figure the factor its curves and
    peaks are divided by (1 where the panel is in SI: :func:`balpipe.draw.live.panel_units`)."""
    u = units or DisplayUnits()
    shown = live.panel_units(w.panels, u)
    return {"figure": f"live-{FIGURE}", "tried": 2, "computed": 1, "t": _b64(w.t), "n": int(len(w.index)),
            "keys": w.keys, "design": {k: _b64(w.design[k]) for k in w.keys},
            "bodies": w.bodies,
            "columns": {k: {b: [None if c is None else _b64(c) for c in w.columns[k][b]] for b in w.bodies}
                        for k in w.keys},
            "parts": [{"name": p.name, "label": p.label, "kind": p.kind, "body": p.body, "design": list(p.design),
                       "lo": list(p.lo), "hi": list(p.hi)} for p in w.parts],
            "params": [{"name": name, "unit": u.unit(q), "factor": u.factor(q)} for name, q in PARAMS],
            "factors": {p["key"]: shown[p["key"]][1] if p["key"] in shown else 1.0 for p in w.panels},
            "stage": w.label}


def section(study, results: dict, styles: dict[str, tuple[int, str]] | None = None,
            units: DisplayUnits | None = None) -> dict | None:
    """The template's ``whatif``: None (no section), ``{"reason": ...}`` (no sliders, and why) or the
    live figure's markup, the maps' JSON and the notes; the figure, the sliders and the peaks in
    the page's display ``units`` (SI when None), the maps and the figure's CSV in SI."""
    w = build(study, results, styles)
    if w is None:
        return None
    if isinstance(w, str):
        return {"reason": w}
    c = curves(w, units)
    figure = live.html(FIGURE, c, "the computed design's samples are in <a href=\"timeseries.csv\">timeseries.csv</a>")
    return {"reason": None, "figure": figure, "data": live.as_script(data(w, units)), "notes": w.notes, "stage": w.label,
            "reference": w.reference_label, "parts": len(w.parts), "samples": int(len(w.index)),
            "efforts": any(k.startswith("effort:") for k in w.keys)}
