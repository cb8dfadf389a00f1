"""The laws of real machines (balpipe.laws): derivatives agree with finite differences of the
positions, periodic laws join at cycle boundaries, tables reproduce a smooth reference, paths
move at the timing law's speed."""

from __future__ import annotations

import math

import balpipe  # noqa: F401
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from balpipe.laws import paths
from balpipe.laws.cycle import Cycle, joins
from balpipe.laws.periodic import Cam, ConstantSpeed, Fourier, cam_jumps
from balpipe.laws.table import Table, TableError, Tabulated, parse_table
from balpipe.laws.drives import CycleDrive, cycle_law
from balpipe.motion import PROFILES, PointToPoint, Polynomial
from balpipe.spec_parts import SpecFieldError


def assert_derivatives(law, t0: float, t1: float, n: int = 40001, skip_jumps: bool = False):
    """q' and q'' against central differences of q and q' (relative to their peaks)."""
    t = np.linspace(t0, t1, n)
    q, qd, qdd = law(t)
    h = t[1] - t[0]
    vd = (q[2:] - q[:-2]) / (2 * h)
    ad = (qd[2:] - qd[:-2]) / (2 * h)
    vs = max(np.max(np.abs(qd)), 1e-300)
    as_ = max(np.max(np.abs(qdd)), 1e-300)
    assert np.max(np.abs(vd - qd[1:-1])) < (1e-4 if skip_jumps else 1e-5) * vs
    err = np.abs(ad - qdd[1:-1])
    if skip_jumps:  # central differences straddle a deliberate jump of the acceleration
        err = err[np.abs(qdd[2:] - qdd[:-2]) < 0.01 * as_]
    assert np.max(err) < 1e-3 * as_  # first order where the jerk jumps (cam joins, corners)


def assert_periodic(law, period: float, displacement: float = 0.0, cycles: int = 3):
    """q, q', q'' at k P- and k P+ (the same state), to 1e-9 of their scale."""
    t = np.linspace(0, period, 2001)
    q, qd, qdd = law(t)
    scales = [max(np.ptp(q), abs(displacement), 1e-300), max(np.max(np.abs(qd)), 1e-300), max(np.max(np.abs(qdd)), 1e-300)]
    for k in range(1, cycles + 1):
        before = law(np.array([k * period * (1 - 1e-13)]))
        after = law(np.array([k * period]))
        start = law(np.array([0.0]))
        for i in range(3):
            assert abs(before[i][0] - after[i][0]) <= 1e-9 * scales[i] + (1e-3 * scales[i] * 1e-13 * period if i < 2 else 0)
            shift = k * displacement if i == 0 else 0.0
            assert abs(after[i][0] - (start[i][0] + shift)) <= 1e-9 * scales[i]


@pytest.mark.parametrize("seed", range(4))
def test_constant_speed_steady_and_from_rest(seed):
    rng = np.random.default_rng(seed)
    q0, w = rng.uniform(-2, 2), rng.uniform(-20, 20)
    law = ConstantSpeed(q0, w)
    q, qd, qdd = law(np.array([0.0, 0.3]))
    assert qd[0] == w and qdd[0] == 0 and q[1] == pytest.approx(q0 + 0.3 * w)  # already moving at t = 0
    assert_periodic(law, 2 * math.pi / abs(w), 2 * math.pi * np.sign(w))
    ramp = ConstantSpeed(q0, w, rng.uniform(0.05, 0.5))
    q, qd, qdd = ramp(np.array([0.0, ramp.ramp, 2.0]))
    assert qd[0] == 0 and qdd[0] == 0 and qd[1] == pytest.approx(w) and qdd[1] == pytest.approx(0, abs=1e-12)
    assert_derivatives(ramp, 0.0, 2 * ramp.ramp)


@pytest.mark.parametrize("profile", ["cycloidal", "quintic", "harmonic"])
@pytest.mark.parametrize("seed", range(3))
def test_cam_laws_join_up_and_derivatives_agree(profile, seed):
    rng = np.random.default_rng(seed)
    if profile == "harmonic":  # continuous in acceleration only without dwells and with rise = return
        rise, dwell, ret = 0.5, 0.0, 0.5
    else:
        rise, dwell, ret = rng.uniform(0.1, 0.35), rng.uniform(0.0, 0.3), rng.uniform(0.1, 0.3)
    P = rng.uniform(0.2, 2.0)
    law = Cam(rng.uniform(-1, 0), rng.uniform(0.1, 1), P, profile, rise, dwell, ret)
    assert cam_jumps(profile, rise, dwell, ret) < 1e-9
    assert_periodic(law, P)
    assert_derivatives(law, -0.3 * P, 2.3 * P, n=80001)


def test_harmonic_with_dwell_jumps():
    assert cam_jumps("harmonic", 0.3, 0.2, 0.3) > 1
    assert cam_jumps("harmonic", 0.3, 0.0, 0.7) > 1


