"""Names on the mechanism drawings that do not overlap, the gears' numbers, and the player's
per-panel view boxes (issue 11, items 3-4)."""

from __future__ import annotations

import itertools
import math
from pathlib import Path

import numpy as np
import pytest

from balpipe.build import Options, build
from balpipe.draw import figures, labels
from balpipe.report import page
from balpipe.draw import player

import drawn_svg

SPECS = Path(__file__).resolve().parents[2] / "specs"
DRAWN = ["paper000_rpr3_idler_loop.yaml", "paper001_4rrr.yaml", "paper002_decoupling.yaml",
         "paper004_five_bar.yaml", "scott_russell.yaml", "custom_four_bar_balancing.yaml"]


# -- the placer itself -------------------------------------------------------------------------

def test_placed_labels_never_overlap_random_crowds():
    rng = np.random.default_rng(11)
    for _ in range(30):
        n = int(rng.integers(5, 40))
        centre = rng.uniform(0, 200, size=2)
        reqs = [labels.Request(f"L{k}", tuple(centre + rng.normal(0, 15, size=2)), float(rng.uniform(8, 60)),
                               float(rng.uniform(8, 14))) for k in range(n)]
        segs = [(tuple(rng.uniform(0, 400, 2)), tuple(rng.uniform(0, 400, 2))) for _ in range(10)]
        placed = labels.place(reqs, segs, bounds=(0.0, 0.0, 400.0, 400.0))
        assert [p.request for p in placed] == reqs
        for a, b in itertools.combinations(placed, 2):
            assert not labels.overlaps(a.box, b.box), (a, b)
        assert placed == labels.place(reqs, segs, bounds=(0.0, 0.0, 400.0, 400.0))  # deterministic


def test_a_free_label_sits_beside_its_anchor_and_a_crowded_one_gets_a_leader():
    first = labels.Request("A", (100.0, 100.0), 20.0, 10.0)
    same = labels.Request("B", (100.0, 100.0), 20.0, 10.0)
    placed = labels.place([first, same] + [labels.Request(f"C{k}", (100.0, 100.0), 20.0, 10.0) for k in range(12)],
                          bounds=(0.0, 0.0, 300.0, 300.0))
    assert not placed[0].displaced and placed[0].box[0] >= 100.0  # east of the anchor, beside it
    assert any(p.displaced for p in placed[1:])
    for a, b in itertools.combinations(placed, 2):
        assert not labels.overlaps(a.box, b.box)


def test_labels_avoid_links_where_they_can():
    link = ((0.0, 100.0), (200.0, 100.0))  # a horizontal link through the anchor
    p = labels.place([labels.Request("B", (100.0, 100.0), 30.0, 10.0)], [link])[0]
    assert not labels.segment_hits_box(link, p.box)
    assert labels.segment_hits_box(((0, 0), (10, 10)), (4, 4, 6, 6))
    assert not labels.segment_hits_box(((0, 0), (10, 0)), (4, 1, 6, 3))


def test_gear_numbers_from_names_else_in_model_order():
    assert labels.number_in_name("gear 5") == "5"
    assert labels.number_in_name("gear 1'") == "1'"
    assert labels.number_in_name("gear1p") == "1'"
    assert labels.number_in_name("gear 1''") == "1''"
    assert labels.number_in_name("cr1.2") == "1"
    assert labels.number_in_name("7") == "7"
    assert labels.number_in_name("disc_crank") is None
    assert labels.gear_key({"cr1.1": "1", "cr1.2": "1", "cr2": "2", "x": "10"}) == "1 = cr1.1, cr1.2; 2 = cr2; 10 = x"


# -- the papers' drawings ----------------------------------------------------------------------

@pytest.mark.parametrize("name", DRAWN)
def test_names_on_the_papers_drawings_never_overlap(studies, name):
    st = studies(name)
    shown = page.shown_stages(st)
    limits = figures.common_limits([(s.stage.model, s.analysis.frame_pose) for s in shown])
    numbers = labels.gear_numbers([s.stage.model for s in shown])
    for s in shown:
        canvas, placed = figures.mechanism_drawing(s.stage.model, s.analysis, page.drawn_instants(st), s.stage.label,
                                                   limits, numbers)
        x0, y0, x1, y1 = canvas.panels[0].box
        drawn = drawn_svg.read(canvas.svg("t"))
        texts, segs = drawn["names"], drawn["links"]
        assert placed, s.stage.name
        for a, b in itertools.combinations(placed, 2):
            assert not labels.overlaps(a.box, b.box), f"{name} {s.stage.name}: {a.request.text!r} over {b.request.text!r}"
        # as drawn: the names' boxes, read back from the SVG, overlap no other name nor a link of
        # the solid pose
        assert sorted(t for t, _ in texts) == sorted(p.request.text for p in placed) and segs
        for (ta, a), (tb, b) in itertools.combinations(texts, 2):
            assert not labels.overlaps(a, b), f"{name} {s.stage.name}: {ta!r} over {tb!r} as drawn"
        crossed = [t for t, box in texts if any(labels.segment_hits_box(sg, box) for sg in segs)]
        assert not crossed, f"{name} {s.stage.name}: names over a link: {crossed}"
        for p in placed:
            assert x0 <= p.box[0] and p.box[2] <= x1 and y0 <= p.box[1] and p.box[3] <= y1, (name, p)
        texts = [p.request.text for p in placed]
        assert "axis" not in texts  # a disc's axis is named by the disc's number
        m = s.stage.model
        for b in m.bodies:
            if len(b.outline) >= 2:
                assert b.name in texts
            for a in b.attachments:
                if a.kind == "counterweight":
                    assert a.name in texts
        gears = sorted(p.request.text for p in placed if p.request.kind == "gear")
        assert gears == sorted(numbers[g] for g in labels.gear_parts(m))


