"""Figures in the style of the papers, as deterministic inline SVG.

Stage styles follow the papers' figures: the unbalanced mechanism solid black, the
counterweight stage dashed, the fully balanced stage grey. Simulated (pymunk) curves are drawn
as thin dotted coloured lines over the analytic ones.
"""

from __future__ import annotations

import io
import math
import re
from dataclasses import replace

import matplotlib

from ..runtime import plotting

matplotlib.use("Agg")
plotting.prepare()  # in the CLI's processes, no docstrings for help() (balpipe.runtime.plotting)
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib.layout_engine import PlaceHolderLayoutEngine  # noqa: E402

from ..mechanics.planar import world_point  # noqa: E402
from ..model import Model  # noqa: E402
from ..cache import figures as cache
from . import extremes  # noqa: E402
from .canvas import Canvas, Label, Panel  # noqa: E402
from .labels import drawing_span, point_places, repeated_names  # noqa: E402
from .layout import fixed_layout, text_metrics  # noqa: E402
from .sleeves import guided_sliders, sleeves  # noqa: E402

plt.rcParams.update({
    "svg.hashsalt": "balpipe",
    "svg.fonttype": "none",
    "font.family": "DejaVu Sans",
    "font.size": 9,
    "axes.grid": True,
    "grid.alpha": 0.3,
    "axes.spines.top": False,
    "axes.spines.right": False,
    "text.usetex": False,
})


def literal(text: str) -> str:
    """A name (spec, point, body, driver, stage) as matplotlib text that is shown literally:
    every '$' is escaped, so that mathtext never parses user data (an unbalanced '$\\frac{'
    would otherwise crash the figure). Matplotlib prints an escaped '\\$' as '$'."""
    return str(text).replace("$", r"\$")

STAGE_STYLES = [
    {"color": "black", "linestyle": "-", "linewidth": 1.4},
    {"color": "black", "linestyle": "--", "linewidth": 1.4},
    {"color": "0.6", "linestyle": "-", "linewidth": 2.4},
    {"color": "tab:blue", "linestyle": "-.", "linewidth": 1.4},
    {"color": "tab:red", "linestyle": ":", "linewidth": 1.4},
]
SIM_COLORS = ["tab:orange", "tab:blue", "tab:green", "tab:purple", "tab:brown"]


MARKERS = ["o", "s", "^", "D", "v"]
# from the sixth stage on (a spec with compared designs): the five line styles again, in colours
# and with markers of their own, so that no two stages of a figure look alike
MORE_COLORS = ["tab:green", "tab:purple", "tab:brown", "tab:olive", "tab:cyan"]
MORE_MARKERS = ["P", "X", "h", "<", ">"]
STYLE_WORDS = ["solid black", "dashed black", "grey", "blue dash-dot", "red dotted"]
LINE_WORDS = ["solid", "dashed", "thick solid", "dash-dot", "dotted"]
MARKER_WORDS = ["circles", "squares", "triangles", "diamonds", "down-triangles",
                "plus signs", "crosses", "hexagons", "left-triangles", "right-triangles"]


#: a line wider than this (the grey of style 2) is drawn under the thin ones (:func:`wide`)
WIDE = 2.0
WIDE_ZORDER = 1.8  # below matplotlib's lines (2), above the grid (1.5)


def wide(width: float) -> bool:
    """Whether a line of ``width`` is drawn under the thin lines: so that a thin curve on the same
    values stays visible over it (a balanced force of 0, dashed, over the grey stage that is 0
    too: paper 000 Fig. 4; case 2's dashes over case 3 in paper 003's Figs. 3-4), in the static
    figures (its zorder) and the interactive plots (:func:`balpipe.draw.live.data`'s ``draw``)."""
    return width > WIDE


