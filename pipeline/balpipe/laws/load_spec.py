"""The spec's ``loads`` section and its conversion to the model's loads
(:mod:`balpipe.mechanics.loads`), on any mechanism (custom or template): springs, dampers,
tabulated force laws, gas pressures, torsional springs, applied forces and torques, joint friction.

Points are a body's named point or [x, y] in its frame (``frame``: a ``frame_points`` name or
global [x, y]). Tables are CSV files next to the spec (read like a motion's tables: regular files
inside the spec's folder), with units in their headers, e.g. ``stroke [m], load [kN]``; a load
table is interpolated linearly against time, a driver's position (an angle table repeats every
turn) or a point's stroke, with an optional falling branch used while the argument decreases.
A preload, a torsional spring without a free angle and a stroke are referred to the mechanism's
pose at the motion's start (its first sample).
"""

from __future__ import annotations

import math
from dataclasses import replace
from typing import Annotated, Any, Literal, Union

import numpy as np
from pydantic import Field, PrivateAttr

from ..mechanics import loads as ml
from ..model import FRAME, Model, Prismatic, Revolute
from ..spec_parts import SpecFieldError, Strict
from ..units import Length, NonNegativeLength, number, quantity
from .table import TableError, parse_table

Source = Literal["internal", "external"]
_NAME = r"^[A-Za-z0-9_\-]+$"  # a column of the time series
_SOURCE = "internal: between two parts of the machine (the frame included), so the frame feels its reaction; " \
          "external: from outside the machine (a well, a workpiece), felt by the frame only through the joints"


class PointRef(Strict):
    """A point of a body: a name from its ``points`` (the frame: ``frame_points``) or [x, y] in its frame."""

    body: str = Field(description="the body's name, or frame")
    point: str | tuple[Length, Length] = Field(description="a named point of the body, or [x, y] in its frame")


class TableFile(Strict):
    """A CSV file of a load table: an argument column (increasing) and a value column, units in the header."""

    file: str = Field(min_length=1, description="CSV file, relative to the spec's folder (inside it)")
    argument: str | None = Field(None, description="name of the argument column (default: the first)")
    value: str | None = Field(None, description="name of the value column (default: the second)")
    _text: str | None = PrivateAttr(None)  # the file's text, read by the loader (laws.drives.read_tables)


class DriverArgument(Strict):
    driver: str = Field(description="the driver whose prescribed position (angle or length) is the argument")


class Stroke(Strict):
    body: str = Field(description="the body whose point moves")
    point: str | tuple[Length, Length] = Field(description="the point (name or [x, y] in the body's frame)")
    direction: tuple[number(), number()] = Field((0.0, 1.0), description="the direction in frame axes along which its displacement is measured")


class StrokeArgument(Strict):
    stroke: Stroke = Field(description="a point's displacement along a direction from its position at the motion's start")


class LoadTableSpec(TableFile):
    """A load tabulated against time, a driver's position or a point's stroke (or a force element's deflection)."""

    against: Literal["time", "deflection"] | DriverArgument | StrokeArgument = Field(
        "time", description="the argument: time, deflection (a force law's length minus its free length), "
        "{driver: name} or {stroke: {body, point, direction}}")
    falling: TableFile | None = Field(None, description="the branch used while the argument decreases (default: the same table)")


class _Element(Strict):
    name: str = Field(min_length=1, pattern=_NAME, description="the load's name (time series, pages)")
    a: PointRef = Field(description="first end")
    b: PointRef = Field(description="second end")
    source: Source = Field("internal", description=_SOURCE)


class SpringSpec(_Element):
    """A linear spring (and damper) between two points: tension k (L - L0) + c dL/dt."""

    type: Literal["spring"]
    stiffness: quantity("stiffness", ge=0) = Field(description="stiffness k")
    free_length: quantity("length", ge=0) | None = Field(None, description="free length L0 (or give a preload)")
    preload: quantity("force") | None = Field(None, description="tension at the motion's start (instead of a free length)")
    damping: quantity("damping", ge=0) = Field(0.0, description="viscous damping c (a spring-damper)")