def test_the_drawing_is_the_same_bytes_twice(studies):
    st = studies("paper004_five_bar.yaml")
    s = st.stages[-1]
    a = figures.mechanism_figure(s.stage.model, s.analysis, None, prefix="m", title="x")
    b = figures.mechanism_figure(s.stage.model, s.analysis, None, prefix="m", title="x")
    assert a == b


def test_the_papers_gear_numbers(studies):
    n4 = labels.gear_numbers([s.stage.model for s in page.shown_stages(studies("paper004_five_bar.yaml"))])
    assert sorted(set(n4.values())) == ["1'", "2'", "3'", "4'", "5", "6", "7"]
    assert n4["gear5"] == "5" and n4["gear6"] == "6" and n4["gear7"] == "7"
    n0 = labels.gear_numbers([s.stage.model for s in studies("paper000_rpr3_idler_loop.yaml").stages])
    assert sorted(set(n0.values())) == ["1", "2", "3", "4"]  # counter-rotations 1-4 (eqs. 9a-d)
    n2 = labels.gear_numbers([s.stage.model for s in studies("paper002_decoupling.yaml").stages])
    assert n2["gear3"] == "3" and n2["gear1p"] == "1'" and n2["gear 2'"] == "2'"
    nc = labels.gear_numbers([s.stage.model for s in studies("custom_four_bar_balancing.yaml").stages])
    assert nc == {"disc_crank": "1", "disc_coupler": "2", "disc_rocker": "3"}  # no number in the names


def test_paper004_page_shows_gears_5_6_7(tmp_path):
    out = tmp_path / "site"
    outcomes = build([str(SPECS / "paper004_five_bar.yaml")], Options(out=out, simulate=False))
    assert [o.status for o in outcomes] == ["ok"]
    html = (out / "paper004_five_bar" / "index.html").read_text(encoding="utf-8")
    assert "5 = gear5; 6 = gear6; 7 = gear7" in html
    mech = html[html.index("<h2 id=\"the-mechanism\"") if "<h2 id=\"the-mechanism\"" in html else html.index("The mechanism</h2>"):]
    for num in ("5", "6", "7", "1'", "3'"):
        assert f">{num}</text>" in mech or f">{num.replace(chr(39), '&#39;')}</text>" in mech, num


# -- the player --------------------------------------------------------------------------------

def _stages(st, moving_base: bool):
    rng = np.random.default_rng(5)
    out = []
    for s in st.stages:
        t = s.analysis.t
        poses = np.array(s.analysis.frame_pose, dtype=float)
        base = np.zeros((len(t), 3))
        if moving_base:  # the frame drifts and turns: the bodies move with it
            u = np.linspace(0, 1, len(t))
            base = np.stack([0.05 * rng.uniform() * np.sin(3 * u), 0.05 * rng.uniform() * u, 0.3 * rng.uniform() * u], 1)
            c, sn = np.cos(base[:, 2])[:, None], np.sin(base[:, 2])[:, None]
            x, y = poses[:, :, 0].copy(), poses[:, :, 1].copy()
            poses[:, :, 0] = base[:, :1] + c * x - sn * y
            poses[:, :, 1] = base[:, 1:2] + sn * x + c * y
            poses[:, :, 2] += base[:, 2:3]
        out.append({"label": s.stage.label, "model": s.stage.model, "t": t, "base": base, "poses": poses})
    return out


def _inside_panel(d, stage, xy):
    ox, oy, s = stage["view"]
    px, py = ox + s * xy[:, 0], oy - s * xy[:, 1]
    X, Y = stage["origin"]
    W, H = d["layout"]["width"], d["layout"]["height"]
    return (px >= X + 1).all() and (px <= X + W - 1).all() and (py >= Y + player.TOP - 1).all() and \
        (py <= Y + H - player.BOTTOM + 1).all(), (px.min() - X, px.max() - X, py.min() - Y, py.max() - Y)


