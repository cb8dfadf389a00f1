"""A small self-contained canvas player: the mechanism moving on its free-floating frame.

The page embeds, per stage, the outline of every body (local points) and its pose at about 60
frames, plus the frame's pose and the sleeves of its prismatic pairs between links (one
connected leg, :mod:`.sleeves`); a few lines of JavaScript draw them in a grid of panels. Each
panel has its own view box, from that stage's swept extent (every instant, parts and frame
included) with a small margin, and its own scale bar in m (the caption says when the panels'
scales differ). The spec's names (pivots, joints, counterweights, links) and the gears' numbers
are placed so that they do not overlap, as in the drawings (:mod:`.labels`). Controls:
play/pause, a time slider, the speed (real time by default, the time scale shown), names on or
off; keyboard: Tab to the canvas, space to pause, arrows to step. Linked to the page's plots
(``templates/live_plots.js``): each drawn frame announces its time (a ``balpipe:time`` event on
the document) and a ``balpipe:seek`` event (a click in a plot) pauses it at the time it carries.
No library, no external file.
"""

from __future__ import annotations

import html
import json
import math
from collections.abc import Set as AbstractSet
from typing import Any

import numpy as np

from ..model import Model
from ..mechanics.sampling import spread_indices
from .labels import drawing_span, point_name_counts, point_places, repeated_names
from .sleeves import guided_sliders, sleeves

FRAMES = 60


def _outline(model: Model) -> list[dict]:
    guided = guided_sliders(model)  # a rod in a sleeve (``sleeves`` of :func:`player_data`), no block
    shapes = []
    for b in model.bodies:
        pts = [b.points[p] for p in b.outline] if len(b.outline) >= 2 else []
        cws = [[round(a.position[0], 5), round(a.position[1], 5), round(a.mass, 4)]
               for a in b.attachments if a.kind == "counterweight"]
        gears = [[round(a.position[0], 5), round(a.position[1], 5), round(a.radius, 5)]
                 for a in b.attachments if a.radius and a.kind != "counterweight"]
        shapes.append({
            "line": [[round(p[0], 5), round(p[1], 5)] for p in pts],
            "radius": round(b.radius, 5) if b.radius else 0,
            "slider": b.kind == "slider" and b.name not in guided,
            "cw": cws,
            "gears": gears,
        })
    return shapes


def _extent_box(model: Model, poses: np.ndarray, base: np.ndarray | None = None) -> np.ndarray:
    """The box [[x_min, y_min], [x_max, y_max]] of the global positions of every named point,
    attachment and disc rim over the frames, and of the frame's pivots and guides (carried by the
    frame's poses ``base`` where it moves): each body's points' tracks reduced as they are
    computed, so that no (frames x every point) array is held (a long grid's would be tens of MB)."""
    lo, hi = np.full(2, np.inf), np.full(2, -np.inf)

    def add(xy: np.ndarray) -> None:
        np.minimum(lo, xy.min(axis=0), out=lo)
        np.maximum(hi, xy.max(axis=0), out=hi)

    def add_tracks(pose: np.ndarray, local: list) -> None:
        """The body points ``local`` carried by the poses ``pose`` (n, 3): (x + cos th px - sin th py,
        y + sin th px + cos th py) at every pose, all of the body's points in one (n, points) array."""
        c, s = np.cos(pose[:, 2:3]), np.sin(pose[:, 2:3])
        px, py = (np.array([p[k] for p in local], dtype=float) for k in (0, 1))
        add(np.stack([(pose[:, 0:1] + c * px - s * py).ravel(), (pose[:, 1:2] + s * px + c * py).ravel()], axis=1))

    add(poses[:, :, :2].reshape(-1, 2))
    for i, b in enumerate(model.bodies):
        local = list(b.points.values()) + [a.position for a in b.attachments]
        r = b.radius or 0.0
        if r:
            local += [(r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)]
        for a in b.attachments:  # a carried disc's rim, around its own centre
            if a.radius:
                px, py = a.position
                local += [(px + a.radius, py), (px - a.radius, py), (px, py + a.radius), (px, py - a.radius)]
        if local:
            add_tracks(poses[:, i], local)
    fixed = list(model.frame_points.values()) + [p for g in model.guides for p in g]
    if not fixed:
        fixed = [(0.0, 0.0)]
    if base is None:
        add(np.array(fixed, dtype=float))
    else:
        add_tracks(base, fixed)
    return np.array([lo, hi])


PANEL_W = 300  # px per panel
#: the panels share one scale (the smallest of their own) while their own scales differ by at
#: most this factor; beyond it (a stage that moves far more than another) each fills its panel
COMMON_SCALE = 3.0
TOP, BOTTOM, SIDE = 22, 40, 10  # px: the stage's name above, the frame's pose and scale bar below
MAX_COLUMNS = 4


