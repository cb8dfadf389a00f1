"""The loads of a mechanism as affine maps of the parts a partial balancing may add (DESIGN.md,
"Partial balancing is a cone program").

At fixed geometry and motion every load is linear in each body's parameters p = (m, mx, my, J)
(mass, first moment and second moment about the body frame's origin;
:func:`.regressor.parameters` with ``angular=True``), and one engine analysis gives the matrices
(:class:`balpipe.balancing.mass_sweep.MassSweep`: shaking force and moment from the momentum regressors,
efforts and multipliers from the dynamics regressor). A counterweight k on body b adds its own
(m_k, s_k, J_k) to b's parameters (s_k = m_k c_k its first moment, J_k its second moment about b's
origin); a counter-rotating disc d adds its inertia I_d to its own body's J. So with the design
vector z (per counterweight m, sx, sy, J; per disc I)

    p(z) = p0 + G z,    load_i(z) = Y_i p(z) = Y_i p0 + (Y_i G) z      (every time sample i)

where p0 is the mechanism with the discs present at zero inertia. A joint's load is linear in the
multipliers (:func:`balpipe.engine.dynamics.joint_reactions`), so its map is that function applied to each
column of the multipliers' map: one evaluation per basis direction. Radial tooth forces of meshes
with pitch radii are not linear (|F_t| tan alpha) and are left out of the joint maps.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import numpy as np

from ...engine import analyse
from ...engine.dynamics import joint_reactions
from ...mechanics.loads import JointFriction
from ..mass_sweep import MassSweep
from ...model import Model, Prismatic, Revolute
from ..parts import add_counterweight
from ..regressor import parameters

JOINT_COMPONENTS = {"revolute": ("Fx", "Fy"), "prismatic": ("N",), "gear": ("T",)}

#: a part lighter than this fraction of the heaviest is no part: the interior-point solver stops at
#: its tolerance (1e-8 of the scaled problem), so a mass it leaves below that is its round-off
#: (a counterweight of 2e-8 kg beside one of 0.6 kg), not a part to build
NO_PART = 1e-7


@dataclass(frozen=True)
class PartVars:
    """A counterweight's variables z[col:col+4] = (m, sx, sy, J) on ``body``; ``kind`` 'point',
    'segment', 'polygon' (``points`` the vertices) or 'disc' (``points`` = (centre,), ``radius``)."""

    name: str
    body: str
    kind: str
    points: tuple[tuple[float, float], ...]
    radius: float
    max_mass: float | None
    col: int


@dataclass(frozen=True)
class DiscVars:
    """A counter-rotating disc's inertia z[col] (its own ``mass`` is fixed, on its axis)."""

    name: str
    mass: float
    max_inertia: float | None
    col: int


def time_weights(t: np.ndarray) -> np.ndarray:
    """The trapezoidal rule's weights of the samples ``t``, summing to 1: sum w_n f(t_n) is the time
    average of f over [t_0, t_N-1]. On a whole cycle sampled uniformly, both ends included, the end
    samples (one instant) count once together, so the average of a periodic f is exact for every
    harmonic below the sampling's Nyquist order (the plain mean of the samples counts that instant
    twice: an RMS-optimal counterweight off by ~1/N)."""
    t = np.asarray(t, dtype=float)
    if len(t) < 2 or t[-1] <= t[0]:
        return np.full(len(t), 1.0 / max(len(t), 1))
    d = np.diff(t)
    w = np.zeros(len(t))
    w[:-1] += d / 2
    w[1:] += d / 2
    return w / w.sum()


@dataclass
class Load:
    """One load over the samples: components ``A @ z + b`` (A (N, k, nz), b (N, k)); ``b0`` the
    unbalanced mechanism's (no parts, no discs); the value per sample is the components' norm.
    ``w`` the samples' time weights (:func:`time_weights`; uniform when not given): an RMS is the
    root of the time average of the squared value."""

    name: str
    unit: str
    A: np.ndarray
    b: np.ndarray
    b0: np.ndarray
    w: np.ndarray | None = None

    @property
    def weights(self) -> np.ndarray:
        return np.full(self.A.shape[0], 1.0 / self.A.shape[0]) if self.w is None else self.w

    def samples(self, z: np.ndarray) -> np.ndarray:
        """|load| per sample for the design z (or designs, rows of z: (D, N))."""
        z = np.asarray(z, dtype=float)
        v = np.einsum("nkj,...j->...nk", self.A, z) + self.b
        return np.sqrt(np.sum(v * v, axis=-1))

    def measure(self, kind: str, z: np.ndarray) -> np.ndarray | float:
        s = self.samples(z)
        return s.max(axis=-1) if kind == "peak" else np.sqrt((s * s) @ self.weights)

    def unbalanced(self, kind: str) -> float:
        s = np.sqrt(np.sum(self.b0 * self.b0, axis=-1))
        return float(s.max() if kind == "peak" else math.sqrt(float((s * s) @ self.weights)))


