"""The spec's drive sections for the laws of :mod:`balpipe.laws` and the builder of their laws.

``motion.drive.<name>`` is a point-to-point drive (:class:`balpipe.spec_parts.DriveSpec`, the
laws of :mod:`balpipe.motion`) unless its ``law`` names one of the laws here: ``constant_speed``,
``cam``, ``fourier``, ``table``, ``cycle`` or ``path``. Values with units are parsed with the
driven coordinate's dimension (an angle or a length) when the laws are built, so errors are
located at the field (:class:`~balpipe.spec_parts.SpecFieldError`).
"""

from __future__ import annotations

import math
from pathlib import Path as FilePath
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import Discriminator, Field, PrivateAttr, Tag

from .. import units
from ..model import Law
from ..motion import PROFILES, PointToPoint, Polynomial, trapezoidal
from ..runtime.inputs import MAX_TABLE_BYTES, InputFileError, read_input_text  # noqa: F401  (drives.MAX_TABLE_BYTES as before)
from ..spec_parts import DriveSpec, SpecFieldError, Strict
from ..units import Angle, Duration, Length, PositiveLength, Rate, RateRate, number
from . import cycle as cycle_laws
from . import paths as geometry
from .periodic import Cam, ConstantSpeed, Fourier, cam_jumps
from .table import Tabulated, TableError, parse_table

#: relative size of a state jump at a join that counts as a jump (of the segment's own scale)
JOIN_TOLERANCE = 1e-9


def _tagger(laws: tuple[str, ...]):
    """The discriminator of a union of laws: an entry's ``law`` when it is one of ``laws``, else
    'profile' (a point-to-point law, whose ``law`` field may be absent)."""

    def tag(v: Any) -> str:
        law = v.get("law") if isinstance(v, dict) else getattr(v, "law", None)
        return f"law[{law if law in laws else 'profile'}]"

    return tag


def _tag(kind: str) -> Tag:
    # 'law[...]' is not a key of the document: the loader drops it from error locations
    return Tag(f"law[{kind}]")


class ConstantSpeedDrive(Strict):
    """Constant speed from ``from``: q = q0 + w t, in steady state (already moving at t = 0)
    unless ``ramp`` asks for a start from rest."""

    law: Literal["constant_speed"] = Field(description="the law: constant_speed")
    start: Any = Field(0.0, alias="from", description="value at t = 0 (angle or length; default 0)")
    speed: Rate = Field(description="the constant speed: 120 rpm, 2 rad/s, 0.5 m/s (SI without a unit)")
    ramp: units.quantity("time", ge=0) = Field(0.0, description="0: steady state; > 0: start from rest and reach the speed after this time (smooth velocity step)")

    def period(self) -> float | None:
        """One turn at this speed, for an angular speed; None for a linear one."""
        angular = getattr(self.speed, "kind", None) == "angular velocity"
        return 2 * math.pi / abs(self.speed) if angular and self.speed and self.ramp == 0 else None


class CamDrive(Strict):
    """A periodic cam law: rise from ``from`` to ``to``, dwell, return, dwell, every period."""

    law: Literal["cam"] = Field(description="the law: cam")
    start: Any = Field(alias="from", description="low value (angle or length)")
    end: Any = Field(alias="to", description="high value")
    period: Duration = Field(description="duration of one cycle")
    profile: Literal["cycloidal", "harmonic", "quintic"] = Field("cycloidal", description="rise and return profile")
    rise: number(gt=0, le=1) = Field(0.5, description="fraction of the period spent rising")
    dwell: number(ge=0, lt=1) = Field(0.0, description="fraction of the period dwelling at the high value")
    ret: number(gt=0, le=1) = Field(0.5, alias="return", description="fraction of the period spent returning (the rest dwells at the low value)")

    def period_of(self) -> float:
        return self.period


class FourierDrive(Strict):
    """q = mean + sum_k (a_k cos(2 pi k t / P) + b_k sin(2 pi k t / P))."""

    law: Literal["fourier"] = Field(description="the law: fourier")
    mean: Any = Field(0.0, description="constant term (angle or length)")
    period: Duration = Field(description="period P")
    terms: list[tuple[Any, Any]] = Field(description="[a_k, b_k] for k = 1, 2, ... (angles or lengths)")

    def period_of(self) -> float:
        return self.period


