"""Serial nR arm template (papers 002 and 003), with its explicit kinematics and dynamics.

Link k (k = 1..n) has its frame at its proximal joint J_k with x along the link to J_{k+1}
(the last link's distal end is the ``tip``); its centre of mass is ``com`` along and
``com_offset`` across the link (left positive). Joint angles: q1 is link 1's absolute angle from
+x, q_k (k > 1) the angle of link k relative to link k-1; the absolute angles are
theta_k = q1 + ... + q_k and the end-effector orientation is phi = theta_n (paper 003, eq. 10).

Drives (``motion.drive``): every joint ``q1`` .. ``qn`` on the motion law (joint torques are the
efforts of drivers ``q1`` .. ``qn``), or ``tip``: the tip on a straight line and, for n = 3, phi
from ``[x, y, phi]`` to ``[x, y, phi]`` (n = 2: ``[x, y]``), both on the motion law. A task-space
motion becomes joint laws by inverse kinematics with exact derivatives (chain rule:
q' = J^-1 x', q'' = J^-1 (x'' - J' q')), so the engine analyses it as any joint-driven arm.

The kinematics works on a *chain of link vectors*: point = base + sum_k R(theta_k) v_k. The tip is
the chain v_k = (l_k, 0); the total centre of mass is the chain
v_k = (m_k c_k + (sum_{i>k} m_i) (l_k, 0)) / m (paper 003, eq. 7 and the l_keq of eq. 8), so the
same inverse kinematics serves both (eqs. 8-10).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from pydantic import Field

from ... import units
from ...cache.content import MEMO
from ...mechanics.joint_laws import PoseJointLaw, body_point_xy, dyad_rates
from ...mechanics.planar import bar_body
from ...laws.drives import drive_laws, path_laws
from ...model import FRAME, Attachment, Body, Driver, Law, Model, Revolute
from ...motion import law_for
from ...spec_parts import DriveSpec, LinkSpec, SpecFieldError, Strict
from ...units import Angle, Inertia, Length, Mass, Sign

DRIVE = ("motion", "drive")


class Payload(Strict):
    """A payload carried by the last link (a point mass at the tip unless placed elsewhere)."""

    mass: Mass = Field(description="payload mass")
    inertia: Inertia = Field(0.0, description="centroidal inertia of the payload")
    position: tuple[Length, Length] | None = Field(
        None, description="position in the last link's frame (default: the tip, [length, 0])"
    )


class SerialArmMechanism(Strict):
    """Planar serial arm of n revolute joints, the first on the frame at ``base``."""

    template: Literal["serial_arm"] = Field(description="mechanism template")
    base: tuple[Length, Length] = Field((0.0, 0.0), description="position of joint 1 on the frame")
    links: list[LinkSpec] = Field(min_length=1, max_length=12, description="links 1..n from the base to the tip")
    payload: Payload | None = Field(None, description="payload on the last link")
    working_mode: Sign = Field(
        1,
        description="branch of the inverse kinematics of a task-space motion (tip or centre of "
        "mass): +1 is the '+' root of paper 003's eq. 8, the elbow turned clockwise "
        "(sin(q2) < 0 for centres of mass on the link axes), -1 the other",
    )
    initial: list[Angle] | None = Field(
        None, description="joint angles q1..qn of an arm without drives (a method plans its motion)"
    )

    def drives(self) -> dict[str, str]:
        out = {f"q{k + 1}": "angle" for k in range(len(self.links))}
        if len(self.links) in (2, 3):
            out["tip"] = "pose"
        return out

    def laws(self, motion) -> dict[str, Law]:
        """Joint laws: q1..qn directly, or from the tip's task-space motion (by inverse kinematics)."""
        n = len(self.links)
        names = list(motion.drive)
        known = self.drives()
        for name in names:
            if name not in known:
                raise SpecFieldError(DRIVE + (name,), f"unknown drive {name!r}; the {n}R arm drives: {', '.join(known)}")
        if "tip" in names:
            if len(names) > 1:
                raise SpecFieldError(DRIVE + ("tip",), "drive either the tip or the joints, not both")
            on_path = path_laws("tip", motion.drive["tip"], motion, 2 if n == 2 else 3)
            if on_path is not None:  # the tip on a path (balpipe.laws.paths), its angle with it for n = 3
                return {"tip": TaskMotion(on_path, "tip", DRIVE + ("tip",))}
            start, end = tip_poses(self, motion.drive["tip"])
            task = [law_for(motion, a, b) for a, b in zip(start, end)]
            return {"tip": TaskMotion(tuple(task), "tip", DRIVE + ("tip",))}
        out: dict[str, Law] = {}
        for name in names:
            d = motion.drive[name]
            if not isinstance(d, DriveSpec):  # constant speed, cam, fourier, table, cycle (balpipe.laws)
                out.update(drive_laws(name, d, known, motion))
                continue
            vals = []
            for key, raw in (("from", d.start), ("to", d.end)):
                try:
                    vals.append(units.parse(raw, "angle"))
                except ValueError as exc:
                    raise SpecFieldError(DRIVE + (name, key), str(exc)) from None
            out[name] = law_for(motion, vals[0], vals[1], d)
        if names and len(names) != n:
            missing = [q for q in known if q.startswith("q") and q not in names]
            raise SpecFieldError(DRIVE, f"drive every joint (missing: {', '.join(missing)}) or the tip")
        return out