class DamperSpec(_Element):
    """A viscous damper between two points: tension c dL/dt."""

    type: Literal["damper"]
    damping: quantity("damping", gt=0) = Field(description="viscous damping c")


class ForceLawSpec(_Element):
    """A tabulated force-deflection law (tension against L - L0) or any load table, between two points."""

    type: Literal["force_law"]
    free_length: quantity("length", ge=0) | None = Field(None, description="L0, for a table against deflection")
    table: LoadTableSpec = Field(description="tension (N, pulling the points together) against its argument")


class PressureSpec(Strict):
    """A pressure times an area pushing a piston off its cylinder head (a gas force, internal)."""

    type: Literal["pressure"]
    name: str = Field(min_length=1, pattern=_NAME, description="the load's name (time series, pages)")
    piston: PointRef = Field(description="the piston's point the pressure pushes")
    head: PointRef = Field(description="the cylinder head's point (the frame for a fixed cylinder)")
    area: quantity("area", gt=0) = Field(description="the piston's area")
    pressure: quantity("pressure") | LoadTableSpec = Field(description="a constant gauge pressure, or a table (pressure against its argument)")
    source: Source = Field("internal", description=_SOURCE)


class TorsionSpec(Strict):
    """A torsional spring and damper at a revolute joint: torque on b -(k (phi - phi0) + c dphi/dt)."""

    type: Literal["torsion"]
    name: str = Field(min_length=1, pattern=_NAME, description="the load's name (time series, pages)")
    joint: str = Field(description="a revolute joint")
    stiffness: quantity("torsional stiffness", ge=0) = Field(0.0, description="torsional stiffness k")
    free_angle: quantity("angle") | None = Field(None, description="the joint angle at which it is free (default: the angle at the motion's start)")
    preload: quantity("torque") | None = Field(None, description="its torque at the motion's start (with no free angle)")
    damping: quantity("torsional damping", ge=0) = Field(0.0, description="torsional damping c")
    source: Source = Field("internal", description=_SOURCE)


class ForceSpec(Strict):
    """A force and/or torque applied at a point of a body: constant, or a table times a direction."""

    type: Literal["force"]
    name: str = Field(min_length=1, pattern=_NAME, description="the load's name (time series, pages)")
    at: PointRef = Field(description="where it acts")
    force: tuple[quantity("force"), quantity("force")] | None = Field(None, description="constant force [Fx, Fy]")
    torque: quantity("torque") | None = Field(None, description="constant torque (counter-clockwise)")
    table: LoadTableSpec | None = Field(None, description="a tabulated force along ``direction`` (or a torque without direction)")
    direction: tuple[number(), number()] | None = Field(None, description="with a table: the unit direction of the tabulated force")
    axes: Literal["frame", "body"] = Field("frame", description="axes of the force and direction: the frame's, or the body's (turning with it)")
    source: Source = Field("external", description=_SOURCE)


class FrictionSpec(Strict):
    """Friction in a revolute or prismatic joint, from the joint's own reaction."""

    type: Literal["friction"]
    name: str = Field(min_length=1, pattern=_NAME, description="the load's name (time series, pages)")
    joint: str = Field(description="a revolute or prismatic joint")
    viscous: number(ge=0) = Field(0.0, description="viscous coefficient, N m s/rad (revolute) or N s/m (prismatic)")
    coefficient: number(ge=0, le=10) = Field(0.0, description="Coulomb coefficient mu")
    pin_radius: NonNegativeLength = Field(0.0, description="revolute: the pin's radius r (friction torque mu r |R|)")


LoadSpec = Annotated[Union[SpringSpec, DamperSpec, ForceLawSpec, PressureSpec, TorsionSpec, ForceSpec, FrictionSpec],
                     Field(discriminator="type")]