@pytest.mark.parametrize("name,moving", [("scott_russell.yaml", False), ("paper000_rpr3_idler_loop.yaml", True),
                                         ("paper004_five_bar.yaml", True)])
def test_player_panels_contain_every_instant_and_fill_their_box(studies, name, moving):
    st = studies(name)
    stages = _stages(st, moving)
    d = player.player_data(stages)
    W, H = d["layout"]["width"], d["layout"]["height"]
    inner_w, inner_h = W - 2 * player.SIDE, H - player.TOP - player.BOTTOM
    spans = []
    for stage, src in zip(d["stages"], stages):
        m = src["model"]
        pts = []
        for i, b in enumerate(m.bodies):  # every instant, not only the ~60 frames shown
            local = list(b.points.values()) + [a.position for a in b.attachments]
            for a in b.attachments:
                if a.radius:
                    local += [(a.position[0] + a.radius * math.cos(q), a.position[1] + a.radius * math.sin(q))
                              for q in np.linspace(0, 2 * math.pi, 16)]
            if b.radius:
                local += [(b.radius * math.cos(q), b.radius * math.sin(q)) for q in np.linspace(0, 2 * math.pi, 16)]
            P = src["poses"][:, i]
            for px, py in local:
                pts.append(np.stack([P[:, 0] + np.cos(P[:, 2]) * px - np.sin(P[:, 2]) * py,
                                     P[:, 1] + np.sin(P[:, 2]) * px + np.cos(P[:, 2]) * py], 1))
        B = src["base"]
        for px, py in list(m.frame_points.values()) + [q for gd in m.guides for q in gd]:
            pts.append(np.stack([B[:, 0] + np.cos(B[:, 2]) * px - np.sin(B[:, 2]) * py,
                                 B[:, 1] + np.sin(B[:, 2]) * px + np.cos(B[:, 2]) * py], 1))
        xy = np.vstack(pts)
        ok, ext = _inside_panel(d, stage, xy)
        assert ok, (name, stage["label"], ext)
        # at one scale for every panel (the stages' own scales within a factor 3 here), the
        # largest stage filling its panel: its swept extent spans most of the width or the height
        ox, oy, s = stage["view"]
        spans.append((s * np.ptp(xy[:, 0]), s * np.ptp(xy[:, 1])))
        # the scale bar is a round length within the panel
        bar = stage["bar"][0]
        assert 0 < bar * s <= inner_w and f"{bar:g}" != "" and stage["bar"][1].endswith("m")
    assert d["same_scale"]
    assert any(w_px >= 0.8 * inner_w or h_px >= 0.8 * inner_h for w_px, h_px in spans), (spans, inner_w, inner_h)


def test_panels_share_one_scale_unless_a_stage_is_three_times_larger():
    """Boxes of 1 m and 2 m: one scale (the smaller, so both fit); 1 m and 4 m: each its own."""
    def ext(size):
        return np.array([[0.0, 0.0], [size, size]])

    shared = player.panel_views([ext(1.0), ext(2.0)])
    assert player.same_scale(shared)
    apart = player.panel_views([ext(1.0), ext(4.0)])
    s = [p["view"][2] for p in apart["panels"]]
    assert not player.same_scale(apart) and s[0] == pytest.approx(4 * s[1])
    assert shared["panels"][0]["view"][2] == pytest.approx(apart["panels"][1]["view"][2] * 2)


def test_player_says_when_the_panels_scales_differ(studies):
    st = studies("scott_russell.yaml")
    stages = _stages(st, False)
    d = player.player_data(stages)
    scales = [p["view"][2] for p in d["stages"]]
    note = player.scale_note(stages)
    if max(scales) > 1.02 * min(scales):
        assert not d["same_scale"] and "scales differ" in note
    else:
        assert d["same_scale"] and "same scale" in note
    # one stage drawn twice, one of them shrunk: different scales, said so
    small = dict(stages[0], model=stages[0]["model"], label="copy")
    d2 = player.player_data([stages[0], small])
    assert d2["same_scale"]
    assert "same scale" in player.scale_note([stages[0], small])


def test_player_grid_and_names_in_the_html(studies):
    st = studies("paper004_five_bar.yaml")
    html = player.player_html(_stages(st, False))
    assert 'id="player-names"' in html and "placeNames" in html
    d = player.player_data(_stages(st, False))
    assert d["layout"]["columns"] == 4 and d["layout"]["rows"] == 1
    names = d["stages"][2]["names"]
    assert sorted(g[-1] for g in names["gears"]) == ["1'", "2'", "3'", "4'", "5", "6", "7"]
    assert html == player.player_html(_stages(st, False))  # same bytes
    # the page's player and its note from one player_data: the same text as each alone
    assert player.player(_stages(st, False)) == (html, player.scale_note(_stages(st, False)))
    assert player.player(_stages(st, False), "p2", floating=False, autoplay=False)[0] == \
        player.player_html(_stages(st, False), "p2", floating=False, autoplay=False)