def tip_poses(mech: SerialArmMechanism, drive) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``from``/``to`` of the tip drive in SI: (x, y, phi) for n = 3, (x, y) for n = 2."""
    n = len(mech.links)
    dims = ("length", "length", "angle")[: 2 if n == 2 else 3]
    out = []
    for key, raw in (("from", drive.start), ("to", drive.end)):
        if not isinstance(raw, (list, tuple)) or len(raw) != len(dims):
            shape = "[x, y, phi]" if n == 3 else "[x, y]"
            raise SpecFieldError(DRIVE + ("tip", key), f"expected the tip pose {shape}, got {raw!r}")
        try:
            out.append(tuple(units.parse(v, d) for v, d in zip(raw, dims)))
        except ValueError as exc:
            raise SpecFieldError(DRIVE + ("tip", key), str(exc)) from None
    return out[0], out[1]


# --------------------------------------------------------------------------------------------
# Kinematics of a chain of link vectors


@dataclass(frozen=True)
class Chain:
    """point(q) = base + sum_k R(theta_k) v_k, theta = cumsum(q). ``vectors`` (n, 2)."""

    base: tuple[float, float]
    vectors: tuple[tuple[float, float], ...]

    @property
    def n(self) -> int:
        return len(self.vectors)

    def terms(self, theta: np.ndarray) -> np.ndarray:
        """R(theta_k) v_k, shape (N, n, 2)."""
        v = np.asarray(self.vectors, dtype=float)
        c, s = np.cos(theta), np.sin(theta)
        return np.stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]], axis=-1)

    def point(self, q: np.ndarray) -> np.ndarray:
        q = np.atleast_2d(q)
        return np.asarray(self.base) + self.terms(np.cumsum(q, axis=1)).sum(axis=1)

    def jacobian(self, q: np.ndarray) -> np.ndarray:
        """d point / d q, (N, 2, n): column j = sum_{k >= j} perp(R(theta_k) v_k)."""
        w = self.terms(np.cumsum(np.atleast_2d(q), axis=1))
        tail = np.cumsum(w[:, ::-1], axis=1)[:, ::-1]  # sum over k >= j
        return np.stack([-tail[..., 1], tail[..., 0]], axis=1)

    def inverse(self, point: np.ndarray, phi: np.ndarray | None, mode: int) -> tuple[np.ndarray, np.ndarray]:
        """Joint angles (N, n) reaching ``point`` (N, 2) with theta_n = ``phi`` (n = 3; None for
        n = 2), in ``mode`` (+1: the '+' root of paper 003's eq. 8). Returns (q, margin): margin
        > 0 where the point is inside the reachable annulus, its size relative to the arm."""
        P = np.atleast_2d(np.asarray(point, dtype=float)) - np.asarray(self.base)
        v = np.asarray(self.vectors, dtype=float)
        if self.n == 3:
            phi = np.asarray(phi, dtype=float).reshape(-1)
            c, s = np.cos(phi), np.sin(phi)
            P = P - np.stack([c * v[2, 0] - s * v[2, 1], s * v[2, 0] + c * v[2, 1]], axis=-1)
        elif self.n != 2:
            raise ValueError("inverse kinematics needs a 2R or 3R chain")
        a, b = math.hypot(*v[0]), math.hypot(*v[1])
        d1, d2 = math.atan2(v[0, 1], v[0, 0]), math.atan2(v[1, 1], v[1, 0])
        r2 = P[:, 0] ** 2 + P[:, 1] ** 2
        r = np.sqrt(r2)
        margin = np.minimum(a + b - r, r - abs(a - b)) / (a + b)
        cg = np.clip((r2 - a * a - b * b) / (2 * a * b), -1.0, 1.0)
        gamma = -mode * np.arccos(cg)  # angle from the first equivalent vector to the second
        alpha1 = np.arctan2(P[:, 1], P[:, 0]) - np.arctan2(b * np.sin(gamma), a + b * np.cos(gamma))
        th1 = alpha1 - d1
        th2 = alpha1 + gamma - d2
        cols = [th1, th2 - th1]
        if self.n == 3:
            cols.append(phi - th2)
        return np.stack(cols, axis=1), margin


def tip_chain(arm: "ArmGeometry") -> Chain:
    return Chain(arm.base, tuple((float(L), 0.0) for L in arm.lengths))


def com_chain(arm: "ArmGeometry") -> Chain:
    """The total centre of mass as a chain (eq. 7): v_k = (m_k c_k + m_{>k} (l_k, 0)) / m."""
    m = np.asarray(arm.masses)
    M = float(m.sum())
    vec = []
    for k in range(arm.n):
        outer = float(m[k + 1:].sum())
        cx, cy = arm.coms[k]
        vec.append(((m[k] * cx + outer * arm.lengths[k]) / M, m[k] * cy / M))
    return Chain(arm.base, tuple(vec))


@dataclass(frozen=True)
class ArmGeometry:
    """What the explicit dynamics needs, read from a serial-arm model: per link (attachments
    included) the length, mass, centre of mass (link frame) and centroidal inertia."""

    base: tuple[float, float]
    lengths: tuple[float, ...]
    masses: tuple[float, ...]
    coms: tuple[tuple[float, float], ...]
    inertias: tuple[float, ...]

    @property
    def n(self) -> int:
        return len(self.lengths)

    @property
    def total_mass(self) -> float:
        return float(sum(self.masses))

    @classmethod
    def of(cls, model: Model) -> "ArmGeometry":
        """From a model built by this template (bodies link1..linkn, joints J1..Jn); every other
        body must be absent (gears make the arm a different mechanism)."""
        n = sum(1 for b in model.bodies if b.name.startswith("link"))
        if len(model.bodies) != n:
            raise ValueError("the explicit serial dynamics covers arms of links only (no extra bodies)")
        lengths, masses, coms, inertias = [], [], [], []
        for k in range(1, n + 1):
            b = model.body(f"link{k}")
            m, c, i = b.mass_properties()
            lengths.append(float(b.point(f"J{k + 1}" if k < n else "tip")[0]))
            masses.append(m)
            coms.append((float(c[0]), float(c[1])))
            inertias.append(i)
        base = model.joint("J1").point_a
        return cls((float(base[0]), float(base[1])), tuple(lengths), tuple(masses), tuple(coms), tuple(inertias))


# --------------------------------------------------------------------------------------------
# Task-space motion -> joint laws


@dataclass(frozen=True)
class TaskMotion:
    """A task-space motion: the laws of (x, y[, phi]) of a point of the arm (the ``tip`` or the
    centre of mass ``com``). ``path`` locates errors in the spec; ``name`` labels them."""

    laws: tuple[Law, ...]
    point: Literal["tip", "com"]
    path: tuple = DRIVE
    name: str = ""

    def values(self, t: np.ndarray):
        vals = [law(t) for law in self.laws]
        return tuple(np.stack([v[k] for v in vals], axis=-1) for k in range(3))


def absolute_motion(chain: Chain, x: np.ndarray, xd: np.ndarray, xdd: np.ndarray, mode: int, rows: bool = False):
    """Absolute link angles theta, theta', theta'' (N, n) of a task-space motion (x, y[, phi])
    with their exact derivatives, (margin, sin gamma) for the reach and singularity checks, and
    the angles' cosines and sines, (n, N) each, when this computed them already (every
    equivalent vector along its link, delta_k = 0: theta_k is alpha_k bit for bit, theta_3 is
    phi), else None: what :func:`absolute_state` would compute again.

    With phi = theta_3 given (n = 3) the first two links reach W = P - R(phi) v3, whose
    derivatives follow by the chain rule; then, with alpha_k = theta_k + delta_k the angles of the
    equivalent vectors (lengths a, b): W = a e(alpha1) + b e(alpha2), so
    [a perp(e1), b perp(e2)] alpha' = W' and the same matrix maps alpha'' to
    W'' + a alpha1'^2 e1 + b alpha2'^2 e2 (solved by Cramer's rule, det = a b sin(alpha2 - alpha1)).
    ``rows``: theta, theta', theta'' as (n, N) rows instead (the same values: what
    :func:`state_rows` takes).
    """
    v = np.asarray(chain.vectors, dtype=float)
    n = chain.n
    Wx, Wy = x[:, 0] - chain.base[0], x[:, 1] - chain.base[1]
    Wdx, Wdy, Wddx, Wddy = xd[:, 0], xd[:, 1], xdd[:, 0], xdd[:, 1]
    if n == 3:
        phi, phid, phidd = x[:, 2], xd[:, 2], xdd[:, 2]
        cf, sf = np.cos(phi), np.sin(phi)
        # W: the point -v3 of the last link's frame placed at the target, phi its angle
        (Wx, Wy), (Wdx, Wdy), (Wddx, Wddy) = body_point_xy(((Wx, Wdx, Wddx), (Wy, Wdy, Wddy), (phi, phid, phidd)), -v[2],
                                                           (cf, sf))
    elif n != 2:
        raise ValueError("task-space motions need a 2R or 3R chain")
    a, b = math.hypot(*v[0]), math.hypot(*v[1])
    d1, d2 = math.atan2(v[0, 1], v[0, 0]), math.atan2(v[1, 1], v[1, 0])
    r2 = Wx * Wx + Wy * Wy
    r = np.sqrt(r2)
    margin = np.minimum(a + b - r, r - abs(a - b)) / (a + b)
    cg = np.clip((r2 - a * a - b * b) / (2 * a * b), -1.0, 1.0)
    gamma = -mode * np.arccos(cg)
    sg = np.sin(gamma)
    al1 = np.arctan2(Wy, Wx) - np.arctan2(b * sg, a + b * cg)
    al2 = al1 + gamma
    c1, s1, c2, s2 = np.cos(al1), np.sin(al1), np.cos(al2), np.sin(al2)
    # det = a b sin(gamma)
    a1d, a2d, a1dd, a2dd = dyad_rates(a, c1, s1, b, c2, s2, a * b * sg, (Wdx, Wdy), (Wddx, Wddy))
    th = [al1 - d1, al2 - d2]
    thd = [a1d, a2d]
    thdd = [a1dd, a2dd]
    trig = None
    if d1 == 0.0 and d2 == 0.0:  # theta_k = alpha_k - 0.0 = alpha_k
        trig = ([c1, c2], [s1, s2])
    if n == 3:
        th.append(phi)
        thd.append(phid)
        thdd.append(phidd)
        if trig is not None:
            trig[0].append(cf), trig[1].append(sf)
    cos_sin = None if trig is None else (np.stack(trig[0]), np.stack(trig[1]))
    axis = 0 if rows else 1
    return np.stack(th, axis), np.stack(thd, axis), np.stack(thdd, axis), margin, sg, cos_sin


class JointSolution:
    """Joint angles, rates and accelerations (N, n) along a task-space motion, exact to
    round-off: q by inverse kinematics (eqs. 8-10), q' = J^-1 x', q'' = J^-1 (x'' - J' q')
    (:func:`absolute_motion`). ``th``, ``thd``, ``thdd``: the absolute angles and derivatives;
    ``trig``: their cosines and sines when :func:`absolute_motion` computed them, else None."""

    def __init__(self, chain: Chain, motion: TaskMotion, mode: int, t: np.ndarray, check: bool = True):
        t = np.asarray(t, dtype=float).reshape(-1)
        x, xd, xdd = motion.values(t)
        n = chain.n
        th, thd, thdd, margin, sg, self.trig = absolute_motion(chain, x, xd, xdd, mode)
        self.t, self.margin, self.det = t, margin, sg
        self.th, self.thd, self.thdd = th, thd, thdd
        if check:
            bad = np.flatnonzero(~(margin > 1e-9) | ~(np.abs(sg) > 1e-6))
            if bad.size:
                k = int(bad[0])
                what = motion.name or motion.point
                where = "the tip" if motion.point == "tip" else "the centre of mass"
                if margin[k] < -1e-12 or not np.isfinite(margin[k]):
                    msg = (f"trajectory {what}: at t = {t[k]:.4g} s {where} target ({x[k, 0]:.4g}, {x[k, 1]:.4g}) m is "
                           f"out of reach of the arm" + (f" with phi = {math.degrees(x[k, 2]):.4g} deg" if n == 3 else ""))
                else:  # on the boundary of the workspace or with a rank-deficient Jacobian
                    msg = (f"trajectory {what}: singular configuration at t = {t[k]:.4g} s ({where} at ({x[k, 0]:.4g}, "
                           f"{x[k, 1]:.4g}) m: the arm is stretched or folded, its Jacobian loses rank)")
                raise SpecFieldError(motion.path, msg)

    @property
    def q(self) -> np.ndarray:
        return np.diff(self.th, axis=1, prepend=0.0)

    @property
    def qd(self) -> np.ndarray:
        return np.diff(self.thd, axis=1, prepend=0.0)

    @property
    def qdd(self) -> np.ndarray:
        return np.diff(self.thdd, axis=1, prepend=0.0)


def task_jacobian(chain: Chain, q: np.ndarray) -> np.ndarray:
    """(N, n, n): the point's Jacobian, and d phi / d q = (1, ..., 1) for n = 3."""
    Jp = chain.jacobian(q)
    if chain.n == 2:
        return Jp
    return np.concatenate([Jp, np.ones((Jp.shape[0], 1, chain.n))], axis=1)


