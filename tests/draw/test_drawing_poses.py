"""Mechanism drawings an engineer can read (issue 22, point 5): one pose solid with the extreme
poses as ghosts (:mod:`balpipe.draw.extremes`), every prismatic leg connected
(:mod:`balpipe.draw.sleeves`), in the drawings and the player, the papers' joint names; the
page's caption says what is drawn. Names clear of each other and of the links, read back from
the drawn figures: tests/draw/test_drawing_labels.py."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from balpipe.build import Options, build
from balpipe.draw import extremes, figures, sleeves
from balpipe.mechanics.planar import world_point
from balpipe.model import Body, Model, Prismatic, Revolute
from balpipe.report import page

SPECS = Path(__file__).resolve().parents[2] / "specs"


def crank(angles: np.ndarray) -> tuple[Model, np.ndarray]:
    """A crank of 0.1 m turning about the origin through ``angles`` (rad): model and poses."""
    body = Body("crank", 1.0, (0.05, 0.0), 0.001, {"O": (0.0, 0.0), "B": (0.1, 0.0)}, outline=("O", "B"))
    model = Model("crank", (body,), (), (), {"crank": (0.0, 0.0, 0.0)})
    poses = np.zeros((len(angles), 1, 3))
    poses[:, 0, 2] = angles
    return model, poses


# -- which poses -------------------------------------------------------------------------------

def test_a_full_turn_shows_the_opposite_pose():
    model, poses = crank(np.linspace(0.0, 2 * math.pi, 361))
    assert extremes.extreme_instants(model, poses) == [180]  # half a turn: B farthest from its start


def test_a_point_to_point_motion_shows_its_end_pose():
    model, poses = crank(np.linspace(0.0, 1.0, 101) ** 2)
    assert extremes.extreme_instants(model, poses) == [100]


def test_out_and_back_twice_shows_both_far_poses_once():
    t = np.linspace(0.0, 1.0, 401)
    model, poses = crank(0.8 * np.sin(4 * math.pi * t))  # +0.8 rad, -0.8 rad, +0.8, -0.8
    ks = extremes.extreme_instants(model, poses)
    assert len(ks) == 2
    angles = sorted(round(float(poses[k, 0, 2]), 6) for k in ks)
    assert angles == [-0.8, 0.8]
    e = extremes.excursion(model, poses)
    for k in ks:  # each a maximum of the excursion, the largest there is
        assert e[k] == pytest.approx(float(e.max()))


def test_a_mechanism_that_barely_moves_has_no_ghost():
    model, poses = crank(np.zeros(50))
    assert extremes.extreme_instants(model, poses) == []
    # out to 1 rad, back, and a last small nudge (a local maximum at the end, under 5 %): one ghost
    model, poses = crank(np.concatenate([np.linspace(0, 1.0, 50), np.linspace(0.98, 0.0, 50), [0.02, 0.04]]))
    e = extremes.excursion(model, poses)
    assert e[-1] > e[-2] and e[-1] < extremes.NEGLIGIBLE * e.max()
    assert extremes.extreme_instants(model, poses) == [49]


def test_excursion_is_the_rms_distance_of_the_points():
    model, poses = crank(np.array([0.0, math.pi / 2]))
    # O stays, B moves by 0.1 sqrt(2): RMS over the two points = 0.1
    assert extremes.excursion(model, poses)[1] == pytest.approx(0.1, rel=1e-12)


def test_the_page_draws_the_end_pose_of_paper000s_point_to_point_motion(studies):
    st = studies("paper000_rpr3_idler_loop.yaml")
    t = st.stages[0].analysis.t
    assert page.drawn_instants(st) == [len(t) - 1]
    d = page.drawing_times(st)
    assert d["solid"] == "0" and d["ghosts"] == f"{float(t[-1]):.4g} s" and d["count"] == 1 and d["sleeves"]


# -- connected legs ----------------------------------------------------------------------------

def _proj(p, a, u) -> float:
    return float(np.dot(np.asarray(p) - a, u))


@pytest.mark.parametrize("name", ["paper000_rpr3_idler_loop.yaml", "paper000_rpr3_scott_russell.yaml"])
def test_every_3rpr_leg_is_one_piece_from_base_pivot_to_platform_at_every_sample(studies, name):
    """At every sample, leg i's drawing covers the segment A_i C_i without a gap: the sleeve
    starts at the base pivot A_i and reaches the piston's inner end B_i, whose rod ends at C_i."""
    st = studies(name)
    for s in page.shown_stages(st):
        m = s.stage.model
        poses = s.analysis.frame_pose
        idx = {b.name: i for i, b in enumerate(m.bodies)}
        assert len(sleeves.pairs(m)) == 3
        assert sleeves.guided_sliders(m) == {"piston1", "piston2", "piston3"}
        gaps = []
        for k in range(0, len(poses), 10):
            row = poses[k]
            for n, (start, end) in enumerate(sleeves.sleeves(m, row), start=1):
                A = np.array(m.frame_points[f"A{n}"])
                C = world_point(row[idx["platform"]], m.body("platform").points[f"C{n}"])
                B = world_point(row[idx[f"piston{n}"]], m.body(f"piston{n}").points["B"])
                rod_end = world_point(row[idx[f"piston{n}"]], m.body(f"piston{n}").points["C"])
                u = (C - A) / np.linalg.norm(C - A)
                assert np.linalg.norm(start - A) < 1e-9  # the sleeve sits on the pivot
                assert np.linalg.norm(rod_end - C) < 1e-6  # the rod is pinned to the platform
                # the sleeve, along the leg, reaches at least to the rod's inner end: no gap
                gaps.append(_proj(B, A, u) - _proj(end, A, u))
                assert abs((end - A)[0] * u[1] - (end - A)[1] * u[0]) < 1e-9  # on the leg's axis
        assert max(gaps) <= 1e-9, (s.stage.name, max(gaps))