def nice_length(span: float) -> float:
    """The largest 1, 2 or 5 x 10^n not above ``span`` (m): a scale bar's length."""
    if not span > 0:
        return 0.0
    e = math.floor(math.log10(span))
    for m in (5.0, 2.0, 1.0):
        if m * 10.0**e <= span * (1 + 1e-12):
            return m * 10.0**e
    return 10.0 ** (e - 1) * 5.0


def _length_text(x: float) -> str:
    return f"{x * 1000:g} mm" if x < 0.1 else f"{x:g} m"


def panel_views(extents: list[np.ndarray], width: int = PANEL_W) -> dict:
    """Per-panel view boxes: every panel the same pixel size (its height from the widest
    aspect of the stages' extents: points (n, 2), e.g. a box's two corners), each mechanism centred in its panel at one scale for every
    panel (the smallest of the panels' own, so that every stage fits) where their own scales
    differ by at most :data:`COMMON_SCALE`, else each scaled to fill its own panel: ``box``
    (x0, y0, x1, y1, m, with a 6 % margin), ``view`` (ox, oy, s: pixel = (ox + s x, oy - s y) on
    the canvas), the scale bar (length m, text) and the layout (columns, rows, panel size)."""
    boxes = []
    for xy in extents:
        lo, hi = xy.min(axis=0), xy.max(axis=0)
        d = 0.06 * float(max(hi - lo)) or 0.05
        boxes.append((float(lo[0] - d), float(lo[1] - d), float(hi[0] + d), float(hi[1] + d)))
    inner_w = width - 2 * SIDE
    aspect = max((b[3] - b[1]) / (b[2] - b[0]) for b in boxes)
    inner_h = int(round(min(max(aspect, 0.4), 1.2) * inner_w))
    height = inner_h + TOP + BOTTOM
    cols = min(len(boxes), MAX_COLUMNS) or 1
    rows = -(-len(boxes) // cols)
    own = [min(inner_w / (b[2] - b[0]), inner_h / (b[3] - b[1])) for b in boxes]
    common = min(own) if max(own) <= COMMON_SCALE * min(own) else None
    panels = []
    for k, b in enumerate(boxes):
        s = common if common is not None else own[k]
        col, row = k % cols, k // cols
        cx, cy = 0.5 * (b[0] + b[2]), 0.5 * (b[1] + b[3])
        ox = col * width + SIDE + 0.5 * inner_w - s * cx
        oy = row * height + TOP + 0.5 * inner_h + s * cy
        bar = nice_length(0.3 * inner_w / s)
        panels.append({"box": [round(v, 6) for v in b], "view": [round(ox, 4), round(oy, 4), round(s, 6)],
                       "origin": [col * width, row * height], "bar": [round(bar, 9), _length_text(bar)]})
    return {"panels": panels, "columns": cols, "rows": rows, "width": width, "height": height}


def same_scale(views: dict, rel: float = 0.02) -> bool:
    """Every panel at the same scale (within ``rel``)."""
    s = [p["view"][2] for p in views["panels"]]
    return max(s) <= (1 + rel) * min(s)


def _labels(model: Model, numbers: dict[str, str], unnamed: AbstractSet[str] = frozenset()) -> dict:
    """What the player names, in body frames: joints (body points, discs' axes left out, and
    the names in ``unnamed``: :func:`labels.repeated_names`, as the drawings), links (middle of
    the first outline segment; a platform at its centroid), counterweights, and every gear's
    number (:func:`labels.gear_numbers`)."""
    joints: list[list[Any]] = []
    links: list[Any] = []
    cws: list[Any] = []
    gears: list[Any] = []
    for j, b in enumerate(model.bodies):
        if b.radius:
            gears.append([j, 0.0, 0.0, round(b.radius, 5), numbers.get(b.name, b.name)])
        else:
            joints += [[j, round(p[0], 5), round(p[1], 5), n] for n, p in b.points.items() if n not in unnamed]
        pts = [b.points[p] for p in b.outline]
        if len(pts) >= 2:
            uniq = list(dict.fromkeys(tuple(p) for p in pts))
            if b.kind == "platform" and len(uniq) > 2:
                mid = (sum(p[0] for p in uniq) / len(uniq), sum(p[1] for p in uniq) / len(uniq))
            else:
                mid = (0.5 * (pts[0][0] + pts[1][0]), 0.5 * (pts[0][1] + pts[1][1]))
            links.append([j, round(mid[0], 5), round(mid[1], 5), b.name])
        for a in b.attachments:
            if a.kind == "counterweight":
                cws.append([j, round(a.position[0], 5), round(a.position[1], 5), a.name])
            elif a.radius:
                gears.append([j, round(a.position[0], 5), round(a.position[1], 5), round(a.radius, 5),
                              numbers.get(a.name, a.name)])
    # the page names coinciding points once, first come first named: the name no other point has
    # goes first (the platform's C1 before the pistons' C), as in the drawings
    count = point_name_counts(model)
    joints.sort(key=lambda j: count[j[3]] > 1)
    return {"joints": joints, "links": links, "cws": cws, "gears": gears}


def unnamed(model: Model, poses: np.ndarray) -> set[str]:
    """The point names the drawings leave off (:func:`labels.repeated_names`), at the first pose."""
    return repeated_names(point_places(model, poses[0], drawing_span(model, poses)))


#: what rounding may move a drawn point at most, in the panel's pixels (:func:`digits`): invisible
PIXEL = 0.05


def digits(scale: float, size: float) -> tuple[int, int]:
    """The decimals a panel's moving coordinates keep: positions (m) at ``scale`` px per m, and
    angles (rad) of bodies no larger than the panel (``size`` px, its diagonal), so that
    rounding moves no drawn point by more than :data:`PIXEL` (half the last kept digit times
    the scale, or times the panel's size for an angle). A 0.6 m mechanism in a 300 px panel
    keeps 4 decimals of a position and 4 of an angle instead of 6: the same drawing, about a
    third fewer bytes in a page."""
    position = max(0, math.ceil(math.log10(scale / (2 * PIXEL))))
    angle = max(0, math.ceil(math.log10(size / (2 * PIXEL))))
    return position, angle


def _poses(a: np.ndarray, position: int, angle: int) -> list:
    """Every row (x, y, angle) of ``a`` (..., 3) rounded to its decimals (:func:`digits`), -0 as
    0, nested as ``a`` is: ``round(v, position) + 0.0`` of x and y, ``round(v, angle) + 0.0`` of the angle."""
    return _formatted(a, (f"%.{position}f", f"%.{position}f", f"%.{angle}f"))


def _formatted(a: np.ndarray, formats: tuple[str, ...]) -> list:
    """Every value of ``a`` (..., len(formats)) written by its column's %-format and read back,
    -0 as 0, nested as ``a`` is: ``float(fmt % v) + 0.0`` each, which for ``"%.nf"`` is
    ``round(v, n) + 0.0`` (both the correctly rounded decimal, read back correctly rounded), from
    one format of all the values (a page's player rounded 200,000 values one call each)."""
    a = np.asarray(a, dtype=float)
    rows = a.reshape(-1, len(formats))
    text = ((" ".join(formats) + " ") * len(rows)) % tuple(rows.ravel().tolist())
    return (np.array(list(map(float, text.split())), dtype=float).reshape(a.shape) + 0.0).tolist()


def _loads(stages: list[dict], ks_of: list[np.ndarray]) -> tuple[list[dict], dict]:
    """The shaking force and moment of each stage at its frames (4 significant digits: what an
    arrow and a 4-digit number show), where the stages carry them (``force`` (n, 2) N,
    ``moment`` (n,) N m about ``point``), and their largest magnitudes over every stage and
    every sample: one arrow scale for all panels, and the floor below which a value is shown as
    0 (1e-9 of that largest: round-off of the model's own scale)."""
    if not all("force" in s for s in stages):
        return [{} for _ in stages], {}
    fmax = max(float(np.max(np.hypot(s["force"][:, 0], s["force"][:, 1]), initial=0.0)) for s in stages)
    mmax = max(float(np.max(np.abs(s["moment"]), initial=0.0)) for s in stages)
    sig = lambda v: float(f"{float(v):.4g}") + 0.0  # noqa: E731
    out = [{"force": _formatted(np.asarray(s["force"])[ks], ("%.4g", "%.4g")),
            "moment": _formatted(np.asarray(s["moment"])[ks], ("%.4g",)),
            "point": [round(float(s["point"][0]), 6), round(float(s["point"][1]), 6)]}
           for s, ks in zip(stages, ks_of)]
    return out, {"fmax": sig(fmax), "mmax": sig(mmax), "floor": 1e-9}


def player_data(stages: list[dict]) -> dict:
    """The player's data: per stage its label, times, frame and body poses (about
    :data:`FRAMES` frames, rounded to what its panel shows: :func:`digits`), shapes, names, its
    own view box (:func:`panel_views`) and, where the stages carry them, the shaking force and
    moment at those frames (:func:`_loads`)."""
    from .labels import gear_numbers

    numbers = gear_numbers([s["model"] for s in stages])
    extents = [_extent_box(s["model"], s["poses"], s["base"]) for s in stages]
    views = panel_views(extents)
    size = math.hypot(views["width"], views["height"])
    data = []
    ks_of = [np.asarray(spread_indices(len(s["t"]), FRAMES)) for s in stages]
    loads, scale = _loads(stages, ks_of)
    for s, view, ks, load in zip(stages, views["panels"], ks_of, loads):
        poses = s["poses"][ks]
        base = s["base"][ks]
        position, angle = digits(view["view"][2], size)
        fp = [[round(p[0], 5), round(p[1], 5)] for p in s["model"].frame_points.values()]
        data.append({
            "label": s["label"],
            "t": [round(float(v), 5) for v in s["t"][ks]],
            "base": _poses(base, position, angle),
            "poses": _poses(poses, position, angle),
            "shapes": _outline(s["model"]),
            "pivots": fp,
            "pivot_names": list(s["model"].frame_points),
            "names": _labels(s["model"], numbers, unnamed(s["model"], s["poses"])),
            "guides": [[[round(a[0], 5), round(a[1], 5)], [round(b[0], 5), round(b[1], 5)]] for a, b in s["model"].guides],
            "sleeves": [[[[round(float(v), position) + 0.0 for v in end] for end in ends]
                         for ends in sleeves(s["model"], frame)] for frame in poses],
            **load,
        })
    for d, p in zip(data, views["panels"]):
        d.update(p)
    return {"stages": data, "layout": {k: views[k] for k in ("columns", "rows", "width", "height")},
            "same_scale": same_scale(views), "numbers": numbers, "loads": scale}


def scale_note(stages: list[dict]) -> str:
    """The caption's sentence on the panels' scales, and the gears' numbers."""
    return _note(player_data(stages))


def player(stages: list[dict], element_id: str = "player", floating: bool = True,
           autoplay: bool = True) -> tuple[str, str]:
    """:func:`player_html` and :func:`scale_note` of the same ``stages``, the same text as each
    alone, from one :func:`player_data` (a page shows both: its poses, loads and names, about
    half of a page's player time, are made once)."""
    d = player_data(stages)
    return _html(d, element_id, floating, autoplay), _note(d)


def _note(d: dict) -> str:
    """:func:`scale_note` of the player's data ``d`` (:func:`player_data`)."""
    from .labels import gear_key

    note = ("Every panel is at the same scale (scale bar in each)." if d["same_scale"] else
            "Each panel is scaled to fill its own box, so the panels' scales differ: read lengths "
            "from each panel's scale bar.")
    if d["numbers"]:
        note += " Gears and counter-rotations are numbered: " + gear_key(d["numbers"]) + "."
    return note


def player_html(stages: list[dict], element_id: str = "player", floating: bool = True, autoplay: bool = True) -> str:
    """``stages``: dicts with label, model, t (n,), base (n, 3) frame-origin poses and poses
    (n, nb, 3) body-frame poses, all in the global frame of the start; optionally ``force``
    (n, 2), ``moment`` (n,) and ``point``: the shaking loads on the frame, drawn as an arrow at
    the moment point (one force scale for every panel) and an arc for the moment, with their
    values. One panel per stage at one scale where the stages allow it (:func:`panel_views`),
    each with its scale bar; as many columns as the page's width holds (one on a phone).
    ``floating``: the frame moves (the free-floating runs), its pose is printed per panel;
    ``autoplay``: it plays at load (unless the reader asked for reduced motion)."""
    return _html(player_data(stages), element_id, floating, autoplay)


def _html(d: dict, element_id: str, floating: bool, autoplay: bool) -> str:
    """:func:`player_html` of the player's data ``d`` (:func:`player_data`)."""
    lay = d["layout"]
    payload = json.dumps({"stages": d["stages"], "layout": lay, "loads": d["loads"]}, separators=(",", ":"), sort_keys=True)
    # names are data: no '</script>' or '<!--' can end the script early
    payload = payload.replace("<", "\\u003c").replace(">", "\\u003e").replace("&", "\\u0026")
    width = lay["width"] * lay["columns"]
    height = lay["height"] * lay["rows"]
    eid = element_id
    labels = html.escape(json.dumps([st["label"] for st in d["stages"]], ensure_ascii=False))
    what = ("the mechanism on its free-floating frame" if floating else
            "the mechanism on its fixed frame with the shaking force and moment it passes to the frame")
    return f"""<div class="player" id="{eid}-box">
<canvas id="{eid}" width="{width}" height="{height}" data-stages="{labels}" style="max-width:100%;border:1px solid #d9dee4" role="img" aria-label="Animation of {what}, one panel per stage, each with a scale bar"></canvas>
<div class="player-controls">
<button type="button" id="{eid}-play" aria-controls="{eid}" aria-label="Pause">Pause</button>
<label for="{eid}-time">time</label>
<input type="range" id="{eid}-time" min="0" max="1000" step="1" value="0" aria-label="Time along the motion">
<label for="{eid}-speed">speed</label>
<select id="{eid}-speed" aria-label="Playback speed"><option value="0.1">0.1×</option><option value="0.25">0.25×</option><option value="0.5">0.5×</option><option value="1" selected>1× (real time)</option><option value="2">2×</option><option value="4">4×</option></select>
<label><input type="checkbox" id="{eid}-names" checked> names</label>
<output id="{eid}-clock" for="{eid}-time" aria-live="off"></output>
</div>
</div>
<script>
(function() {{
const D = {payload};
const cv = document.getElementById("{eid}"), g = cv.getContext("2d");
const btn = document.getElementById("{eid}-play"), slider = document.getElementById("{eid}-time");
const speedSel = document.getElementById("{eid}-speed"), clock = document.getElementById("{eid}-clock");
const names = document.getElementById("{eid}-names");
const L = D.layout, PW = L.width, PH = L.height, FLOATING = {str(floating).lower()};
// as many columns as the page's width holds (the canvas is never shrunk below its panels' size):
// each panel's view moves with its panel
let COLS = L.columns;
function layout() {{
  const avail = (cv.parentElement && cv.parentElement.clientWidth) || PW * L.columns;
  COLS = Math.max(1, Math.min(L.columns, Math.floor((avail - 2) / PW)));
  const rows = Math.ceil(D.stages.length / COLS);
  cv.width = COLS * PW; cv.height = rows * PH;
  D.stages.forEach((st, k) => {{
    st.view0 = st.view0 || st.view; st.origin0 = st.origin0 || st.origin;
    const o = [(k % COLS) * PW, Math.floor(k / COLS) * PH];
    st.origin = o;
    st.view = [st.view0[0] - st.origin0[0] + o[0], st.view0[1] - st.origin0[1] + o[1], st.view0[2]];
  }});
  cv.dataset.columns = String(COLS);
}}
// a stage's name cut to its panel's width ("…" at the end); the page's table gives it whole
function fit(text, w) {{ if (g.measureText(text).width <= w) return text;
  let n = text.length; while (n > 1 && g.measureText(text.slice(0, n) + "…").width > w) n--; return text.slice(0, n).trimEnd() + "…"; }}
const LD = D.loads || {{}};
function loadText(v, max, unit) {{ return (Math.abs(v) <= LD.floor * max ? "0" : Number(v.toPrecision(4)).toString()) + " " + unit; }}
function arrowHead(q, dx, dy, size) {{ const n = Math.hypot(dx, dy) || 1, ux = dx / n, uy = dy / n;
  g.beginPath(); g.moveTo(q[0], q[1]); g.lineTo(q[0] - size * ux + 0.5 * size * uy, q[1] - size * uy - 0.5 * size * ux);
  g.lineTo(q[0] - size * ux - 0.5 * size * uy, q[1] - size * uy + 0.5 * size * ux); g.closePath(); g.fill(); }}
// the shaking force as an arrow at the moment point (one scale, N per px, for every panel) and the
// shaking moment as an arc around it (its sweep proportional to the moment, counter-clockwise positive)
function drawLoads(st, i, base, P) {{
  if (!st.force || !LD.fmax) return;
  const q = P(...T(base, st.point)), f = st.force[i], m = st.moment[i];
  const k = 0.28 * Math.min(PW, PH - 62) / LD.fmax;
  g.strokeStyle = g.fillStyle = "#d55e00"; g.lineWidth = 2.5;
  if (Math.hypot(f[0], f[1]) > LD.floor * LD.fmax) {{
    const e = [q[0] + k * f[0], q[1] - k * f[1]];
    g.beginPath(); g.moveTo(...q); g.lineTo(...e); g.stroke(); arrowHead(e, e[0] - q[0], e[1] - q[1], 9);
  }}
  if (LD.mmax && Math.abs(m) > LD.floor * LD.mmax) {{
    const r = 15, sweep = 1.5 * Math.PI * m / LD.mmax;  // canvas angles run clockwise: negate
    g.lineWidth = 1.8; g.beginPath(); g.arc(q[0], q[1], r, 0, -sweep, sweep > 0); g.stroke();
    const a = -sweep, tip = [q[0] + r * Math.cos(a), q[1] + r * Math.sin(a)];
    arrowHead(tip, (sweep > 0 ? 1 : -1) * Math.sin(a), (sweep > 0 ? -1 : 1) * Math.cos(a), 7);
  }}
  g.lineWidth = 1;
}}
const T0 = D.stages[0].t[0], T1 = D.stages[0].t[D.stages[0].t.length - 1], span = Math.max(T1 - T0, 1e-9);
function T(pose, p) {{ const c = Math.cos(pose[2]), si = Math.sin(pose[2]);
  return [pose[0] + c * p[0] - si * p[1], pose[1] + si * p[0] + c * p[1]]; }}
function fixed(v, d) {{ const t = v.toFixed(d); return /^-0(\\.0*)?$/.test(t) ? t.slice(1) : t; }}  // no "-0.000"
function frameAt(st, time) {{ let i = 0; while (i + 1 < st.t.length && st.t[i + 1] <= time + 1e-12) i++; return i; }}
function hit(a, b) {{ return a[0] < b[2] && b[0] < a[2] && a[1] < b[3] && b[1] < a[3]; }}
function segHit(p, q, b) {{ // Liang-Barsky: does segment p-q cross box b (x0, y0, x1, y1)?
  let t0 = 0, t1 = 1; const dx = q[0] - p[0], dy = q[1] - p[1];
  for (const [pp, qq] of [[-dx, p[0] - b[0]], [dx, b[2] - p[0]], [-dy, p[1] - b[1]], [dy, b[3] - p[1]]]) {{
    if (pp === 0) {{ if (qq < 0) return false; }}
    else {{ const t = qq / pp; if (pp < 0) t0 = Math.max(t0, t); else t1 = Math.min(t1, t); if (t0 > t1) return false; }}
  }}
  return true;
}}
const DIRS8 = [...Array(8).keys()].map(k => [Math.cos(k * Math.PI / 4), Math.sin(k * Math.PI / 4)]);
const DIRS16 = [...Array(16).keys()].map(k => [Math.cos(k * Math.PI / 8), Math.sin(k * Math.PI / 8)]);
// names that do not overlap: rings of candidates around each anchor (the report's labels.place);
// a name with no free place in its panel is left out of that frame rather than drawn over another
function placeNames(items, segs, marks, area) {{
  const done = [];
  items.forEach((it, idx) => {{
    g.font = it.font; const w = g.measureText(it.text).width + 4, h = 12;
    let chosen = null, fallback = null;
    for (let k = 0; k < 6 && !chosen; k++) {{
      const r = it.clear + 2 + k * h;
      for (const d of (k < 2 ? DIRS8 : DIRS16)) {{
        const cx = it.at[0] + d[0] * (r + w / 2), cy = it.at[1] - d[1] * (r + h / 2);
        const b = [cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2];
        if (b[0] < area[0] || b[1] < area[1] || b[2] > area[2] || b[3] > area[3] || done.some(o => hit(b, o.box))) continue;
        if (!segs.some(s => segHit(s[0], s[1], b)) && !marks.some((m, j) => j !== it.mark && hit(b, m))) {{ chosen = [b, k > 0]; break; }}
        if (!fallback) fallback = [b, k > 0];
      }}
    }}
    chosen = chosen || fallback;
    if (chosen) done.push({{box: chosen[0], lead: chosen[1], it}});
  }});
  done.forEach(o => {{
    const b = o.box, it = o.it;
    if (o.lead) {{ g.strokeStyle = "#888"; g.lineWidth = 0.7; g.beginPath(); g.moveTo(...it.at);
      g.lineTo(Math.min(Math.max(it.at[0], b[0]), b[2]), Math.min(Math.max(it.at[1], b[1]), b[3])); g.stroke(); g.lineWidth = 1; }}
    g.fillStyle = "rgba(255,255,255,0.8)"; g.fillRect(b[0], b[1], b[2] - b[0], b[3] - b[1]);
    g.font = it.font; g.fillStyle = it.color; g.textAlign = "center"; g.textBaseline = "middle";
    g.fillText(it.text, (b[0] + b[2]) / 2, (b[1] + b[3]) / 2);
  }});
  g.textAlign = "start"; g.textBaseline = "alphabetic";
  return done.length;
}}
let time = T0, playing = true, last = null;
function draw() {{
  g.clearRect(0, 0, cv.width, cv.height);
  const shown = [];
  D.stages.forEach((st, k) => {{
    const v = st.view, s = v[2], O = st.origin;
    const P = (x, y) => [v[0] + x * s, v[1] - y * s];
    const i = frameAt(st, time), base = st.base[i];
    const segs = [], marks = [], items = [];
    const mark = (q, r) => {{ marks.push([q[0] - r, q[1] - r, q[0] + r, q[1] + r]); return marks.length - 1; }};
    g.save(); g.beginPath(); g.rect(O[0], O[1], PW, PH); g.clip();
    g.fillStyle = "#e8edf3"; g.strokeStyle = "#8aa4c0";
    g.beginPath(); st.pivots.forEach((p, j) => {{ const q = P(...T(base, p)); j ? g.lineTo(...q) : g.moveTo(...q); }});
    g.closePath(); g.stroke();
    st.guides.forEach(gd => {{ const a = P(...T(base, gd[0])), e = P(...T(base, gd[1]));
      g.strokeStyle = "#8aa4c0"; g.beginPath(); g.moveTo(...a); g.lineTo(...e); g.stroke(); segs.push([a, e]); }});
    st.pivots.forEach((p, j) => {{ const q = P(...T(base, p)); g.fillStyle = "#22303f"; g.fillRect(q[0] - 4, q[1] - 4, 8, 8);
      items.push({{text: st.pivot_names[j], at: q, clear: 4, mark: mark(q, 4), font: "11px sans-serif", color: "#111"}}); }});
    st.sleeves[i].forEach(sl => {{ const a = P(...sl[0]), e = P(...sl[1]); g.lineCap = "butt";
      g.strokeStyle = "#555"; g.lineWidth = 9; g.beginPath(); g.moveTo(...a); g.lineTo(...e); g.stroke();
      g.strokeStyle = "#ddd"; g.lineWidth = 7; g.beginPath(); g.moveTo(...a); g.lineTo(...e); g.stroke();
      g.lineWidth = 1; segs.push([a, e]); }});
    st.shapes.forEach((sh, j) => {{
      const pose = st.poses[i][j];
      if (sh.radius) {{ const c = P(...T(pose, [0, 0])); g.strokeStyle = "#2e8b57"; g.beginPath();
        g.arc(c[0], c[1], sh.radius * s, 0, 2 * Math.PI); g.stroke(); const e = P(...T(pose, [sh.radius, 0]));
        g.beginPath(); g.moveTo(...c); g.lineTo(...e); g.stroke(); }}
      if (sh.slider) {{ const c = P(...T(pose, [0, 0])); g.fillStyle = "#ccc"; g.fillRect(c[0] - 8, c[1] - 5, 16, 10); }}
      sh.gears.forEach(gr => {{ const c = P(...T(pose, gr)); g.strokeStyle = "#2e8b57"; g.beginPath();
        g.arc(c[0], c[1], gr[2] * s, 0, 2 * Math.PI); g.stroke(); }});
      sh.cw.forEach(cw => {{ const c = P(...T(pose, cw)), o = P(...T(pose, [0, 0]));
        g.strokeStyle = "rgba(214,39,40,0.8)"; g.beginPath(); g.moveTo(...o); g.lineTo(...c); g.stroke(); segs.push([o, c]);
        g.fillStyle = "rgba(214,39,40,0.6)"; g.beginPath();
        g.arc(c[0], c[1], 3 + 2 * Math.sqrt(cw[2]), 0, 2 * Math.PI); g.fill(); }});
      if (sh.line.length > 1) {{ g.strokeStyle = "#111"; g.lineWidth = 3; g.beginPath();
        const q = sh.line.map(p => P(...T(pose, p)));
        q.forEach((p, m) => {{ m ? g.lineTo(...p) : g.moveTo(...p); if (m) segs.push([q[m - 1], p]); }}); g.stroke(); g.lineWidth = 1; }}
    }});
    if (names.checked) {{
      const N = st.names, seen = [];
      st.pivots.forEach(p => seen.push(P(...T(base, p))));
      N.joints.forEach(n => {{ const q = P(...T(st.poses[i][n[0]], [n[1], n[2]]));
        if (seen.some(o => Math.abs(o[0] - q[0]) < 3 && Math.abs(o[1] - q[1]) < 3)) return; seen.push(q);
        items.push({{text: n[3], at: q, clear: 3, mark: mark(q, 3), font: "11px sans-serif", color: "#222"}}); }});
      N.gears.forEach(n => {{ const c = P(...T(st.poses[i][n[0]], [n[1], n[2]])), r = n[3] * s * Math.SQRT1_2;
        items.push({{text: n[4], at: [c[0] + r, c[1] - r], clear: 1, mark: -1, font: "bold 12px sans-serif", color: "#2e8b57"}}); }});
      N.cws.forEach(n => {{ const q = P(...T(st.poses[i][n[0]], [n[1], n[2]]));
        items.push({{text: n[3], at: q, clear: 5, mark: mark(q, 5), font: "10px sans-serif", color: "#c0282d"}}); }});
      N.links.forEach(n => {{ const q = P(...T(st.poses[i][n[0]], [n[1], n[2]]));
        items.push({{text: n[3], at: q, clear: 2, mark: -1, font: "italic 10px sans-serif", color: "#1f6fb4"}}); }});
    }} else items.length = 0;
    cv.dataset["names" + k] = String(placeNames(items, segs, marks, [O[0] + 2, O[1] + 18, O[0] + PW - 2, O[1] + PH - 36]));
    drawLoads(st, i, base, P);
    g.restore();
    g.fillStyle = "#1d232b"; g.font = "12px sans-serif";
    g.fillText(fit(st.label, PW - 16), O[0] + 8, O[1] + 15);
    if (FLOATING) {{
      const dx = base[0] * 1000, dy = base[1] * 1000, rot = base[2] * 180 / Math.PI;
      g.fillText(`frame: (${{fixed(dx, 2)}}, ${{fixed(dy, 2)}}) mm, ${{fixed(rot, 3)}} deg`, O[0] + 8, O[1] + PH - 8);
    }}
    if (st.force && LD.fmax) {{
      const f = st.force[i], text = `|F| ${{loadText(Math.hypot(f[0], f[1]), LD.fmax, "N")}}, M ${{loadText(st.moment[i], LD.mmax, "N m")}}`;
      g.fillStyle = "#a0440a"; g.fillText(text, O[0] + 8, O[1] + PH - (FLOATING ? 22 : 8)); shown.push(text);
    }}
    // scale bar, bottom right of the panel: this panel's own scale
    const bl = st.bar[0] * s, bx = O[0] + PW - 12 - bl, by = O[1] + PH - 26;
    g.strokeStyle = "#1d232b"; g.lineWidth = 2; g.beginPath(); g.moveTo(bx, by - 4); g.lineTo(bx, by); g.lineTo(bx + bl, by);
    g.lineTo(bx + bl, by - 4); g.stroke(); g.lineWidth = 1; g.font = "11px sans-serif"; g.textAlign = "center";
    g.fillText(st.bar[1], bx + bl / 2, by - 5); g.textAlign = "start";
    if (k % L.columns) {{ g.strokeStyle = "#d9dee4"; g.beginPath(); g.moveTo(O[0] + 0.5, O[1]); g.lineTo(O[0] + 0.5, O[1] + PH); g.stroke(); }}
    if (O[1] > 0) {{ g.strokeStyle = "#d9dee4"; g.beginPath(); g.moveTo(O[0], O[1] + 0.5); g.lineTo(O[0] + PW, O[1] + 0.5); g.stroke(); }}
  }});
  cv.dataset.loads = shown.join(" | ");
  slider.value = String(Math.round(1000 * (time - T0) / span));
  clock.textContent = `t = ${{time.toFixed(3)}} s of ${{T1.toFixed(3)}} s · ${{speedSel.value}}× real time`;
  document.dispatchEvent(new CustomEvent("balpipe:time", {{detail: {{time: time}}}}));  // the plots' cursors follow
}}
function tick(now) {{
  if (!playing) {{ last = null; return; }}
  if (last !== null) {{ time += (now - last) / 1000 * parseFloat(speedSel.value);
    if (time > T1) time = T0 + (time - T1) % span; }}
  last = now; draw(); requestAnimationFrame(tick);
}}
function setPlaying(on) {{ playing = on; btn.textContent = on ? "Pause" : "Play"; btn.setAttribute("aria-label", btn.textContent);
  cv.dataset.playing = on ? "1" : "0"; if (on) {{ last = null; requestAnimationFrame(tick); }} }}
btn.addEventListener("click", () => setPlaying(!playing));
slider.addEventListener("input", () => {{ setPlaying(false); time = T0 + span * parseInt(slider.value, 10) / 1000; draw(); }});
speedSel.addEventListener("change", draw);
// a click in a plot (live_plots.js) sends the player to that time, paused
document.addEventListener("balpipe:seek", ev => {{ setPlaying(false); time = Math.min(T1, Math.max(T0, +ev.detail.time)); draw(); }});
names.addEventListener("change", draw);
cv.tabIndex = 0;
cv.addEventListener("keydown", ev => {{
  if (ev.key === " " || ev.key === "k") {{ ev.preventDefault(); setPlaying(!playing); }}
  else if (ev.key === "ArrowRight" || ev.key === "ArrowLeft") {{ ev.preventDefault(); setPlaying(false);
    time = Math.min(T1, Math.max(T0, time + (ev.key === "ArrowRight" ? 1 : -1) * span / 100)); draw(); }}
}});
layout();
addEventListener("resize", () => {{ const c = COLS; layout(); if (c !== COLS || !playing) draw(); }});
draw(); setPlaying({str(autoplay).lower()} && !matchMedia("(prefers-reduced-motion: reduce)").matches);
}})();
</script>"""