@dataclass(eq=False)
class JointLaw(PoseJointLaw):
    """Joint ``index`` of a task-space motion, as a scalar law for a driver. The laws of one
    motion share ``_cache``: one inverse-kinematics solution per time grid for every joint (a
    memo, left out of the caches' keys: :data:`balpipe.cache.content.MEMO`)."""

    chain: Chain
    motion: TaskMotion
    mode: int
    index: int
    _cache: dict = field(default_factory=dict, repr=False, compare=False, metadata={MEMO: True})

    @property
    def coordinate(self) -> int:
        return self.index

    def store(self) -> dict:
        return self._cache

    def solve(self, t):
        js = JointSolution(self.chain, self.motion, self.mode, t, check=False)
        q, qd, qdd = js.q, js.qd, js.qdd
        return {i: (q[:, i], qd[:, i], qdd[:, i]) for i in range(self.chain.n)}


def joint_laws(chain: Chain, motion: TaskMotion, mode: int) -> list[JointLaw]:
    """One law per joint sharing one inverse-kinematics solution (cached per time grid)."""
    cache: dict = {}
    return [JointLaw(chain, motion, mode, i, cache) for i in range(chain.n)]


# --------------------------------------------------------------------------------------------
# Model


def link_body(k: int, n: int, link: LinkSpec, payload: Payload | None) -> Body:
    distal = f"J{k + 1}" if k < n else "tip"
    att = ()
    if k == n and payload is not None and (payload.mass > 0 or payload.inertia > 0):
        pos = tuple(payload.position) if payload.position is not None else (link.length, 0.0)
        att = (Attachment("payload", payload.mass, pos, payload.inertia, "payload"),)
    return bar_body(f"link{k}", link, f"J{k}", distal, link.length, att)


