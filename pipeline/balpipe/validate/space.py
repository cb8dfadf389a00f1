"""Generic translation of a balpipe :class:`~balpipe.model.Model` into a pymunk 7 space.

Nothing here knows a mechanism: every body, joint and driver of the model is mapped by type.
:mod:`balpipe.validate.run` drives the space along the motion and measures the loads.

Bodies
    One ``pymunk.Body(mass, moment)`` per model body, no shapes (so nothing collides). The
    pymunk body's origin is the body's centre of mass (attachments included): its
    ``center_of_gravity`` stays (0, 0) and is set before ``angle``, itself set before
    ``position`` (see ../shared/reference/PYMUNK.md), so ``body.position`` and
    ``body.velocity`` are the centre of mass's. Joint points are converted from the model's
    body frame to offsets from the centre of mass. pymunk needs positive masses and moments
    and its iterative solver stalls on light bodies between heavy ones: every mass (moment)
    below ``mass_floor`` times the model's largest is raised to it (``SimModel.floored``).
    :mod:`balpipe.validate` measures the loads with the model's own masses on the simulated
    motion, which the drivers impose, so the floors only change internal forces there.

Frame
    ``space.static_body`` (its local coordinates are global coordinates), or, for the
    free-floating demonstration, a dynamic base body whose local coordinates are the model's
    global coordinates at t = 0 and whose centre of gravity is a chosen point.

Joints (every position error corrected in one step: ``error_bias = 0``, unless ``joint_bias``)
    * Revolute: ``PivotJoint``.
    * Prismatic: ``GrooveJoint`` (the guide's line through ``point_guide``, long enough never to
      be left) plus ``GearJoint(guide, slider, angle, 1)`` locking the relative rotation
      (a groove alone leaves the slider free to turn).
    * Angle relations (gear pairs, the rotation lock, angle drivers) are written, as in the
      engine, ``sum_k c_k theta_k = phase (+ law)``; a static frame drops out (theta = 0), a
      free base is added to relations whose coefficients do not cancel (an angle driver is
      then measured from the base). One or two moving bodies: one ``GearJoint``. Between two
      moving bodies whose coefficients do not cancel (a gear pair carried by a static frame,
      ratio != 1) pymunk's GearJoint gives the right motion but not the reaction couple
      (1 - ratio) lambda, which is the frame's: the momentum measurement (minus the rate of
      change of the moving bodies' momenta) includes it by construction.
    * Gear pairs whose two gears and carrier all move (planetary gears; every gear pair on a
      free base): no set of two-body GearJoints can express a relation between three angles,
      ``gear_model`` chooses:

      - ``"mesh"`` (default): what a gear pair is. Gears a and b turn on pivots of the carrier
        (the points where revolute joints connect them to it) and touch at the pitch point P
        of the line of centres, |P - Oa| / |P - Ob| = |ratio|; a ``GrooveJoint`` (groove on a
        along the line of centres, anchor on b) forbids relative sliding there. Groove and
        anchor are re-placed at P for the positions the next step integrates to, so the
        velocity constraint is exactly (w_b - w_c) = ratio (w_a - w_c); the anchor is moved
        along the tangent by the accumulated angle error times b's pitch radius so that the
        angle relation itself is restored every step. Every force acts between two bodies at
        one point: the mesh couple reaches the carrier through the pivots and momentum is
        conserved, implicitly in the solver. Without such pivots (coaxial gears, or none
        declared) two auxiliary light gears are pinned to the carrier at virtual centres and
        locked to a and b by ratio-1 GearJoints. Its convergence degrades when a gear's moment
        is large next to its mass times its pitch radius squared.
      - ``"explicit"``: one GearJoint, theta_b - ratio theta_a = phase + (1 - ratio) theta_c,
        the carrier's angle extrapolated to the end of the next step (``_CarriedGear``). Always
        converges; the carrier misses its (1 - ratio) couple, harmless for a motion imposed by
        drivers, but the extrapolation lags where the carrier's acceleration jumps.
      - ``"absolute"``: the carrier's angle frozen at t = 0: PYMUNK.md's trap, for measurement.

Drivers (the dead-beat recipe)
    Chipmunk moves positions before it solves velocities, so a constraint's target set before
    the step from t is reached at t + 2 dt. Every driver constraint has ``error_bias = 0`` and
    its target is set before each step to the law at t + 2 dt (``SimModel.prepare``).

    * revolute joint or absolute angle: ``GearJoint(a, b, phase, 1)``, phase = law;
    * prismatic joint: a second ``GrooveJoint`` across the axis, moved along it with the law
      (its force and the guide's act at the same point, so momentum is conserved; a pivot with
      a moving anchor puts the two ends of its impulse ~ v dt apart);
    * x and y of one body point (a path law): one ``PivotJoint`` between the frame and the
      point, its anchor on the frame moved to the laws' values. Two perpendicular grooves on one
      point (below) do not hold it: Chipmunk's groove solves a two-dimensional impulse and keeps
      its component across the groove, which then depends on the sliding along it, and each
      groove slides along the other at the point's speed. On the five-bar of
      ``custom_five_bar_circle.yaml`` the grooves left residuals of 5.7e-4 (force) and 1.5e-3
      (moment) of the reference at 200 iterations, the pivot 9.3e-7 and 2.0e-6 at 100; on a
      five-bar with longer distal links (0.34 m on 0.22 m proximal links, pivots 0.16 m apart) the
      grooves let the mechanism come apart within 0.07 s at any iteration count or step, the pivot
      follows it to 2.8e-4 of its size (``tests/validate/test_point_drivers.py``). On a free base the
      two grooves stay: a moving anchor would put the two ends of the impulse ~ v dt apart, a
      spurious couple on the base;
    * x or y of a body point alone: a ``GrooveJoint`` on the frame, the vertical (horizontal)
      line at the law's value, the point as anchor.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
import pymunk
from pymunk._chipmunk_cffi import lib as _cp

from ..model import FRAME, Driver, Gear, Model, Prismatic, Revolute

__all__ = ["SimModel", "build_space", "assembled_state"]


def _rot(th: float, v) -> tuple[float, float]:
    c, s = math.cos(th), math.sin(th)
    return (c * v[0] - s * v[1], s * v[0] + c * v[1])


def _unrot(th: float, v) -> tuple[float, float]:
    c, s = math.cos(th), math.sin(th)
    return (c * v[0] + s * v[1], -s * v[0] + c * v[1])


@dataclass
class _Drive:
    """A constraint whose target follows a law: ``set(value)`` before each step."""

    name: str
    driver: Driver
    # "phase" (a GearJoint's phase), "groove" (a groove across an axis) or "anchor_x" / "anchor_y"
    # (a coordinate of a pivot's anchor on the frame)
    kind: str
    constraint: pymunk.Constraint
    scale: float = 1.0
    offset: float = 0.0
    base_point: tuple[float, float] = (0.0, 0.0)
    axis: tuple[float, float] = (1.0, 0.0)
    half_length: float = 1.0

    def set(self, value: float) -> None:
        c = self.constraint
        if self.kind == "phase":
            c.phase = self.offset + self.scale * value
        elif self.kind == "anchor_x":  # a point's x: its pivot's anchor on the frame
            c.anchor_a = (value, c.anchor_a[1])
        elif self.kind == "anchor_y":
            c.anchor_a = (c.anchor_a[0], value)
        else:  # groove: line through axis-coordinate `value`, perpendicular to axis
            ax, L = self.axis, self.half_length
            n = (-ax[1], ax[0])
            p = (self.base_point[0] + ax[0] * value, self.base_point[1] + ax[1] * value)
            c.groove_a = (p[0] - n[0] * L, p[1] - n[1] * L)
            c.groove_b = (p[0] + n[0] * L, p[1] + n[1] * L)


@dataclass
class _Mesh:
    """A gear pair on a moving carrier: a groove re-placed at the pitch point every step."""

    name: str
    groove: pymunk.GrooveJoint
    a: pymunk.Body  # the body holding the groove (gear a, or its auxiliary)
    b: pymunk.Body  # the body holding the anchor (gear b, or its auxiliary)
    c: pymunk.Body  # carrier
    ta: pymunk.Body  # bodies whose angles enter the relation
    tb: pymunk.Body
    oa: tuple[float, float]  # gear centres in the carrier's local coordinates
    ob: tuple[float, float]
    ratio: float
    phase: float
    half_length: float
    auxiliary: bool = False

    def update(self, dt: float) -> None:
        """Place groove and anchor for the positions the next step will integrate to. (The bodies'
        state read and the joint's geometry set through Chipmunk's own accessors, as pymunk's
        properties do, without their Vec2d objects: the same numbers, a third of the time; each
        predicted angle's cosine and sine taken once, where ``_rot`` and ``_unrot`` took them at
        every use: the same numbers again, the same Chipmunk calls in the same order, 7.1 -> 6.1 us a call.)"""
        angle, spin = _cp.cpBodyGetAngle, _cp.cpBodyGetAngularVelocity
        xc, yc, thc, cc, sc = _predicted(self.c._body, dt)
        xa, ya, tha, ca, sa = _predicted(self.a._body, dt)
        xb, yb, thb, cb, sb = _predicted(self.b._body, dt)
        ta, tb = self.ta._body, self.tb._body
        tha_r = angle(ta) + dt * spin(ta)
        thb_r = angle(tb) + dt * spin(tb)
        (oax, oay), (obx, oby) = self.oa, self.ob
        wax, way = xc + (cc * oax - sc * oay), yc + (sc * oax + cc * oay)  # _rot(thc, oa) from the carrier's centre
        wbx, wby = xc + (cc * obx - sc * oby), yc + (sc * obx + cc * oby)
        dx, dy = wbx - wax, wby - way
        d = math.hypot(dx, dy)
        if not d > 0.0:  # the mechanism came apart
            raise FloatingPointError(f"gear pair {self.name!r}: its centres coincide")
        ux, uy = dx / d, dy / d
        tx, ty = -uy, ux
        R = self.ratio
        p = R * d / (R - 1.0)
        q = d / (R - 1.0)
        err = (thb_r - thc) - R * (tha_r - thc) - self.phase
        Px, Py = wax + p * ux, way + p * uy
        ax, ay = Px + q * err * tx, Py + q * err * ty  # the anchor
        L = self.half_length
        g1x, g1y = Px - L * ux - xa, Py - L * uy - ya  # _unrot(tha, .) of these, below
        g2x, g2y = Px + L * ux - xa, Py + L * uy - ya
        bx, by = ax - xb, ay - yb  # _unrot(thb, .)
        c = self.groove._constraint
        _cp.cpGrooveJointSetGrooveA(c, (ca * g1x + sa * g1y, -sa * g1x + ca * g1y))
        _cp.cpGrooveJointSetGrooveB(c, (ca * g2x + sa * g2y, -sa * g2x + ca * g2y))
        _cp.cpGrooveJointSetAnchorB(c, (cb * bx + sb * by, -sb * bx + cb * by))


def _predicted(b, dt: float) -> tuple[float, float, float, float, float]:
    """The pose a Chipmunk body ``b`` (``Body._body``) integrates to in a step of ``dt`` (pymunk
    integrates the centre of gravity: p += v dt, angle += w dt), its origin's x, y and angle th,
    and cos th, sin th."""
    th = _cp.cpBodyGetAngle(b) + dt * _cp.cpBodyGetAngularVelocity(b)
    cog = _cp.cpBodyGetCenterOfGravity(b)
    g = _cp.cpBodyLocalToWorld(b, cog)
    v = _cp.cpBodyGetVelocity(b)
    c, s = math.cos(th), math.sin(th)
    return g.x + dt * v.x - (c * cog.x - s * cog.y), g.y + dt * v.y - (s * cog.x + c * cog.y), th, c, s


@dataclass
class _CarriedGear:
    """A gear pair on a moving carrier as one GearJoint between the gears' absolute angles,
    theta_b - ratio theta_a = phase + (1 - ratio) theta_c, the carrier's angle entering the
    phase explicitly: before each step it is set to the carrier's angle extrapolated to the
    end of the next step (the dead-beat recipe of the drivers, with the carrier's own motion
    in place of a law). The gears get their mesh couples; the carrier does not get its
    (1 - ratio) share, which changes only the internal forces of a mechanism whose motion is
    imposed by its drivers, not its motion, hence not the momentum measurement."""

    name: str
    joint: pymunk.GearJoint
    scale: float
    offset: float
    carrier: pymunk.Body
    factor: float  # 1 - ratio
    w_prev: float | None = None

    def update(self, dt: float) -> None:
        c = self.carrier
        w = c.angular_velocity
        w_next = w if self.w_prev is None else 2.0 * w - self.w_prev
        self.w_prev = w
        theta = c.angle + dt * (w + w_next)
        self.joint.phase = self.offset + self.scale * self.factor * theta


@dataclass
class _Actuator:
    """A driver replaced by the force or torque its actuator applies (torque-driven runs).

    The generalized force of a driver's effort e is e times its constraint gradient (the
    engine's convention, :mod:`balpipe.engine`): a revolute joint (a, b) gets +e on b and -e on
    a; an absolute angle +e on the body (the reaction is the frame's); a prismatic joint a
    force e along the guide's axis on the slider at the slider's point and -e on the guide at
    the same point; an x or y coordinate a force e along that axis at the body's point. Forces
    are applied for the positions the coming step integrates to (pymunk moves positions
    before it integrates velocities), so the moment arms are second-order accurate."""

    name: str
    kind: str  # "torque", "axis" (prismatic) or "fixed_axis" (x / y of a point)
    body: pymunk.Body  # the driven body (b, the slider, the body)
    other: pymunk.Body | None = None  # the reacting body (a, the guide), None for the frame
    point: tuple[float, float] = (0.0, 0.0)  # the slider's / body's point, from its centre of mass
    axis: tuple[float, float] = (1.0, 0.0)  # in the guide's frame ("axis") or global ("fixed_axis")

    def apply(self, value: float, dt: float) -> None:
        if self.kind == "torque":
            self.body.torque += value
            if self.other is not None:
                self.other.torque -= value
            return

        def pred(body: pymunk.Body) -> tuple[float, float, float]:
            return (body.position.x + dt * body.velocity.x, body.position.y + dt * body.velocity.y,
                    body.angle + dt * body.angular_velocity)

        x, y, th = pred(self.body)
        off = _rot(th, self.point)
        P = (x + off[0], y + off[1])
        if self.kind == "axis":
            e = _rot(pred(self.other)[2], self.axis) if self.other is not None else self.axis
        else:
            e = self.axis
        f = (value * e[0], value * e[1])
        for body, sign in ((self.body, 1.0), (self.other, -1.0)):
            if body is None or body.body_type != pymunk.Body.DYNAMIC:
                continue
            cx, cy, _ = pred(body)
            body.force = (body.force.x + sign * f[0], body.force.y + sign * f[1])
            body.torque += sign * ((P[0] - cx) * f[1] - (P[1] - cy) * f[0])


@dataclass
class SimModel:
    """A model built in a pymunk space.

    ``bodies`` are the model's bodies in ``model.bodies`` order (their ``position`` is the centre
    of mass); ``auxiliary`` holds the light bodies added for meshes without a carrier pivot;
    ``base`` is the frame (``space.static_body``, or the dynamic base when floating).
    ``floored`` names the bodies whose mass or moment was raised to the floor.
    """

    model: Model
    space: pymunk.Space
    bodies: list[pymunk.Body]
    auxiliary: list[pymunk.Body]
    base: pymunk.Body
    floating: bool
    drives: list[_Drive]
    meshes: list[_Mesh]
    com_local: list[tuple[float, float]]
    floored: list[str] = field(default_factory=list)
    carried: list[_CarriedGear] = field(default_factory=list)
    actuators: list[_Actuator] = field(default_factory=list)
    notes: list[str] = field(default_factory=list)

    @property
    def moving(self) -> list[pymunk.Body]:
        """Every dynamic body of the mechanism (not the base)."""
        return self.bodies + self.auxiliary

    def prepare(self, targets: dict[str, float], dt: float) -> None:
        """Set driver targets (law values at t + 2 dt) and re-place meshes before a step."""
        for d in self.drives:
            d.set(targets[d.driver.name])
        for m in self.meshes:
            m.update(dt)
        for g in self.carried:
            g.update(dt)

    def step(self, targets: dict[str, float], dt: float) -> None:
        self.prepare(targets, dt)
        self.space.step(dt)

    def state(self) -> np.ndarray:
        """(nb, 3) centre-of-mass coordinates x, y, theta of the model's bodies."""
        return np.array([(b.position.x, b.position.y, b.angle) for b in self.bodies])


