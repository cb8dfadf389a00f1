"""Five-bar (planar 5R) template, plain or fixed-sequence with gear-coupled inputs (paper 004).

Geometry (Figs. 3-4): base pivots A1, A2; the input (proximal) links 1 = A1B1 and 2 = A2B2, the
distal links 3 = B1C and 4 = B2C, the gripper at the common joint C. All angles are absolute,
counter-clockwise from +x: theta1, theta2 of links 1, 2 and theta3, theta4 of links 3, 4.

Inverse kinematics (eqs. 1-8, written with the angle of A_jC so that the pivots may lie
anywhere): theta_j = atan2(C - A_j) + sigma_j beta_j with
cos beta_j = (l_pj^2 + |A_jC|^2 - l_dj^2) / (2 l_pj |A_jC|). sigma_j = +1 puts B_j on the
counter-clockwise side of A_jC; this is the sign of the square root in eq. 2, and the paper's
Fig. 3 has sigma1 = +1, sigma2 = -1.

Forward kinematics: C is the intersection of the circles (B1, l3) and (B2, l4) on the side of
B1B2 that the initial configuration fixes (the assembly mode, +1 when C is on the left of
B1 -> B2); it cannot change without passing through B1, C, B2 aligned.

Fixed-sequence version (Fig. 4, ``coupling`` given): gear 1' fixed on link 1 at A1, the idler 5
on the frame, gear 2' fixed on link 2 at A2, the three centres on A1A2, so that
w2 = (r1'/r2') w1 = U21 w1. From the gripper's initial and final positions: the input angles by
IK, their rotations, U21 = dtheta2 / dtheta1, r2' = r1' / U21 and r5 from
r1' + 2 r5 + r2' = |A1A2|. Only theta1 is driven (``motion.drive.gripper`` names the two
positions, ``motion.law`` the law of theta1); the gripper path between them is not straight.

Plain version (``coupling`` omitted): both inputs are actuated and the gripper follows the
straight segment on the motion law.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Literal

import numpy as np
from pydantic import Field

from ...diagnose import actuation
from ... import units
from ...laws.drives import path_laws
from ...mechanics.meshes import DEFAULT_PRESSURE_ANGLE, PressureAngle
from ...mechanics.planar import bar_body, cross, wrap_angle, world_point
from ...model import FRAME, Attachment, Body, Driver, Gear, Law, Model, Revolute
from ...motion import law_for
from ...laws.paths import PathComponent
from ...spec_parts import LinkSpec, SpecFieldError, Strict
from ...units import Inertia, Length, Mass, PositiveLength, Sign

GRIPPER_PATH = ("motion", "drive", "gripper")


class GearPart(Strict):
    """Mass properties of a gear whose radius the synthesis fixes."""

    mass: Mass = Field(0.0, description="mass of the gear (its centre is on its axis)")
    inertia: Inertia = Field(0.0, description="axial moment of inertia of the gear")


class CouplingSpec(Strict):
    """Gears 1' (on link 1 at A1), 5 (idler on the frame) and 2' (on link 2 at A2), centres
    collinear on A1A2: r1' + 2 r5 + r2' = |A1A2|. r2' and r5 are synthesised from r1'."""

    r1p: PositiveLength = Field(description="radius of gear 1' (the paper's r1')")
    gear_1p: GearPart = Field(GearPart(), description="gear 1', fixed on input link 1 at A1")
    gear_2p: GearPart = Field(GearPart(), description="gear 2', fixed on input link 2 at A2")
    gear_5: GearPart = Field(
        GearPart(), description="the idler gear 5 on the frame, as built before moment balancing"
    )
    pressure_angle: PressureAngle = Field(
        DEFAULT_PRESSURE_ANGLE, description="pressure angle of the meshes 1'-5 and 5-2' (default "
        "20 deg): the radial tooth force that the bearings A1, O5, A2 carry is |tangential| tan of it"
    )


class Pivots(Strict):
    A1: tuple[Length, Length] = Field(description="base pivot of input link 1")
    A2: tuple[Length, Length] = Field(description="base pivot of input link 2")


class FiveBarLinks(Strict):
    """Bar links; leg 2 repeats leg 1 unless ``proximal_2``/``distal_2`` are given."""

    proximal: LinkSpec = Field(description="input link 1, A1B1 (and link 2 unless proximal_2)")
    distal: LinkSpec = Field(description="distal link 3, B1C (and link 4 unless distal_2)")
    proximal_2: LinkSpec | None = Field(None, description="input link 2, A2B2, if it differs from link 1")
    distal_2: LinkSpec | None = Field(None, description="distal link 4, B2C, if it differs from link 3")


class FiveBarMechanism(Strict):
    """Planar 5R: two legs A_jB_jC from the base pivots to the gripper C (paper 004)."""

    template: Literal["five_bar"] = Field(description="mechanism template")
    pivots: Pivots = Field(description="base pivots A1, A2 (the paper: (-l0, 0), (+l0, 0))")
    links: FiveBarLinks
    working_modes: tuple[Sign, Sign] = Field(
        (1, -1),
        description="sigma1, sigma2: +1 puts B_j on the counter-clockwise side of A_jC (the sign "
        "of the root in eq. 2; the paper's Fig. 3 is [+1, -1])",
    )
    actuators: list[str] | None = Field(
        None, description="the motors' joints: default A1 and A2 for the plain 5R (their torques "
        "are reported), the driven A1 when coupled; [] reports the virtual gripper forces instead",
    )
    coupling: CouplingSpec | None = Field(
        None,
        description="gear coupling 1'-5-2' of the inputs (fixed-sequence manipulator, one "
        "actuator at A1); omit for the plain 5R with both inputs actuated",
    )

    def drives(self) -> dict[str, str]:
        return {"gripper": "point"}

    def legs(self) -> tuple[tuple[LinkSpec, LinkSpec], tuple[LinkSpec, LinkSpec]]:
        lk = self.links
        return (lk.proximal, lk.distal), (lk.proximal_2 or lk.proximal, lk.distal_2 or lk.distal)

    def laws(self, motion) -> dict[str, Law]:
        """Fixed-sequence: {"theta1": CoupledInput}; plain: {"gripper_x", "gripper_y"} (on a
        path when motion.drive.gripper has law: path, see balpipe.laws)."""
        on_path = path_laws("gripper", motion.drive.get("gripper"), motion, 2)
        if on_path is not None:
            if self.coupling is not None:
                raise SpecFieldError(GRIPPER_PATH + ("law",), "the fixed-sequence five-bar moves its gripper between "
                                     "two positions (from, to); a path needs the plain five-bar (no coupling)")
            return {"gripper_x": on_path[0], "gripper_y": on_path[1]}
        start, end = gripper_positions(motion)
        if self.coupling is None:
            return {
                "gripper_x": law_for(motion, start[0], end[0]),
                "gripper_y": law_for(motion, start[1], end[1]),
            }
        syn = synthesise(self, start, end)
        return {"theta1": CoupledInput(law_for(motion, syn.theta1i, syn.theta1f), syn)}


# --------------------------------------------------------------------------------------------
# Kinematics


def inverse_leg(A, lp: float, ld: float, C, sigma: int) -> np.ndarray:
    """theta_j for gripper positions C (..., 2); raises ValueError out of reach."""
    d = np.asarray(C, dtype=float) - np.asarray(A, dtype=float)
    dist = np.hypot(d[..., 0], d[..., 1])
    with np.errstate(divide="ignore", invalid="ignore"):
        cb = (lp**2 + dist**2 - ld**2) / (2 * lp * dist)
    if np.any(~(np.abs(cb) <= 1.0)):
        raise ValueError("out of reach")
    return np.arctan2(d[..., 1], d[..., 0]) + sigma * np.arccos(cb)


def reach_message(leg: int, A, lp: float, ld: float, C, sigma: int) -> str | None:
    """Why leg ``leg`` (1 or 2) cannot reach C, or None."""
    dist = math.hypot(C[0] - A[0], C[1] - A[1])
    name = (f"leg {leg} (links {leg} and {leg + 2} from A{leg} = ({A[0]:g}, {A[1]:g})) cannot reach "
            f"({C[0]:.4g}, {C[1]:.4g}) in working mode sigma{leg} = {sigma:+d} nor in the other")
    if dist >= lp + ld:
        return f"{name}: |A{leg}C| = {dist:.4g} m is not below |A{leg}B{leg}| + |B{leg}C| = {lp + ld:.4g} m"
    if dist <= abs(lp - ld):
        return f"{name}: |A{leg}C| = {dist:.4g} m is not above ||A{leg}B{leg}| - |B{leg}C|| = {abs(lp - ld):.4g} m"
    return None


def inverse_kinematics(mech: FiveBarMechanism, C, path: tuple = GRIPPER_PATH) -> tuple[float, float]:
    """(theta1, theta2) of a gripper position, in the spec's working modes (eqs. 1-8)."""
    out = []
    for j, ((lp, ld), A, sigma) in enumerate(
        zip(mech.legs(), (mech.pivots.A1, mech.pivots.A2), mech.working_modes), start=1
    ):
        msg = reach_message(j, A, lp.length, ld.length, C, sigma)
        if msg:
            raise SpecFieldError(path, msg + " (outside the workspace)")
        out.append(float(inverse_leg(A, lp.length, ld.length, C, sigma)))
    return out[0], out[1]