def frame_poses(arm_base, lengths, q) -> dict[str, tuple[float, float, float]]:
    """Pose of each link frame for joint angles q (n,)."""
    x, y = float(arm_base[0]), float(arm_base[1])
    th = 0.0
    out = {}
    for k, (L, qk) in enumerate(zip(lengths, q), start=1):
        th += float(qk)
        out[f"link{k}"] = (x, y, th)
        x, y = x + L * math.cos(th), y + L * math.sin(th)
    return out


def with_joint_laws(model: Model, laws: list[Law], t0: float = 0.0) -> Model:
    """The arm ``model`` driven by ``laws`` (one per joint, J1..Jn), assembled at their values
    at ``t0``. Bodies other than the links keep their initial poses (the engine refines them)."""
    from dataclasses import replace

    n = len(laws)
    lengths = [model.body(f"link{k}").point(f"J{k + 1}" if k < n else "tip")[0] for k in range(1, n + 1)]
    q0 = [float(np.asarray(law(np.array([t0]))[0])[0]) for law in laws]
    initial = dict(model.initial)
    initial.update(frame_poses(model.joint("J1").point_a, lengths, q0))
    drivers = tuple(Driver(f"q{k}", ("joint", f"J{k}"), law) for k, law in enumerate(laws, start=1))
    return replace(model, drivers=drivers, initial=initial)