def assembled_state(model: Model, t0: float = 0.0) -> tuple[np.ndarray, np.ndarray]:
    """Assembled centre-of-mass pose and velocity (nb, 3) at t0, from the engine."""
    from ..engine import analyse

    a = analyse(model, np.array([t0]))
    return a.q[0], a.v[0]


def _length_scale(model: Model, pose: np.ndarray) -> float:
    vals = [1e-3]
    for b in model.bodies:
        vals += [abs(c) for p in b.points.values() for c in p]
        vals += [abs(c) for c in b.com]
    for j in model.joints:
        if isinstance(j, Revolute):
            vals += [abs(c) for c in j.point_a + j.point_b]
        elif isinstance(j, Prismatic):
            vals += [abs(c) for c in j.point_guide + j.point_slider]
    vals += list(np.abs(pose[:, :2]).ravel())
    return float(max(vals))


def build_space(
    model: Model,
    pose: np.ndarray | None = None,
    velocity: np.ndarray | None = None,
    *,
    gravity: tuple[float, float] = (0.0, 0.0),
    iterations: int = 30,
    floating_base: tuple[float, float, tuple[float, float]] | None = None,
    mass_floor: float = 1e-6,
    gear_model: str | None = None,
    joint_bias: float | None = None,
    dt: float = 1e-3,
    drive: bool = True,
) -> SimModel:
    """Build ``model`` in a new pymunk space.

    ``pose`` and ``velocity`` are (nb, 3) centre-of-mass coordinates and their rates in
    ``model.bodies`` order (default: the engine's assembly and velocities at t = 0).
    ``floating_base = (mass, moment, centre_of_gravity)`` makes the frame a free body (used by
    :func:`balpipe.validate.free_floating`); otherwise the frame is ``space.static_body``.
    ``gear_model`` chooses how a gear pair whose two gears and carrier all move is built:
    ``"mesh"`` (default), ``"explicit"`` or ``"absolute"`` (see the module's docstring).
    ``mass_floor``: masses and moments below this fraction of the model's largest are raised
    to it.
    ``joint_bias``: fraction of a passive joint's position error corrected per step (default
    1: all of it, dead-beat); drivers and meshes always correct all of it. ``dt`` is the step
    the space will be stepped with (used to convert ``joint_bias`` into pymunk's error_bias).
    ``drive=False`` builds no driver constraints: each driver becomes an actuator
    (``SimModel.actuators``, :class:`_Actuator`) that applies a given effort (torque-driven runs).
    """
    if pose is None:
        pose, v0 = assembled_state(model)
        velocity = v0 if velocity is None else velocity
    pose = np.asarray(pose, dtype=float)
    velocity = np.zeros_like(pose) if velocity is None else np.asarray(velocity, dtype=float)
    names = [b.name for b in model.bodies]
    if FRAME in names:
        raise ValueError(f"'{FRAME}' is reserved for the fixed frame")

    space = pymunk.Space()
    space.iterations = int(iterations)
    space.gravity = tuple(float(g) for g in gravity)
    scale = _length_scale(model, pose)
    half = 100.0 * scale

    props = [b.mass_properties() for b in model.bodies]
    m_ref = max([p[0] for p in props] + [0.0]) or 1.0
    i_ref = max([p[2] for p in props] + [0.0]) or m_ref * scale**2
    floored: list[str] = []
    bodies: list[pymunk.Body] = []
    com_local: list[tuple[float, float]] = []
    for b, (m, com, inertia), q, v in zip(model.bodies, props, pose, velocity):
        mm = max(m, mass_floor * m_ref)
        ii = max(inertia, mass_floor * i_ref)
        if mm != m or ii != inertia:
            floored.append(b.name)
        body = pymunk.Body(mm, ii)
        body.center_of_gravity = (0.0, 0.0)  # first (the origin is the centre of mass)
        body.angle = float(q[2])  # then the angle
        body.position = (float(q[0]), float(q[1]))  # then the position
        body.velocity = (float(v[0]), float(v[1]))
        body.angular_velocity = float(v[2])
        space.add(body)
        bodies.append(body)
        com_local.append((float(com[0]), float(com[1])))

    if floating_base is None:
        base = space.static_body
        floating = False
    else:
        bm, bi, cg = floating_base
        base = pymunk.Body(float(bm), float(bi))
        base.center_of_gravity = (float(cg[0]), float(cg[1]))
        base.angle = 0.0
        base.position = (0.0, 0.0)
        space.add(base)
        floating = True

    pb = {FRAME: base, **dict(zip(names, bodies))}
    com = {FRAME: (0.0, 0.0), **dict(zip(names, com_local))}
    sim = SimModel(model, space, bodies, [], base, floating, [], [], com_local, floored)

    def local(body: str, p) -> tuple[float, float]:
        c = com[body]
        return (float(p[0]) - c[0], float(p[1]) - c[1])

    passive_bias = 0.0 if joint_bias is None or joint_bias >= 1 else (1.0 - joint_bias) ** (1.0 / dt)

    def add(c: pymunk.Constraint, error_bias: float | None = None) -> pymunk.Constraint:
        c.collide_bodies = False
        c.error_bias = passive_bias if error_bias is None else error_bias
        space.add(c)
        return c

    def is_static(name: str) -> bool:
        return name == FRAME and not floating

    def angle_joint(
        coeffs: dict[str, float], phase: float, eb: float | None = None, absolute: bool = False
    ) -> tuple[pymunk.GearJoint, float, float]:
        """One GearJoint for sum_k c_k theta_k = phase + s(t); returns it with (scale, offset)
        such that the joint's phase = offset + scale * s. On a floating base, angles whose
        coefficients do not cancel are measured from the base (unless ``absolute``)."""
        terms = [(n, k) for n, k in coeffs.items() if k != 0.0 and not is_static(n)]
        if floating and not absolute:
            total = sum(k for _, k in terms)
            if abs(total) > 1e-12:  # an absolute angle: relative to the base
                terms.append((FRAME, -total))
                merged: dict[str, float] = {}
                for n, k in terms:
                    merged[n] = merged.get(n, 0.0) + k
                terms = [(n, k) for n, k in merged.items() if abs(k) > 1e-15]
        if len(terms) == 1:
            (n, k), = terms
            return add(pymunk.GearJoint(base, pb[n], phase / k, 1.0), eb), 1.0 / k, phase / k
        if len(terms) == 2:
            (n1, k1), (n2, k2) = terms
            r = -k2 / k1
            j = add(pymunk.GearJoint(pb[n1], pb[n2], -phase / k1, r), eb)
            return j, -1.0 / k1, -phase / k1
        raise ValueError(f"cannot express {coeffs} with one GearJoint")

    driven: dict[str, Driver] = {}
    for d in model.drivers:
        if d.target[0] == "joint":
            driven[d.target[1]] = d

    init_angle = {FRAME: 0.0, **{n: float(q[2]) for n, q in zip(names, pose)}}
    for jt in model.joints:
        if isinstance(jt, Revolute):
            add(pymunk.PivotJoint(pb[jt.a], pb[jt.b], local(jt.a, jt.point_a), local(jt.b, jt.point_b)))
        elif isinstance(jt, Prismatic):
            ax = np.asarray(jt.axis, dtype=float)
            ax = tuple(ax / np.linalg.norm(ax))
            pg = local(jt.guide, jt.point_guide)
            ps = local(jt.slider, jt.point_slider)
            angle_joint({jt.slider: 1.0, jt.guide: -1.0}, jt.angle)
            g1 = (pg[0] - half * ax[0], pg[1] - half * ax[1])
            g2 = (pg[0] + half * ax[0], pg[1] + half * ax[1])
            add(pymunk.GrooveJoint(pb[jt.guide], pb[jt.slider], g1, g2, ps))
            d = driven.get(jt.name)
            if d is not None and drive:
                # a second groove across the axis, moved along it with the law
                c = add(pymunk.GrooveJoint(pb[jt.guide], pb[jt.slider], g1, g2, ps), 0.0)
                dr = _Drive(d.name, d, "groove", c, base_point=pg, axis=ax, half_length=half)
                dr.set(float(d.law(np.array([0.0]))[0][0]))
                sim.drives.append(dr)
        elif isinstance(jt, Gear):
            _add_gear(sim, jt, pb, com, init_angle, model, angle_joint, add, is_static, gear_model or 'mesh', half, mass_floor, m_ref, i_ref)
        else:  # pragma: no cover
            raise TypeError(jt)

    pivots: dict[tuple, pymunk.PivotJoint] = {}
    paired = set() if floating else _paired_points(model)
    for d in model.drivers:
        if not drive:
            if not model.actuators:  # named actuators apply the efforts instead (below)
                sim.actuators.append(_actuator(model, d, pb, local))
            continue
        kind = d.target[0]
        if kind == "joint":
            jt = model.joint(d.target[1])
            if isinstance(jt, Revolute):
                c, s, o = angle_joint({jt.b: 1.0, jt.a: -1.0}, 0.0, 0.0)
                sim.drives.append(_Drive(d.name, d, "phase", c, scale=s, offset=o))
            elif isinstance(jt, Prismatic):
                pass  # built with the joint
            else:
                raise ValueError(f"driver {d.name!r}: a gear pair cannot be driven")
        elif kind == "angle":
            c, s, o = angle_joint({d.target[1]: 1.0}, 0.0, 0.0)
            sim.drives.append(_Drive(d.name, d, "phase", c, scale=s, offset=o))
        elif kind in ("x", "y") and d.target[1:] in paired:
            key = d.target[1:]
            if key not in pivots:  # x and y of one point: one pivot on the frame (see the module)
                point = model.body(key[0]).point(key[1]) if len(key) > 1 else (0.0, 0.0)
                pivots[key] = add(pymunk.PivotJoint(base, pb[key[0]], (0.0, 0.0), local(key[0], point)), 0.0)
            dr = _Drive(d.name, d, "anchor_" + kind, pivots[key])
            dr.set(float(d.law(np.array([0.0]))[0][0]))
            sim.drives.append(dr)
        elif kind in ("x", "y"):
            body = d.target[1]
            point = model.body(body).point(d.target[2]) if len(d.target) > 2 else (0.0, 0.0)
            axis = (1.0, 0.0) if kind == "x" else (0.0, 1.0)
            c = add(pymunk.GrooveJoint(base, pb[body], (0.0, -half), (0.0, half), local(body, point)), 0.0)
            dr = _Drive(d.name, d, "groove", c, axis=axis, half_length=half)
            dr.set(float(d.law(np.array([0.0]))[0][0]))
            sim.drives.append(dr)
        else:
            raise ValueError(f"driver {d.name!r}: unknown target {d.target!r}")
    if not drive:  # motors at named joints (Model.actuators): their efforts, the engine's
        sim.actuators += [_actuator(model, Driver(a.name, ("joint", a.joint), None), pb, local) for a in model.actuators]
    return sim