class TableDrive(Strict):
    """A tabulated law from a CSV file (header 't [s], q [deg]'), through a spline."""

    law: Literal["table"] = Field(description="the law: table")
    file: str = Field(min_length=1, description="CSV file, relative to the spec's folder")
    time: str | None = Field(None, description="name of the time column (default: the first)")
    value: str | None = Field(None, description="name of the value column (default: the second)")
    ends: Literal["not-a-knot", "clamped", "natural", "periodic"] = Field(
        "not-a-knot", description="spline end conditions: clamped starts and ends at rest; periodic repeats the table")
    smoothing: number(ge=0) | None = Field(None, description="smoothing spline penalty (scipy make_smoothing_spline lam); default: interpolate the rows")
    _text: str | None = PrivateAttr(None)  # the file's text, read by the loader (read_tables)


# --------------------------------------------------------------------------------------------
# Cycle segments


class ProfileSegment(Strict):
    law: Literal["quintic", "cycloidal", "bang_bang", "trapezoidal"] = Field(description="point-to-point law")
    duration: Duration = Field(description="duration of the segment")
    to: Any = Field(None, description="value at the end of the segment (or give by)")
    by: Any = Field(None, description="displacement over the segment (or give to)")
    accel_fraction: number(gt=0, le=0.5) = Field(1 / 3, description="trapezoidal law: fraction accelerating")


class DwellSegment(Strict):
    law: Literal["dwell"] = Field(description="the segment's law: dwell (at rest)")
    duration: Duration = Field(description="duration of the segment")


class SpeedSegment(Strict):
    law: Literal["constant_speed"] = Field(description="the segment's law: constant_speed")
    duration: Duration = Field(description="duration of the segment")
    speed: Rate = Field(description="constant speed over the segment")


class PolynomialSegment(Strict):
    """The lowest-degree polynomial from the previous segment's end state (q, q', q'') to ``to``
    with the next segment's start velocity and acceleration (unless given)."""

    law: Literal["polynomial"] = Field(description="the segment's law: polynomial (states matched at both ends)")
    duration: Duration = Field(description="duration of the segment")
    to: Any = Field(None, description="value at the end of the segment (or give by)")
    by: Any = Field(None, description="displacement over the segment (or give to)")
    end_velocity: Rate | None = Field(None, description="default: the next segment's start velocity (0 after a polynomial)")
    end_acceleration: RateRate | None = Field(None, description="default: the next segment's start acceleration")


def _segment_tag(v: Any) -> str:
    law = v.get("law") if isinstance(v, dict) else getattr(v, "law", None)
    return f"law[{law if law in ('dwell', 'constant_speed', 'polynomial') else 'profile'}]"


Segment = Annotated[
    Union[Annotated[ProfileSegment, _tag("profile")], Annotated[DwellSegment, _tag("dwell")],
          Annotated[SpeedSegment, _tag("constant_speed")], Annotated[PolynomialSegment, _tag("polynomial")]],
    Discriminator(_segment_tag),
]


class CycleDrive(Strict):
    """A cycle of segments (pick, move, dwell, return), repeated; states matched at the joins."""

    law: Literal["cycle"] = Field(description="the law: cycle")
    start: Any = Field(alias="from", description="value at the start of the first segment")
    segments: list[Segment] = Field(min_length=1, description="the segments in order, each with its law and duration")

    def period_of(self) -> float:
        return float(sum(s.duration for s in self.segments))


# --------------------------------------------------------------------------------------------
# Paths


class LinePath(Strict):
    type: Literal["line"]
    start: tuple[Length, Length] = Field(alias="from", description="start point")
    end: tuple[Length, Length] = Field(alias="to", description="end point")


class CirclePath(Strict):
    type: Literal["circle"]
    centre: tuple[Length, Length] = Field(description="centre of the circle")
    radius: PositiveLength = Field(description="radius of the circle")
    start_angle: Angle = Field(0.0, description="where the point starts, as the angle about the centre")
    direction: Literal["ccw", "cw"] = Field("ccw", description="counter-clockwise or clockwise")