@pytest.mark.parametrize("seed", range(4))
def test_fourier_series(seed):
    rng = np.random.default_rng(seed)
    P = rng.uniform(0.1, 3)
    law = Fourier(rng.normal(), P, tuple((rng.normal(), rng.normal()) for _ in range(rng.integers(1, 6))))
    assert_periodic(law, P)
    assert_derivatives(law, 0.0, 2 * P, n=80001)


def test_cycle_of_segments_matches_states():
    rest = PointToPoint(0.0, 1.0, 0.4, PROFILES["cycloidal"])
    dwell = ConstantSpeed(1.0, 0.0)
    back = PointToPoint(1.0, 0.0, 0.3, PROFILES["quintic"])
    cyc = Cycle((rest, dwell, back, ConstantSpeed(0.0, 0.0)), (0.4, 0.2, 0.3, 0.1))
    assert cyc.period == pytest.approx(1.0) and cyc.displacement == 0.0
    for dq, dv, da in joins(cyc):
        assert abs(dq) < 1e-12 and abs(dv) < 1e-12 and abs(da) < 1e-9
    assert_periodic(cyc, 1.0)
    assert_derivatives(cyc, 0.0, 2.0, n=80001)


def test_cycle_with_polynomial_blend_to_constant_speed():
    # a crank that turns at 2 rad/s for 0.5 s, blends to rest, dwells, and blends back up
    v = 2.0
    seg1 = ConstantSpeed(0.0, v)
    q1 = 1.0
    blend_down = Polynomial.from_boundary((q1, v, 0.0), (q1 + 0.3, 0.0, 0.0), 0.3)
    dwell = ConstantSpeed(q1 + 0.3, 0.0)
    blend_up = Polynomial.from_boundary((q1 + 0.3, 0.0, 0.0), (q1 + 0.6, v, 0.0), 0.3)
    cyc = Cycle((seg1, blend_down, dwell, blend_up), (0.5, 0.3, 0.2, 0.3))
    assert cyc.displacement == pytest.approx(q1 + 0.6)
    for dq, dv, da in joins(cyc):
        assert abs(dq) < 1e-12 and abs(dv) < 1e-9 and abs(da) < 1e-9
    assert_periodic(cyc, cyc.period, cyc.displacement)
    assert_derivatives(cyc, 0.0, 2 * cyc.period, n=80001)


def test_table_reproduces_a_smooth_reference():
    P = 1.0
    t = np.linspace(0, P, 201)
    text = "t [s], crank [deg]\n" + "".join(f"{float(a)!r}, {math.degrees(0.5 * math.sin(2 * math.pi * a))!r}\n" for a in t)
    table = parse_table(text, "angle")
    assert table.q[50] == pytest.approx(0.5 * math.sin(2 * math.pi * t[50]))  # deg -> rad
    law = Tabulated(table, "periodic")
    tt = np.linspace(0, 2 * P, 1001)
    q, qd, qdd = law(tt)
    w = 2 * math.pi
    assert np.max(np.abs(q - 0.5 * np.sin(w * tt))) < 1e-7
    assert np.max(np.abs(qd - 0.5 * w * np.cos(w * tt))) < 1e-5 * 0.5 * w
    assert np.max(np.abs(qdd + 0.5 * w * w * np.sin(w * tt))) < 1e-3 * 0.5 * w * w
    assert_derivatives(law, 0.0, 2 * P, n=80001)
    assert_periodic(law, P)
    smooth = Tabulated(table, smoothing=1e-9)
    assert np.max(np.abs(smooth(tt[:400])[0] - 0.5 * np.sin(w * tt[:400]))) < 1e-4
    assert_derivatives(smooth, 0.0, P)


@pytest.mark.parametrize("text, row, words", [
    ("t [s], q [deg]\n0, 0\n0.1, 1\n0.1, 2\n", 4, "increase"),
    ("t [s], q [deg]\n0, 0\n0.1, x\n", 3, "numbers"),
    ("t [s], q [deg]\n" + "".join(f"{k * 0.1}, {k}\n" for k in range(5)), None, "too coarse"),
    ("t [s], q [kg]\n" + "".join(f"{k * 0.1}, {k}\n" for k in range(9)), 1, "angle unit"),
    ("t [s], q [deg]\n" + "".join(f"{k * 0.1}, {k}\n" for k in range(9)) + "5, 1\n", 11, "gap"),
])
def test_bad_tables_name_the_row(text, row, words):
    with pytest.raises(TableError, match=words) as err:
        parse_table(text, "angle")
    assert err.value.row == row


def test_path_pieces_are_continuous_and_arc_length_parametrised():
    g = paths.polyline([(0, 0), (0.3, 0), (0.3, 0.2), (0.0, 0.35)], 0.05)
    s = np.linspace(0, g.length, 200001)
    P, T, K, H = g.geometry(s)
    step = np.hypot(*np.diff(P, axis=0).T)
    assert np.max(np.abs(step - (s[1] - s[0]))) < 1e-9  # unit speed in s, no gaps at the joins
    assert np.max(np.abs(np.diff(H))) < 1e-3  # tangent continuous
    assert P[0] == pytest.approx([0, 0]) and P[-1] == pytest.approx([0.0, 0.35])
    with pytest.raises(paths.PathError, match="does not fit"):
        paths.polyline([(0, 0), (0.01, 0), (0.01, 0.01)], 0.05)