def table_files(loads: list) -> list[tuple[tuple, TableFile]]:
    """(path below the spec, file entry) of every table of a ``loads`` list, in order."""
    out = []
    for k, ld in enumerate(loads):
        for key in ("table", "pressure"):
            t = getattr(ld, key, None)
            if isinstance(t, LoadTableSpec):
                out.append((("loads", k, key), t))
                if t.falling is not None:
                    out.append((("loads", k, key, "falling"), t.falling))
    return out


class _Resolver:
    """Names of a model to points, joints and drivers, with located errors."""

    def __init__(self, model: Model, t0: float):
        self.model, self.t0 = model, t0
        self._start = None

    def point(self, ref: PointRef | Stroke, path: tuple) -> ml.Anchor:
        if ref.body == FRAME:
            table = self.model.frame_points
        else:
            try:
                table = self.model.body(ref.body).points
            except KeyError:
                raise SpecFieldError(path + ("body",), f"no body {ref.body!r} (bodies: frame, "
                                     f"{', '.join(b.name for b in self.model.bodies)})") from None
        if isinstance(ref.point, str):
            if ref.point not in table:
                raise SpecFieldError(path + ("point",), f"{ref.body} has no point {ref.point!r} (points: "
                                     f"{', '.join(table) or 'none'}; or give [x, y])")
            return ml.Anchor(ref.body, tuple(float(v) for v in table[ref.point]))
        return ml.Anchor(ref.body, (float(ref.point[0]), float(ref.point[1])))

    def joint(self, name: str, path: tuple, kinds: tuple = (Revolute, Prismatic)):
        try:
            jt = self.model.joint(name)
        except KeyError:
            raise SpecFieldError(path, f"no joint {name!r} (joints: {', '.join(j.name for j in self.model.joints)})") from None
        if not isinstance(jt, kinds):
            raise SpecFieldError(path, f"joint {name!r} is a {type(jt).__name__.lower()}, not a "
                                 + " or ".join(k.__name__.lower() for k in kinds) + " joint")
        return jt

    def start(self, path: tuple):
        """The analysis of the first two samples (positions at the motion's start)."""
        if self._start is None:
            from ..engine import AnalysisError, analyse

            try:
                self._start = analyse(replace(self.model, loads=()), np.array([self.t0, self.t0 + 1e-6]))
            except (AnalysisError, ValueError) as exc:
                raise SpecFieldError(path, f"the mechanism does not assemble at the motion's start, so this load's "
                                     f"reference there is unknown: {exc}") from None
        return self._start

    def start_point(self, a: ml.Anchor, path: tuple) -> np.ndarray:
        if a.body == FRAME:
            return np.asarray(a.point, dtype=float)
        x, y, th = self.start(path).pose(0, a.body)
        c, s = math.cos(th), math.sin(th)
        return np.array([x + c * a.point[0] - s * a.point[1], y + s * a.point[0] + c * a.point[1]])

    def start_angle(self, body: str, path: tuple) -> float:
        return 0.0 if body == FRAME else float(self.start(path).pose(0, body)[2])

    def driver_dimension(self, name: str, path: tuple) -> str:
        for d in self.model.drivers:
            if d.name == name:
                if d.target[0] == "joint":
                    return "angle" if isinstance(self.model.joint(d.target[1]), Revolute) else "length"
                return "angle" if d.target[0] == "angle" else "length"
        raise SpecFieldError(path, f"no driver {name!r} (drivers: {', '.join(d.name for d in self.model.drivers)})")


def _read(tf: TableFile, value_dim: str, arg_dim: str, path: tuple) -> tuple[np.ndarray, np.ndarray]:
    if tf._text is None:
        raise SpecFieldError(path + ("file",), f"the table {tf.file!r} was not read (load the spec with balpipe.loader)")
    try:
        tab = parse_table(tf._text, value_dim, tf.argument, tf.value, argument=arg_dim, spline=False)
    except TableError as exc:
        raise SpecFieldError(path + ("file",), f"{tf.file}" + (f":{exc.row}" if exc.row else "") + f": {exc}") from None
    return tab.t, tab.q