def _paired_points(model: Model) -> set[tuple]:
    """The (body, point) targets driven in both x and y (one pivot drives each)."""
    x = {d.target[1:] for d in model.drivers if d.target[0] == "x"}
    return x & {d.target[1:] for d in model.drivers if d.target[0] == "y"}


def _actuator(model: Model, d: Driver, pb: dict, local) -> _Actuator:
    """The actuator of driver ``d`` (see :class:`_Actuator`)."""
    kind = d.target[0]
    frame = pb[FRAME]

    def body(name: str) -> pymunk.Body | None:
        b = pb[name]
        return None if b is frame and b.body_type != pymunk.Body.DYNAMIC else b

    if kind == "joint":
        jt = model.joint(d.target[1])
        if isinstance(jt, Revolute):
            return _Actuator(d.name, "torque", pb[jt.b], body(jt.a))
        if isinstance(jt, Prismatic):
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            return _Actuator(d.name, "axis", pb[jt.slider], body(jt.guide), local(jt.slider, jt.point_slider),
                             (float(ax[0]), float(ax[1])))
        raise ValueError(f"driver {d.name!r}: a gear pair cannot be driven")
    if kind == "angle":
        return _Actuator(d.name, "torque", pb[d.target[1]], None)
    if kind in ("x", "y"):
        name = d.target[1]
        point = model.body(name).point(d.target[2]) if len(d.target) > 2 else (0.0, 0.0)
        return _Actuator(d.name, "fixed_axis", pb[name], None, local(name, point),
                         (1.0, 0.0) if kind == "x" else (0.0, 1.0))
    raise ValueError(f"driver {d.name!r}: unknown target {d.target!r}")