class ArcPath(Strict):
    type: Literal["arc"]
    centre: tuple[Length, Length] = Field(description="centre of the arc")
    radius: PositiveLength = Field(description="radius of the arc")
    start_angle: Angle = Field(alias="from", description="start, as the angle about the centre")
    end_angle: Angle = Field(alias="to", description="end angle; the arc turns from 'from' to 'to' (counter-clockwise when to > from)")


class PolylinePath(Strict):
    type: Literal["polyline"]
    points: list[tuple[Length, Length]] = Field(min_length=2, description="corner points in order")
    corner_radius: units.quantity("length", ge=0) = Field(0.0, description="radius of the arcs that round the corners")


PathSpec = Annotated[Union[LinePath, CirclePath, ArcPath, PolylinePath], Field(discriminator="type")]


class ProfileTiming(Strict):
    """Arc length from 0 to the path's length over the whole motion on a point-to-point law."""

    law: Literal["quintic", "cycloidal", "bang_bang", "trapezoidal"] = Field(description="point-to-point law of the arc length")
    accel_fraction: number(gt=0, le=0.5) = Field(1 / 3, description="trapezoidal law: fraction accelerating")


Timing = Annotated[
    Union[Annotated[ProfileTiming, _tag("profile")], Annotated[ConstantSpeedDrive, _tag("constant_speed")],
          Annotated[CycleDrive, _tag("cycle")], Annotated[CamDrive, _tag("cam")],
          Annotated[TableDrive, _tag("table")], Annotated[FourierDrive, _tag("fourier")]],
    Discriminator(_tagger(("constant_speed", "cycle", "cam", "table", "fourier"))),
]


class PathDrive(Strict):
    """A point (or pose) moving along a path, timed by a law on the arc length (in m)."""

    law: Literal["path"] = Field(description="the law: path")
    path: PathSpec = Field(description="line, circle, arc or polyline (with rounded corners)")
    timing: Timing = Field(description="law of the arc length s (m): a point-to-point law (0 to the path's length), constant_speed, cycle, ...")
    components: list[str] | None = Field(
        None, min_length=2, max_length=3,
        description="the drives that the path feeds: [x, y] or [x, y, angle] (e.g. a platform's x, y, phi); "
        "default: the drive itself (a template's point or pose drive)")
    heading: bool = Field(False, description="with an angle component: the angle follows the path's tangent (plus angle); otherwise it stays at angle")
    angle: Angle = Field(0.0, description="the pose's angle (or its offset from the tangent, with heading)")

    def geometry(self) -> geometry.Path:
        p = self.path
        if isinstance(p, LinePath):
            return geometry.line(p.start, p.end)
        if isinstance(p, CirclePath):
            return geometry.arc(p.centre, p.radius, p.start_angle, 2 * math.pi * (1 if p.direction == "ccw" else -1))
        if isinstance(p, ArcPath):
            return geometry.arc(p.centre, p.radius, p.start_angle, p.end_angle - p.start_angle)
        return geometry.polyline(p.points, p.corner_radius)

    def period_of(self) -> float | None:
        t = self.timing
        if isinstance(t, ConstantSpeedDrive):
            try:
                g = self.geometry()
            except geometry.PathError:
                return None
            return g.length / abs(t.speed) if g.closed and t.speed and t.ramp == 0 else None
        return t.period_of() if hasattr(t, "period_of") else None


NEW_LAWS = ("constant_speed", "cam", "fourier", "table", "cycle", "path")


#: one ``motion.drive`` entry: point-to-point (DriveSpec) or one of the laws here
Drive = Annotated[
    Union[Annotated[DriveSpec, _tag("profile")], Annotated[ConstantSpeedDrive, _tag("constant_speed")],
          Annotated[CamDrive, _tag("cam")], Annotated[FourierDrive, _tag("fourier")],
          Annotated[TableDrive, _tag("table")], Annotated[CycleDrive, _tag("cycle")],
          Annotated[PathDrive, _tag("path")]],
    Discriminator(_tagger(NEW_LAWS)),
]