def style(k: int) -> dict:
    """Stage ``k``'s line: colour, line style, width, and a wide line's lower zorder (:func:`wide`)."""
    n = len(STAGE_STYLES)
    base = STAGE_STYLES[k % n]
    if k >= n:
        base = {**base, "color": MORE_COLORS[(k // n - 1 + k) % len(MORE_COLORS)]}
    return {**base, "zorder": WIDE_ZORDER} if wide(base["linewidth"]) else base


def marker(k: int) -> str:
    """Stage ``k``'s marker symbol (matplotlib), the same order as :func:`marked` and
    :func:`style_text` use."""
    return (MARKERS + MORE_MARKERS)[k % (len(MARKERS) + len(MORE_MARKERS))]


def style_text(k: int, markers: bool = True) -> str:
    """Words for stage ``k``'s line (and marker, as :func:`marked` draws it): 'solid black,
    circles'; 'dashed purple, crosses' from the sixth stage on."""
    n = len(STAGE_STYLES)
    if k < n:
        line = STYLE_WORDS[k]
    else:
        line = LINE_WORDS[k % n] + " " + style(k)["color"].removeprefix("tab:")
    return line + (f", {MARKER_WORDS[k % len(MARKER_WORDS)]}" if markers else "")


def marked(k: int, n: int) -> dict:
    """A stage's line style with its own marker, placed at staggered samples (offset per stage)
    so that curves that coincide stay distinguishable."""
    every = max(1, n // 12)
    return {**style(k), "marker": marker(k), "markersize": 4.5, "markerfacecolor": "none",
            "markevery": (min(n - 1, (k * every) // max(1, len(MARKERS))), every)}


def coinciding(curves: list[tuple[str, np.ndarray]], rel: float = 1e-6, log: bool = False) -> list[str]:
    """Groups of curves that agree within ``rel`` of the panel's largest value (``log``: of
    either value at every sample, as a logarithmic axis shows them), as "a = b = c" (each curve
    in the group of the first it agrees with)."""
    scale = max([float(np.max(np.abs(y))) for _, y in curves] + [0.0]) or 1.0

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        if a.shape != b.shape:
            return False
        if log:
            return bool(np.all(np.abs(a - b) <= rel * np.maximum(np.abs(a), np.abs(b))))
        return float(np.max(np.abs(a - b))) <= rel * scale

    groups: list[list[int]] = []
    for i, (_, y) in enumerate(curves):
        for g in groups:
            if same(curves[g[0]][1], y):
                g.append(i)
                break
        else:
            groups.append([i])
    return [" = ".join(curves[i][0] for i in g) for g in groups if len(g) > 1]


def to_svg(fig, prefix: str) -> str:
    """Serialise a figure to SVG with no date, and every id prefixed so that several figures can
    be inlined in one page without clashing."""
    buf = io.StringIO()
    if isinstance(fig.get_layout_engine(), PlaceHolderLayoutEngine):
        # what fig.tight_layout() leaves behind: savefig would draw the whole figure once more
        # (for a layout engine that does nothing); without it the SVG is byte for byte the same
        fig.set_layout_engine(None)
    fig.savefig(buf, format="svg", metadata={"Date": None, "Creator": None})
    plt.close(fig)
    svg = buf.getvalue()
    svg = svg[svg.index("<svg"):]
    svg = re.sub(r'id="([^"]+)"', lambda m: f'id="{prefix}-{m.group(1)}"', svg)
    svg = re.sub(r"url\(#([^)]+)\)", lambda m: f"url(#{prefix}-{m.group(1)})", svg)
    svg = re.sub(r'xlink:href="#([^"]+)"', lambda m: f'xlink:href="#{prefix}-{m.group(1)}"', svg)
    return svg


def legend_below(fig, ax, fontsize: float = 8.5) -> None:
    """``ax``'s legend under the figure's axes, never over a curve: as many columns (at most 3) as
    the figure's width holds, the figure made taller by the legend's height, the layout above it.
    Call it instead of ``fig.tight_layout()`` (it lays the figure out with :func:`layout.fixed_layout`)."""
    handles, labels = ax.get_legend_handles_labels()
    if not labels:
        fixed_layout(fig)
        return
    renderer = fig.canvas.get_renderer()
    W, H = fig.get_size_inches()
    for ncol in range(min(len(labels), 3), 0, -1):
        leg = fig.legend(handles, labels, loc="lower center", bbox_to_anchor=(0.5, 0.0), ncol=ncol,
                         fontsize=fontsize, frameon=False)
        if ncol == 1 or leg.get_window_extent(renderer).width <= 0.98 * W * fig.dpi:
            break
        leg.remove()
    h = leg.get_window_extent(renderer).height / fig.dpi + 0.05
    fig.set_size_inches(W, H + h)
    fixed_layout(fig, rect=(0, h / (H + h), 1, 1))


def effort_axis(unit: str) -> str:
    """An effort panel's axis label: 'torque (N m)', 'force (N)', or 'effort' without a unit."""
    return {"N m": "torque (N m)", "N": "force (N)"}.get(unit, "effort")


def mechanism_figure(model: Model, analysis, ghosts: list[int] | None = None, prefix: str = "mech",
                     title: str = "", limits: tuple[float, float, float, float] | None = None,
                     numbers: dict[str, str] | None = None, texts: dict[str, str] | None = None) -> str:
    """The mechanism drawn solid at its reference pose (t = 0, where the player starts) over its
    extreme poses as light grey ghosts (:mod:`.extremes`: the instants where it is farthest from
    the solid pose; ``ghosts``: their sample indices, computed from ``model`` when None), with
    the thin paths of the link points. A prismatic pair between two links is one connected leg,
    a rod in a sleeve (:mod:`.sleeves`); counterweights are discs whose area grows with their
    mass, gears circles. The solid pose carries the spec's names (points, links,
    counterweights) and the gears' numbers (``numbers``: part name -> number,
    :func:`labels.gear_numbers`), placed so that no two overlap (:func:`labels.place`);
    ``limits`` (x0, y0, x1, y1) gives every panel of a figure the same scale; ``texts``: name ->
    the text drawn for it (the paper's symbol, :class:`balpipe.notation.Names`)."""
    return cache.svg(mechanism_svg, drawn_model(model), analysis.frame_pose, ghosts, prefix, title, limits,
                     numbers, texts)


def drawn_model(model: Model) -> Model:
    """``model`` as the drawings read it: without its drivers and actuators (motion laws are
    functions, which :mod:`.cache` cannot hash, and no drawing reads them), its initial
    assembly pose and the spec locations of its parts."""
    return replace(model, drivers=(), actuators=(), initial={}, sources={})


def mechanism_svg(model: Model, poses: np.ndarray, ghosts: list[int] | None, prefix: str, title: str,
                  limits: tuple[float, float, float, float] | None, numbers: dict[str, str] | None,
                  texts: dict[str, str] | None) -> str:
    """:func:`mechanism_figure` from the body poses (N, bodies, 3) alone: what :mod:`.cache` hashes."""
    canvas, _ = pose_drawing(model, poses, ghosts, title, limits, numbers, texts)
    return canvas.svg(prefix)


SOLID = {"link": "black", "width": 2.2, "marker": True, "fill": "0.85", "edge": "black", "alpha": 1.0, "z": 3}
GHOST = {"link": "0.72", "width": 1.6, "marker": False, "fill": "0.94", "edge": "0.72", "alpha": 0.3, "z": 1}
SLEEVE = 0.018  # half-width of a sleeve / span
GREEN, RED = "tab:green", "tab:red"


def _draw_pose(panel: Panel, model: Model, pose_row: np.ndarray, span: float, max_cw: float, guided: set[str],
               look: dict) -> None:
    """One pose of the mechanism in the style ``look`` (``SOLID`` or ``GHOST``): links, discs,
    counterweights, slider blocks and the sleeves of prismatic pairs between links."""
    a, z = look["alpha"], look["z"]
    for i, b in enumerate(model.bodies):
        pose = pose_row[i]
        if b.radius:
            centre, edge = world_point(pose, (0, 0)), world_point(pose, (b.radius, 0))
            panel.circle(centre, b.radius, edge=GREEN, alpha=a, width=1.2, z=z)
            panel.line([centre[0], edge[0]], [centre[1], edge[1]], GREEN, alpha=a, width=0.8, z=z)
        if b.kind == "slider" and b.name not in guided:
            c = world_point(pose, (0, 0))
            w = 0.06 * span
            panel.polygon([c + d for d in ((-w, -w / 2), (w, -w / 2), (w, w / 2), (-w, w / 2))], fill=look["fill"],
                          edge=look["edge"], z=z)
        for att in b.attachments:
            if att.kind == "counterweight":
                g = np.array([world_point(pose, p) for p in
                              (b.points[b.outline[0]] if b.outline else (0, 0), att.position)])
                panel.line(g[:, 0], g[:, 1], RED, alpha=a, width=1.5, z=z)
                r = 0.035 * span * math.sqrt(att.mass / max_cw)
                panel.circle(world_point(pose, att.position), r, fill=RED, edge=RED, alpha=0.6 * a, z=z)
            elif att.radius:
                panel.circle(world_point(pose, att.position), att.radius, edge=GREEN, alpha=a, z=z)
    # links (a guide's under its sleeve), the sleeves, the rods sliding in them (thinner), joints on top
    outlines = [(b.name in guided, np.array([world_point(pose_row[i], b.points[p]) for p in b.outline]))
                for i, b in enumerate(model.bodies) if len(b.outline) >= 2]
    cls = "link" if look is SOLID else ""
    for g in (g for rod, g in outlines if not rod):
        panel.line(g[:, 0], g[:, 1], look["link"], width=look["width"], cap="round", z=z, cls=cls)
    for ends in sleeves(model, pose_row):
        panel.polygon(_sleeve_outline(ends, span), fill=look["fill"], edge=look["edge"], width=0.9, z=z)
    for g in (g for rod, g in outlines if rod):
        panel.line(g[:, 0], g[:, 1], look["link"], width=0.75 * look["width"], cap="round", z=z, cls=cls)
    if look["marker"]:
        for _, g in outlines:
            panel.markers(g, "o", 4.0, face="white", edge="black", z=z + 0.5)


def _sleeve_outline(ends: tuple[np.ndarray, np.ndarray], span: float) -> list[np.ndarray]:
    """The four corners of a sleeve (:func:`sleeves.sleeves`: its two ends, global)."""
    p, q = ends
    d = q - p
    n = np.array([-d[1], d[0]]) / (float(np.hypot(*d)) or 1.0) * SLEEVE * span
    return [p - n, q - n, q + n, p + n]


def mechanism_drawing(model: Model, analysis, ghosts: list[int] | None = None, title: str = "",
                      limits: tuple[float, float, float, float] | None = None,
                      numbers: dict[str, str] | None = None, texts: dict[str, str] | None = None) -> tuple:
    """The drawing of :func:`mechanism_figure` (a :class:`.canvas.Canvas`) and its placed labels
    (:class:`labels.Placed`, boxes in the canvas's layout points)."""
    return pose_drawing(model, analysis.frame_pose, ghosts, title, limits, numbers, texts)


def pose_drawing(model: Model, poses: np.ndarray, ghosts: list[int] | None = None, title: str = "",
                 limits: tuple[float, float, float, float] | None = None,
                 numbers: dict[str, str] | None = None, texts: dict[str, str] | None = None) -> tuple:
    """:func:`mechanism_drawing` from the body poses (N, bodies, 3) of the analysis."""
    canvas = Canvas(6.0 * 72, 4.6 * 72)
    panel = canvas.panels[0]
    ref = extremes.REFERENCE
    if ghosts is None:
        ghosts = extremes.extreme_instants(model, poses)
    max_cw = max([a.mass for b in model.bodies for a in b.attachments] + [1e-12])
    span = drawing_span(model, poses)
    guided = guided_sliders(model)
    # paths of every named point, thin
    for i, b in enumerate(model.bodies):
        x, y, th = poses[:, i, 0], poses[:, i, 1], poses[:, i, 2]
        for p in b.points.values():
            px = x + np.cos(th) * p[0] - np.sin(th) * p[1]
            py = y + np.sin(th) * p[0] + np.cos(th) * p[1]
            panel.line(px, py, "tab:blue", width=0.5, alpha=0.5, z=0.5)
    for k in ghosts:
        _draw_pose(panel, model, poses[k], span, max_cw, guided, GHOST)
    _draw_pose(panel, model, poses[ref], span, max_cw, guided, SOLID)
    for (a, b) in model.guides:
        panel.line([a[0], b[0]], [a[1], b[1]], "0.3", width=1.0)
    for name, p in model.frame_points.items():
        panel.marker(p[0], p[1], "^", 9.0, z=4)
    panel.limits = limits
    panel.title = title
    canvas.layout()
    placed = place_names(panel, model, poses[ref], span, max_cw, numbers, texts=texts)
    return canvas, placed


LABEL_STYLES = {  # kind -> font size, colour, style, weight
    "pivot": (8.0, "black", "normal", "normal"),
    "joint": (8.0, "0.15", "normal", "normal"),
    "gear": (8.5, "tab:green", "normal", "bold"),
    "counterweight": (7.5, "tab:red", "normal", "normal"),
    "link": (7.5, "tab:blue", "italic", "normal"),
}


def name_requests(model: Model, pose_row: np.ndarray, span: float, max_cw: float,
                  numbers: dict[str, str], disc: float = 0.035) -> tuple[list, list, list]:
    """What to label at one instant, in placing order (frame pivots, joints, gears,
    counterweights, links), in model coordinates: (text, anchor, kind) triples, the links'
    segments, and the joint markers, pivots, slider blocks and counterweight discs to keep clear,
    as (centre, radius), radius None for a joint's marker and -1 for a pivot's triangle.
    ``disc``: a counterweight's disc radius / ``span`` for the heaviest (``max_cw``), as drawn.
    A slider in a moving guide is drawn as a rod in a sleeve (:mod:`.sleeves`), whose edges
    and axis are kept clear, not as a block."""
    out: list[tuple[str, np.ndarray, str]] = []
    keep: list[tuple[np.ndarray, float | None]] = []
    segs: list[tuple[np.ndarray, np.ndarray]] = []
    for name, p in model.frame_points.items():
        out.append((name, np.asarray(p, dtype=float), "pivot"))
        keep.append((np.asarray(p, dtype=float), -1.0))  # the pivot's triangle
    # every named point once: one name per place, none for a name at several places (its marker
    # is still kept clear)
    places = point_places(model, pose_row, span)
    unnamed = repeated_names(places)
    for name, g in places:
        if name not in unnamed:
            out.append((name, g, "joint"))
        keep.append((g, None))
    gears, cws, links = [], [], []
    guided = guided_sliders(model)
    for i, b in enumerate(model.bodies):
        pose = pose_row[i]
        if b.kind == "slider" and b.name not in guided:
            keep.append((world_point(pose, (0, 0)), 0.06 * span))  # the slider's block
        if b.radius:
            rim = world_point(pose, (0, 0)) + b.radius * np.array([math.sqrt(0.5), math.sqrt(0.5)])
            gears.append((numbers.get(b.name, b.name), rim, "gear"))
        for a in b.attachments:
            c = world_point(pose, a.position)
            if a.kind == "counterweight":
                cws.append((a.name, c, "counterweight"))
                keep.append((c, disc * span * math.sqrt(a.mass / max_cw)))
                root = world_point(pose, b.points[b.outline[0]] if b.outline else (0, 0))
                segs.append((root, c))
            elif a.radius:
                gears.append((numbers.get(a.name, a.name), c + a.radius * np.array([math.sqrt(0.5), math.sqrt(0.5)]),
                              "gear"))
        pts = [world_point(pose, b.points[p]) for p in b.outline]
        segs += list(zip(pts[:-1], pts[1:]))
        if len(pts) >= 2:
            unique = [q for k, q in enumerate(pts) if not any(np.allclose(q, r) for r in pts[:k])]
            mid = np.mean(unique, axis=0) if b.kind == "platform" and len(unique) > 2 else 0.5 * (pts[0] + pts[1])
            links.append((b.name, mid, "link"))
    for a, b in model.guides:
        segs.append((np.asarray(a, dtype=float), np.asarray(b, dtype=float)))
    for ends in sleeves(model, pose_row):
        c = _sleeve_outline(ends, span)
        segs += [(c[0], c[1]), (c[2], c[3]), (0.5 * (c[0] + c[3]), 0.5 * (c[1] + c[2]))]
    return out + gears + cws + links, segs, keep


def place_names(panel: Panel, model: Model, pose_row: np.ndarray, span: float, max_cw: float,
                numbers: dict[str, str] | None, disc: float = 0.035, kinds: tuple[str, ...] | None = None,
                marks: list | tuple = (), texts: dict[str, str] | None = None) -> list:
    """Names of the spec at one instant (every body point once per place, every link, every
    counterweight, every gear's number), placed on a laid-out ``panel`` by :func:`labels.place`
    so that no two overlap, avoiding the links and markers; a displaced name gets a leader line.
    ``disc``: as :func:`name_requests`; ``kinds``: only these kinds of names (``LABEL_STYLES``'
    keys; all when None); ``marks``: further points drawn (model coordinates) to keep clear,
    e.g. centres of mass; ``texts``: name -> the text drawn (a paper's notation)."""
    from . import labels as lb

    numbers = numbers if numbers is not None else lb.gear_numbers([model])
    items, segs, keep = name_requests(model, pose_row, span, max_cw, numbers, disc)
    items = [((texts or {}).get(t, t), a, k) for t, a, k in items if kinds is None or k in kinds]
    keep = keep + [(np.asarray(p, dtype=float), None) for p in marks]
    placed = placement(items, segs, keep, panel.to_px, 1.0, panel.box,
                       lambda text, kind: text_metrics(text, *_font(kind))[:2])
    for pl in placed:
        size, color, fstyle, weight = LABEL_STYLES[pl.request.kind]
        panel.name(Label(pl.request.text, pl.centre, pl.request.anchor if pl.displaced else None, size, color,
                         fstyle, weight))
    return placed


def _font(kind: str) -> tuple[float, str, str]:
    size, _, fstyle, weight = LABEL_STYLES[kind]
    return size, fstyle, weight


def placement(items: list, segs: list, keep: list, to_px, unit: float, bounds: tuple, measure) -> list:
    """Where :func:`labels.place` puts ``items`` (text, anchor, kind) given in model coordinates,
    in placing order: ``to_px`` maps model coordinates to the drawing's units (``unit`` of them
    a point), ``bounds`` the drawing area in those units, ``measure(text, kind)`` a text's width
    and height in them; ``segs``: lines to keep clear ((x, y), (x, y)); ``keep``: markers and
    discs as (centre, radius), radius None for a point marker, -1 for a pivot's triangle."""
    from . import labels as lb

    pad, dot = 2.0 * unit, 3.0 * unit
    blocks = []
    for c, r in keep:
        x, y = to_px(c)
        rr = dot if r is None else 5.0 * unit if r < 0 else \
            max(dot, abs(float(to_px(c + np.array([r, 0.0]))[0]) - float(x)))
        blocks.append((float(x) - rr, float(y) - rr, float(x) + rr, float(y) + rr))
    requests = []
    for text, anchor, kind in items:
        w, h = measure(str(text), kind)
        x, y = float(to_px(anchor)[0]), float(to_px(anchor)[1])
        own = [0.5 * (b[2] - b[0]) for b in blocks if b[0] <= x <= b[2] and b[1] <= y <= b[3]]
        requests.append(lb.Request(str(text), (x, y), float(w) + 2 * pad, float(h) + pad, kind, max(own + [0.0])))
    seg_px = [(tuple(map(float, to_px(a))), tuple(map(float, to_px(b)))) for a, b in segs]
    return lb.place(requests, seg_px, blocks, bounds=tuple(float(v) for v in bounds), gap=pad)


def place_items(fig, ax, items: list, segs: list, keep: list) -> list:
    """:func:`placement` on a matplotlib axes whose layout is final, the names drawn as
    annotations (a displaced one with a leader line); returns the :class:`labels.Placed`
    (display pixels)."""
    from matplotlib.font_manager import FontProperties

    ax.apply_aspect()
    renderer = fig.canvas.get_renderer()

    def measure(text: str, kind: str) -> tuple[float, float]:
        size, fstyle, weight = _font(kind)
        prop = FontProperties(family="DejaVu Sans", size=size, style=fstyle, weight=weight)
        w, h, _ = renderer.get_text_width_height_descent(text, prop, ismath=False)
        return float(w), float(h)

    placed = placement(items, segs, keep, ax.transData.transform, fig.dpi / 72.0, ax.bbox.extents, measure)
    to_pt = 72.0 / fig.dpi
    for (text, anchor, kind), pl in zip(items, placed):
        size, color, fstyle, weight = LABEL_STYLES[kind]
        cx, cy = pl.centre
        off = ((cx - pl.request.anchor[0]) * to_pt, (cy - pl.request.anchor[1]) * to_pt)
        ax.annotate(literal(text), (float(anchor[0]), float(anchor[1])), textcoords="offset points",
                    xytext=(round(off[0], 3), round(off[1], 3)), ha="center", va="center", fontsize=size,
                    color=color, style=fstyle, weight=weight, annotation_clip=False, zorder=5,
                    bbox={"boxstyle": "square,pad=0.05", "facecolor": "white", "edgecolor": "none", "alpha": 0.85},
                    arrowprops={"arrowstyle": "-", "color": "0.45", "linewidth": 0.6, "shrinkA": 0, "shrinkB": 0}
                    if pl.displaced else None)
    return placed


def common_limits(items: list[tuple[Model, np.ndarray]], pad: float = 0.08) -> tuple[float, float, float, float]:
    """One box for every panel: every point, attachment and disc rim of every (model, poses)."""
    from .player import _extent_box

    xy = np.vstack([_extent_box(m, p) for m, p in items])
    lo, hi = xy.min(axis=0), xy.max(axis=0)
    d = pad * float(max(hi - lo)) or 0.05
    return (float(lo[0] - d), float(lo[1] - d), float(hi[0] + d), float(hi[1] + d))


def overlay_figure(old, new, prefix: str = "overlay", round_off: tuple[bool, bool] = (False, False),
                   scale: tuple[float, float] | None = None) -> str:
    """One stage of two designs: Fx, Fy, |F| and M over time, old dashed grey, new solid black.
    A load that is round-off in both designs (``round_off`` = (force, moment)) is drawn as zero
    on the unbalanced ``scale`` (peak |F|, peak |M|), with a note, not as a signal."""
    fig, axes = plt.subplots(2, 2, figsize=(9.0, 5.2), sharex=False)
    panels = [
        (axes[0, 0], "Shaking force Fx (N)", lambda a: a.force[:, 0]),
        (axes[0, 1], "Shaking force Fy (N)", lambda a: a.force[:, 1]),
        (axes[1, 0], "Shaking force |F| (N)", lambda a: np.hypot(a.force[:, 0], a.force[:, 1])),
        (axes[1, 1], "Shaking moment M (N m)", lambda a: a.moment),
    ]
    for n, (ax, title, fn) in enumerate(panels):
        quiet = round_off[1] if n == 3 else round_off[0]
        if quiet:
            ax.plot(old.t, np.zeros_like(old.t), color="0.55", linestyle="--", linewidth=1.6, label="old")
            ax.plot(new.t, np.zeros_like(new.t), color="black", linestyle="-", linewidth=1.3, label="new")
            lim = (scale[1] if n == 3 else scale[0]) if scale else 1.0
            ax.set_ylim(-1.05 * lim, 1.05 * lim)
            ax.text(0.5, 0.85, "round-off in both designs (shown as 0,\non the unbalanced scale)", transform=ax.transAxes,
                    ha="center", va="top", fontsize=8, color="0.3")
        else:
            ax.plot(old.t, fn(old), color="0.55", linestyle="--", linewidth=1.6, label="old")
            ax.plot(new.t, fn(new), color="black", linestyle="-", linewidth=1.3, label="new")
        ax.set_title(literal(title), fontsize=9)
    for ax in axes[1]:
        ax.set_xlabel("time (s)")
    axes[0, 0].legend(fontsize=8)
    fixed_layout(fig)
    return to_svg(fig, prefix)