@dataclass
class Maps:
    """Every load of ``model`` (discs included, at zero inertia) as affine maps of z."""

    model: Model
    unbalanced: Model
    t: np.ndarray
    parts: list[PartVars]
    discs: list[DiscVars]
    loads: dict[str, Load]
    drivers: list[str]
    nz: int
    moving: dict[str, bool] = field(default_factory=dict)

    @property
    def fixed_mass(self) -> float:
        return float(sum(d.mass for d in self.discs))

    def load(self, load: str, actuator: str | None = None, joint: str | None = None) -> list[Load]:
        """The maps a term refers to: one, or every actuator's effort when ``actuator`` is None."""
        if load == "effort":
            names = [actuator] if actuator else self.drivers
            return [self.loads[f"effort:{d}"] for d in names]
        if load == "joint":
            return [self.loads[f"joint:{joint}"]]
        return [self.loads[load]]

    def added_mass(self, z: np.ndarray) -> float:
        return float(sum(z[p.col] for p in self.parts)) + self.fixed_mass

    def realised(self, z: np.ndarray, tiny: float | None = None) -> np.ndarray:
        """z as :meth:`design` builds it: no part below ``tiny`` x the largest mass, every
        J >= |s|^2 / m and every disc inertia >= 0 exactly (a solver meets them to its tolerance)."""
        z = np.asarray(z, dtype=float).copy()
        tiny = NO_PART if tiny is None else tiny
        big = max([abs(z[p.col]) for p in self.parts] + [1e-300])
        for p in self.parts:
            m, sx, sy, J = z[p.col : p.col + 4]
            if m <= tiny * big:
                z[p.col : p.col + 4] = 0.0
            else:
                z[p.col + 3] = max(J, (sx * sx + sy * sy) / m)
        for d in self.discs:
            z[d.col] = max(0.0, z[d.col])
        return z

    def design(self, z: np.ndarray, tiny: float | None = None) -> Model:
        """The model with the parts of design z: each counterweight of mass m at s / m with
        centroidal inertia J - |s|^2 / m (none below ``tiny`` x the largest mass), each disc's
        inertia."""
        z = np.asarray(z, dtype=float)
        tiny = NO_PART if tiny is None else tiny
        out = self.model
        big = max([abs(z[p.col]) for p in self.parts] + [1e-300])
        for p in self.parts:
            m, sx, sy, J = z[p.col : p.col + 4]
            if m <= tiny * big:
                continue
            c = (sx / m, sy / m)
            out = add_counterweight(out, p.body, p.name, m, c, max(0.0, J - m * (c[0] ** 2 + c[1] ** 2)))
        for d in self.discs:
            out = out.replace_body(replace(out.body(d.name), inertia=max(0.0, float(z[d.col]))))
        return out


def _basis(model: Model, parts: list[PartVars], discs: list[DiscVars], nz: int) -> np.ndarray:
    """G (4 nb, nz): where each design variable enters the parameters p."""
    names = [b.name for b in model.bodies]
    G = np.zeros((4 * len(names), nz))
    for p in parts:
        k = names.index(p.body)
        G[4 * k : 4 * k + 4, p.col : p.col + 4] = np.eye(4)
    for d in discs:
        G[4 * names.index(d.name) + 3, d.col] = 1.0
    return G


def _joint_maps(sweep: MassSweep) -> dict[str, np.ndarray]:
    """Y (N, k, np) of each joint's load components, from the multipliers' map column by column."""
    model, c = sweep.model, sweep.compiled
    cols = [joint_reactions(model, c, sweep.Lam[:, :, j], sweep.mesh_geo) for j in range(sweep.Lam.shape[2])]
    out = {}
    for jt in model.joints:
        kind = "revolute" if isinstance(jt, Revolute) else "prismatic" if isinstance(jt, Prismatic) else "gear"
        comps = JOINT_COMPONENTS[kind]
        out[jt.name] = np.stack([np.stack([col[jt.name][k] for k in comps], axis=1) for col in cols], axis=2)
    return out


