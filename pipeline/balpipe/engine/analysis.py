"""The engine's result, :class:`Analysis`, and :func:`analyse`: kinematics, inverse dynamics and
both routes to the shaking loads."""

from __future__ import annotations

import weakref
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from ..cache.content import MEMO
from ..mechanics.planar import cross
from ..model import Model
from ..runtime.allocator import keep_freed_memory
from . import fastpath, shared, structure
from .compile import Compiled, compile_model
from .constraints import with_frame
from .dynamics import joint_reactions, solve_multipliers, radial_tooth_loads, tooth_rows, actuation_condition
from .conditioning import motion_peak
from .errors import AnalysisError
from .kinematics import jacobian_by_type
from .loads import solve as solve_loads, terms as load_terms
from .positions import condition_numbers, redundancy
from .vectorised import vectorised_of


@dataclass
class Analysis:
    """Everything the engine computes for one model along one motion (SI units).

    ``q``, ``v``, ``a``: (N, nb, 3) centre-of-mass coordinates and their derivatives.
    ``force``/``moment``: shaking force (N, 2) and moment (N,) on the frame from the reactions
    (route a), about ``moment_point``; ``force_momentum``/``moment_momentum`` the same from the
    momentum derivative (route b). ``efforts``: actuator torque or force per driver, applied by
    the actuator to the driven body. ``reactions``: constraint loads per joint (the generalized
    forces of the joint's multipliers, see :func:`joint_reactions`), for revolutes the force
    exerted on body b by body a.

    What every reader of an analysis uses besides: ``frame_pose`` (N, nb, 3), each body's own
    frame (origin and angle, not its centre of mass), for drawing; ``total_mass`` of the moving
    bodies (kg); ``redundant_actuators``, the actuators beyond the degrees of freedom (0 when the
    drive is exact); ``actuated``: whether the model has actuators apart from its drivers, and
    then ``actuation_condition`` (N,), the condition number of the actuation matrix, and
    ``actuator_rates``, each actuator's rate along the motion; :attr:`condition`, the condition
    numbers of the constraint Jacobian Phi_q along the motion, computed when first read (an SVD
    per sample) unless the engine's path had them, and :meth:`condition_peak`, their first
    largest value with fewer SVDs.
    """

    t: np.ndarray
    names: list[str]
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    force_momentum: np.ndarray
    moment_momentum: np.ndarray
    efforts: dict[str, np.ndarray]
    reactions: dict[str, dict[str, np.ndarray]]
    com: np.ndarray
    momentum: np.ndarray
    angular_momentum: np.ndarray
    moment_point: tuple[float, float]
    gravity: tuple[float, float]
    frame_pose: np.ndarray
    total_mass: float
    redundant_actuators: int = 0
    actuated: bool = False
    actuation_condition: np.ndarray | None = None
    actuator_rates: dict[str, np.ndarray] | None = None
    frame_force: np.ndarray | None = None
    frame_moment: np.ndarray | None = None
    loads: dict[str, dict[str, np.ndarray]] = field(default_factory=dict)
    # the condition numbers as given by the engine's path (None: computed from _motion when read);
    # memos of the caches' keys (a function of the model and q, which the keys hold)
    _condition: np.ndarray | None = field(default=None, repr=False, compare=False, metadata={MEMO: True})
    _motion: tuple[Compiled, np.ndarray] | None = field(default=None, repr=False, compare=False, metadata={MEMO: True})
    _peak: tuple[int, float] | None = field(default=None, repr=False, compare=False, metadata={MEMO: True})

    @property
    def condition(self) -> np.ndarray:
        """The condition numbers of Phi_q along the motion (N,), computed when first read."""
        if self._condition is None:
            if self._motion is None:
                raise ValueError("an analysis without its condition numbers or the motion to compute them from")
            self._condition = condition_numbers(*self._motion)
        return self._condition

    def condition_peak(self) -> tuple[int, float]:
        """(k, cond[k]) of the first largest condition number: from the array when it has been
        read, else by :func:`.conditioning.motion_peak` (kept): the same sample and value."""
        if self._condition is not None or self._motion is None:
            return _argmax(self.condition)
        if self._peak is None:
            self._peak = motion_peak(*self._motion)
        return self._peak

    def __getstate__(self) -> dict:
        """Pickled with its condition numbers computed and without the compiled model."""
        state = dict(self.__dict__)
        state["_condition"] = self.condition
        state["_motion"] = None
        return state

    @property
    def frame_load(self) -> tuple[np.ndarray, np.ndarray]:
        """What the frame feels, force (N, 2) and moment (N,) about the moment point: the
        bearing and slideway reactions, the motors' reactions and the frame-side reactions of
        internal loads. It equals the shaking load plus the external loads (the same as the
        shaking load without external loads, :mod:`.loads`)."""
        if self.frame_force is None or self.frame_moment is None:
            return self.force, self.moment
        return self.frame_force, self.frame_moment

    @property
    def max_force(self) -> float:
        return float(np.max(np.linalg.norm(self.force, axis=1)))

    @property
    def max_moment(self) -> float:
        return float(np.max(np.abs(self.moment)))

    def static_load(self) -> tuple[np.ndarray, np.ndarray]:
        """The part of the shaking loads due to the moving links' weight: the force m g (2,)
        and its moment (N,) about the moment point, (r_com - P) x m g. Zero without gravity."""
        W = self.total_mass * np.asarray(self.gravity)
        r = self.com - np.asarray(self.moment_point)
        return W, r[:, 0] * W[1] - r[:, 1] * W[0]

    @property
    def inertial_force(self) -> np.ndarray:
        """Shaking force minus the links' weight: -dP/dt (N, 2)."""
        return self.force - self.static_load()[0]

    @property
    def inertial_moment(self) -> np.ndarray:
        """Shaking moment minus the weight's moment: -dH_P/dt (N,)."""
        return self.moment - self.static_load()[1]

    @property
    def max_inertial_force(self) -> float:
        return float(np.max(np.linalg.norm(self.inertial_force, axis=1)))

    @property
    def max_inertial_moment(self) -> float:
        return float(np.max(np.abs(self.inertial_moment)))

    def route_difference(self) -> tuple[float, float]:
        """Absolute max |reactions - momentum| of the force (N) and of the moment (N m); the
        study divides them by the unbalanced stage's peaks."""
        df = float(np.max(np.linalg.norm(self.force - self.force_momentum, axis=1)))
        dm = float(np.max(np.abs(self.moment - self.moment_momentum)))
        return df, dm

    def pose(self, k: int, body: str) -> tuple[float, float, float]:
        """Pose of a body's own frame (not its centre of mass) at sample k."""
        i = self.names.index(body)
        return self.frame_pose[k, i].tolist()