def law_names(motion: Any) -> str:
    """The laws the drives use, for a page's summary ("quintic", "constant_speed and cam")."""
    names = list(dict.fromkeys((getattr(d, "law", None) or motion.law) for d in motion.drive.values())) or [motion.law]
    return " and ".join([", ".join(names[:-1]), names[-1]] if len(names) > 1 else names)


def period(drive: Any) -> float | None:
    """The period of a periodic drive (None for a point-to-point or aperiodic one)."""
    if isinstance(drive, ConstantSpeedDrive):
        return drive.period()
    if isinstance(drive, TableDrive):
        return None
    f = getattr(drive, "period_of", None)
    return f() if f is not None else None


def common_period(periods: list[float]) -> float | None:
    """The longest of ``periods`` when every other divides it (to 1e-9), else None."""
    if not periods:
        return None
    P = max(periods)
    for p in periods:
        r = P / p
        if abs(r - round(r)) > 1e-9 * r:
            return None
    return P


# --------------------------------------------------------------------------------------------
# Building the laws


def _value(raw: Any, dim: str, path: tuple) -> float:
    try:
        return units.parse(raw, dim)
    except ValueError as exc:
        raise SpecFieldError(path, str(exc)) from None


def _rate(value: Any, dim: str, path: tuple) -> float:
    try:
        units.check_rate(value, dim)
    except ValueError as exc:
        raise SpecFieldError(path, str(exc)) from None
    return float(value)


def _profile(law: str, fraction: float):
    return trapezoidal(fraction) if law == "trapezoidal" else PROFILES[law]


def cycle_law(drive: CycleDrive, dim: str, path: tuple) -> cycle_laws.Cycle:
    """The :class:`~balpipe.laws.cycle.Cycle` of a cycle drive; a velocity jump at a join is an
    error located at the segment after it."""
    segs = drive.segments
    n = len(segs)
    q = _value(drive.start, dim, path + ("from",))
    laws: list[Law] = []
    for k, s in enumerate(segs):
        sp = path + ("segments", k)
        T = s.duration
        if isinstance(s, (ProfileSegment, PolynomialSegment)):
            if (s.to is None) == (s.by is None):
                raise SpecFieldError(sp, "give either to (the value at the segment's end) or by (its displacement)")
            end = _value(s.to, dim, sp + ("to",)) if s.to is not None else q + _value(s.by, dim, sp + ("by",))
        if isinstance(s, DwellSegment):
            law: Law = ConstantSpeed(q, 0.0)
        elif isinstance(s, SpeedSegment):
            law = ConstantSpeed(q, _rate(s.speed, dim, sp + ("speed",)))
        elif isinstance(s, ProfileSegment):
            law = PointToPoint(q, end, T, _profile(s.law, s.accel_fraction))
        else:
            prev = laws[-1] if laws else None
            if prev is not None:
                v0, a0 = cycle_laws.end_state(prev, segs[k - 1].duration)[1:]
            else:
                v0, a0 = _boundary(segs[-1], dim, path + ("segments", n - 1), "end")
            nxt = segs[(k + 1) % n]
            v1, a1 = _boundary(nxt, dim, path + ("segments", (k + 1) % n), "start")
            if s.end_velocity is not None:
                v1 = _rate(s.end_velocity, dim, sp + ("end_velocity",))
            if s.end_acceleration is not None:
                a1 = _rate(s.end_acceleration, dim, sp + ("end_acceleration",))
            law = Polynomial.from_boundary((q, v0, a0), (end, v1, a1), T)
        laws.append(law)
        q = cycle_laws.end_state(law, T)[0]
    cyc = cycle_laws.Cycle(tuple(laws), tuple(s.duration for s in segs))
    scale = max(abs(float(v)) for law, s in zip(laws, segs) for v in law(np.linspace(0, s.duration, 33))[1]) or 1.0
    for k, (dq, dv, _) in enumerate(cycle_laws.joins(cyc)):
        if abs(dv) > JOIN_TOLERANCE * scale:
            nxt = (k + 1) % n
            raise SpecFieldError(path + ("segments", nxt), (
                f"the velocity jumps by {dv:.4g} (SI) from segment {k} to segment {nxt}"
                + (" (the cycle repeats: the last segment's end joins the first one's start)" if nxt == 0 else "")
                + ": put a polynomial segment between them, or start and end at rest"))
    return cyc