def elbows(mech: FiveBarMechanism, theta1, theta2) -> tuple[np.ndarray, np.ndarray]:
    (p1, _), (p2, _) = mech.legs()
    A1, A2 = np.asarray(mech.pivots.A1, float), np.asarray(mech.pivots.A2, float)
    t1, t2 = np.asarray(theta1, float), np.asarray(theta2, float)
    B1 = A1 + p1.length * np.stack([np.cos(t1), np.sin(t1)], axis=-1)
    B2 = A2 + p2.length * np.stack([np.cos(t2), np.sin(t2)], axis=-1)
    return B1, B2


def assembly_mode(mech: FiveBarMechanism, theta1: float, theta2: float, C) -> int:
    """+1 when C is on the left of B1 -> B2, -1 on the right."""
    B1, B2 = elbows(mech, theta1, theta2)
    e, c = B2 - B1, np.asarray(C, float) - B1
    return 1 if e[0] * c[1] - e[1] * c[0] > 0 else -1


def forward_kinematics(mech: FiveBarMechanism, theta1, theta2, assembly: int) -> tuple[np.ndarray, np.ndarray]:
    """Gripper positions (..., 2) and a flag array (True where the distal links close)."""
    (_, d1), (_, d2) = mech.legs()
    l3, l4 = d1.length, d2.length
    B1, B2 = elbows(mech, theta1, theta2)
    e = B2 - B1
    d = np.hypot(e[..., 0], e[..., 1])
    ok = (d < l3 + l4) & (d > abs(l3 - l4))
    dsafe = np.where(d > 0, d, 1.0)
    a = (l3**2 - l4**2 + d**2) / (2 * dsafe)
    h = np.sqrt(np.maximum(l3**2 - a**2, 0.0))
    u = e / dsafe[..., None]
    n = np.stack([-u[..., 1], u[..., 0]], axis=-1)
    return B1 + a[..., None] * u + assembly * h[..., None] * n, ok


