"""The generic planar multibody model that every mechanism template produces.

A :class:`Model` is a list of rigid bodies, the joints between them (and the frame), and the
drivers that impose the motion of the actuated coordinates. Balancing methods transform models
(add attachments, add bodies such as counter-rotating gears); the analysis engine
(:mod:`balpipe.engine`) and the pymunk validator (:mod:`balpipe.validate`) read them. Nothing in
here is specific to a mechanism.

Conventions (SI units throughout):

* Every body has its own frame. ``com``, ``points`` and attachment positions are given in that
  frame; the body's pose is (x, y, theta) of the frame origin in the global frame.
* The frame (ground) is the body named :data:`FRAME`; its points are global coordinates.
* A revolute joint makes two points coincide; a prismatic joint keeps the slider's point on the
  guide's axis and their relative angle constant; a gear pair imposes
  ``(theta_b - theta_c) = ratio * (theta_a - theta_c) + phase`` with ``c`` the carrier, so the
  mesh couple lands on the carrier (see ../shared/DESIGN.md, "Conventions").
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np

FRAME = "frame"

Vec2 = tuple[float, float]


@dataclass(frozen=True)
class Attachment:
    """A part rigidly fixed to a body: a counterweight (point mass or disc) or a carried gear.

    ``position`` is in the body's frame; ``inertia`` is the part's centroidal inertia.
    ``radius`` is used only for drawing.
    """

    name: str
    mass: float
    position: Vec2
    inertia: float = 0.0
    kind: Literal["counterweight", "gear", "payload", "part"] = "counterweight"
    radius: float | None = None


@dataclass(frozen=True)
class Body:
    """A rigid body: the link itself plus the parts attached to it.

    ``mass``, ``com`` and ``inertia`` describe the bare link; :meth:`mass_properties` adds the
    attachments. ``points`` name local points (joint centres, tips) used by joints and drawings;
    ``outline`` lists the point names drawn as the link's polyline; ``radius`` draws the body as a
    disc (gears, counter-rotations).
    """

    name: str
    mass: float
    com: Vec2
    inertia: float
    points: dict[str, Vec2] = field(default_factory=dict)
    attachments: tuple[Attachment, ...] = ()
    outline: tuple[str, ...] = ()
    radius: float | None = None
    kind: Literal["link", "gear", "slider", "platform"] = "link"

    def mass_properties(self) -> tuple[float, Vec2, float]:
        """Total mass, centre of mass (body frame) and centroidal inertia, attachments included.

        Parallel-axis theorem: I = sum(I_k + m_k |p_k - c|^2).
        """
        parts = [(self.mass, self.com, self.inertia)] + [
            (a.mass, a.position, a.inertia) for a in self.attachments
        ]
        m = sum(p[0] for p in parts)
        if m > 0:
            cx = sum(p[0] * p[1][0] for p in parts) / m
            cy = sum(p[0] * p[1][1] for p in parts) / m
        else:
            cx, cy = self.com
        inertia = sum(
            p[2] + p[0] * ((p[1][0] - cx) ** 2 + (p[1][1] - cy) ** 2) for p in parts
        )
        return m, (cx, cy), inertia

    def with_attachments(self, *extra: Attachment) -> "Body":
        return replace(self, attachments=self.attachments + tuple(extra))

    def point(self, name: str) -> Vec2:
        try:
            return self.points[name]
        except KeyError:
            raise KeyError(f"body {self.name!r} has no point {name!r}") from None


@dataclass(frozen=True)
class Revolute:
    """Pin joint: point ``point_a`` of body ``a`` coincides with ``point_b`` of body ``b``.

    Points are local coordinates (global ones on the frame). The joint coordinate is
    theta_b - theta_a.
    """

    name: str
    a: str
    b: str
    point_a: Vec2
    point_b: Vec2


@dataclass(frozen=True)
class Prismatic:
    """Sliding pair: the slider's point ``point_slider`` stays on the line of ``guide`` through
    ``point_guide`` with direction ``axis`` (guide frame), and the relative angle
    theta_slider - theta_guide stays at ``angle``. The joint coordinate is the signed distance
    along ``axis`` from ``point_guide`` to the slider's point.
    """

    name: str
    guide: str
    slider: str
    point_guide: Vec2
    axis: Vec2
    point_slider: Vec2 = (0.0, 0.0)
    angle: float = 0.0


@dataclass(frozen=True)
class Gear:
    """Gear pair (or belt) between bodies ``a`` and ``b`` whose axes are held by ``carrier``.

    Constraint: (theta_b - theta_c) - ratio (theta_a - theta_c) = phase. An external mesh of
    radii r_a, r_b has ratio = -r_a / r_b; an internal mesh or a belt +r_a / r_b. ``phase``
    None means "as assembled in the initial pose". ``radius_a``/``radius_b`` are the pitch
    radii: given, the mesh passes its tooth force (tangential from the mesh torque, radial
    from ``pressure_angle``) between the gears, whose bearings on the carrier then carry it
    (:mod:`balpipe.mechanics.meshes`); omitted (a belt), the pair acts as a couple only.
    """

    name: str
    a: str
    b: str
    carrier: str
    ratio: float
    phase: float | None = None
    radius_a: float | None = None
    radius_b: float | None = None
    pressure_angle: float = math.radians(20.0)


Joint = Revolute | Prismatic | Gear


class Law:
    """A scalar motion law q(t) with its first two derivatives, vectorised over t."""

    def __call__(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        raise NotImplementedError


@dataclass(frozen=True)
class Driver:
    """An actuated coordinate that follows a law.

    ``target`` is either ``("joint", joint_name)`` (a revolute's relative angle or a prismatic's
    displacement) or ``("x" | "y" | "angle", body_name, point_name)`` for a coordinate of a
    body point in the global frame (or the body's absolute angle; point_name ignored).
    """

    name: str
    target: tuple[str, ...]
    law: Law


@dataclass(frozen=True)
class Actuator:
    """A motor at a joint: a torque (N m) about a revolute's axis, applied to body b and
    reacted on body a, or a force (N) along a prismatic pair's axis, on the slider and reacted
    on the guide. Its effort is the generalized force conjugate to the joint coordinate (the
    revolute's theta_b - theta_a, the prismatic's displacement), so the virtual work of the
    effort is tau d(coordinate) (DESIGN.md, "What moves and what drives are two lists":
    M q'' + h = B tau + Phi_q^T lambda, B the coordinates' gradients)."""

    name: str
    joint: str


@dataclass(frozen=True)
class Model:
    """A planar mechanism: bodies, joints, drivers and an initial pose for assembly.

    ``initial`` maps each body to an approximate pose (x, y, theta) of its frame at t = 0; the
    engine refines it by Newton-Raphson. ``frame_points`` are named fixed points (pivots) drawn
    on the frame; ``guides`` are fixed line segments drawn on the frame (slider guides).

    ``actuators``: the motors, distinct from the drivers. Empty (the default): each driver is
    its own actuator and the efforts are the drivers' (virtual ones when a driver prescribes a
    point or a pose). Given: the drivers only prescribe the motion, and the efforts are the
    actuators' (:mod:`balpipe.engine.dynamics`). ``sources`` maps body, joint, driver and
    actuator names to the spec field that defines them, for located errors.

    ``loads``: force elements, applied loads and joint friction
    (:mod:`balpipe.mechanics.loads`); balancing stages keep them (they only add parts), and the
    engine counts them in the efforts, reactions and frame loads, never in the shaking loads.
    """

    name: str
    bodies: tuple[Body, ...]
    joints: tuple[Joint, ...]
    drivers: tuple[Driver, ...]
    initial: dict[str, tuple[float, float, float]]
    frame_points: dict[str, Vec2] = field(default_factory=dict)
    guides: tuple[tuple[Vec2, Vec2], ...] = ()
    actuators: tuple[Actuator, ...] = ()
    loads: tuple = ()
    sources: dict[str, tuple] = field(default_factory=dict, compare=False)

    def body(self, name: str) -> Body:
        for b in self.bodies:
            if b.name == name:
                return b
        raise KeyError(f"model {self.name!r} has no body {name!r}")

    def joint(self, name: str) -> Joint:
        for j in self.joints:
            if j.name == name:
                return j
        raise KeyError(f"model {self.name!r} has no joint {name!r}")

    def replace_body(self, body: Body) -> "Model":
        """A copy with the body of the same name replaced."""
        self.body(body.name)
        return replace(
            self, bodies=tuple(body if b.name == body.name else b for b in self.bodies)
        )

    def add(
        self,
        bodies: tuple[Body, ...] = (),
        joints: tuple[Joint, ...] = (),
        initial: dict[str, tuple[float, float, float]] | None = None,
    ) -> "Model":
        """A copy with extra bodies (with their initial poses) and joints."""
        init = dict(self.initial)
        init.update(initial or {})
        return replace(
            self, bodies=self.bodies + tuple(bodies), joints=self.joints + tuple(joints), initial=init
        )

    def total_mass(self) -> float:
        return sum(b.mass_properties()[0] for b in self.bodies)


def rot(theta: float) -> np.ndarray:
    c, s = math.cos(theta), math.sin(theta)
    return np.array([[c, -s], [s, c]])


def pose_of_com(body: Body, pose: tuple[float, float, float]) -> tuple[float, float, float]:
    """Convert a pose of the body frame into (x_com, y_com, theta)."""
    _, com, _ = body.mass_properties()
    x, y, th = pose
    p = np.array([x, y]) + rot(th) @ np.array(com)
    return float(p[0]), float(p[1]), th