def _boundary(s: Any, dim: str, path: tuple, where: str) -> tuple[float, float]:
    """Velocity and acceleration at the ``where`` end of a non-polynomial segment (0, 0 for a
    polynomial neighbour)."""
    if isinstance(s, SpeedSegment):
        return _rate(s.speed, dim, path + ("speed",)), 0.0
    return 0.0, 0.0  # dwell and point-to-point segments start and end at rest


def table_law(drive: TableDrive, dim: str, path: tuple, duration: float) -> Tabulated:
    """The spline of a table drive (read by :func:`read_tables`); the table must cover the
    motion unless it is periodic."""
    text = drive._text
    if text is None:
        raise SpecFieldError(path + ("file",), f"the table {drive.file!r} was not read (load the spec with balpipe.loader)")
    try:
        table = parse_table(text, dim, drive.time, drive.value)
    except TableError as exc:
        raise SpecFieldError(path + ("file",), f"{drive.file}" + (f":{exc.row}" if exc.row else "") + f": {exc}") from None
    law = Tabulated(table, drive.ends, drive.smoothing)
    t0, t1 = law.span
    if drive.ends != "periodic" and (t0 > 0 or t1 < duration * (1 - 1e-12)):
        raise SpecFieldError(path + ("file",), f"{drive.file}: the table covers t = {t0:g} to {t1:g} s, not the whole "
                             f"motion (0 to {duration:g} s); extend it or set ends: periodic")
    try:
        law.spline()
    except ValueError as exc:
        raise SpecFieldError(path + ("ends",), f"{drive.file}: {exc}") from None
    return law


def scalar_law(drive: Any, dim: str, path: tuple, duration: float) -> Law:
    """The law of one scalar coordinate of dimension ``dim`` ('angle' or 'length')."""
    if isinstance(drive, ConstantSpeedDrive):
        return ConstantSpeed(_value(drive.start, dim, path + ("from",)), _rate(drive.speed, dim, path + ("speed",)), drive.ramp)
    if isinstance(drive, CamDrive):
        if drive.rise + drive.dwell + drive.ret > 1 + 1e-12:
            raise SpecFieldError(path + ("return",), f"rise + dwell + return = {drive.rise + drive.dwell + drive.ret:.4g} "
                                 "is more than the period (1)")
        jump = cam_jumps(drive.profile, drive.rise, drive.dwell, drive.ret)
        if jump > 1e-9:
            raise SpecFieldError(path + ("profile",), "the harmonic law's acceleration jumps at the dwells or where "
                                 "rise and return differ in length; use cycloidal or quintic, or rise = return without dwells")
        return Cam(_value(drive.start, dim, path + ("from",)), _value(drive.end, dim, path + ("to",)), drive.period,
                   drive.profile, drive.rise, drive.dwell, drive.ret)
    if isinstance(drive, FourierDrive):
        if not drive.terms:
            raise SpecFieldError(path + ("terms",), "give at least one term [a_1, b_1]")
        terms = tuple((_value(a, dim, path + ("terms", k, 0)), _value(b, dim, path + ("terms", k, 1)))
                      for k, (a, b) in enumerate(drive.terms))
        return Fourier(_value(drive.mean, dim, path + ("mean",)), drive.period, terms)
    if isinstance(drive, TableDrive):
        return table_law(drive, dim, path, duration)
    if isinstance(drive, CycleDrive):
        return cycle_law(drive, dim, path)
    raise SpecFieldError(path + ("law",), f"law {drive.law!r} does not apply to a single coordinate")