# --------------------------------------------------------------------------------------------
# Gear-train synthesis


@dataclass(frozen=True)
class Synthesis:
    """The fixed-sequence design for one pair of gripper positions (Sec. III, Sec. VI)."""

    start: tuple[float, float]
    end: tuple[float, float]
    theta1i: float
    theta1f: float
    theta2i: float
    theta2f: float
    U21: float
    r1p: float
    r2p: float
    r5: float
    pivot_distance: float
    assembly: int
    path_deviation: float

    @property
    def dtheta1(self) -> float:
        return self.theta1f - self.theta1i

    @property
    def dtheta2(self) -> float:
        return self.theta2f - self.theta2i

    @property
    def U51(self) -> float:
        """w5 / w1 for the external mesh 1'-5."""
        return -self.r1p / self.r5

    def theta2(self, theta1):
        return self.theta2i + self.U21 * (np.asarray(theta1, float) - self.theta1i)


@dataclass(frozen=True)
class CoupledInput(Law):
    """The law of theta1, carrying the synthesis that the template and the method need."""

    law: Law
    synthesis: Synthesis

    def __call__(self, t):
        return self.law(t)


def gripper_positions(motion) -> tuple[tuple[float, float], tuple[float, float]]:
    """motion.drive.gripper's from/to as points in m."""
    for name in motion.drive:
        if name != "gripper":
            raise SpecFieldError(("motion", "drive", name), f"unknown drive {name!r}; the five-bar drives: gripper")
    if "gripper" not in motion.drive:
        raise SpecFieldError(("motion", "drive"), "the five-bar needs motion.drive.gripper: {from: [x, y], to: [x, y]}")
    drive = motion.drive["gripper"]
    for key in ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration"):
        if getattr(drive, key):
            raise SpecFieldError(
                GRIPPER_PATH + (key,),
                "boundary velocities and accelerations are not supported for the gripper (a "
                "point); the five-bar starts and ends at rest",
            )
    out = []
    for key, raw in (("from", drive.start), ("to", drive.end)):
        if not isinstance(raw, (list, tuple)) or len(raw) != 2:
            raise SpecFieldError(GRIPPER_PATH + (key,), f"expected a point [x, y] (lengths), got {raw!r}")
        try:
            out.append((units.parse(raw[0], "length"), units.parse(raw[1], "length")))
        except ValueError as exc:
            raise SpecFieldError(GRIPPER_PATH + (key,), str(exc)) from None
    return out[0], out[1]