def build(mech: SerialArmMechanism, laws: dict, t: np.ndarray) -> Model:
    """The arm: links 1..n, joints J1 (frame) .. Jn, driven per joint (``q1`` .. ``qn``), by the
    tip's task-space motion (``tip``, joint laws from the inverse kinematics), or not at all
    (``motion.drive: {}``: a method plans the motion; the arm rests at ``initial``)."""
    n = len(mech.links)
    base = (float(mech.base[0]), float(mech.base[1]))
    bodies = tuple(link_body(k, n, lk, mech.payload) for k, lk in enumerate(mech.links, start=1))
    joints = [Revolute("J1", FRAME, "link1", base, (0.0, 0.0))]
    for k in range(2, n + 1):
        joints.append(Revolute(f"J{k}", f"link{k - 1}", f"link{k}", (mech.links[k - 2].length, 0.0), (0.0, 0.0)))
    model = Model(
        name=f"serial {n}R arm", bodies=bodies, joints=tuple(joints), drivers=(),
        initial=frame_poses(base, [lk.length for lk in mech.links], mech.initial or [0.0] * n),
        frame_points={"J1": base},
    )
    if not laws:
        if mech.initial is not None and len(mech.initial) != n:
            raise SpecFieldError(("mechanism", "initial"), f"give {n} joint angles, got {len(mech.initial)}")
        return model
    if "tip" in laws:
        motion: TaskMotion = laws["tip"]
        chain = tip_chain(ArmGeometry.of(model))
        JointSolution(chain, motion, mech.working_mode, t)  # located errors: out of reach, singular
        return with_joint_laws(model, joint_laws(chain, motion, mech.working_mode))
    return with_joint_laws(model, [laws[f"q{k}"] for k in range(1, n + 1)])