def _argmax(values: Any) -> tuple[int, float]:
    v = np.asarray(values, dtype=float)
    k = int(np.argmax(v))
    return k, float(v[k])


def condition_peak(an: Analysis, key: str = "condition") -> tuple[int, float] | None:
    """The first sample k of the largest value of ``an``'s ``condition`` (the condition numbers
    of Phi_q: :meth:`Analysis.condition_peak`, SVDs only where they can be) or
    ``actuation_condition`` and that value; None for an analysis without actuation condition."""
    if key == "condition":
        return an.condition_peak()
    values = getattr(an, key)
    return _argmax(values) if values is not None else None


_COMPILED: dict[int, tuple[weakref.ref, Compiled]] = {}


def compiled(model: Model) -> Compiled:
    """:func:`compile_model`, kept per model object (and its block structure, shared by every
    model of the same pattern, :func:`.structure.decompose`)."""
    hit = _COMPILED.get(id(model))
    if hit is not None and hit[0]() is model:
        return hit[1]
    c = compile_model(model)
    if len(_COMPILED) >= 128:
        _COMPILED.clear()
    _COMPILED[id(model)] = (weakref.ref(model), c)
    return c


def clear_cache() -> None:
    """Forget compiled models, block structures and solved motions (for benchmarks of cold
    calls); the anchors of :mod:`.warmstart` are the caller's."""
    _COMPILED.clear()
    structure._CACHE.clear()
    fastpath._MOTIONS.clear()
    shared.clear()