def path_motion(drive: PathDrive, path: tuple, duration: float) -> geometry.PathMotion:
    """The path and its timing law on the arc length; an open path must not be overrun."""
    try:
        g = drive.geometry()
    except geometry.PathError as exc:
        raise SpecFieldError(path + ("path",), str(exc)) from None
    t = drive.timing
    if isinstance(t, ProfileTiming):
        timing: Law = PointToPoint(0.0, g.length, duration, _profile(t.law, t.accel_fraction))
    else:
        timing = scalar_law(t, "length", path + ("timing",), duration)
    if not g.closed:  # (a closed path, a circle, has no end to overrun and no corner)
        t = np.linspace(0.0, duration, 2001)
        s = timing(t)[0]
        over = np.flatnonzero((s < -1e-9 * g.length) | (s > g.length * (1 + 1e-9)))
        if over.size:
            k = int(over[0])
            raise SpecFieldError(path + ("timing",), (
                f"the arc length reaches {s[k]:.4g} m at t = {t[k]:.4g} s, outside the path "
                f"(0 to {g.length:.4g} m long); shorten the motion or lengthen the path"))
        _check_corners(g, timing, t, s, drive.heading, path)
    return geometry.PathMotion(g, timing, drive.heading, drive.angle)


CORNER_SPEED = 1e-6  # of the path's mean speed (length / duration): a sharp corner passed faster is an error


def _check_corners(g: geometry.Path, timing: Law, t: np.ndarray, s: np.ndarray, heading: bool, path: tuple) -> None:
    """A sharp corner (:func:`.paths.corners`) that the point passes at speed, or any sharp corner
    of a path whose heading drives an angle, asks for an infinite acceleration: an error naming
    the corner, the speed and the time (the analysis would miss the impulse there, and no finite
    effort gives it). ``s``: the arc length at the times ``t`` over the motion."""
    duration = float(t[-1] - t[0])
    for sc, turn, point in geometry.corners(g):
        where = (f"the path turns {math.degrees(abs(turn)):.4g} deg at ({point[0]:.4g}, {point[1]:.4g}) m "
                 "with no rounded corner")
        if heading:
            raise SpecFieldError(path + ("path",), f"{where}: the heading (an angle that follows the tangent) would "
                                 f"jump by that much at once; give the path a corner_radius")
        for k in np.flatnonzero((s[:-1] - sc) * (s[1:] - sc) <= 0.0):
            tc = _crossing(timing, sc, float(t[k]), float(t[k + 1]))
            v = float(timing(np.array([tc]))[1][0])
            if abs(v) > CORNER_SPEED * g.length / duration:
                raise SpecFieldError(path + ("path",), (
                    f"{where}, which the timing passes at {abs(v):.4g} m/s (t = {tc:.4g} s): the velocity would "
                    "turn at once there, an infinite acceleration that no finite effort gives and the analysis "
                    "cannot show; give the path a corner_radius, or a timing that stops at the corner"))


def _crossing(timing: Law, sc: float, a: float, b: float) -> float:
    """The time in [a, b] where the arc length ``timing`` reaches ``sc`` (bisection; it is
    reached there)."""
    fa = float(timing(np.array([a]))[0][0]) - sc
    if fa == 0.0:
        return a
    for _ in range(60):
        m = 0.5 * (a + b)
        fm = float(timing(np.array([m]))[0][0]) - sc
        if fm == 0.0:
            return m
        if (fm < 0.0) == (fa < 0.0):
            a, fa = m, fm
        else:
            b = m
    return 0.5 * (a + b)


def drive_laws(name: str, drive: Any, dims: dict[str, str], motion: Any) -> dict[str, Law]:
    """The laws of one ``motion.drive`` entry that is not point-to-point: a scalar drive's law,
    or a path's component laws (``components``: its x, y and optional angle drives)."""
    path = ("motion", "drive", name)
    if isinstance(drive, PathDrive):
        comps = drive.components
        if comps is None:
            raise SpecFieldError(path, f"a path drives two or three coordinates: give components: [x, y] "
                                 f"(this mechanism drives: {', '.join(dims)})")
        want = ("length", "length", "angle")
        for k, c in enumerate(comps):
            if c not in dims:
                raise SpecFieldError(path + ("components", k), f"unknown drive {c!r}; this mechanism drives: {', '.join(dims)}")
            if dims[c] != want[k]:
                raise SpecFieldError(path + ("components", k), f"{c!r} is {'an' if dims[c][0] in 'aeiou' else 'a'} "
                                     f"{dims[c]}, not {'an' if want[k][0] == 'a' else 'a'} {want[k]}")
        pm = path_motion(drive, path, motion.duration)
        return {c: geometry.PathComponent(pm, k) for k, c in enumerate(comps)}
    if name not in dims:
        raise SpecFieldError(path, f"unknown drive {name!r}; this mechanism drives: {', '.join(dims)}")
    if dims[name] not in ("angle", "length"):
        raise SpecFieldError(path + ("law",), f"{name!r} is a {dims[name]}: drive it with law: path")
    return {name: scalar_law(drive, dims[name], path, motion.duration)}