def test_a_slider_on_the_frame_keeps_its_block_and_has_no_sleeve(studies):
    st = studies("offset_slider_crank.yaml")
    m = st.stages[0].stage.model
    assert sleeves.pairs(m) == [] and sleeves.guided_sliders(m) == set()


def test_a_rod_longer_than_its_guide_needs_no_stretch():
    """A guide whose outline already holds the slider: the sleeve is the guide's own extent."""
    guide = Body("g", 1.0, (0.0, 0.0), 0.0, {"A": (0.0, 0.0), "T": (0.5, 0.0)}, outline=("A", "T"))
    rod = Body("r", 1.0, (0.0, 0.0), 0.0, {"B": (-0.3, 0.0), "C": (0.0, 0.0)}, outline=("B", "C"), kind="slider")
    m = Model("m", (guide, rod), (Revolute("A", "frame", "g", (0.0, 0.0), (0.0, 0.0)),
                                  Prismatic("P", "g", "r", (0.0, 0.0), (1.0, 0.0))), (), {})
    row = np.array([[0.0, 0.0, math.pi / 2], [0.0, 0.6, math.pi / 2]])  # rod from 0.3 to 0.6 along y
    (start, end), = sleeves.sleeves(m, row)
    assert np.allclose(start, [0.0, 0.0]) and np.allclose(end, [0.0, 0.5])
    row[1, 1] = 1.2  # rod from 0.9 to 1.2: the sleeve stretches to 0.9
    (start, end), = sleeves.sleeves(m, row)
    assert np.allclose(end, [0.0, 0.9])


# -- names ---------------------------------------------------------------------------------------

def test_the_platform_joints_carry_the_papers_names(studies):
    """Where the piston's C meets the platform's C1, the drawing names it C1 (the name no other
    point has), not C."""
    st = studies("paper000_rpr3_idler_loop.yaml")
    s = st.stages[0]
    _, placed = figures.mechanism_drawing(s.stage.model, s.analysis, [])
    texts = [p.request.text for p in placed]
    assert {"C1", "C2", "C3", "A1", "A2", "A3"} <= set(texts) and "C" not in texts


def test_the_3rpr_drawing_is_the_same_bytes_twice(studies):
    st = studies("paper000_rpr3_idler_loop.yaml")
    s = st.stages[-1]
    a = figures.mechanism_figure(s.stage.model, s.analysis, None, prefix="m", title="x")
    assert a == figures.mechanism_figure(s.stage.model, s.analysis, None, prefix="m", title="x")


def test_the_page_caption_says_solid_and_ghosts(tmp_path):
    out = tmp_path / "site"
    outcomes = build([str(SPECS / "paper000_rpr3_idler_loop.yaml")], Options(out=out, simulate=False))
    assert [o.status for o in outcomes] == ["ok"]
    html = (out / "paper000_rpr3_idler_loop" / "index.html").read_text(encoding="utf-8")
    assert "light to dark" not in html
    assert "Drawn solid at t = 0 s" in html and "in light grey at t = 0.25 s" in html
    assert "rod in the guiding link" in html


def test_the_player_draws_the_same_connected_legs(studies):
    """The player's frames carry each frame's sleeves (the drawing's, :func:`sleeves.sleeves`),
    and a piston in its cylinder is no block."""
    from balpipe.draw import player

    st = studies("paper000_rpr3_idler_loop.yaml")
    s = st.stages[0]
    poses = np.asarray(s.analysis.frame_pose, dtype=float)
    d = player.player_data([{"label": "x", "model": s.stage.model, "t": s.analysis.t,
                             "base": np.zeros((len(poses), 3)), "poses": poses}])["stages"][0]
    assert len(d["sleeves"]) == len(d["poses"]) and all(len(f) == 3 for f in d["sleeves"])
    assert d["t"][0] == 0.0  # the player starts where the drawing's solid pose is
    first = sleeves.sleeves(s.stage.model, poses[0])
    # rounded to what the panel shows: no drawn point moves by more than player.PIXEL
    scale = d["view"][2]
    assert np.allclose(np.array(d["sleeves"][0]), np.array([[a, b] for a, b in first]), atol=player.PIXEL / scale)
    assert np.allclose(np.array(d["poses"][0])[:, :2], poses[0][:, :2], atol=player.PIXEL / scale)
    names = [b.name for b in s.stage.model.bodies]
    assert not any(sh["slider"] for n, sh in zip(names, d["shapes"]) if n.startswith("piston"))