# --------------------------------------------------------------------------------------------
# Explicit dynamics (the fast path of the optimisers; tests check it against the engine)


@dataclass
class ArmState:
    """Centres of mass (x, y: (N, n)) with their accelerations, joint origins (N, n) and the
    absolute angular accelerations (N, n) of the links."""

    rx: np.ndarray
    ry: np.ndarray
    ax: np.ndarray
    ay: np.ndarray
    ox: np.ndarray
    oy: np.ndarray
    thdd: np.ndarray


def arm_state(arm: ArmGeometry, q: np.ndarray, qd: np.ndarray, qdd: np.ndarray) -> ArmState:
    """From joint angles (relative) and their derivatives."""
    return absolute_state(arm, np.cumsum(q, axis=1), np.cumsum(qd, axis=1), np.cumsum(qdd, axis=1))


def absolute_state(arm: ArmGeometry, th: np.ndarray, thd: np.ndarray, thdd: np.ndarray,
                   trig: tuple[np.ndarray, np.ndarray] | None = None) -> ArmState:
    """Positions and accelerations of the centres of mass from the absolute link angles (N, n):
    :func:`state_rows` on the angles' rows, its results back in (N, n) fields. ``trig``: the
    angles' cosines and sines (n, N) when known (:func:`absolute_motion`'s), not computed again."""
    w, acc = (np.ascontiguousarray(a.T) for a in (thd, thdd))
    rows = state_rows(arm, np.ascontiguousarray(th.T) if trig is None else None, w, acc, trig)
    rx, ry, ax, ay, ox, oy = (np.ascontiguousarray(a.T) for a in rows)
    return ArmState(rx, ry, ax, ay, ox, oy, thdd)