def synthesise(mech: FiveBarMechanism, start, end) -> Synthesis:
    """Input angles, U21, gear radii and the gripper path check for one pair of positions."""
    th1i, th2i = inverse_kinematics(mech, start, GRIPPER_PATH + ("from",))
    th1f, th2f = inverse_kinematics(mech, end, GRIPPER_PATH + ("to",))
    d1, d2 = wrap_angle(th1f - th1i), wrap_angle(th2f - th2i)
    th1f, th2f = th1i + d1, th2i + d2
    to = GRIPPER_PATH + ("to",)
    if math.hypot(end[0] - start[0], end[1] - start[1]) == 0.0:
        raise SpecFieldError(to, "the final position equals the initial one: nothing to synthesise")
    if abs(d1) < 1e-9:
        raise SpecFieldError(
            to, f"input link 1 does not rotate between the two positions (dtheta2 = {d2:.4g} rad): "
            "the gripper cannot be moved by link 1 alone",
        )
    U21 = d2 / d1
    if abs(d2) < 1e-9 or U21 <= 0:
        raise SpecFieldError(
            to,
            f"the inputs rotate by dtheta1 = {d1:.4g} rad and dtheta2 = {d2:.4g} rad, so U21 = "
            f"{U21:.4g}; the train 1'-5-2' with one idler needs U21 > 0 (both inputs turning the "
            "same way): choose other positions or working modes",
        )
    A1, A2 = np.asarray(mech.pivots.A1, float), np.asarray(mech.pivots.A2, float)
    dist = float(np.hypot(*(A2 - A1)))
    r1p = mech.coupling.r1p
    r2p = r1p / U21
    r5 = (dist - r1p - r2p) / 2
    if not r5 > 0:
        raise SpecFieldError(
            ("mechanism", "coupling", "r1p"),
            f"gears 1' and 2' cannot fit between the pivots: r1' = {r1p:.4g} m and r2' = r1'/U21 = "
            f"{r2p:.4g} m (U21 = {U21:.4g}) leave r5 = (|A1A2| - r1' - r2')/2 = {r5:.4g} m for the "
            f"idler 5 (|A1A2| = {dist:.4g} m); r1' must be below |A1A2| U21/(1 + U21) = "
            f"{dist * U21 / (1 + U21):.4g} m",
        )
    asm = assembly_mode(mech, th1i, th2i, start)
    # the coupled path: theta2 follows theta1 through the gears
    th1 = np.linspace(th1i, th1f, 2001)
    th2 = th2i + U21 * (th1 - th1i)
    C, ok = forward_kinematics(mech, th1, th2, asm)
    (_, dl1), (_, dl2) = mech.legs()
    if not ok.all():
        k = int(np.argmin(ok))
        B1, B2 = elbows(mech, th1[k], th2[k])
        raise SpecFieldError(
            to,
            f"with the gear-coupled inputs the distal links cannot close the loop on the way: at "
            f"theta1 = {th1[k]:.4g} rad, theta2 = {th2[k]:.4g} rad, |B1B2| = "
            f"{float(np.hypot(*(B2 - B1))):.4g} m is outside [||B1C| - |B2C||, |B1C| + |B2C|] = "
            f"[{abs(dl1.length - dl2.length):.4g}, {dl1.length + dl2.length:.4g}] m",
        )
    if assembly_mode(mech, th1f, th2f, end) != asm or math.hypot(*(C[-1] - np.asarray(end))) > 1e-9 * max(1.0, dist):
        raise SpecFieldError(
            to,
            "the final position is in the other assembly mode of the distal links (C on the other "
            "side of B1B2): the gripper would have to pass through B1, C, B2 aligned",
        )
    S, E = np.asarray(start, float), np.asarray(end, float)
    dev = float(np.max(segment_distance(C, S, E)))
    return Synthesis(
        tuple(map(float, start)), tuple(map(float, end)), th1i, th1f, th2i, th2f, U21, r1p, r2p, r5, dist, asm, dev
    )