def _table(r: _Resolver, spec: LoadTableSpec, value_dim: str, path: tuple, element: bool = False) -> ml.LoadTable:
    against, period = spec.against, None
    if against == "time":
        arg, dim = ("time",), "time"
    elif against == "deflection":
        if not element:
            raise SpecFieldError(path + ("against",), "deflection is the argument of a force element's own table (type force_law)")
        arg, dim = ("deflection",), "length"
    elif isinstance(against, DriverArgument):
        dim = r.driver_dimension(against.driver, path + ("against", "driver"))
        arg, period = ("driver", against.driver), (2 * math.pi if dim == "angle" else None)
    else:
        st, sp = against.stroke, path + ("against", "stroke")
        a = r.point(st, sp)
        d = np.asarray(st.direction, dtype=float)
        if not np.linalg.norm(d) > 0:
            raise SpecFieldError(sp + ("direction",), "the direction must not be zero")
        d = d / np.linalg.norm(d)
        origin = float(r.start_point(a, sp) @ d)
        arg, dim = ("stroke", a.body, a.point, (float(d[0]), float(d[1])), origin), "length"
    rising = _read(spec, value_dim, dim, path)
    falling = None if spec.falling is None else _read(spec.falling, value_dim, dim, path + ("falling",))
    if period is not None:
        for x, where in ((rising[0], path), (falling[0] if falling else None, path + ("falling",))):
            if x is not None and x[-1] - x[0] > period + 1e-12:
                raise SpecFieldError(where + ("file",), "an angle table covers one turn at most (it repeats every turn)")
    return ml.LoadTable(arg, rising, falling, period)


def _refs(r: _Resolver, free, preload, stiffness: float, reference, path: tuple, what: str) -> tuple[float | None, float]:
    """(free length or angle, preload): a preload is referred to the motion's start."""
    if free is not None and preload is not None:
        raise SpecFieldError(path + ("preload",), f"give the free {what} or the preload, not both")
    if free is not None:
        return float(free), 0.0
    if stiffness and preload is None:
        raise SpecFieldError(path + ("stiffness",), f"a spring needs its free {what} or its preload")
    return (reference() if stiffness else None), float(preload or 0.0)


def model_loads(loads: list, model: Model, t0: float) -> tuple:
    """The model's loads from the spec's ``loads`` (errors located at ``loads[k]``)."""
    r = _Resolver(model, t0)
    out, names = [], set()
    for k, ld in enumerate(loads):
        path = ("loads", k)
        if ld.name in names:
            raise SpecFieldError(path + ("name",), f"the load name {ld.name!r} is used twice")
        names.add(ld.name)
        out.append(_convert(r, ld, path))
    return tuple(out)


def _length(r: _Resolver, a: ml.Anchor, b: ml.Anchor, path: tuple) -> float:
    return float(np.linalg.norm(r.start_point(b, path) - r.start_point(a, path)))


def _external_end(ld: Any, a: ml.Anchor, b: ml.Anchor, path: tuple) -> None:
    if ld.source == "external" and (a.on_frame == b.on_frame):
        raise SpecFieldError(path + ("source",), "an external force element has one end on the frame (the outside "
                             "world's end); between two moving parts it is internal")


