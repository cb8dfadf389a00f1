"""The ``custom`` template: any planar mechanism written as a list of bodies, joints and drivers.

Points on a body are given in the body's frame, either as [x, y] or by the name of one of the
body's ``points``; on the frame, as global [x, y] or by the name of a ``frame_points`` entry.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

import numpy as np
from pydantic import Field

from ...diagnose import actuation
from ...mechanics.meshes import DEFAULT_PRESSURE_ANGLE, PressureAngle, mesh_geometry
from ...model import FRAME, Attachment, Body, Driver, Gear, Model, Prismatic, Revolute
from ...spec_parts import SpecFieldError, Strict
from ...units import Angle, Inertia, Length, Mass, Number, PositiveLength

Point = Union[str, tuple[Length, Length]]


class CustomAttachment(Strict):
    """A rigid part fixed to a custom body (its mass, centre and inertia add to the body's)."""

    name: str = Field(min_length=1, description="name, unique on the body")
    mass: Mass = Field(description="mass")
    position: tuple[Length, Length] | str = Field((0.0, 0.0), description="centre of mass, [x, y] in the body frame or a named point")
    inertia: Inertia = Field(0.0, description="centroidal moment of inertia")
    kind: Literal["counterweight", "gear", "payload", "part"] = Field("counterweight", description="for drawing and accounting")
    radius: PositiveLength | None = Field(None, description="drawn as a disc of this radius (a gear's pitch radius)")


class CustomBody(Strict):
    """A rigid body with its own frame."""

    name: str = Field(min_length=1, description="unique name; 'frame' is the fixed frame")
    mass: Mass = Field(description="mass")
    com: tuple[Length, Length] = Field((0.0, 0.0), description="centre of mass in the body frame")
    inertia: Inertia = Field(0.0, description="centroidal moment of inertia")
    points: dict[str, tuple[Length, Length]] = Field({}, description="named points in the body frame")
    pose: tuple[Length, Length, Angle] = Field(
        description="approximate pose (x, y, angle) of the body frame at t = 0, refined by assembly"
    )
    radius: PositiveLength | None = Field(None, description="draw the body as a disc of this radius (gears)")
    kind: Literal["link", "gear", "slider", "platform"] = Field("link", description="for drawing and accounting")
    attachments: list[CustomAttachment] = Field([], description="parts fixed to the body: counterweights, carried gears, payloads")


class RevoluteSpec(Strict):
    type: Literal["revolute"]
    name: str = Field(min_length=1)
    a: str = Field(description="first body (or 'frame')")
    b: str = Field(description="second body")
    point_a: Point = Field(description="joint centre on a")
    point_b: Point = Field((0.0, 0.0), description="joint centre on b")


class PrismaticSpec(Strict):
    type: Literal["prismatic"]
    name: str = Field(min_length=1)
    guide: str = Field(description="body carrying the guide (or 'frame')")
    slider: str = Field(description="sliding body")
    point_guide: Point = Field(description="a point of the guide's axis")
    axis: tuple[Number, Number] = Field(description="direction of the guide in the guide's frame")
    point_slider: Point = Field((0.0, 0.0), description="the slider's point that stays on the axis")
    angle: Angle = Field(0.0, description="constant angle of the slider relative to the guide")


class GearSpec(Strict):
    type: Literal["gear"]
    name: str = Field(min_length=1)
    a: str = Field(description="driving gear's body")
    b: str = Field(description="driven gear's body")
    carrier: str = Field(FRAME, description="body holding both axes ('frame' for fixed axes)")
    ratio: Number = Field(description="(w_b - w_c) / (w_a - w_c); -r_a/r_b for an external mesh")
    radius_a: PositiveLength | None = Field(
        None,
        description="pitch radius of gear a; with radius_b the mesh passes its tooth force between "
        "the gears' bearings (revolute joints pivoting a and b on the carrier, r_a + r_b apart, "
        "|r_a - r_b| for an internal mesh); omitted (a belt): the pair acts as a couple only",
    )
    radius_b: PositiveLength | None = Field(None, description="pitch radius of gear b")
    pressure_angle: PressureAngle = Field(
        DEFAULT_PRESSURE_ANGLE, description="pressure angle (default 20 deg): radial tooth force = "
        "|tangential| tan(pressure angle)"
    )


JointSpec = Annotated[Union[RevoluteSpec, PrismaticSpec, GearSpec], Field(discriminator="type")]


class DriverSpec(Strict):
    """An actuated coordinate; its motion is motion.drive[name]."""

    name: str = Field(min_length=1)
    joint: str | None = Field(None, description="a revolute or prismatic joint to drive")
    body: str | None = Field(None, description="or a body whose coordinate is driven")
    coordinate: Literal["x", "y", "angle"] | None = Field(None, description="with body: which coordinate")
    point: str | None = Field(None, description="with body and x/y: the body's point")


class CustomMechanism(Strict):
    """Explicit bodies, joints and drivers, for mechanisms no template covers."""

    template: Literal["custom"] = Field(description="mechanism template")
    frame_points: dict[str, tuple[Length, Length]] = Field({}, description="named fixed points")
    bodies: list[CustomBody] = Field(min_length=1, description="the moving bodies")
    joints: list[JointSpec] = Field(min_length=1, description="revolute, prismatic and gear joints")
    drivers: list[DriverSpec] = Field(min_length=1, description="the prescribed coordinates (their motion is motion.drive)")
    actuators: list[str] | None = Field(None, description=actuation.DESCRIPTION)

    def drives(self) -> dict[str, str]:
        out = {}
        joints = {j.name: j for j in self.joints}
        for d in self.drivers:
            if d.joint is not None:
                out[d.name] = "length" if isinstance(joints.get(d.joint), PrismaticSpec) else "angle"
            else:
                out[d.name] = "angle" if d.coordinate == "angle" else "length"
        return out


def _attachments(b: CustomBody, path: tuple) -> tuple[Attachment, ...]:
    out, seen = [], set()
    for k, a in enumerate(b.attachments):
        if a.name in seen:
            raise SpecFieldError(path + ("attachments", k, "name"), f"part name {a.name!r} is used twice on {b.name!r}")
        seen.add(a.name)
        if isinstance(a.position, str):
            if a.position not in b.points:
                raise SpecFieldError(path + ("attachments", k, "position"),
                                     f"{b.name!r} has no point {a.position!r} (known: {', '.join(b.points) or 'none'})")
            pos = tuple(b.points[a.position])
        else:
            pos = (float(a.position[0]), float(a.position[1]))
        out.append(Attachment(a.name, a.mass, pos, a.inertia, a.kind, a.radius))
    return tuple(out)


def build(mech: CustomMechanism, laws: dict, t: np.ndarray) -> Model:
    names = [b.name for b in mech.bodies]
    root = ("mechanism",)
    for k, n in enumerate(names):
        if n == FRAME or names.index(n) != k:
            raise SpecFieldError(root + ("bodies", k, "name"), f"body name {n!r} is reserved or used twice")
    bodies = {b.name: b for b in mech.bodies}

    def check_body(name: str, path) -> None:
        if name != FRAME and name not in bodies:
            raise SpecFieldError(path, f"unknown body {name!r} (bodies: {', '.join(names)}, frame)")

    def point(body: str, p: Point, path) -> tuple[float, float]:
        if not isinstance(p, str):
            return (float(p[0]), float(p[1]))
        table = mech.frame_points if body == FRAME else bodies[body].points
        if p not in table:
            raise SpecFieldError(path, f"{body!r} has no point {p!r} (known: {', '.join(table) or 'none'})")
        return tuple(table[p])

    joints = []
    for k, j in enumerate(mech.joints):
        jp = root + ("joints", k)
        if any(o.name == j.name for o in mech.joints[:k]):
            raise SpecFieldError(jp + ("name",), f"joint name {j.name!r} is used twice (each joint needs its own name)")
        if isinstance(j, RevoluteSpec):
            check_body(j.a, jp + ("a",))
            check_body(j.b, jp + ("b",))
            joints.append(Revolute(j.name, j.a, j.b, point(j.a, j.point_a, jp + ("point_a",)), point(j.b, j.point_b, jp + ("point_b",))))
        elif isinstance(j, PrismaticSpec):
            check_body(j.guide, jp + ("guide",))
            check_body(j.slider, jp + ("slider",))
            if np.hypot(*j.axis) == 0:
                raise SpecFieldError(jp + ("axis",), "the axis must not be zero")
            joints.append(Prismatic(j.name, j.guide, j.slider, point(j.guide, j.point_guide, jp + ("point_guide",)), tuple(j.axis), point(j.slider, j.point_slider, jp + ("point_slider",)), j.angle))
        else:
            for key in ("a", "b", "carrier"):
                check_body(getattr(j, key), jp + (key,))
            joints.append(Gear(j.name, j.a, j.b, j.carrier, j.ratio, None, j.radius_a, j.radius_b, j.pressure_angle))
    jnames = {j.name for j in joints}
    drivers = []
    for k, d in enumerate(mech.drivers):
        dp = root + ("drivers", k)
        if any(o.name == d.name for o in mech.drivers[:k]):
            raise SpecFieldError(dp + ("name",), f"driver name {d.name!r} is used twice (each driver needs its own name)")
        if d.joint is not None:
            if d.joint not in jnames:
                raise SpecFieldError(dp + ("joint",), f"unknown joint {d.joint!r}")
            target: tuple = ("joint", d.joint)
        elif d.body is not None and d.coordinate is not None:
            check_body(d.body, dp + ("body",))
            target = (d.coordinate, d.body) + ((d.point,) if d.point else ())
        else:
            raise SpecFieldError(dp, "a driver needs either joint, or body and coordinate")
        if d.name not in laws:
            raise SpecFieldError(("motion", "drive"), f"the driver {d.name!r} has no law: give motion.drive.{d.name} "
                                 f"(drivers: {', '.join(x.name for x in mech.drivers)})")
        drivers.append(Driver(d.name, target, laws[d.name]))
    model_bodies = tuple(
        Body(b.name, b.mass, tuple(b.com), b.inertia, dict(b.points), outline=tuple(b.points), radius=b.radius,
             kind=b.kind, attachments=_attachments(b, root + ("bodies", k)))
        for k, b in enumerate(mech.bodies)
    )
    model = Model(
        name="custom",
        bodies=model_bodies,
        joints=tuple(joints),
        drivers=tuple(drivers),
        initial={b.name: tuple(b.pose) for b in mech.bodies},
        frame_points={k: tuple(v) for k, v in mech.frame_points.items()},
        sources={**{b.name: root + ("bodies", k) for k, b in enumerate(mech.bodies)},
                 **{j.name: root + ("joints", k) for k, j in enumerate(mech.joints)}},
    )
    for k, (j, jt) in enumerate(zip(mech.joints, joints)):
        if isinstance(jt, Gear):
            try:
                mesh_geometry(model, jt)
            except ValueError as exc:
                key = "radius_b" if j.radius_a is not None and j.radius_b is None else "radius_a"
                raise SpecFieldError(root + ("joints", k, key), str(exc)) from None
    model = actuation.with_actuators(model, mech.actuators, root + ("actuators",))
    return model


def notation(mech: CustomMechanism) -> dict:
    """Symbols named after the spec's own bodies, points, joints and drivers: m_<body>,
    I_<body>, S_<body> (centre of mass), m_<part> of an attachment, U_<gear pair>, q_<driver>."""
    from ...notation import drive_table, ours

    table = drive_table({d.name: ours(f"q_{{{d.name}}}", f"coordinate driven by `{d.name}`") for d in mech.drivers}, end_time="T")
    for name in mech.frame_points:
        table[f"mechanism.frame_points.{name}"] = ours(f"`{name}`", f"fixed point `{name}` on the frame")
    for k, b in enumerate(mech.bodies):
        p, n = f"mechanism.bodies[{k}]", b.name
        table.update({
            f"{p}.mass": ours(f"m_{{{n}}}", f"mass of `{n}`"),
            f"{p}.com": ours(f"S_{{{n}}}", f"centre of mass of `{n}`, in its own frame"),
            f"{p}.inertia": ours(f"I_{{{n}}}", f"moment of inertia of `{n}` about its centre of mass"),
            f"{p}.pose": ours(f"(x, y, θ)_{{{n}}}", f"pose of `{n}`'s frame at the start (assembly guess): x, y and angle"),
            f"{p}.radius": ours(f"r_{{{n}}}", f"radius of `{n}` drawn as a disc"),
            f"{p}.kind": ours("kind", f"what `{n}` is, for drawing and accounting"),
        })
        for pt in b.points:
            table[f"{p}.points.{pt}"] = ours(f"`{pt}`", f"point `{pt}` of `{n}`, in `{n}`'s frame")
        for j, a in enumerate(b.attachments):
            q = f"{p}.attachments[{j}]"
            table.update({
                f"{q}.mass": ours(f"m_{{{a.name}}}", f"mass of `{a.name}`, fixed on `{n}`"),
                f"{q}.position": ours(f"S_{{{a.name}}}", f"centre of mass of `{a.name}`, in `{n}`'s frame"),
                f"{q}.inertia": ours(f"I_{{{a.name}}}", f"moment of inertia of `{a.name}`"),
                f"{q}.radius": ours(f"r_{{{a.name}}}", f"radius of `{a.name}` drawn as a disc"),
                f"{q}.kind": ours("kind", f"what `{a.name}` is"),
            })
    for k, j in enumerate(mech.joints):
        p = f"mechanism.joints[{k}]"
        table.update({
            f"{p}.type": ours(f"`{j.name}`", f"kind of joint `{j.name}`"),
            f"{p}.a": ours(f"`{j.name}`", f"first body of joint `{j.name}`"),
            f"{p}.b": ours(f"`{j.name}`", f"second body of joint `{j.name}`"),
            f"{p}.point_a": ours(f"`{j.name}`", f"centre of joint `{j.name}` on its first body"),
            f"{p}.point_b": ours(f"`{j.name}`", f"centre of joint `{j.name}` on its second body"),
            f"{p}.guide": ours(f"`{j.name}`", f"body carrying the guide of `{j.name}`"),
            f"{p}.slider": ours(f"`{j.name}`", f"sliding body of `{j.name}`"),
            f"{p}.point_guide": ours(f"`{j.name}`", f"a point of `{j.name}`'s axis"),
            f"{p}.axis": ours(f"`{j.name}`", f"direction of `{j.name}`'s guide"),
            f"{p}.point_slider": ours(f"`{j.name}`", f"the slider's point on `{j.name}`'s axis"),
            f"{p}.angle": ours(f"θ_{{{j.name}}}", f"constant angle of the slider of `{j.name}` relative to its guide"),
            f"{p}.carrier": ours(f"`{j.name}`", f"body holding both axes of gear pair `{j.name}`"),
            f"{p}.ratio": ours(f"U_{{{j.name}}}", f"ratio of gear pair `{j.name}`: (ω_b − ω_c) / (ω_a − ω_c)"),
            f"{p}.radius_a": ours(f"r_{{{j.name},a}}", f"pitch radius of the driving gear of `{j.name}`"),
            f"{p}.radius_b": ours(f"r_{{{j.name},b}}", f"pitch radius of the driven gear of `{j.name}`"),
            f"{p}.pressure_angle": ours(f"α_{{{j.name}}}", f"pressure angle of gear pair `{j.name}`"),
        })
    for k, a in enumerate(mech.actuators or []):
        table[f"mechanism.actuators[{k}]"] = ours(f"τ_{{{a}}}", f"motor at joint `{a}`: its torque (revolute) or force (prismatic)")
    for k, d in enumerate(mech.drivers):
        p = f"mechanism.drivers[{k}]"
        for field, what in (("joint", "joint it drives"), ("body", "body whose coordinate it drives"),
                            ("coordinate", "coordinate of the body it drives"), ("point", "point of the body it drives")):
            table[f"{p}.{field}"] = ours(f"`{d.name}`", f"driver `{d.name}`: {what}")
    return table