def segment_distance(P: np.ndarray, S: np.ndarray, E: np.ndarray) -> np.ndarray:
    """Distance of points P (..., 2) from the segment SE."""
    v = E - S
    u = np.clip(((P - S) @ v) / float(v @ v), 0.0, 1.0) if float(v @ v) > 0 else np.zeros(P.shape[:-1])
    return np.hypot(*(P - S - u[..., None] * v).T)


# --------------------------------------------------------------------------------------------
# Model


def build(mech: FiveBarMechanism, laws: dict, t: np.ndarray) -> Model:
    """The unbalanced five-bar: links 1-4 (+ gears 1', 2' on links 1, 2 and the idler 5 on the
    frame with its two meshes, carrier the frame, when coupled), driven at A1 (coupled) or at
    the gripper (plain)."""
    (p1, d1), (p2, d2) = mech.legs()
    A1, A2 = tuple(map(float, mech.pivots.A1)), tuple(map(float, mech.pivots.A2))
    if mech.coupling is not None:
        law = laws["theta1"]
        syn: Synthesis = law.synthesis
        th1, th2, C0 = syn.theta1i, syn.theta2i, syn.start
        cp = mech.coupling
        g1 = Attachment("gear 1'", cp.gear_1p.mass, (0.0, 0.0), cp.gear_1p.inertia, "gear", syn.r1p)
        g2 = Attachment("gear 2'", cp.gear_2p.mass, (0.0, 0.0), cp.gear_2p.inertia, "gear", syn.r2p)
        extra_links = ((g1,), (g2,))
    else:
        lx, ly = laws["gripper_x"], laws["gripper_y"]
        C = np.stack([lx(t)[0], ly(t)[0]], axis=1)
        _check_gripper_path(mech, C, t, isinstance(lx, PathComponent))
        C0 = (float(C[0, 0]), float(C[0, 1]))
        th1, th2 = inverse_kinematics(mech, C0, GRIPPER_PATH + ("from",))
        extra_links = ((), ())
    B1, B2 = elbows(mech, th1, th2)
    link1 = bar_body("link1", p1, "A1", "B1", p1.length, extra_links[0])
    link2 = bar_body("link2", p2, "A2", "B2", p2.length, extra_links[1])
    link3 = bar_body("link3", d1, "B1", "C", d1.length)
    link4 = bar_body("link4", d2, "B2", "C", d2.length)
    ang = lambda P, Q: math.atan2(Q[1] - P[1], Q[0] - P[0])  # noqa: E731
    initial = {
        "link1": (A1[0], A1[1], th1),
        "link2": (A2[0], A2[1], th2),
        "link3": (float(B1[0]), float(B1[1]), ang(B1, C0)),
        "link4": (float(B2[0]), float(B2[1]), ang(B2, C0)),
    }
    bodies = [link1, link2, link3, link4]
    joints = [
        Revolute("A1", FRAME, "link1", A1, (0.0, 0.0)),
        Revolute("A2", FRAME, "link2", A2, (0.0, 0.0)),
        Revolute("B1", "link1", "link3", (p1.length, 0.0), (0.0, 0.0)),
        Revolute("B2", "link2", "link4", (p2.length, 0.0), (0.0, 0.0)),
        Revolute("C", "link3", "link4", (d1.length, 0.0), (d2.length, 0.0)),
    ]
    frame_points = {"A1": A1, "A2": A2}
    if mech.coupling is not None:
        u = (np.asarray(A2) - np.asarray(A1)) / syn.pivot_distance
        O5 = tuple(float(v) for v in np.asarray(A1) + (syn.r1p + syn.r5) * u)
        g5 = mech.coupling.gear_5
        bodies.append(Body("gear5", g5.mass, (0.0, 0.0), g5.inertia, {"O5": (0.0, 0.0)}, radius=syn.r5, kind="gear"))
        initial["gear5"] = (O5[0], O5[1], 0.0)
        joints += [
            Revolute("O5", FRAME, "gear5", O5, (0.0, 0.0)),
            Gear("1'-5", "link1", "gear5", FRAME, -syn.r1p / syn.r5, None, syn.r1p, syn.r5, cp.pressure_angle),
            Gear("5-2'", "gear5", "link2", FRAME, -syn.r5 / syn.r2p, None, syn.r5, syn.r2p, cp.pressure_angle),
        ]
        frame_points["O5"] = O5
        drivers = (Driver("theta1", ("joint", "A1"), law),)
        name = "fixed-sequence five-bar"
    else:
        drivers = (
            Driver("gripper_x", ("x", "link3", "C"), laws["gripper_x"]),
            Driver("gripper_y", ("y", "link3", "C"), laws["gripper_y"]),
        )
        name = "five-bar"
    model = Model(
        name=name, bodies=tuple(bodies), joints=tuple(joints), drivers=drivers,
        initial=initial, frame_points=frame_points,
    )
    motors = mech.actuators if mech.actuators is not None else (["A1", "A2"] if mech.coupling is None else None)
    return actuation.with_actuators(model, motors, ("mechanism", "actuators"))