def state_rows(arm: ArmGeometry, th: np.ndarray | None, w: np.ndarray, acc: np.ndarray,
               trig: tuple[np.ndarray, np.ndarray] | None = None) -> tuple[np.ndarray, ...]:
    """The links' centres of mass, their accelerations and the proximal joints, (rx, ry, ax, ay,
    ox, oy) as (n, N) rows, from the absolute angles' rows ``th`` (or their cosines and sines
    ``trig``, then ``th`` may be None), rates ``w`` and accelerations ``acc`` (n, N):
    (R u)'' = theta'' perp(R u) - theta'^2 R u for every vector u fixed in a link, computed link
    by link on rows, so that every operation runs along the samples (paper 003's optimiser calls
    it thousands of times on three links)."""
    if trig is None:
        c, s = np.cos(th), np.sin(th)
    else:
        c, s = trig
    L = np.asarray(arm.lengths, dtype=float)[:, None]
    cm = np.asarray(arm.coms, dtype=float)
    cx, cy = cm[:, :1], cm[:, 1:]
    w2 = w * w
    segx, segy = c * L, s * L
    rcx, rcy = c * cx - s * cy, s * cx + c * cy
    sax, say = -acc * segy - w2 * segx, acc * segx - w2 * segy
    rax, ray = -acc * rcy - w2 * rcx, acc * rcx - w2 * rcy
    ox, oy = _proximal(segx, arm.base[0]), _proximal(segy, arm.base[1])
    oax, oay = _proximal(sax), _proximal(say)
    return ox + rcx, oy + rcy, oax + rax, oay + ray, ox, oy


def _proximal(seg: np.ndarray, start: float | None = None) -> np.ndarray:
    """Rows (n, N) of the links' proximal joints: row k is ``start`` plus the sum of the rows
    before k of ``seg`` (row 0: ``start``, or 0), added in order as np.cumsum adds them."""
    out = np.empty_like(seg)
    out[0] = 0.0 if start is None else start
    total = None
    for k in range(1, len(seg)):
        total = seg[0] if k == 1 else total + seg[k - 1]
        out[k] = total if start is None else start + total
    return out