# -- paper 001's 4-RRR drawings (Figs. 2a, 3a-f, 4a, 4b, 6) -------------------------------------

PAPER001 = ["paper001_4rrr.yaml", "paper001_4rrr_fig6a.yaml", "paper001_4rrr_fig6b.yaml", "paper001_4rrr_fig6c.yaml"]


def _only(canvas, k: int, prefix: str) -> str:
    """The SVG of ``canvas`` with only its ``k``-th shown panel."""
    shown = [p for p in canvas.panels if p.visible]
    keep = [p.visible for p in canvas.panels]
    for p in canvas.panels:
        p.visible = p is shown[k]
    try:
        return canvas.svg(prefix)
    finally:
        for p, v in zip(canvas.panels, keep):
            p.visible = v


def _disc_hits_box(centre, r, box) -> bool:
    qx = min(max(centre[0], box[0]), box[2])
    qy = min(max(centre[1], box[1]), box[3])
    return math.hypot(qx - centre[0], qy - centre[1]) < r


@pytest.mark.parametrize("name", PAPER001)
def test_names_on_paper001_drawings_never_overlap(studies, name, monkeypatch):
    """Every 4-RRR drawing of paper 001 (the balanced stages; Figs. 3a-f; Fig. 4b): the names drawn
    (pivots A1-A4 at least) overlap no other name, no counter-mass disc and no link, read back
    from the figures themselves."""
    from balpipe.families.rrr4 import figures as rrr4

    drawn = []

    def keep(panels, prefix):
        canvas = rrr4.panels_canvas(panels)
        drawn.append((prefix, canvas))
        return canvas.svg(prefix)

    monkeypatch.setattr(rrr4, "draw_panels", keep)
    st = studies(name)
    rrr4.topology_figure(st)
    checked = rrr4.designs_drawn(st)
    if checked:
        rrr4.designs_figure(st, checked, rrr4.FIG3)
        rrr4.designs_figure(st, checked, ("Fig. 4b",))
    assert len(drawn) == (3 if checked else 1)
    panels = 0
    for prefix, canvas in drawn:
        # at most three panels a row (four: 2 x 2), each as large as the others' (4.2 in)
        assert canvas.width <= 3 * 4.2 * 72 + 1e-9, (name, prefix, canvas.width)
        shown = [p for p in canvas.panels if p.visible]
        for k, panel in enumerate(shown):
            panels += 1
            one = drawn_svg.read(_only(canvas, k, prefix))
            texts, discs, segs = one["names"], one["discs"], one["links"] + one["outlines"]
            where = f"{name} {prefix} {panel.title!r}"
            names = [t for t, _ in texts]
            assert {"A1", "A2", "A3", "A4"} <= set(names), (where, names)
            assert discs and segs, where
            for (ta, a), (tb, b) in itertools.combinations(texts, 2):
                assert not labels.overlaps(a, b), f"{where}: {ta!r} over {tb!r}"
            for t, box in texts:
                for c, r in discs:
                    assert not _disc_hits_box(c, r, box), f"{where}: {t!r} over a disc at {c}"
                for sg in segs:
                    assert not labels.segment_hits_box(sg, box), f"{where}: {t!r} over a link {sg}"
    assert panels >= 4


def test_the_drawings_box_is_every_point_tracks_extremes(studies):
    """The box the drawings share (:func:`balpipe.draw.figures.common_limits`, the player's panels)
    is reduced body by body (a long grid's (frames x every point) array is never held):
    it equals the extremes of every body origin, named point and attachment over the frames and
    of the frame's pivots, stacked."""
    from balpipe.draw.player import _extent_box
    from balpipe.mechanics.planar import world_point

    for s in studies("custom_four_bar_balancing.yaml").stages:
        model, poses = s.stage.model, s.analysis.frame_pose
        tracks = [poses[:, :, :2].reshape(-1, 2), np.array(list(model.frame_points.values()), dtype=float)]
        for i, b in enumerate(model.bodies):
            local = list(b.points.values()) + [a.position for a in b.attachments]
            r = b.radius or 0.0
            local += [(r, 0.0), (-r, 0.0), (0.0, r), (0.0, -r)] if r else []
            local += [(a.position[0] + dx * a.radius, a.position[1] + dy * a.radius) for a in b.attachments if a.radius
                      for dx, dy in ((1, 0), (-1, 0), (0, 1), (0, -1))]
            tracks += [world_point(poses[:, i], p) for p in local]
        xy = np.vstack(tracks)
        assert np.array_equal(_extent_box(model, poses), np.array([xy.min(axis=0), xy.max(axis=0)]))