def path_laws(name: str, drive: Any, motion: Any, n: int) -> tuple[Law, ...] | None:
    """The first ``n`` component laws (x, y and, for n = 3, the angle) of a template's point or
    pose drive (a five-bar's gripper, a serial arm's tip, an n-RRR's platform) on a path, or None
    for a point-to-point drive (from, to); another law is a located error."""
    if drive is None or isinstance(drive, DriveSpec):
        return None
    if not isinstance(drive, PathDrive):
        raise SpecFieldError(("motion", "drive", name, "law"), f"{name!r} is a point or a pose: give from and to "
                             f"(a point-to-point law) or law: path, not law: {drive.law}")
    if drive.components is not None:
        raise SpecFieldError(("motion", "drive", name, "components"), f"{name!r} is the point itself: leave out components")
    pm = path_motion(drive, ("motion", "drive", name), motion.duration)
    return tuple(geometry.PathComponent(pm, k) for k in range(n))


def motion_sections(spec: Any):
    """(path, motion) of every motion section of ``spec``: its ``motion``, then the further
    ``motions`` of its balancing methods (the main one's and each compared design's), if any."""
    yield ("motion",), spec.motion
    designs = [(("balancing",), spec.balancing)] + [(("compare", k, "balancing"), d.balancing)
                                                   for k, d in enumerate(getattr(spec, "compare", None) or [])]
    for root, balancing in designs:
        for k, other in enumerate(getattr(balancing, "motions", None) or []):
            yield root + ("motions", k, "motion"), other.motion


def spec_tables(spec: Any) -> list[tuple[tuple, Any]]:
    """(path, entry with ``file`` and ``_text``) of every table ``spec`` reads: its motions'
    table drives, then its loads' tables (:func:`.load_spec.table_files`)."""
    out = [(sub, d) for root, motion in motion_sections(spec) for name, drive in motion.drive.items()
           for sub, d in _tables(drive, root + ("drive", name))]
    loads = getattr(spec, "loads", None)
    if not loads:  # the loads' section module only for a spec with loads
        return out
    from .load_spec import table_files as table_files_of_loads

    return out + table_files_of_loads(loads)


def read_tables(spec: Any, folder: FilePath) -> None:
    """Read the CSV file of every table of ``spec`` (:func:`spec_tables`, relative to ``folder``,
    the spec's), keeping its text on the entry. The file is read by
    :func:`balpipe.runtime.inputs.read_input_text`: only a regular file inside the spec's folder,
    at most :data:`MAX_TABLE_BYTES`; anything else is a located error that quotes none of it."""
    for sub, d in spec_tables(spec):
        try:
            d._text = read_input_text(folder, d.file, MAX_TABLE_BYTES, "table")
        except InputFileError as exc:
            raise SpecFieldError(sub + ("file",), str(exc)) from None


def table_texts(spec: Any) -> str:
    """The text of every table the spec reads, for the build's input hash ("" without tables, so
    the hash of a spec without tables is unchanged): a changed CSV rebuilds the page."""
    return "".join(f"\0table {d.file}\0{d._text}" for _, d in spec_tables(spec))


def table_files(spec: Any) -> list[str]:
    """The files of the tables the spec reads, as written in it, in :func:`table_texts`'s order."""
    return [d.file for _, d in spec_tables(spec)]


def _tables(drive: Any, path: tuple):
    if isinstance(drive, TableDrive):
        yield path, drive
    elif isinstance(drive, PathDrive) and isinstance(drive.timing, TableDrive):
        yield path + ("timing",), drive.timing