def _gear_phase(jt: Gear, model: Model) -> float:
    """The phase exactly as the engine computes it (from the model's initial poses)."""
    if jt.phase is not None:
        return float(jt.phase)
    from ..model import pose_of_com

    th = {FRAME: 0.0}
    for n in (jt.a, jt.b, jt.carrier):
        if n != FRAME:
            th[n] = pose_of_com(model.body(n), model.initial[n])[2]
    return (th[jt.b] - th[jt.carrier]) - jt.ratio * (th[jt.a] - th[jt.carrier])


def _add_gear(sim, jt, pb, com, init_angle, model, angle_joint, add, is_static, gear_model, half, floor, m_ref, i_ref):
    phase = _gear_phase(jt, model)
    coeffs: dict[str, float] = {}
    for n, v in ((jt.b, 1.0), (jt.carrier, -1.0), (jt.a, -jt.ratio), (jt.carrier, jt.ratio)):
        coeffs[n] = coeffs.get(n, 0.0) + v
    moving = [n for n, k in coeffs.items() if k != 0.0 and not is_static(n)]
    if len(moving) <= 2:
        angle_joint(coeffs, phase)
        return
    if gear_model == "absolute":
        # the trap: theta_b - ratio theta_a = phase + (1 - ratio) theta_c(t = 0), carrier ignored
        c0 = init_angle[jt.carrier]
        angle_joint({jt.b: 1.0, jt.a: -jt.ratio}, phase + (1.0 - jt.ratio) * c0, absolute=True)
        sim.notes.append(f"gear {jt.name!r}: absolute GearJoint, carrier ignored")
        return
    if gear_model == "explicit":
        j, scale, offset = angle_joint({jt.b: 1.0, jt.a: -jt.ratio}, phase, 0.0, absolute=True)
        sim.carried.append(_CarriedGear(jt.name, j, scale, offset, pb[jt.carrier], 1.0 - jt.ratio))
        return
    if gear_model != "mesh":
        raise ValueError(f"unknown gear_model {gear_model!r}")
    # three moving bodies: a mesh on the carrier
    def centre(g: str) -> tuple[float, float] | None:
        for j in model.joints:
            if isinstance(j, Revolute):
                if j.a == jt.carrier and j.b == g:
                    return (j.point_a[0] - com[jt.carrier][0], j.point_a[1] - com[jt.carrier][1])
                if j.b == jt.carrier and j.a == g:
                    return (j.point_b[0] - com[jt.carrier][0], j.point_b[1] - com[jt.carrier][1])
        return None

    oa, ob = centre(jt.a), centre(jt.b)
    A, B, C = pb[jt.a], pb[jt.b], pb[jt.carrier]
    auxiliary = False
    if oa is None or ob is None or math.dist(oa, ob) < 1e-9 * half:
        # auxiliary light gears pinned to the carrier at virtual centres and locked to a and b
        auxiliary = True
        span = half / 100.0
        oa = (0.0, 0.0)
        ob = (span, 0.0)
        aux = []
        for g, o in ((jt.a, oa), (jt.b, ob)):
            gb = pb[g]
            body = pymunk.Body(floor * m_ref, floor * i_ref)
            body.center_of_gravity = (0.0, 0.0)
            body.angle = gb.angle
            w = _rot(C.angle, o)
            body.position = (C.position.x + w[0], C.position.y + w[1])
            vc = C.velocity_at_local_point(o)
            body.velocity = (vc.x, vc.y)
            body.angular_velocity = gb.angular_velocity
            sim.space.add(body)
            sim.auxiliary.append(body)
            add(pymunk.PivotJoint(C, body, o, (0.0, 0.0)))
            add(pymunk.GearJoint(gb, body, body.angle - gb.angle, 1.0))
            aux.append(body)
        A, B = aux
        sim.notes.append(f"gear {jt.name!r}: no carrier pivot for its gears, auxiliary gears used")
    groove = add(pymunk.GrooveJoint(A, B, (0.0, -half), (0.0, half), (0.0, 0.0)), 0.0)
    sim.meshes.append(
        _Mesh(jt.name, groove, A, B, C, pb[jt.a], pb[jt.b], oa, ob, float(jt.ratio), phase, half, auxiliary)
    )