def _check_gripper_path(mech: FiveBarMechanism, C: np.ndarray, t: np.ndarray, on_path: bool = False) -> None:
    """Plain 5R: every point of the gripper's path reachable in the same working modes, and the
    distal links never aligned. ``on_path``: the drive is ``law: path`` (a problem is located at
    its ``path`` field), else a point-to-point drive (a straight path, located at its ``to``)."""
    where, what = (GRIPPER_PATH + ("path",), "the path") if on_path else (GRIPPER_PATH + ("to",), "the straight path")
    A = (mech.pivots.A1, mech.pivots.A2)
    th = []
    for j, ((lp, ld), Aj, sigma) in enumerate(zip(mech.legs(), A, mech.working_modes), start=1):
        dist = np.hypot(C[:, 0] - Aj[0], C[:, 1] - Aj[1])
        margin = np.minimum(lp.length + ld.length - dist, dist - abs(lp.length - ld.length))
        if np.any(margin <= 1e-9 * (lp.length + ld.length)):
            k = int(np.argmin(margin))
            raise SpecFieldError(
                where,
                f"{what} leaves the workspace at t = {t[k]:.4g} s, ({C[k, 0]:.4g}, "
                f"{C[k, 1]:.4g}): {reach_message(j, Aj, lp.length, ld.length, C[k], sigma) or f'leg {j} is stretched or folded (singular)'}",
            )
        th.append(inverse_leg(Aj, lp.length, ld.length, C, sigma))
    B1, B2 = elbows(mech, th[0], th[1])
    e, c = B2 - B1, C - B1
    side = cross(e, c)
    if np.any(np.sign(side) != np.sign(side[0])) or np.any(side == 0):
        k = int(np.argmax(np.sign(side) != np.sign(side[0])))
        raise SpecFieldError(
            where,
            f"{what} crosses a parallel singularity (B1, C, B2 aligned) near t = {t[k]:.4g} s",
        )