def _convert(r: _Resolver, ld: Any, path: tuple):
    if isinstance(ld, (SpringSpec, DamperSpec, ForceLawSpec)):
        a, b = r.point(ld.a, path + ("a",)), r.point(ld.b, path + ("b",))
        _external_end(ld, a, b, path)
        if isinstance(ld, SpringSpec):
            free, pre = _refs(r, ld.free_length, ld.preload, ld.stiffness, lambda: _length(r, a, b, path), path, "length")
            return ml.ForceElement(ld.name, a, b, float(ld.stiffness), free, pre, float(ld.damping), source=ld.source)
        if isinstance(ld, DamperSpec):
            return ml.ForceElement(ld.name, a, b, damping=float(ld.damping), source=ld.source)
        if ld.table.against == "deflection" and ld.free_length is None:
            raise SpecFieldError(path + ("free_length",), "a table against deflection needs the free length")
        law = _table(r, ld.table, "force", path + ("table",), element=True)
        return ml.ForceElement(ld.name, a, b, free_length=ld.free_length, law=law, source=ld.source)
    if isinstance(ld, PressureSpec):
        a, b = r.point(ld.head, path + ("head",)), r.point(ld.piston, path + ("piston",))
        _external_end(ld, a, b, path)
        if isinstance(ld.pressure, LoadTableSpec):
            law = _table(r, ld.pressure, "pressure", path + ("pressure",))
            return ml.ForceElement(ld.name, a, b, law=law, scale=-float(ld.area), source=ld.source)
        return ml.ForceElement(ld.name, a, b, preload=-float(ld.area) * float(ld.pressure), source=ld.source)
    if isinstance(ld, TorsionSpec):
        jt = r.joint(ld.joint, path + ("joint",), (Revolute,))
        free, pre = _refs(r, ld.free_angle, ld.preload, ld.stiffness,
                          lambda: r.start_angle(jt.b, path) - r.start_angle(jt.a, path), path, "angle")
        if ld.source == "external" and FRAME not in (jt.a, jt.b):
            raise SpecFieldError(path + ("source",), "an external torsional spring is at a joint with the frame")
        return ml.TorsionElement(ld.name, jt.name, float(ld.stiffness), free, pre, float(ld.damping), ld.source)
    if isinstance(ld, ForceSpec):
        at = r.point(ld.at, path + ("at",))
        if at.on_frame:
            raise SpecFieldError(path + ("at", "body"), "a force on the frame moves nothing: apply it to a moving body")
        if ld.table is not None:
            if ld.force is not None or ld.torque is not None:
                raise SpecFieldError(path + ("table",), "give a constant force/torque or a table, not both")
            if ld.direction is None:
                law = _table(r, ld.table, "torque", path + ("table",))
                return ml.AppliedLoad(ld.name, at, torque=1.0, axes=ld.axes, law=law, source=ld.source)
            d = np.asarray(ld.direction, dtype=float)
            if not np.linalg.norm(d) > 0:
                raise SpecFieldError(path + ("direction",), "the direction must not be zero")
            d = d / np.linalg.norm(d)
            law = _table(r, ld.table, "force", path + ("table",))
            return ml.AppliedLoad(ld.name, at, (float(d[0]), float(d[1])), 0.0, ld.axes, law, ld.source)
        if ld.direction is not None:
            raise SpecFieldError(path + ("direction",), "a direction goes with a table (a constant force is [Fx, Fy])")
        if ld.force is None and ld.torque is None:
            raise SpecFieldError(path, "give a force [Fx, Fy], a torque, or a table")
        force = (0.0, 0.0) if ld.force is None else (float(ld.force[0]), float(ld.force[1]))
        return ml.AppliedLoad(ld.name, at, force, float(ld.torque or 0.0), ld.axes, None, ld.source)
    if isinstance(ld, FrictionSpec):
        jt = r.joint(ld.joint, path + ("joint",))
        if isinstance(jt, Revolute) and ld.coefficient and not ld.pin_radius:
            raise SpecFieldError(path + ("pin_radius",), "Coulomb friction in a revolute joint needs the pin radius")
        if isinstance(jt, Prismatic) and ld.pin_radius:
            raise SpecFieldError(path + ("pin_radius",), "a prismatic joint has no pin: its friction is mu |N|")
        return ml.JointFriction(ld.name, jt.name, float(ld.viscous), float(ld.coefficient), float(ld.pin_radius))
    raise TypeError(ld)  # pragma: no cover - the union is closed