def analyse(
    model: Model,
    t: np.ndarray,
    gravity: tuple[float, float] = (0.0, 0.0),
    moment_point: tuple[float, float] = (0.0, 0.0),
    *,
    method: str = "auto",
) -> Analysis:
    """Kinematics, inverse dynamics and shaking loads of ``model`` at times ``t``.

    ``method``: ``"auto"`` takes the block-triangular path (:mod:`.fastpath`) where it applies
    and the general dense path otherwise; ``"dense"`` forces the general path (continuation,
    batched Newton-Raphson and dense batched solves on every sample's full Jacobian). Both give
    the same results to round-off. The first call sets the C allocator's thresholds for the
    arrays of the chunks (:func:`balpipe.runtime.allocator.keep_freed_memory`: no page faulted in
    again for every chunk; the same results).
    """
    if method not in ("auto", "dense"):
        raise ValueError(f"method must be 'auto' or 'dense', not {method!r}")
    keep_freed_memory()
    c = compiled(model)
    t = np.asarray(t, dtype=float)
    g = np.asarray(gravity, dtype=float)
    Mdiag = np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(1, -1)
    kin: fastpath.Kinematics | fastpath.Motion | None = None
    actuation = rates = None
    # the block path, chunk by chunk, where the multipliers are one backward solve (no loads,
    # meshes or actuators apart from the drivers); otherwise its kinematics on the whole grid
    by_chunks = not model.loads and not c.meshes and c.dynamics is None
    if method == "auto":
        if c.fast is None:
            c.fast = fastpath.prepare(c)
        try:
            kin = (fastpath.dynamics_by_chunks(c, c.fast, t, Mdiag, g) if by_chunks
                   else fastpath.kinematics(c, c.fast, t))
        except fastpath.Fallback:
            kin = None
    placed = None
    if kin is None:
        q, v, a, placed = shared.kinematics(c, t)  # placed in the frame motion of its geometry (solved once)
        cond = c.condition  # None where the screen showed the motion regular: computed when read
    else:
        q, v, a = kin.X[3:-1].T, kin.V[3:-1].T, kin.A[3:-1].T
        cond = None  # the block path's: computed when read
    cd = c.dynamics or c  # the system of the inverse dynamics: the actuators' rows, or the drivers'
    lt = load_terms(model, c, t, q, v) if model.loads else None
    mesh_geo: list = []
    radial_on_frame = None
    if isinstance(kin, fastpath.Motion):
        done = kin

        def solver(rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            return done.lamT.T, done.frame

        rhs = q  # not read: the chunks solved with Q - M q''
    elif isinstance(kin, fastpath.Kinematics) and not c.meshes and c.dynamics is None:
        rhsT = -Mdiag.T * kin.A[3:-1]
        rhsT[0::3] += (c.mass * g[0])[:, None]
        rhsT[1::3] += (c.mass * g[1])[:, None]
        fast_kin = kin

        def solver(rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            lamT = fastpath.multipliers(c.fast, fast_kin, rhs.T)
            return lamT.T, fastpath.frame_load(c.fast, fast_kin.vals, lamT)

        rhs = rhsT.T
    else:
        Q = np.zeros_like(q)
        Q[:, 0::3] = c.mass * g[0]
        Q[:, 1::3] = c.mass * g[1]
        rhs = Q - Mdiag * a
        by_frame = shared.multipliers(c, placed, rhs)  # a placed model: its geometry's map, made once
        if by_frame is not None:
            J0, base = by_frame[1], rhs

            def solver(rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                again = by_frame if rhs is base else shared.multipliers(c, placed, rhs)
                assert again is not None  # the same placed geometry as the base's, which has its map
                lam = again[0]
                return lam, -np.einsum("nmk,nm->nk", J0, lam)  # load on the frame: Fx, Fy, M_O
        else:
            qx = with_frame(q)
            J = jacobian_by_type(vectorised_of(cd), q)[1]  # constraints.jacobian's values (fewer numpy calls)
            mesh_geo = tooth_rows(cd, qx, J)  # gear meshes with pitch radii act by tooth forces
            Jf, J0 = J[:, :, 3:], J[:, :, :3]
            if c.dynamics is not None:
                actuation = actuation_condition(cd, Jf, t)
                rates = {name: np.einsum("nk,nk->n", Jf[:, row, :], v) for name, row in cd.driver_rows.items()}

            def solver(rhs: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
                lam = solve_multipliers(cd, Jf, rhs)
                return lam, -np.einsum("nmk,nm->nk", J0, lam)  # load on the frame: Fx, Fy, M_O
    if lt is None:
        lam, gen0 = solver(rhs)
    else:
        if lt.coulomb and mesh_geo:
            raise AnalysisError("Coulomb friction in a model whose gear meshes carry tooth forces is not supported: "
                                "give the friction as viscous, or the gears without pitch radii", float(t[0]))
        lam, gen0 = solve_loads(lt, rhs, solver)
    if mesh_geo:  # the radial tooth forces move the bearings' multipliers: the frame's share too
        before = lam.copy()
        lam, radial_on_frame = radial_tooth_loads(cd, mesh_geo, lam)
        if lt is None:
            gen0 = -np.einsum("nmk,nm->nk", J0, lam) + radial_on_frame  # load on the frame: Fx, Fy, M_O
        else:
            gen0 = gen0 - np.einsum("nmk,nm->nk", J0, lam - before) + radial_on_frame
    frame_gen = gen0
    if lt is not None:
        gen0 = gen0 - lt.external  # the shaking load: the frame load less the external loads
    P = np.asarray(moment_point, dtype=float)
    force = gen0[:, :2]
    moment_O = gen0[:, 2]

    nb = c.nb

    qb, vb, ab = q.reshape(-1, nb, 3), v.reshape(-1, nb, 3), a.reshape(-1, nb, 3)
    m, I = c.mass, c.inertia
    r, rd, rdd = qb[:, :, :2], vb[:, :, :2], ab[:, :, :2]
    dP = np.einsum("k,nkd->nd", m, rdd)
    dH = np.einsum("k,nk->n", m, cross(r, rdd)) + ab[:, :, 2] @ I
    weight = m.sum() * g
    force_mom = weight[None, :] - dP
    moment_mom = np.einsum("k,nk->n", m, cross(r, np.broadcast_to(g, r.shape))) - dH
    momentum = np.einsum("k,nkd->nd", m, rd)
    ang = np.einsum("k,nk->n", m, cross(r, rd)) + vb[:, :, 2] @ I
    com = np.einsum("k,nkd->nd", m, r) / m.sum() if m.sum() > 0 else np.zeros((len(t), 2))

    def about_P(M: np.ndarray, F: np.ndarray) -> np.ndarray:
        return M - (P[0] * F[:, 1] - P[1] * F[:, 0])

    efforts = {name: -lam[:, row] for name, row in cd.driver_rows.items()}
    reactions = joint_reactions(model, cd, lam, mesh_geo)
    # frame poses for drawing: frame origin = com - A(theta) com_local
    if kin is not None:  # coordinate-major, as the block path's q (a view of its rows, no copy)
        frame_pose = fastpath.place_rows(kin.X[3:-1], -c.com_local).T.reshape(qb.shape)
    else:
        frame_pose = fastpath._place(q, -c.com_local).reshape(qb.shape)
    return Analysis(
        t=t, names=c.names, q=qb, v=vb, a=ab,
        force=force, moment=about_P(moment_O, force),
        force_momentum=force_mom, moment_momentum=about_P(moment_mom, force_mom),
        efforts=efforts, reactions=reactions, com=com, momentum=momentum, angular_momentum=ang,
        moment_point=(float(P[0]), float(P[1])), gravity=(float(g[0]), float(g[1])),
        frame_force=None if lt is None else frame_gen[:, :2],
        frame_moment=None if lt is None else about_P(frame_gen[:, 2], frame_gen[:, :2]),
        loads={} if lt is None else lt.series,
        frame_pose=frame_pose, total_mass=float(m.sum()), redundant_actuators=redundancy(cd),
        actuated=c.dynamics is not None, actuation_condition=actuation, actuator_rates=rates,
        _condition=cond, _motion=None if cond is not None else (c, q),
    )