def test_the_player_names_the_platform_joints_first(studies):
    """The player names coinciding points by the first in its list: the platform's C1-C3 (names
    no other point has) come before the pistons' C."""
    from balpipe.draw import player

    s = studies("paper000_rpr3_idler_loop.yaml").stages[0]
    joints = [j[3] for j in player._labels(s.stage.model, {})["joints"]]
    assert joints.index("C1") < joints.index("C") and joints.index("C3") < joints.index("C")


def test_every_named_point_is_named_once_and_repeated_names_are_left_off(studies):
    """Issue 22: each 3-RPR leg's cylinder 'tip' and piston 'B' (the same name on every leg, three
    places) are left unlabelled, in the drawing and the player; every other name appears once,
    the pivots and the platform's joints included."""
    from collections import Counter

    from balpipe.draw import player

    for spec in ("paper000_rpr3_idler_loop.yaml", "paper000_rpr3_scott_russell.yaml"):
        s = studies(spec).stages[0]
        _, placed = figures.mechanism_drawing(s.stage.model, s.analysis, [])
        texts = Counter(p.request.text for p in placed if p.request.kind in ("pivot", "joint"))
        assert {"A1", "A2", "A3", "C1", "C2", "C3"} <= set(texts)
        assert "tip" not in texts and "B" not in texts
        assert all(n == 1 for n in texts.values()), texts
        poses = np.asarray(s.analysis.frame_pose, dtype=float)
        d = player.player_data([{"label": "x", "model": s.stage.model, "t": s.analysis.t,
                                 "base": np.zeros((len(poses), 3)), "poses": poses}])["stages"][0]
        names = {j[3] for j in d["names"]["joints"]}
        assert "tip" not in names and "B" not in names and {"C1", "C2", "C3", "P"} <= names


def test_a_name_two_bodies_share_at_one_place_is_named_once():
    """A crank's B and the rod's B at the same pin: one place, one label 'B'; the rod's far end,
    named by the rod alone, is labelled too."""
    from balpipe.draw import labels

    crank_ = Body("crank", 1.0, (0.05, 0.0), 0.001, {"O": (0.0, 0.0), "B": (0.1, 0.0)}, outline=("O", "B"))
    rod = Body("rod", 1.0, (0.1, 0.0), 0.001, {"B": (0.0, 0.0), "D": (0.2, 0.0)}, outline=("B", "D"))
    model = Model("two", (crank_, rod), (), (), {"crank": (0.0, 0.0, 0.0), "rod": (0.1, 0.0, 0.3)},
                  frame_points={"O": (0.0, 0.0)})
    row = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.3]])
    places = labels.point_places(model, row, 0.3)
    assert sorted(n for n, _ in places) == ["B", "D"] and labels.repeated_names(places) == set()
    requests, _, keep = figures.name_requests(model, row, 0.3, 1.0, {})
    assert [t for t, _, k in requests if k in ("pivot", "joint")] == ["O", "B", "D"]
    # two rods, each with its own 'D' at different places: 'D' names no one point
    rod2 = Body("rod2", 1.0, (0.1, 0.0), 0.001, {"B": (0.0, 0.0), "D": (0.2, 0.0)}, outline=("B", "D"))
    model = Model("three", (crank_, rod, rod2), (), (),
                  {"crank": (0.0, 0.0, 0.0), "rod": (0.1, 0.0, 0.3), "rod2": (0.1, 0.0, -0.3)},
                  frame_points={"O": (0.0, 0.0)})
    row = np.array([[0.0, 0.0, 0.0], [0.1, 0.0, 0.3], [0.1, 0.0, -0.3]])
    requests, _, keep = figures.name_requests(model, row, 0.3, 1.0, {})
    assert [t for t, _, k in requests if k in ("pivot", "joint")] == ["O", "B"]
    assert len([c for c, r in keep if r is None]) == 3  # the unnamed ends' markers are still kept clear


def test_the_players_rounding_moves_no_drawn_point_by_more_than_its_bound():
    """The player's poses keep the decimals their panel shows (issue 22, a page's weight): half
    the last kept digit, at the panel's scale (a position) or across the whole panel (an angle),
    is at most player.PIXEL px; one decimal fewer would be more."""
    from balpipe.draw import player

    for scale in (0.3, 7.0, 500.0, 3000.0, 2.5e5):
        for size in (120.0, 424.0, 900.0):
            position, angle = player.digits(scale, size)
            assert 0.5 * 10.0 ** -position * scale <= player.PIXEL
            assert 0.5 * 10.0 ** -angle * size <= player.PIXEL
            assert position == 0 or 0.5 * 10.0 ** (1 - position) * scale > player.PIXEL
            assert 0.5 * 10.0 ** (1 - angle) * size > player.PIXEL