def test_sharp_corners_are_where_the_tangent_turns_at_once():
    """paths.corners: a polyline without corner radius turns at each interior point (arc length,
    signed turn, point); rounded corners, lines, arcs and circles have none."""
    sharp = paths.polyline([(0, 0), (0.3, 0), (0.3, 0.2), (0.0, 0.35)], 0.0)
    found = paths.corners(sharp)
    assert [(s, p) for s, _, p in found] == [(pytest.approx(0.3), (0.3, 0.0)), (pytest.approx(0.5), (0.3, 0.2))]
    assert found[0][1] == pytest.approx(math.pi / 2)  # left
    assert found[1][1] == pytest.approx(math.pi / 2 - math.atan2(0.15, 0.3))  # up, then up-left
    assert paths.corners(paths.polyline([(0, 0), (0.3, 0), (0.3, 0.2)], 0.05)) == []
    assert paths.corners(paths.line((0, 0), (1, 1))) == []
    assert paths.corners(paths.arc((0, 0), 0.1, 0.0, 2 * math.pi)) == []
    assert paths.corners(paths.polyline([(0, 0), (0.3, 0), (0.6, 0)], 0.0)) == []  # straight on: no corner


@pytest.mark.parametrize("seed", range(3))
def test_path_motion_derivatives_and_circle_laps(seed):
    rng = np.random.default_rng(seed)
    R, v = rng.uniform(0.02, 0.2), rng.uniform(0.1, 1.0)
    circle = paths.arc((rng.normal(), rng.normal()), R, rng.uniform(0, 6), 2 * math.pi)
    assert circle.closed
    pm = paths.PathMotion(circle, ConstantSpeed(0.0, v), heading=True, offset=0.2)
    period = 2 * math.pi * R / v
    for k in range(3):
        law = paths.PathComponent(pm, k)
        assert_derivatives(law, 0.0, 1.5 * period, n=80001)
        assert_periodic(law, period, 2 * math.pi if k == 2 else 0.0)
    # centripetal acceleration v^2 / R toward the centre
    (x, xd, xdd), (y, yd, ydd), _ = pm.values(np.linspace(0, period, 7))
    assert np.allclose(np.hypot(xdd, ydd), v * v / R) and np.allclose(np.hypot(xd, yd), v)
    g = paths.polyline([(0, 0), (0.3, 0), (0.3, 0.2)], 0.05)
    timed = paths.PathMotion(g, PointToPoint(0.0, g.length, 1.0, PROFILES["quintic"]))
    for k in range(2):  # the acceleration jumps where the curvature does: skip those samples
        assert_derivatives(paths.PathComponent(timed, k), 0.0, 1.0, n=80001, skip_jumps=True)


SEGMENT = st.one_of(
    st.builds(lambda law, T, by: {"law": law, "duration": T, "by": by},
              st.sampled_from(["quintic", "cycloidal", "bang_bang", "trapezoidal"]), st.floats(0.05, 1), st.floats(-3, 3)),
    st.builds(lambda T: {"law": "dwell", "duration": T}, st.floats(0.05, 1)),
    st.builds(lambda T, w: {"law": "constant_speed", "duration": T, "speed": w}, st.floats(0.05, 1), st.floats(-5, 5)),
    st.builds(lambda T, by: {"law": "polynomial", "duration": T, "by": by}, st.floats(0.05, 1), st.floats(-3, 3)),
)


@settings(max_examples=60, deadline=None, derandomize=True)
@given(st.lists(SEGMENT, min_size=1, max_size=5), st.floats(-3, 3))
def test_random_cycles_join_or_are_refused(segments, start):
    """A cycle of random segments either joins up in position and velocity at every join (the
    wrap-around included) or is refused at the segment after a velocity jump."""
    drive = CycleDrive.model_validate({"law": "cycle", "from": start, "segments": segments})
    try:
        cyc = cycle_law(drive, "angle", ("motion", "drive", "q"))
    except SpecFieldError as exc:
        assert "velocity jumps" in exc.message and exc.path[-2] == "segments"
        return
    P = cyc.period
    t = np.linspace(0, P, 4001)
    q, qd, _ = cyc(t)
    vs = max(float(np.max(np.abs(qd))), 1e-12)
    for dq, dv, _ in joins(cyc):
        assert abs(dq) <= 1e-9 * max(1.0, float(np.ptp(q))) and abs(dv) <= 1e-9 * vs
    # the next cycle starts where this one ends, shifted by the displacement
    a, b = cyc(np.array([P])), cyc(np.array([P * (1 + 1e-12) + 1e-12]))
    assert abs(b[0][0] - a[0][0]) < 1e-6 * max(1.0, vs) and abs(b[1][0] - a[1][0]) < 1e-6 * vs