# --------------------------------------------------------------------------------------------
# Results for the report


def gripper_path(analysis, model: Model) -> np.ndarray:
    """The gripper C(t) (N, 2) from an analysis of any stage (distal end of link 3)."""
    k = analysis.names.index("link3")
    pose = analysis.frame_pose[:, k]
    cx, cy = model.body("link3").point("C")
    return world_point(pose, (cx, cy))


def input_angles(analysis) -> tuple[np.ndarray, np.ndarray]:
    """theta1(t), theta2(t) (Figs. 8-9) from an analysis."""
    q = analysis.frame_pose
    return q[:, analysis.names.index("link1"), 2], q[:, analysis.names.index("link2"), 2]


def gripper_path_fk(mech: FiveBarMechanism, synthesis: Synthesis, samples: int = 201) -> np.ndarray:
    """The coupled gripper path (samples, 2) by forward kinematics, independent of the law."""
    th1 = np.linspace(synthesis.theta1i, synthesis.theta1f, samples)
    C, _ = forward_kinematics(mech, th1, synthesis.theta2(th1), synthesis.assembly)
    return C


__all__ = [
    "FiveBarMechanism", "CouplingSpec", "GearPart", "Synthesis", "CoupledInput", "build",
    "synthesise", "inverse_kinematics", "forward_kinematics", "gripper_path", "gripper_path_fk",
    "input_angles",
]


