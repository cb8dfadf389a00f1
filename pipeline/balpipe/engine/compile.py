"""Compilation of a :class:`~balpipe.model.Model` into constraint primitives (see the package
docstring): body indices, joint points relative to each centre of mass, constraint rows."""

from __future__ import annotations

from dataclasses import dataclass, field, replace
from typing import Any, Callable

import numpy as np

from ..mechanics.meshes import mesh_geometry
from ..model import FRAME, Gear, Joint, Law, Model, Prismatic, Revolute, pose_of_com

#: a body's index by name (``where`` names the joint or driver for the error)
Index = Callable[[str, str], int]
#: a point of a body in coordinates relative to its centre of mass
Local = Callable[[str, Any], np.ndarray]


def _perp(v: np.ndarray) -> np.ndarray:
    """Rotate vectors (..., 2) by +90 degrees."""
    out = np.empty_like(v)
    out[..., 0] = -v[..., 1]
    out[..., 1] = v[..., 0]
    return out


@dataclass
class _Coincident:
    owner: str
    i: int
    si: np.ndarray
    j: int
    sj: np.ndarray
    rows: int = 2


@dataclass
class _Angle:
    owner: str
    coeffs: list[tuple[int, float]]
    const: float = 0.0
    law: Law | None = None
    rows: int = 1


@dataclass
class _Projection:
    owner: str
    i: int
    a: np.ndarray
    si: np.ndarray
    j: int
    sj: np.ndarray
    const: float = 0.0
    law: Law | None = None
    rows: int = 1


@dataclass
class Compiled:
    """A model prepared for vectorised evaluation."""

    model: Model
    names: list[str]  # body names, index k+1 for body k (0 is the frame)
    mass: np.ndarray  # (nb,)
    inertia: np.ndarray  # (nb,)
    prims: list
    row_owner: list[str]  # joint/driver name per constraint row
    driver_rows: dict[str, int]
    joint_rows: dict[str, list[int]]
    q0: np.ndarray  # (3 nb,) initial guess
    condition: np.ndarray | None = None  # condition numbers of Phi_q along the last motion solved (None: shown regular)
    meshes: list = field(default_factory=list)  # _Mesh: gear pairs that pass tooth forces
    fast: Any = None  # the block-triangular path's data (:func:`.fastpath.prepare`), made once
    com_local: np.ndarray = field(default_factory=lambda: np.zeros((0, 2)))  # (nb, 2) centres of mass in the bodies' own frames (set by compile_model)
    frame: "Compiled | None" = None  # the frame model's (:func:`.fastpath.frame_motion`), made once
    keys: tuple | None = None  # (shape, numbers, law ids) of the model (:func:`.warmstart.model_keys`), made once
    dynamics: "Compiled | None" = None  # with actuators: the joints' rows and the actuators' (:func:`_actuated`)
    revolutes: Any = None  # the revolute joints' rows at once (:func:`.constraints.revolute_rows`), made once
    vectorised: Any = None  # its constraints by primitive type (:func:`.vectorised.vectorised_of`), made once

    @property
    def nb(self) -> int:
        return len(self.names)


