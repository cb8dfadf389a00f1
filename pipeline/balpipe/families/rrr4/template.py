"""Planar 4-RRR parallel manipulator (paper 001, Fig. 1), and its 1-, 2- and 3-RRR variants.

Geometry (Fig. 1): leg i (1..4) runs from the base pivot A_i = (a_i, b_i) through the elbow B_i
to the platform joint C_i; link l_i1 = A_iB_i at absolute angle theta_i1, link l_i2 = B_iC_i at
theta_i2. The platform (half width c5, half height d5, orientation theta5) carries C1..C4 at
(+c5, -d5), (-c5, -d5), (-c5, +d5), (+c5, +d5) in its frame, whose origin is the platform's
centre. A link's centre of mass is at (p_ij, q_ij): p along the link from its proximal joint, q
normal to it (left positive); the platform's at (p5, q5) from its centre. These are the body
frames of the model, so a body's first moments (m c_x, m c_y) are the paper's (m p, m q).

Legs can be left out (1-, 2-, 3-RRR); paper 001 notes that eq. 17 holds with a leg "taken out"
by giving it zero mass, which is a massless leg, kinematically still there.

Motion: the platform pose (x, y, theta5) of its centre moves on ``motion.law`` from
``motion.drive.platform.from`` to ``.to``; the actuated joints (default: the base joints A_i of
every leg, four motors for three degrees of freedom: redundant actuation, analysed with the
minimum-norm efforts) follow it by inverse kinematics. Elbow ``+1`` puts B_i on the counter-
clockwise side of A_iC_i.

Special kinematics (Sec. IV, Fig. 5), for a non-rotating platform: ``fig5a`` makes leg 4 a copy
of leg 1 with its links swapped (l41 = l12, l42 = l11, A4 = A1 + C4 - C1, the other elbow), so
l11 || l42 and l12 || l41, and leg 3 likewise of leg 2 (l31 = l22, l32 = l21); ``fig5b`` makes
legs 4 and 3 translated copies of legs 1 and 2 (l41 = l11, l42 = l12, A4 = A1 + C4 - C1, same
elbow), so l11 || l41, l12 || l42, l21 || l31, l22 || l32. Legs 3 and 4 then take their geometry
from legs 1 and 2 (the spec gives their masses; a length or pivot it gives must agree).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from ... import units
from ...mechanics.joint_laws import PoseJointLaw, body_point, dyad_rates
from ...mechanics.planar import bar_body, wrap_angle
from ...laws.drives import path_laws
from ...model import FRAME, Body, Driver, Law, Model, Revolute
from ...motion import law_for
from ...spec_parts import SpecFieldError, Strict
from ...units import Inertia, Length, Mass, PositiveLength, Sign

PLATFORM_PATH = ("motion", "drive", "platform")
LEGS = (1, 2, 3, 4)
CORNER_SIGNS = {1: (1.0, -1.0), 2: (-1.0, -1.0), 3: (-1.0, 1.0), 4: (1.0, 1.0)}


class RRRLink(Strict):
    """A bar link of a leg, frame at its proximal joint, x towards the distal joint."""

    length: PositiveLength | None = Field(
        None, description="l_ij, joint to joint (required unless the special kinematics derive it)"
    )
    mass: Mass = Field(description="m_ij, mass of the bare link")
    com: Length = Field(description="p_ij: centre of mass along the link from its proximal joint")
    com_offset: Length = Field(0.0, description="q_ij: centre of mass normal to the link, left positive")
    inertia: Inertia = Field(description="centroidal moment of inertia of the bare link")


class LegSpec(Strict):
    """Leg i: base pivot A_i, link l_i1 = A_iB_i, link l_i2 = B_iC_i."""

    pivot: tuple[Length, Length] | None = Field(
        None, description="A_i = (a_i, b_i) (required unless the special kinematics derive it)"
    )
    proximal: RRRLink = Field(description="link l_i1, A_iB_i")
    distal: RRRLink = Field(description="link l_i2, B_iC_i")
    elbow: Sign | None = Field(
        None, description="+1: B_i on the counter-clockwise side of A_iC_i (default +1, or derived)"
    )


class PlatformSpec(Strict):
    """The platform: C1..C4 at (+c5,-d5), (-c5,-d5), (-c5,+d5), (+c5,+d5) in its frame."""

    half_width: PositiveLength = Field(description="c5")
    half_height: PositiveLength = Field(description="d5")
    mass: Mass = Field(description="m5")
    com: tuple[Length, Length] = Field((0.0, 0.0), description="(p5, q5) from the platform's centre")
    inertia: Inertia = Field(0.0, description="centroidal moment of inertia")


class RRR4Mechanism(Strict):
    """Planar n-RRR parallel manipulator, n = 1..4 (paper 001's 4-RRR with legs removable)."""

    template: Literal["rrr4"] = Field(description="mechanism template")
    platform: PlatformSpec
    legs: dict[Literal[1, 2, 3, 4], LegSpec] = Field(
        description="legs by number i = 1..4 (leg i ends at C_i); leave legs out for 1-, 2-, 3-RRR"
    )
    kinematics: Literal["general", "fig5a", "fig5b"] = Field(
        "general",
        description="fig5a / fig5b: the special kinematics of Fig. 5 (legs 4, 3 derived from "
        "legs 1, 2 so that their links stay parallel for a non-rotating platform)",
    )
    actuators: list[str] | None = Field(
        None,
        description="actuated joints among A_i, B_i, C_i of the legs present (default: every A_i); "
        "at least three, more is redundant actuation (minimum-norm efforts)",
    )

    def drives(self) -> dict[str, str]:
        return {"platform": "pose"}

    def laws(self, motion) -> dict[str, Law]:
        """The platform pose's three laws: {"x", "y", "angle"} (on a path with law: path, see
        balpipe.laws)."""
        on_path = path_laws("platform", motion.drive.get("platform"), motion, 3)
        if on_path is not None:
            return dict(zip(("x", "y", "angle"), on_path))
        start, end = platform_poses(motion)
        return {k: law_for(motion, start[n], end[n]) for n, k in enumerate(("x", "y", "angle"))}


# --------------------------------------------------------------------------------------------
# Geometry


@dataclass(frozen=True)
class Leg:
    """Resolved geometry and mass data of one leg."""

    i: int
    A: tuple[float, float]
    l1: float
    l2: float
    elbow: int
    proximal: RRRLink
    distal: RRRLink


def corner(mech: RRR4Mechanism, i: int) -> np.ndarray:
    """C_i in the platform frame."""
    sx, sy = CORNER_SIGNS[i]
    return np.array([sx * mech.platform.half_width, sy * mech.platform.half_height])


def resolve_legs(mech: RRR4Mechanism) -> dict[int, Leg]:
    """Every present leg's pivot, lengths and elbow, with the special kinematics applied."""
    root = ("mechanism", "legs")
    if not mech.legs:
        raise SpecFieldError(root, "at least one leg is needed")
    derived: dict[int, tuple[int, bool]] = {}
    if mech.kinematics != "general":
        for i, src in ((4, 1), (3, 2)):
            if src not in mech.legs or i not in mech.legs:
                raise SpecFieldError(
                    root, f"kinematics {mech.kinematics} derives leg {i} from leg {src}: both are needed"
                )
            derived[i] = (src, mech.kinematics == "fig5a")
    out: dict[int, Leg] = {}
    for i in sorted(mech.legs):
        if i in derived:
            continue
        leg = mech.legs[i]
        for key, link in (("proximal", leg.proximal), ("distal", leg.distal)):
            if link.length is None:
                raise SpecFieldError(root + (i, key, "length"), f"leg {i}: the length of l_{i}{1 if key == 'proximal' else 2} is required")
        if leg.pivot is None:
            raise SpecFieldError(root + (i,), f"leg {i}: the base pivot A{i} (pivot) is required")
        out[i] = Leg(i, (float(leg.pivot[0]), float(leg.pivot[1])), leg.proximal.length, leg.distal.length,
                     leg.elbow or 1, leg.proximal, leg.distal)
    for i, (src, swap) in derived.items():
        s, leg = out[src], mech.legs[i]
        shift = corner(mech, i) - corner(mech, src)
        A = (s.A[0] + float(shift[0]), s.A[1] + float(shift[1]))
        l1, l2 = (s.l2, s.l1) if swap else (s.l1, s.l2)
        elbow = -s.elbow if swap else s.elbow
        path = root + (i,)
        for key, given, want in (("proximal", leg.proximal.length, l1), ("distal", leg.distal.length, l2)):
            if given is not None and abs(given - want) > 1e-9 * max(1.0, want):
                raise SpecFieldError(path + (key, "length"), f"kinematics {mech.kinematics} needs {want:.6g} m here (got {given:.6g} m)")
        if leg.pivot is not None and math.hypot(leg.pivot[0] - A[0], leg.pivot[1] - A[1]) > 1e-9:
            raise SpecFieldError(path + ("pivot",), f"kinematics {mech.kinematics} puts A{i} at ({A[0]:.6g}, {A[1]:.6g}) m")
        if leg.elbow is not None and leg.elbow != elbow:
            raise SpecFieldError(path + ("elbow",), f"kinematics {mech.kinematics} needs elbow {elbow:+d} here")
        out[i] = Leg(i, A, l1, l2, elbow, leg.proximal, leg.distal)
    return dict(sorted(out.items()))


def platform_poses(motion) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """motion.drive.platform's from/to as (x, y, theta5) in m, m, rad."""
    for name in motion.drive:
        if name != "platform":
            raise SpecFieldError(("motion", "drive", name), f"unknown drive {name!r}; the n-RRR drives: platform")
    if "platform" not in motion.drive:
        raise SpecFieldError(("motion", "drive"), "the n-RRR needs motion.drive.platform: {from: [x, y, angle], to: [x, y, angle]}")
    drive = motion.drive["platform"]
    for key in ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration"):
        if getattr(drive, key):
            raise SpecFieldError(PLATFORM_PATH + (key,), "boundary velocities are not supported for the platform pose; it starts and ends at rest")
    out = []
    for key, raw in (("from", drive.start), ("to", drive.end)):
        if not isinstance(raw, (list, tuple)) or len(raw) != 3:
            raise SpecFieldError(PLATFORM_PATH + (key,), f"expected a pose [x, y, angle], got {raw!r}")
        try:
            out.append(tuple(units.parse(v, d) for v, d in zip(raw, ("length", "length", "angle"))))
        except ValueError as exc:
            raise SpecFieldError(PLATFORM_PATH + (key,), str(exc)) from None
    return out[0], out[1]


@dataclass(frozen=True)
class LegMotion:
    """theta_i1, theta_i2 and their first two time derivatives, each (N,)."""

    th1: np.ndarray
    th2: np.ndarray
    w1: np.ndarray
    w2: np.ndarray
    a1: np.ndarray
    a2: np.ndarray


def corner_motion(mech: RRR4Mechanism, i: int, pose) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """C_i(t), its velocity and acceleration (N, 2) from the pose laws' values."""
    return body_point(pose, corner(mech, i))


def reach_margin(leg: Leg, C: np.ndarray) -> np.ndarray:
    """min(l1 + l2 - |A C|, |A C| - |l1 - l2|): positive inside the leg's workspace."""
    dist = np.hypot(C[:, 0] - leg.A[0], C[:, 1] - leg.A[1])
    return np.minimum(leg.l1 + leg.l2 - dist, dist - abs(leg.l1 - leg.l2))


def leg_motion(leg: Leg, C, Cd, Cdd, ref: tuple[float, float] | None = None) -> LegMotion:
    """Inverse kinematics of one leg, angles continuous about ``ref`` (their values at t = 0)."""
    d = C - np.asarray(leg.A)
    dist = np.hypot(d[:, 0], d[:, 1])
    cb = np.clip((leg.l1**2 + dist**2 - leg.l2**2) / (2 * leg.l1 * dist), -1.0, 1.0)
    th1 = np.arctan2(d[:, 1], d[:, 0]) + leg.elbow * np.arccos(cb)
    B = np.asarray(leg.A) + leg.l1 * np.stack([np.cos(th1), np.sin(th1)], axis=-1)
    th2 = np.arctan2(C[:, 1] - B[:, 1], C[:, 0] - B[:, 0])
    if ref is not None:
        th1 = ref[0] + wrap_angle(th1 - ref[0])
        th2 = ref[1] + wrap_angle(th2 - ref[1])
    c1, s1, c2, s2 = np.cos(th1), np.sin(th1), np.cos(th2), np.sin(th2)
    # l1 perp(e1) w1 + l2 perp(e2) w2 = C' and its derivative (det = l1 l2 sin(theta2 - theta1))
    det = leg.l1 * leg.l2 * (c1 * s2 - s1 * c2)
    w1, w2, a1, a2 = dyad_rates(leg.l1, c1, s1, leg.l2, c2, s2, det, (Cd[:, 0], Cd[:, 1]), (Cdd[:, 0], Cdd[:, 1]))
    return LegMotion(th1, th2, w1, w2, a1, a2)


@dataclass(frozen=True)
class JointLaw(PoseJointLaw):
    """The law of an actuated joint, by inverse kinematics of the platform pose's laws.

    ``kind``: "A" (theta_i1), "B" (theta_i2 - theta_i1) or "C" (theta5 - theta_i2). The link
    angles are taken within 180 deg of their values at t = 0 (``ref``), so that any set of times
    gives the same branch; :func:`build` checks that the motion stays inside that range."""

    mech: RRR4Mechanism
    leg: Leg
    kind: str
    pose: tuple[Law, Law, Law]
    ref: tuple[float, float]

    @property
    def coordinate(self) -> str:
        return self.kind

    def solve(self, t):
        pose = tuple(law(t) for law in self.pose)
        lm = leg_motion(self.leg, *corner_motion(self.mech, self.leg.i, pose), self.ref)
        ph = pose[2]
        return {"A": (lm.th1, lm.w1, lm.a1), "B": (lm.th2 - lm.th1, lm.w2 - lm.w1, lm.a2 - lm.a1),
                "C": (ph[0] - lm.th2, ph[1] - lm.w2, ph[2] - lm.a2)}


def check_workspace(mech: RRR4Mechanism, legs: dict[int, Leg], pose_laws, t: np.ndarray) -> None:
    """Every leg reaches its C_i at every sample, strictly (a stretched or folded leg is a
    singularity); otherwise a located error naming the time and the leg."""
    pose = tuple(law(t) for law in pose_laws)
    for i, leg in legs.items():
        C, _, _ = corner_motion(mech, i, pose)
        margin = reach_margin(leg, C)
        bad = np.flatnonzero(margin <= 1e-9 * (leg.l1 + leg.l2))
        if bad.size:
            k = int(bad[0])
            dist = math.hypot(C[k, 0] - leg.A[0], C[k, 1] - leg.A[1])
            x, y, ph = (float(p[0][k]) for p in pose)
            limit = (f"l{i}1 + l{i}2 = {leg.l1 + leg.l2:.4g} m" if dist >= leg.l1 + leg.l2 - 1e-9 * (leg.l1 + leg.l2)
                     else f"|l{i}1 - l{i}2| = {abs(leg.l1 - leg.l2):.4g} m")
            key = "from" if k == 0 else "to"
            raise SpecFieldError(
                PLATFORM_PATH + (key,),
                f"at t = {t[k]:.4g} s the platform pose (x = {x:.4g} m, y = {y:.4g} m, theta5 = "
                f"{math.degrees(ph):.4g} deg) is outside the workspace: leg {i} cannot reach C{i} = "
                f"({C[k, 0]:.4g}, {C[k, 1]:.4g}) m from A{i} = ({leg.A[0]:.4g}, {leg.A[1]:.4g}) m "
                f"(|A{i}C{i}| = {dist:.4g} m, limit {limit})",
            )


# --------------------------------------------------------------------------------------------
# Model


def platform_body(mech: RRR4Mechanism) -> Body:
    p = mech.platform
    pts = {f"C{i}": tuple(float(v) for v in corner(mech, i)) for i in LEGS}
    return Body("platform", p.mass, tuple(map(float, p.com)), p.inertia, pts,
                outline=("C1", "C2", "C3", "C4", "C1"), kind="platform")


def actuators(mech: RRR4Mechanism, legs: dict[int, Leg]) -> list[str]:
    path = ("mechanism", "actuators")
    names = mech.actuators if mech.actuators is not None else [f"A{i}" for i in legs]
    known = [f"{j}{i}" for i in legs for j in "ABC"]
    for k, n in enumerate(names):
        if n not in known:
            raise SpecFieldError(path + (k,), f"unknown joint {n!r}; the legs present have {', '.join(known)}")
        if names.index(n) != k:
            raise SpecFieldError(path + (k,), f"joint {n!r} is listed twice")
    if len(names) < 3:
        raise SpecFieldError(
            path if mech.actuators is not None else ("mechanism", "legs"),
            f"the platform has 3 degrees of freedom but only {len(names)} actuated joint(s) "
            f"({', '.join(names)}); list at least three in mechanism.actuators",
        )
    return list(names)


def build(mech: RRR4Mechanism, laws: dict, t: np.ndarray) -> Model:
    """The n-RRR as a model: links link{i}1, link{i}2, the platform; joints A_i (frame-link i1),
    B_i (link i1-link i2), C_i (link i2-platform); the actuated joints driven by inverse
    kinematics of the platform pose."""
    legs = resolve_legs(mech)
    pose_laws = (laws["x"], laws["y"], laws["angle"])
    check_workspace(mech, legs, pose_laws, np.asarray(t, dtype=float))
    t0 = np.zeros(1)
    pose0 = tuple(law(t0) for law in pose_laws)
    bodies, joints, initial, frame_points, refs = [], [], {}, {}, {}
    tt = np.asarray(t, dtype=float)
    pose_t = tuple(law(tt) for law in pose_laws)
    for i, leg in legs.items():
        lm = leg_motion(leg, *corner_motion(mech, i, pose0))
        th1, th2 = float(lm.th1[0]), float(lm.th2[0])
        refs[i] = (th1, th2)
        along = leg_motion(leg, *corner_motion(mech, i, pose_t))
        for n, th, ref in ((1, along.th1, th1), (2, along.th2, th2)):
            turn = np.abs(np.unwrap(np.concatenate([[ref], th])) - ref)[1:]
            if np.any(turn >= np.pi * (1 - 1e-9)):
                k = int(np.argmax(turn >= np.pi * (1 - 1e-9)))
                raise SpecFieldError(PLATFORM_PATH + ("to",), f"link l{i}{n} turns by 180 deg or more from its "
                                     f"initial angle (at t = {tt[k]:.4g} s); split the motion into shorter moves")
        B = (leg.A[0] + leg.l1 * math.cos(th1), leg.A[1] + leg.l1 * math.sin(th1))
        bodies += [bar_body(f"link{i}1", leg.proximal, f"A{i}", f"B{i}", leg.l1),
                   bar_body(f"link{i}2", leg.distal, f"B{i}", f"C{i}", leg.l2)]
        initial[f"link{i}1"] = (leg.A[0], leg.A[1], th1)
        initial[f"link{i}2"] = (B[0], B[1], th2)
        joints += [
            Revolute(f"A{i}", FRAME, f"link{i}1", leg.A, (0.0, 0.0)),
            Revolute(f"B{i}", f"link{i}1", f"link{i}2", (leg.l1, 0.0), (0.0, 0.0)),
            Revolute(f"C{i}", f"link{i}2", "platform", (leg.l2, 0.0), tuple(float(v) for v in corner(mech, i))),
        ]
        frame_points[f"A{i}"] = leg.A
    bodies.append(platform_body(mech))
    initial["platform"] = tuple(float(p[0][0]) for p in pose0)
    drivers = tuple(
        Driver(n, ("joint", n), JointLaw(mech, legs[int(n[1:])], n[0], pose_laws, refs[int(n[1:])]))
        for n in actuators(mech, legs)
    )
    name = f"{len(legs)}-RRR" + ("" if mech.kinematics == "general" else f" ({mech.kinematics})")
    return Model(name=name, bodies=tuple(bodies), joints=tuple(joints), drivers=drivers,
                 initial=initial, frame_points=frame_points)


def mass_parameters(model: Model) -> dict[str, float]:
    """The paper's named mass parameters of a model built by :func:`build` (attachments
    included): m_ij, m_ij p_ij, m_ij q_ij per link (keys ``m11``, ``m11p11``, ``m11q11``) and
    m5, m5 p5, m5 q5 for the platform. Legs absent from the model count as massless."""
    out: dict[str, float] = {}
    names = {b.name for b in model.bodies}
    for i in LEGS:
        for j in (1, 2):
            ij = f"{i}{j}"
            if f"link{ij}" in names:
                m, c, _ = model.body(f"link{ij}").mass_properties()
            else:
                m, c = 0.0, (0.0, 0.0)
            out[f"m{ij}"], out[f"m{ij}p{ij}"], out[f"m{ij}q{ij}"] = m, m * c[0], m * c[1]
    m, c, _ = model.body("platform").mass_properties()
    out["m5"], out["m5p5"], out["m5q5"] = m, m * c[0], m * c[1]
    return out


__all__ = ["RRR4Mechanism", "LegSpec", "RRRLink", "PlatformSpec", "build", "resolve_legs",
           "mass_parameters", "leg_motion", "corner"]


def _notation() -> dict:
    from ...notation import Sym, drive_table, names_table, ours, setting

    table = drive_table({"platform": Sym("(x, y, θ_5)", "platform pose: position of its centre and orientation θ_5")}, end_time="T")
    table.update({
        "mechanism.platform.half_width": Sym("c_5", "half width of the platform"),
        "mechanism.platform.half_height": Sym("d_5", "half height of the platform"),
        "mechanism.platform.mass": Sym("m_5", "mass of the platform"),
        "mechanism.platform.com": Sym("(p_5, q_5)", "centre of mass of the platform from its centre"),
        "mechanism.platform.inertia": ours("I_5", "centroidal moment of inertia of the platform"),
        "mechanism.legs.<i>.pivot": Sym("A_<i> = (a_<i>, b_<i>)", "base pivot of leg <i>"),
        "mechanism.legs.<i>.elbow": ours("σ_<i>", "leg <i>: +1 puts B_<i> on the counter-clockwise side of A_<i>C_<i>"),
        "mechanism.kinematics": ours("kinematics", "general, or the special kinematics of Fig. 5a / 5b"),
        "mechanism.actuators": setting("actuators", "actuated joints"),
        "motion.duration": ours("T", "duration of the motion"),
    })
    for j, name, a, b in ((1, "proximal", "A", "B"), (2, "distal", "B", "C")):
        p = f"mechanism.legs.<i>.{name}"
        table.update({
            f"{p}.length": Sym(f"l_{{<i>{j}}}", f"length {a}_<i>{b}_<i> of link l_{{<i>{j}}}"),
            f"{p}.mass": Sym(f"m_{{<i>{j}}}", f"mass of the bare link l_{{<i>{j}}}"),
            f"{p}.com": Sym(f"p_{{<i>{j}}}", f"centre of mass of link l_{{<i>{j}}} along the link from {a}_<i>"),
            f"{p}.com_offset": Sym(f"q_{{<i>{j}}}", f"centre of mass of link l_{{<i>{j}}} normal to the link (left positive)"),
            f"{p}.inertia": ours(f"I_{{<i>{j}}}", f"centroidal moment of inertia of link l_{{<i>{j}}}"),
        })
    # the model's names (Sec. II, Fig. 1): the paper calls link ij by its length l_ij ("links
    # l_i2", "l_32"), its angles θ_i1, θ_i2; an actuator at A_i drives θ_i1, one at B_i the
    # relative angle θ_i2 − θ_i1. Each leg named (patterns would also take "A1'").
    legs = range(1, 5)
    table.update(names_table(
        drivers={**{f"A{i}": Sym(f"θ_{{{i}1}}", f"angle of link {i}1, actuated at A_{i}") for i in legs},
                 **{f"B{i}": Sym(f"θ_{{{i}2}} − θ_{{{i}1}}", f"angle of link {i}2 relative to link {i}1, actuated at B_{i}")
                    for i in legs}},
        parts={f"link{i}{j}": Sym(f"l_{{{i}{j}}}", f"link {j} of leg {i}") for i in legs for j in (1, 2)},
        joints={f"{p}{i}": Sym(f"{p}_{i}", f"joint {p}_{i} of leg {i}") for p in "ABC" for i in legs},
    ))
    return table


#: Paper 001's symbols (Sec. II, Fig. 1) for this template's inputs.
NOTATION = _notation()