def _notation() -> dict:
    from ...notation import Sym, drive_table, names_table, ours

    table = drive_table({"gripper": Sym("P", "gripper position (x, y)")}, end_time="T")
    # the model's names (Sec. II, Fig. 3): input angles θ_1, θ_2 at A_1, A_2 (the gear-coupled
    # five-bar drives θ_1 alone), links 1-4, gears 5-7, joints A_j, B_j
    table.update(names_table(
        drivers={"theta1": Sym("θ_1", "input angle of link 1 at A_1"),
                 "A1": Sym("θ_1", "input angle of link 1, its motor at A_1"),
                 "A2": Sym("θ_2", "input angle of link 2, its motor at A_2")},
        parts={**{f"link{j}": Sym(f"link {j}", ("input" if j < 3 else "distal") + f" link {j}") for j in range(1, 5)},
               **{f"gear{j}": Sym(f"gear {j}", f"gear {j}") for j in (5, 6, 7)}},
        joints={f"{p}{j}": Sym(f"{p}_{j}", f"joint {p}_{j}") for p in "AB" for j in (1, 2)},
    ))
    table.update({
        "mechanism.pivots.A1": Sym("A_1", "base pivot of input link 1, (−l_0, 0) in the paper"),
        "mechanism.pivots.A2": Sym("A_2", "base pivot of input link 2, (l_0, 0) in the paper"),
        "mechanism.links.proximal.length": Sym("l_1", "length A_1B_1 = A_2B_2 of the input links 1, 2"),
        "mechanism.links.proximal.mass": Sym("m_1 = m_2", "mass of each bare input link"),
        "mechanism.links.proximal.com": Sym("r_1 = r_2", "centre of mass S_j of the input links from A_j along A_jB_j"),
        "mechanism.links.proximal.com_offset": ours("e_1 = e_2", "offset of S_1, S_2 normal to the link"),
        "mechanism.links.proximal.inertia": Sym("I_1 = I_2", "axial moment of inertia of each bare input link"),
        "mechanism.links.distal.length": Sym("l_2", "length B_1P = B_2P of the distal links 3, 4"),
        "mechanism.links.distal.mass": Sym("m_3 = m_4", "mass of each bare distal link"),
        "mechanism.links.distal.com": Sym("r_3 = r_4", "centre of mass of the distal links from B_j along B_jP"),
        "mechanism.links.distal.com_offset": ours("e_3 = e_4", "offset of S_3, S_4 normal to the link"),
        "mechanism.links.distal.inertia": Sym("I_3 = I_4", "axial moment of inertia of each bare distal link"),
        "mechanism.links.proximal_2.length": Sym("l_1", "length A_2B_2 of input link 2"),
        "mechanism.links.proximal_2.mass": Sym("m_2", "mass of input link 2"),
        "mechanism.links.proximal_2.com": Sym("r_2", "centre of mass of link 2 from A_2"),
        "mechanism.links.proximal_2.com_offset": ours("e_2", "offset of S_2 normal to link 2"),
        "mechanism.links.proximal_2.inertia": Sym("I_2", "axial moment of inertia of link 2"),
        "mechanism.links.distal_2.length": Sym("l_2", "length B_2P of distal link 4"),
        "mechanism.links.distal_2.mass": Sym("m_4", "mass of distal link 4"),
        "mechanism.links.distal_2.com": Sym("r_4", "centre of mass of link 4 from B_2"),
        "mechanism.links.distal_2.com_offset": ours("e_4", "offset of S_4 normal to link 4"),
        "mechanism.links.distal_2.inertia": Sym("I_4", "axial moment of inertia of link 4"),
        "mechanism.actuators[0]": ours("τ_1", "first motor's joint (default A1): its torque is reported"),
        "mechanism.actuators[1]": ours("τ_2", "second motor's joint (default A2): its torque is reported"),
        "mechanism.working_modes": Sym("(σ_1, σ_2)", "working modes: +1 puts B_j on the counter-clockwise side of A_jP (eq. 2)"),
        "mechanism.coupling.r1p": Sym("r_{1'}", "pitch radius of gear 1' on input link 1"),
        "mechanism.coupling.gear_1p.mass": Sym("m_{1'}", "mass of gear 1' (on link 1 at A_1)"),
        "mechanism.coupling.gear_1p.inertia": Sym("I_{1'}", "axial moment of inertia of gear 1', before moment balancing"),
        "mechanism.coupling.gear_2p.mass": Sym("m_{2'}", "mass of gear 2' (on link 2 at A_2)"),
        "mechanism.coupling.gear_2p.inertia": Sym("I_{2'}", "axial moment of inertia of gear 2', before moment balancing"),
        "mechanism.coupling.gear_5.mass": Sym("m_5", "mass of the idler gear 5 on the frame"),
        "mechanism.coupling.gear_5.inertia": Sym("I_5", "axial moment of inertia of gear 5, before moment balancing"),
        "mechanism.coupling.pressure_angle": ours("α", "pressure angle of the meshes 1'-5 and 5-2'"),
        "motion.drive.gripper.start": Sym("P_i = (x_i, y_i)", "initial position of the gripper"),
        "motion.drive.gripper.end": Sym("P_f = (x_f, y_f)", "final position of the gripper"),
        "motion.duration": ours("T", "duration of the fifth-order law of θ_1 (the paper gives none)"),
    })
    return table


#: Paper 004's symbols (Sec. II, Figs. 3-6, Sec. VI) for this template's inputs.
NOTATION = _notation()