def compile_model(model: Model) -> Compiled:
    """Index bodies, express joint points relative to each body's centre of mass and reduce
    joints and drivers to primitives."""
    names = [b.name for b in model.bodies]
    if FRAME in names:
        raise ValueError(f"'{FRAME}' is reserved for the fixed frame")
    if len(set(names)) != len(names):
        raise ValueError("body names must be unique")
    index = {FRAME: 0, **{n: k + 1 for k, n in enumerate(names)}}
    com = {FRAME: np.zeros(2)}
    mass, inertia = [], []
    for b in model.bodies:
        m, c, i = b.mass_properties()
        if m < 0 or i < 0:
            raise ValueError(f"body {b.name!r} has a negative mass or inertia")
        mass.append(m)
        inertia.append(i)
        com[b.name] = np.array(c, dtype=float)

    def idx(name: str, where: str) -> int:
        try:
            return index[name]
        except KeyError:
            raise ValueError(f"{where} refers to unknown body {name!r}") from None

    def local(name: str, p: Any) -> np.ndarray:
        return np.asarray(p, dtype=float) - com[name]

    init = {FRAME: (0.0, 0.0, 0.0)}
    for b in model.bodies:
        if b.name not in model.initial:
            raise ValueError(f"body {b.name!r} has no initial pose")
        init[b.name] = pose_of_com(b, model.initial[b.name])

    prims: list = []
    joints_by_name: dict[str, Joint] = {}
    for jt in model.joints:
        if jt.name in joints_by_name:
            raise ValueError(f"joint name {jt.name!r} is used twice")
        joints_by_name[jt.name] = jt
        if isinstance(jt, Revolute):
            prims.append(
                _Coincident(jt.name, idx(jt.a, jt.name), local(jt.a, jt.point_a), idx(jt.b, jt.name), local(jt.b, jt.point_b))
            )
        elif isinstance(jt, Prismatic):
            g, s = idx(jt.guide, jt.name), idx(jt.slider, jt.name)
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            prims.append(_Angle(jt.name, [(s, 1.0), (g, -1.0)], jt.angle))
            prims.append(
                _Projection(jt.name, g, _perp(ax), local(jt.guide, jt.point_guide), s, local(jt.slider, jt.point_slider))
            )
        elif isinstance(jt, Gear):
            ia, ib, ic = idx(jt.a, jt.name), idx(jt.b, jt.name), idx(jt.carrier, jt.name)
            coeffs: dict[int, float] = {}
            for k, v in ((ib, 1.0), (ic, -1.0), (ia, -jt.ratio), (ic, jt.ratio)):
                coeffs[k] = coeffs.get(k, 0.0) + v
            if jt.phase is None:
                th = {n: init[n][2] for n in (jt.a, jt.b, jt.carrier)}
                phase = (th[jt.b] - th[jt.carrier]) - jt.ratio * (th[jt.a] - th[jt.carrier])
            else:
                phase = jt.phase
            prims.append(_Angle(jt.name, [(k, v) for k, v in coeffs.items() if v != 0.0], phase))
        else:  # pragma: no cover - the Joint union is closed
            raise TypeError(jt)

    driver_rows: dict[str, int] = {}
    for d in model.drivers:
        start = len(prims)
        prims.append(_driver_primitive(d.name, d.target, d.law, joints_by_name, idx, local, model))
        driver_rows[d.name] = start

    row_owner: list[str] = []
    joint_rows: dict[str, list[int]] = {}
    prim_first_row = []
    for p in prims:
        prim_first_row.append(len(row_owner))
        joint_rows.setdefault(p.owner, []).extend(range(len(row_owner), len(row_owner) + p.rows))
        row_owner.extend([p.owner] * p.rows)
    driver_rows = {n: prim_first_row[k] for n, k in driver_rows.items()}

    q0 = np.array([v for n in names for v in init[n]], dtype=float)
    compiled = Compiled(
        model, names, np.array(mass), np.array(inertia), prims, row_owner, driver_rows, joint_rows, q0
    )
    compiled.meshes = _compile_meshes(model, idx, local, joint_rows)
    compiled.com_local = np.array([com[n] for n in names], dtype=float).reshape(-1, 2)
    compiled.dynamics = _actuated(compiled, joints_by_name, idx, local)
    return compiled


def _actuated(c: Compiled, joints: dict[str, Joint], idx: Index, local: Local) -> Compiled | None:
    """The system of the inverse dynamics when the model names actuators: the joints' own rows
    (same indices as in ``c``) followed by one row per actuator, the gradient of its joint
    coordinate (the primitive a driver of that joint would have). The drivers' rows are left
    out: they prescribe the motion but apply nothing. With B the actuators' rows,
    M q'' + Phi_j^T lambda_j - B^T tau = Q, i.e. the multipliers of this system with the
    actuators' multipliers -tau (DESIGN.md, "Real machines"). None without actuators."""
    model = c.model
    if not model.actuators:
        return None
    nd = len(model.drivers)
    joint_prims = c.prims[: len(c.prims) - nd]
    rows = sum(p.rows for p in joint_prims)
    prims = list(joint_prims)
    actuator_rows: dict[str, int] = {}
    for a in model.actuators:
        jt = joints.get(a.joint)
        if jt is None or isinstance(jt, Gear):
            what = "unknown joint" if jt is None else "a gear pair, not a revolute or prismatic joint"
            raise ValueError(f"actuator {a.name!r}: {a.joint!r} is {what}")
        if a.name in actuator_rows:
            raise ValueError(f"actuator name {a.name!r} is used twice")
        prims.append(_driver_primitive(a.name, ("joint", a.joint), None, joints, idx, local, model))
        actuator_rows[a.name] = rows + len(actuator_rows)
    owner = c.row_owner[:rows] + list(actuator_rows)
    joint_rows = {n: [r for r in rs if r < rows] for n, rs in c.joint_rows.items() if n in joints}
    return replace(c, prims=prims, row_owner=owner, driver_rows=actuator_rows, joint_rows=joint_rows,
                   fast=None, frame=None, keys=None, condition=None, revolutes=None)