def shaking_loads(arm: ArmGeometry, st: ArmState, gravity=(0.0, 0.0), point=(0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """F = sum m (g - r''), M_P = sum [(r - P) x m (g - r'') - I theta''] (paper 002, eqs. 1-2)."""
    m = np.asarray(arm.masses)
    fx, fy = m * (gravity[0] - st.ax), m * (gravity[1] - st.ay)
    M = ((st.rx - point[0]) * fy - (st.ry - point[1]) * fx) @ np.ones(arm.n) - st.thdd @ np.asarray(arm.inertias)
    return np.stack([fx.sum(axis=1), fy.sum(axis=1)], axis=1), M


def shaking_moment(arm: ArmGeometry, st: ArmState, gravity=(0.0, 0.0), point=(0.0, 0.0)) -> np.ndarray:
    """The moment of :func:`shaking_loads` alone (the optimiser's objective)."""
    return moment_rows(arm, st.rx.T, st.ry.T, st.ax.T, st.ay.T, st.thdd, gravity, point)


def moment_rows(arm: ArmGeometry, rx: np.ndarray, ry: np.ndarray, ax: np.ndarray, ay: np.ndarray,
                thdd: np.ndarray, gravity=(0.0, 0.0), point=(0.0, 0.0), grids: int = 1) -> np.ndarray:
    """:func:`shaking_moment` from the centres of mass and their accelerations as (n, N) rows
    (:func:`state_rows`'s) and the angular accelerations ``thdd`` (N, n). ``grids``: the samples
    are that many grids of equal length one after the other (several motions at once: the
    optimiser's points), each grid's moment the same bits as alone (a matrix-vector product
    rounds a row as its place in the product makes it: the inertia term is computed per grid; the
    sum over the links rounds every row alike)."""
    m = np.asarray(arm.masses)[:, None]
    fx, fy = m * (gravity[0] - ax), m * (gravity[1] - ay)
    inertias = np.asarray(arm.inertias)
    inertia = thdd @ inertias if grids == 1 else np.concatenate([part @ inertias for part in np.split(thdd, grids)])
    return np.ascontiguousarray(((rx - point[0]) * fy - (ry - point[1]) * fx).T) @ np.ones(arm.n) - inertia


def joint_torques(arm: ArmGeometry, st: ArmState, gravity=(0.0, 0.0)) -> np.ndarray:
    """tau_j = sum_{k >= j} [(r_k - O_j) x m_k (r_k'' - g) + I_k theta_k''] (virtual work), (N, n):
    :func:`torques_rows` on the state's rows."""
    return torques_rows(arm, (st.rx.T, st.ry.T, st.ax.T, st.ay.T, st.ox.T, st.oy.T), st.thdd, gravity)


def torques_rows(arm: ArmGeometry, rows: tuple[np.ndarray, ...], thdd: np.ndarray, gravity=(0.0, 0.0)) -> np.ndarray:
    """:func:`joint_torques` from :func:`state_rows`'s (rx, ry, ax, ay, ox, oy) rows (n, N) and the
    angular accelerations ``thdd`` (N, n): the links' terms added in order, as numpy sums a row of
    fewer than eight (the 3R arm's, tested), and the inertia term the same matrix-vector product
    on ``thdd``'s columns."""
    rx, ry, ax, ay, ox, oy = rows
    m, I = np.asarray(arm.masses)[:, None], np.asarray(arm.inertias)
    fx, fy = m * (ax - gravity[0]), m * (ay - gravity[1])
    out = np.empty(thdd.shape)
    for j in range(arm.n):
        terms = (rx[j:] - ox[j]) * fy[j:] - (ry[j:] - oy[j]) * fx[j:]
        total = terms[0]
        for term in terms[1:]:
            total = total + term
        out[:, j] = total + thdd[:, j:] @ I[j:]
    return out


def notation(mech: SerialArmMechanism) -> dict:
    """Symbols of an n-link arm's inputs: paper 003's for the 3R arm (joints O, A, B, tip C:
    l_OA, l_AB, l_BC; r_i, m_i, I_i; q_i), the same pattern with l_i for other arms (paper 002's
    method renames them as that paper does)."""
    from ...notation import Sym, drive_table, names_table, ours

    n = len(mech.links)
    joints = "OABC" if n == 3 else None
    table = drive_table({f"q{k}": Sym(f"q_{k}", f"angle of joint {k}") for k in range(1, n + 1)}, end_time="t_f")
    table.update(drive_table({"tip": Sym("(x, y, φ)", "tip pose: position and orientation of the last link")}, end_time="t_f"))
    for k in range(1, n + 1):
        p = f"mechanism.links[{k - 1}]"
        length = f"l_{{{joints[k - 1]}{joints[k]}}}" if joints else f"l_{k}"
        table.update({
            f"{p}.length": Sym(length, f"length of link {k}, joint {k} to joint {k + 1}" if k < n else f"length of link {k}, joint {k} to the tip"),
            f"{p}.mass": Sym(f"m_{k}", f"mass of link {k}"),
            f"{p}.com": Sym(f"r_{k}", f"distance of link {k}'s centre of mass S_{k} from joint {k}, along the link"),
            f"{p}.com_offset": ours(f"e_{k}", f"offset of S_{k} normal to link {k}"),
            f"{p}.inertia": Sym(f"I_{k}", f"axial moment of inertia of link {k} about S_{k}"),
        })
        table[f"mechanism.initial[{k - 1}]"] = ours(f"q_{k}(0)", f"angle of joint {k} of an arm without drives")
    table.update({
        "mechanism.base": (Sym("O", "joint O of link 1 on the frame") if joints
                           else ours("A", "position of joint 1 on the frame")),
        "mechanism.payload.mass": Sym("m_p", "mass of the payload"),
        "mechanism.payload.inertia": ours("I_p", "centroidal inertia of the payload"),
        "mechanism.payload.position": ours("r_p", "position of the payload in the last link's frame"),
        "mechanism.working_mode": Sym("±", "branch of the inverse kinematics (+1: the '+' root of paper 003's eq. 8)"),
        "motion.duration": Sym("t_f", "duration of the motion"),
    })
    # the model's names: drivers q_k (joint k's angle), links k, and paper 003's joints O, A, B
    table.update(names_table(
        drivers={f"q{k}": Sym(f"q_{k}", f"angle of joint {k}") for k in range(1, n + 1)},
        parts={f"link{k}": Sym(f"link {k}", f"link {k} of the arm") for k in range(1, n + 1)},
        joints={f"J{k}": Sym(joints[k - 1], f"joint {joints[k - 1]}, joint {k} of the arm") for k in range(1, n + 1)}
        if joints else {},
    ))
    return table
