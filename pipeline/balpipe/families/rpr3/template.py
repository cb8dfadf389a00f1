"""3-RPR planar parallel manipulator template (paper 000, Sec. 2, Fig. 2(a)).

Geometry (the paper's, and ../shared/reference/PAPERS.md's reading): O is the circumcentre of
the base triangle A1A2A3, x along A1A2; A_i = Rb (cos a_i, sin a_i) with a_i = -150, -30,
90 deg. The platform's frame has its origin at P, the centroid of C1C2C3, and turns by phi:
C_i = P + R(phi) Rp (cos a_i, sin a_i) (platform parallel to the base at phi = 0).

Leg i (i = 1, 2, 3): the cylinder (link i1) pivots on the base at A_i; the piston (link i2, of
length L1 = |B_iC_i|) slides in it along u_i = (C_i - A_i) / |C_i - A_i| and is pinned to the
platform at C_i. Centres of mass on the leg axis: the cylinder's at A_i + c1 u_i (the paper's
d_AiS1i = r1 L1 u_i, r1 = 2 in Sec. 2), the piston's at B_i + c2 u_i (= C_i + (r2 - 1) L1 u_i).

Bodies: ``cyl{i}`` (frame origin A_i, x along u_i), ``piston{i}`` (origin C_i, x along u_i,
points ``B`` = (-L1, 0) and ``C`` = (0, 0)), ``platform`` (origin P, angle phi, points C1..C3
and ``P``). Joints: revolutes ``A{i}`` (frame-cylinder) and ``C{i}`` (piston-platform), the
prismatic pair ``B{i}`` (cylinder-piston, coordinate rho_i = |A_iC_i|).

Motion: the platform pose (x, y, phi) on the spec's law. The template drives the actuated joints
(prismatic: rho_i; revolute: the cylinder's angle theta_i) on laws obtained from the pose by
inverse kinematics, with exact first and second derivatives by the chain rule, so the engine
reports the actuator efforts at those joints: the axial force of each prismatic actuator, or
the torque of each revolute one. A pose out of the stroke, or a parallel singularity of the
chosen actuation (prismatic: the three leg lines concurrent, e.g. a platform homothetic to the
base, as at the paper's start pose phi = 0), is a located error naming the time (and the leg).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from typing import Literal

import numpy as np
from pydantic import Field

from ...mechanics.joint_laws import PoseJointLaw, body_point
from ...mechanics.planar import cross
from ...model import FRAME, Body, Driver, Law, Model, Prismatic, Revolute
from ...spec_parts import SpecFieldError, Strict
from ...units import Inertia, Length, Mass, PositiveLength

ANGLES_DEG = (-150.0, -30.0, 90.0)
DRIVE_PATH = ("motion", "drive")


class CylinderSpec(Strict):
    """Link i1, pivoted on the base at A_i."""

    mass: Mass = Field(description="mass of each cylinder (the paper's m1)")
    com: Length = Field(
        description="centre of mass along the leg from A_i towards C_i (the paper's r1 L1; "
        "negative: beyond A_i)"
    )
    inertia: Inertia = Field(description="centroidal inertia of each cylinder (I1)")


class PistonSpec(Strict):
    """Link i2, sliding in the cylinder, pinned to the platform at C_i."""

    length: PositiveLength = Field(description="|B_iC_i|, the paper's L1")
    mass: Mass = Field(description="mass of each piston (m2)")
    com: Length = Field(description="centre of mass along the leg from B_i towards C_i (r2 L1)")
    inertia: Inertia = Field(description="centroidal inertia of each piston (I2)")


class PlatformSpec(Strict):
    """The moving platform; its centre of mass is P, the centroid of C1C2C3."""

    mass: Mass = Field(description="mass mp")
    inertia: Inertia = Field(description="centroidal inertia Ip")


class Rpr3Mechanism(Strict):
    """3-RPR parallel manipulator: three legs A_i-B_i-C_i between an equilateral base and an
    equilateral platform (paper 000, Fig. 2)."""

    template: Literal["rpr3"] = Field(description="mechanism template")
    base_radius: PositiveLength = Field(description="Rb, circumradius of A1A2A3")
    platform_radius: PositiveLength = Field(description="Rp, circumradius of C1C2C3")
    cylinder: CylinderSpec
    piston: PistonSpec
    platform: PlatformSpec
    actuation: Literal["prismatic", "revolute"] = Field(
        "prismatic",
        description="actuated joint of each leg: the prismatic pair B_i (effort: axial force) or "
        "the base revolute A_i (effort: torque)",
    )
    stroke: tuple[PositiveLength, PositiveLength] | None = Field(
        None,
        description="range [min, max] of the leg length |A_iC_i| that the prismatic pair allows; "
        "default: from the piston's length (B_i may not pass A_i) to unbounded",
    )

    def drives(self) -> dict[str, str]:
        """The platform pose: x, y of P and the angle phi."""
        return {"x": "length", "y": "length", "phi": "angle"}


# --------------------------------------------------------------------------------------------
# Geometry and inverse kinematics


def unit(a: float) -> np.ndarray:
    return np.array([math.cos(a), math.sin(a)])


def base_points(Rb: float) -> np.ndarray:
    """(3, 2) A_i."""
    return np.array([Rb * unit(math.radians(a)) for a in ANGLES_DEG])


def platform_points(Rp: float) -> np.ndarray:
    """(3, 2) C_i in the platform frame (origin P)."""
    return np.array([Rp * unit(math.radians(a)) for a in ANGLES_DEG])


@dataclass(frozen=True)
class Pose:
    """Platform pose laws x(t), y(t), phi(t)."""

    x: Law
    y: Law
    phi: Law
    grid: np.ndarray | None = field(default=None, compare=False, repr=False)  # the analysis' time samples

    def joint_point(self, c: np.ndarray, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """C(t), C'(t), C''(t) (N, 2) of the platform point with local coordinates ``c``:
        C = P + R(phi) c, C' = P' + phi' J R c, C'' = P'' + phi'' J R c - phi'^2 R c
        (:func:`balpipe.mechanics.joint_laws.body_point`)."""
        return body_point((self.x(t), self.y(t), self.phi(t)), c)


def leg_coordinates(A: np.ndarray, C, Cd, Cdd) -> dict[str, np.ndarray]:
    """rho = |C - A| and theta = angle of C - A with their first two time derivatives:
    rho' = d.d'/rho, rho'' = (d'.d' + d.d'' - rho'^2)/rho, theta' = (d x d')/rho^2,
    theta'' = (d x d'')/rho^2 - 2 rho' theta'/rho (d = C - A)."""
    d = C - A
    rho = np.hypot(d[:, 0], d[:, 1])
    rhod = (d * Cd).sum(1) / rho
    rhodd = ((Cd * Cd).sum(1) + (d * Cdd).sum(1) - rhod**2) / rho
    th = np.unwrap(np.arctan2(d[:, 1], d[:, 0]))
    thd = cross(d, Cd) / rho**2
    thdd = cross(d, Cdd) / rho**2 - 2 * rhod * thd / rho
    return {"rho": (rho, rhod, rhodd), "theta": (th, thd, thdd)}


@dataclass(frozen=True)
class LegLaw(PoseJointLaw):
    """The law of leg i's actuated coordinate (``rho`` or ``theta``) from the platform pose by
    inverse kinematics, exact to second order (chain rule)."""

    pose: Pose
    A: tuple[float, float]
    c: tuple[float, float]
    coordinate: Literal["rho", "theta"]

    def solve(self, t):
        C, Cd, Cdd = self.pose.joint_point(np.asarray(self.c), t)
        return leg_coordinates(np.asarray(self.A), C, Cd, Cdd)


def pose_laws(laws: dict[str, Law]) -> Pose:
    missing = [k for k in ("x", "y", "phi") if k not in laws]
    if missing:
        raise SpecFieldError(
            DRIVE_PATH,
            f"the 3-RPR moves its platform: give motion.drive.x, .y and .phi (missing: {', '.join(missing)}; "
            "a constant coordinate has equal from and to)",
        )
    return Pose(laws["x"], laws["y"], laws["phi"])


def leg_lengths(mech: Rpr3Mechanism, pose: Pose, t: np.ndarray) -> np.ndarray:
    """(N, 3) rho_i(t)."""
    A, c = base_points(mech.base_radius), platform_points(mech.platform_radius)
    out = []
    for i in range(3):
        C = pose.joint_point(c[i], t)[0]
        out.append(np.hypot(C[:, 0] - A[i, 0], C[:, 1] - A[i, 1]))
    return np.stack(out, axis=1)


def check_workspace(mech: Rpr3Mechanism, pose: Pose, t: np.ndarray) -> np.ndarray:
    """rho_i(t), or a located error naming the first time and leg outside the stroke."""
    rho = leg_lengths(mech, pose, t)
    lo, hi = mech.stroke if mech.stroke is not None else (mech.piston.length, math.inf)
    bad = (rho <= lo) | (rho >= hi)
    if np.any(bad):
        k = int(np.argmax(bad.any(axis=1)))
        i = int(np.argmax(bad[k]))
        x, y, f = (float(law(t[k:k + 1])[0][0]) for law in (pose.x, pose.y, pose.phi))
        limit = (f"shorter than its minimum {lo:.4g} m" + ("" if mech.stroke else " (the piston's length: B_i would pass A_i)")
                 if rho[k, i] <= lo else f"longer than its maximum {hi:.4g} m")
        raise SpecFieldError(
            DRIVE_PATH,
            f"the platform pose at t = {t[k]:.4g} s (x = {x:.4g} m, y = {y:.4g} m, phi = "
            f"{math.degrees(f):.4g} deg) is outside the workspace: leg {i + 1} (A{i + 1}C{i + 1}) would be "
            f"{rho[k, i]:.4g} m, {limit}",
        )
    return rho


def leg_jacobian(mech: Rpr3Mechanism, pose: Pose, t: np.ndarray) -> np.ndarray:
    """(N, 3, 3) J with q' = J (x', y', phi') for the actuated coordinates q: rows
    [u_i, (R c_i) x u_i] for rho_i (prismatic) and [n_i, (R c_i) x n_i] / rho_i for theta_i
    (revolute), u_i the leg's direction, n_i its left normal."""
    A, c = base_points(mech.base_radius), platform_points(mech.platform_radius)
    f = pose.phi(t)[0]
    cf, sf = np.cos(f), np.sin(f)
    rows = []
    for i in range(3):
        rc = np.stack([cf * c[i, 0] - sf * c[i, 1], sf * c[i, 0] + cf * c[i, 1]], axis=1)
        C = pose.joint_point(c[i], t)[0]
        d = C - A[i]
        rho = np.hypot(d[:, 0], d[:, 1])
        u = d / rho[:, None]
        v = u if mech.actuation == "prismatic" else np.stack([-u[:, 1], u[:, 0]], axis=1) / rho[:, None]
        rows.append(np.stack([v[:, 0], v[:, 1], rc[:, 0] * v[:, 1] - rc[:, 1] * v[:, 0]], axis=1))
    return np.stack(rows, axis=1)


SINGULAR = 1e10  # condition number of the (dimensionless) leg Jacobian taken as a parallel singularity


def check_regular(mech: Rpr3Mechanism, pose: Pose, t: np.ndarray) -> np.ndarray:
    """Condition numbers of the leg Jacobian (rotation column scaled by Rp), or a located error
    where the actuated joints cannot control the platform (a parallel singularity: with
    prismatic actuation the three leg lines meet in one point, e.g. a platform homothetic to the
    base at phi = 0)."""
    J = leg_jacobian(mech, pose, t)
    J[:, :, 2] /= mech.platform_radius
    s = np.linalg.svd(J, compute_uv=False)
    cond = s[:, 0] / np.maximum(s[:, -1], 1e-300)
    bad = ~(cond < SINGULAR)
    if np.any(bad):
        k = int(np.argmax(bad))
        x, y, f = (float(law(t[k:k + 1])[0][0]) for law in (pose.x, pose.y, pose.phi))
        what = ("the three leg lines A_iC_i meet in one point" if mech.actuation == "prismatic"
                else "the normals to the legs at C_i meet in one point")
        raise SpecFieldError(
            ("mechanism", "actuation"),
            f"{mech.actuation} actuation is singular at t = {t[k]:.4g} s (x = {x:.4g} m, y = {y:.4g} m, "
            f"phi = {math.degrees(f):.4g} deg): {what}, so the actuators cannot control the platform "
            f"there (condition number {cond[k]:.2g}) and their efforts are unbounded; choose the other "
            "actuation or a motion away from this pose",
        )
    return cond


# --------------------------------------------------------------------------------------------
# Model


def build(mech: Rpr3Mechanism, laws: dict[str, Law], t: np.ndarray) -> Model:
    """The plain 3-RPR (Fig. 2(a)) driven at its actuated joints."""
    pose = replace(pose_laws(laws), grid=np.asarray(t, dtype=float))
    check_workspace(mech, pose, t)
    check_regular(mech, pose, t)
    A, c = base_points(mech.base_radius), platform_points(mech.platform_radius)
    L, cyl, pis, pl = mech.piston.length, mech.cylinder, mech.piston, mech.platform
    t0 = np.zeros(1)
    x0, y0, f0 = (float(law(t0)[0][0]) for law in (pose.x, pose.y, pose.phi))
    platform = Body(
        "platform", pl.mass, (0.0, 0.0), pl.inertia,
        {"P": (0.0, 0.0), **{f"C{i + 1}": (float(c[i, 0]), float(c[i, 1])) for i in range(3)}},
        outline=("C1", "C2", "C3", "C1"), kind="platform",
    )
    bodies, joints, drivers = [], [], []
    initial = {"platform": (x0, y0, f0)}
    for i in range(3):
        n = i + 1
        C, Cd, Cdd = pose.joint_point(c[i], t0)
        lc = leg_coordinates(A[i], C, Cd, Cdd)
        th0 = float(lc["theta"][0][0])
        bodies += [
            Body(f"cyl{n}", cyl.mass, (cyl.com, 0.0), cyl.inertia, {"A": (0.0, 0.0), "tip": (max(cyl.com, L), 0.0)},
                 outline=("A", "tip")),
            Body(f"piston{n}", pis.mass, (pis.com - L, 0.0), pis.inertia, {"B": (-L, 0.0), "C": (0.0, 0.0)},
                 outline=("B", "C"), kind="slider"),
        ]
        initial[f"cyl{n}"] = (float(A[i, 0]), float(A[i, 1]), th0)
        initial[f"piston{n}"] = (float(C[0, 0]), float(C[0, 1]), th0)
        joints += [
            Revolute(f"A{n}", FRAME, f"cyl{n}", (float(A[i, 0]), float(A[i, 1])), (0.0, 0.0)),
            Prismatic(f"B{n}", f"cyl{n}", f"piston{n}", (0.0, 0.0), (1.0, 0.0)),
            Revolute(f"C{n}", f"piston{n}", "platform", (0.0, 0.0), (float(c[i, 0]), float(c[i, 1]))),
        ]
        coordinate = "rho" if mech.actuation == "prismatic" else "theta"
        law = LegLaw(pose, (float(A[i, 0]), float(A[i, 1])), (float(c[i, 0]), float(c[i, 1])), coordinate)
        drivers.append(Driver(f"{coordinate}{n}", ("joint", f"B{n}" if coordinate == "rho" else f"A{n}"), law))
    return Model(
        name="3-RPR",
        bodies=tuple(bodies) + (platform,),
        joints=tuple(joints),
        drivers=tuple(drivers),
        initial=initial,
        frame_points={f"A{i + 1}": (float(A[i, 0]), float(A[i, 1])) for i in range(3)},
    )


def sample_times(model: Model) -> np.ndarray:
    """The analysis' time samples the template checked the motion on."""
    return pose_of(model).grid


def pose_of(model: Model) -> Pose:
    """The platform pose laws carried by a 3-RPR model's drivers."""
    for d in model.drivers:
        if isinstance(d.law, LegLaw):
            return d.law.pose
    raise ValueError(f"model {model.name!r} is not driven through a 3-RPR platform pose")


def prismatic_equivalent(mech: Rpr3Mechanism, pose: Pose, t: np.ndarray, torques: np.ndarray) -> np.ndarray:
    """(N, 3) axial forces that prismatic actuators would need for the same motion as revolute
    actuators exerting ``torques`` (N, 3): both give the same generalised force on the platform
    (virtual work; the passive joints do none), J_p^T f = J_r^T tau. NaN where J_p is singular."""
    Jr = leg_jacobian(mech.model_copy(update={"actuation": "revolute"}), pose, t)
    Jp = leg_jacobian(mech.model_copy(update={"actuation": "prismatic"}), pose, t)
    Q = np.einsum("nij,ni->nj", Jr, torques)
    scaled = Jp.copy()
    scaled[:, :, 2] /= mech.platform_radius
    s = np.linalg.svd(scaled, compute_uv=False)
    ok = s[:, 0] / np.maximum(s[:, -1], 1e-300) < SINGULAR
    out = np.full_like(Q, np.nan)
    out[ok] = np.linalg.solve(np.transpose(Jp[ok], (0, 2, 1)), Q[ok][..., None])[..., 0]
    return out


def _notation() -> dict:
    from ...notation import Sym, drive_table, names_table, ours, setting

    table = drive_table({"x": Sym("x", "x of the platform's point P"), "y": Sym("y", "y of P"),
                         "phi": Sym("φ", "platform angle, C_1C_2 to A_1A_2")})
    for d, s in (("x", "x"), ("y", "y"), ("phi", "φ")):
        table[f"motion.drive.{d}.start"] = Sym(f"{s}_0", f"{table[f'motion.drive.{d}.start'].text.split(':')[0]} at t = 0 (eq. 10)")
        table[f"motion.drive.{d}.end"] = Sym(f"{s}_f", f"{table[f'motion.drive.{d}.end'].text.split(':')[0]} at t = t_f (eq. 10)")
    table.update({
        "mechanism.base_radius": Sym("R_b", "circumradius of the base triangle A_1A_2A_3"),
        "mechanism.platform_radius": Sym("R_p", "circumradius of the platform triangle C_1C_2C_3"),
        "mechanism.cylinder.mass": Sym("m_1", "mass of each cylinder, link i1 (Sec. 2)"),
        "mechanism.cylinder.com": Sym("r_1 L_1", "centre of mass S_{1i} of the cylinder from A_i towards C_i"),
        "mechanism.cylinder.inertia": Sym("I_1", "axial moment of inertia of each cylinder"),
        "mechanism.piston.length": Sym("L_1", "length B_iC_i of the piston"),
        "mechanism.piston.mass": Sym("m_2", "mass of each piston, link i2"),
        "mechanism.piston.com": Sym("r_2 L_1", "centre of mass S_{2i} of the piston from B_i towards C_i"),
        "mechanism.piston.inertia": Sym("I_2", "axial moment of inertia of each piston"),
        "mechanism.platform.mass": Sym("m_p", "mass of the platform (centre of mass at P)"),
        "mechanism.platform.inertia": Sym("I_p", "axial moment of inertia of the platform"),
        "mechanism.actuation": setting("actuation", "actuated joint of each leg: prismatic B_i or revolute A_i"),
        "mechanism.stroke": ours("|A_iC_i|_{min}, |A_iC_i|_{max}", "range of the leg length the prismatic pair allows"),
        "motion.duration": Sym("t_f", "duration of the motion (eq. 10)"),
    })
    # the model's names (Sec. 2, Fig. 2): leg i's angle θ_i at A_i, its links i1 (cylinder) and
    # i2 (piston), joints A_i, B_i, C_i; three legs, each named (a pattern would also take A1')
    legs = range(1, 4)
    table.update(names_table(
        drivers={**{f"theta{i}": Sym(f"θ_{i}", f"angle of leg {i} at A_{i}, its actuated revolute joint") for i in legs},
                 **{f"rho{i}": ours(f"ρ_{i}", f"length |A_{i}C_{i}| of leg {i}, set by its actuated prismatic pair B_{i}")
                    for i in legs}},
        parts={**{f"cyl{i}": Sym(f"link {i}1", f"cylinder of leg {i}, pivoted at A_{i}") for i in legs},
               **{f"piston{i}": Sym(f"link {i}2", f"piston of leg {i}, pivoted on the platform at C_{i}") for i in legs}},
        joints={f"{p}{i}": Sym(f"{p}_{i}", f"joint {p}_{i} of leg {i}") for p in "ABC" for i in legs},
    ))
    return table


#: Paper 000's symbols (Sec. 2, Fig. 2; Sec. 2.1, eq. 10) for this template's inputs.
NOTATION = _notation()


#: the stages' line styles on a page (:attr:`balancing.base.Stage.style`, ``draw.figures.style``):
#: Figs. 4 and 8 of paper 000 draw the plain 3-RPR solid (style 0), the counterweights dashed
#: (style 1) and the counter-rotations grey (style 2); the added linkage, which the paper does not
#: plot, takes the next style (blue dash-dot)
STYLES = {"unbalanced": 0, "counterweights": 1, "counter_rotations": 2, "idler_loop": 3, "scott_russell": 3}