def _load_offsets(sweep: MassSweep) -> dict[str, np.ndarray]:
    """The efforts and joint loads (N, k) that the model's loads add to every design (none
    without loads): the affine maps' constant terms beside Y p."""
    if not sweep.model.loads:
        return {}
    out = {f"effort:{d}": np.asarray(sweep.G0)[:, k: k + 1] for k, d in enumerate(sweep.drivers)}
    reactions = joint_reactions(sweep.model, sweep.compiled, np.asarray(sweep.Lam0), sweep.mesh_geo)
    for jt in sweep.model.joints:
        kind = "revolute" if isinstance(jt, Revolute) else "prismatic" if isinstance(jt, Prismatic) else "gear"
        out[f"joint:{jt.name}"] = np.stack([reactions[jt.name][k] for k in JOINT_COMPONENTS[kind]], axis=1)
    return out


def coulomb_friction(model: Model) -> list[str]:
    """The model's joint frictions with a Coulomb part (their names): their moment depends on the
    joint's reaction, so the loads are not affine in the parts' masses."""
    return [f.name for f in getattr(model, "loads", ()) if isinstance(f, JointFriction) and f.coefficient]


def _frame_offsets(model: Model, t: np.ndarray, gravity, moment_point) -> dict[str, np.ndarray]:
    """What the frame feels beyond the shaking load, (N, k): the loads from outside the machine
    (the frame force and moment less the shaking ones, the same in every design: they depend on
    the motion alone); nothing without loads."""
    if not getattr(model, "loads", ()):
        return {}
    an = analyse(model, t, gravity, moment_point)
    if an.frame_force is None:
        return {}
    return {"frame_force": an.frame_force - an.force, "frame_moment": (an.frame_moment - an.moment)[:, None]}


def build(model: Model, unbalanced: Model, t: np.ndarray, parts: list[PartVars], discs: list[DiscVars],
          gravity=(0.0, 0.0), moment_point=(0.0, 0.0)) -> Maps:
    """One engine analysis of ``model`` (the mechanism with the discs at zero inertia) and the
    affine maps of every load in the design variables, the applied loads included (efforts,
    joint loads and frame loads; raises ValueError for Coulomb friction, not affine)."""
    if coulomb_friction(model):
        raise ValueError(f"Coulomb friction ({', '.join(coulomb_friction(model))}) makes the efforts and reactions "
                         "depend on the reactions, not affinely on the parts' masses")
    nz = 4 * len(parts) + len(discs)
    sweep = MassSweep.build(model, t, gravity, moment_point)
    p0 = parameters(model, angular=True)
    disc_rows = [4 * [b.name for b in model.bodies].index(d.name) + j for d in discs for j in range(4)]
    p_unb = p0.copy()
    p_unb[disc_rows] = 0.0  # a massless, inertia-free disc transmits nothing: the unbalanced mechanism
    G = _basis(model, parts, discs, nz)
    Ys = {"shaking_force": (sweep.YF, "N"), "shaking_moment": (sweep.YM[:, None, :], "N m"),
          "frame_force": (sweep.YF, "N"), "frame_moment": (sweep.YM[:, None, :], "N m")}
    for k, d in enumerate(sweep.drivers):
        Ys[f"effort:{d}"] = (sweep.G[:, k : k + 1, :], "N or N m")
    for name, Y in _joint_maps(sweep).items():
        Ys[f"joint:{name}"] = (Y, "N or N m")
    fixed = _load_offsets(sweep)  # the model's loads: the same in every design (MassSweep.Lam0)
    fixed.update(_frame_offsets(model, t, gravity, moment_point))  # the outside loads on the frame
    w = time_weights(t)
    loads = {name: Load(name, unit, Y @ G, Y @ p0 + fixed.get(name, 0.0), Y @ p_unb + fixed.get(name, 0.0), w)
             for name, (Y, unit) in Ys.items()}
    moving = {}  # a body is at rest when its frame neither accelerates (m column less the weight) nor turns
    for k, b in enumerate(model.bodies):
        acc = sweep.YF[:, :, 4 * k] - np.asarray(gravity, dtype=float)
        moving[b.name] = bool(np.any(acc != 0) or np.any(sweep.YF[:, :, 4 * k + 1 : 4 * k + 3] != 0))
    return Maps(model, unbalanced, np.asarray(t, dtype=float), parts, discs, loads, list(sweep.drivers), nz, moving)