@dataclass
class _Mesh:
    """A gear pair with pitch radii (see :mod:`balpipe.mechanics.meshes`), indexed for the engine."""

    name: str
    row: int  # the gear's constraint row
    ia: int
    ib: int
    ic: int
    sca: np.ndarray  # bearing centres O_a, O_b on the carrier (relative to its centre of mass)
    scb: np.ndarray
    pitch_a: float
    pitch_b: float
    side: float
    external: bool
    tan_alpha: float
    rows_a: list[int]  # rows of the bearings' revolute joints
    rows_b: list[int]
    sign_a: float  # +1 when the gear is body b of its bearing (its reaction is the force on the gear)
    sign_b: float


def _compile_meshes(model: Model, idx: Index, local: Local, joint_rows: dict[str, list[int]]) -> list[_Mesh]:
    out = []
    for jt in model.joints:
        if not isinstance(jt, Gear):
            continue
        geo = mesh_geometry(model, jt)
        if geo is None:
            continue
        ba, bb = geo.bearing_a, geo.bearing_b
        out.append(_Mesh(
            jt.name, joint_rows[jt.name][0], idx(jt.a, jt.name), idx(jt.b, jt.name), idx(jt.carrier, jt.name),
            local(jt.carrier, ba.centre_carrier), local(jt.carrier, bb.centre_carrier),
            geo.pitch_a, geo.pitch_b, geo.side, geo.external, float(np.tan(geo.pressure_angle)),
            joint_rows[ba.joint], joint_rows[bb.joint],
            1.0 if ba.gear_is_b else -1.0, 1.0 if bb.gear_is_b else -1.0,
        ))
    return out


def _driver_primitive(name: str, target: tuple[str, ...], law: Law | None, joints: dict[str, Joint], idx: Index,
                      local: Local, model: Model) -> _Angle | _Projection:
    """The primitive of a coordinate ``target`` (a driver's, with its law; an actuator's, without)."""
    kind = target[0]
    if kind == "joint":
        jt = joints.get(target[1])
        if jt is None:
            raise ValueError(f"driver {name!r} refers to unknown joint {target[1]!r}")
        if isinstance(jt, Revolute):
            return _Angle(name, [(idx(jt.b, name), 1.0), (idx(jt.a, name), -1.0)], 0.0, law)
        if isinstance(jt, Prismatic):
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            return _Projection(
                name, idx(jt.guide, name), ax, local(jt.guide, jt.point_guide),
                idx(jt.slider, name), local(jt.slider, jt.point_slider), 0.0, law,
            )
        raise ValueError(f"driver {name!r}: a gear pair cannot be driven, drive one of its bodies")
    body = target[1]
    b = idx(body, name)
    if kind == "angle":  # absolute angle: theta_b - theta_frame, so the reaction lands on the frame
        return _Angle(name, [(b, 1.0), (0, -1.0)], 0.0, law)
    if kind in ("x", "y"):
        point = model.body(body).point(target[2]) if len(target) > 2 else (0.0, 0.0)
        axis = np.array([1.0, 0.0]) if kind == "x" else np.array([0.0, 1.0])
        return _Projection(name, 0, axis, np.zeros(2), b, local(body, point), 0.0, law)
    raise ValueError(f"driver {name!r}: unknown target {target!r}")
