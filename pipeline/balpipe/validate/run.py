"""Running a model in pymunk along the analysed motion and measuring the loads on the frame.

``simulate`` drives the space built by :mod:`balpipe.validate.space` along the analysis' motion
laws (dead-beat drivers) and records the load on the frame from the simulated momenta;
``_run_adaptive`` chooses the solver effort (iterations doubled until the loads converge, gear
models tried in turn). See :mod:`balpipe.validate.loads` for the method and measured accuracy.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Any, Callable

import numpy as np
import pymunk
import pymunk.batch
from pymunk._chipmunk_cffi import lib as _cp

from ..display import numbers
from ..engine import Analysis
from ..mechanics.planar import rotate
from ..model import FRAME, Gear, Model, Prismatic, Revolute
from .extend import is_periodic_moving, start_state
from .feedforward import inertial_forces, periodic_times
from .settings import HEALTH_LIMIT, MAX_ITERATIONS, _jumps
from .space import SimModel, build_space

#: checked samples compared with the analysis at a time (a run that comes apart ends at most
#: this many checks, ten steps apart, after it strays)
CHECK_BLOCK = 5
#: steps between two looks at a run's tracking error where it may stop once that error suffices
#: (``simulate(stop_at=...)``)
STOP_EVERY = 50

@dataclass
class SimulationRun:
    """Raw simulation output, one sample per step (``t``)."""

    t: np.ndarray
    force: np.ndarray  # (n, 2) load on the frame
    moment: np.ndarray  # (n,) about the analysis' moment point
    poses: np.ndarray  # (n, nb, 3) centre-of-mass coordinates
    base: np.ndarray  # (n, 3) pose of the frame's origin (zeros when static)
    driver_error: dict[str, np.ndarray]
    momentum: np.ndarray  # (n, 3) P_x, P_y, H about the moment point of all dynamic bodies
    dt: float
    iterations: int
    wall: float
    sim: SimModel
    #: the run ended before the motion's end (``simulate(stop_at=...)``): its arrays stop there
    stopped: bool = False



def _driver_coordinate(model: Model, d, poses: dict[str, tuple], com: dict):
    """The driven coordinate measured on simulated poses (centre-of-mass poses for bodies, the
    origin's pose for the frame), in the frame's coordinates; each pose's x, y and angle may be
    arrays (one value per step: the coordinate is then an array)."""

    def world(body: str, p) -> tuple[float, float]:
        x, y, th = poses[body]
        c = com[body]
        lx, ly = p[0] - c[0], p[1] - c[1]
        cs, sn = np.cos(th), np.sin(th)
        return x + cs * lx - sn * ly, y + sn * lx + cs * ly

    kind = d.target[0]
    th0 = poses[FRAME][2]
    if kind == "joint":
        jt = model.joint(d.target[1])
        if isinstance(jt, Revolute):
            return poses[jt.b][2] - poses[jt.a][2]
        if isinstance(jt, Prismatic):
            ax = np.asarray(jt.axis, dtype=float)
            ax = ax / np.linalg.norm(ax)
            thg = poses[jt.guide][2]
            e = (np.cos(thg) * ax[0] - np.sin(thg) * ax[1], np.sin(thg) * ax[0] + np.cos(thg) * ax[1])
            ps = world(jt.slider, jt.point_slider)
            pg = world(jt.guide, jt.point_guide)
            return (ps[0] - pg[0]) * e[0] + (ps[1] - pg[1]) * e[1]
        raise ValueError(f"driver {d.name!r}: a gear pair cannot be driven")
    if kind == "angle":
        return poses[d.target[1]][2] - th0
    body = d.target[1]
    point = model.body(body).point(d.target[2]) if len(d.target) > 2 else (0.0, 0.0)
    p = world(body, point)
    rel = (p[0] - poses[FRAME][0], p[1] - poses[FRAME][1])
    cs, sn = np.cos(th0), np.sin(th0)
    loc = (cs * rel[0] + sn * rel[1], -sn * rel[0] + cs * rel[1])
    return loc[0] if kind == "x" else loc[1]



def initial_state(model: Model, analysis: Analysis, dt: float, settle: int = 0) -> tuple[np.ndarray, np.ndarray]:
    """The state :func:`simulate` builds its space in (centre-of-mass poses and velocities, (nb, 3)
    each): one step before the first simulated step's landing q0 (``settle`` steps before t0),
    q0 - dt v_h with the half-step velocity v_h = v0 - a0 dt / 2."""
    q0, v0, a0 = start_state(model, analysis, settle, dt)
    vh = v0 - 0.5 * dt * a0
    return q0 - dt * vh, vh


def simulate(
    model: Model,
    analysis: Analysis,
    dt: float,
    iterations: int,
    *,
    startup_steps: int = 10,
    startup_iterations: int = 5000,
    floating_base: tuple[float, float, tuple[float, float]] | None = None,
    record_poses: bool = True,
    efforts: dict[str, np.ndarray] | None = None,
    measure_with: Model | None = None,
    abort: tuple[float, float] | None = None,
    settle: int = 0,
    feedforward: bool = False,
    applied=None,
    stop_at: tuple[float, dict[str, float]] | None = None,
    **build_options,
) -> SimulationRun:
    """Simulate ``model`` along ``analysis``' motion and measure the loads on the frame.

    ``dt`` should divide the analysis' duration (see :func:`validate`, which picks it).
    Start-up: pymunk integrates positions with the velocities of the previous step
    (symplectic Euler), so its velocities belong half a step after its positions. The run
    starts one step before t0 at q(t0) - dt v(t0 - dt/2) with the velocity
    v(t0 - dt/2) = v(t0) - a(t0) dt/2 (the analysis at t0 is the only analytic input), so that
    the first step lands exactly on q(t0). The loads at step time t_k are
    F = sum m g - (P_{k+1/2} - P_{k-1/2}) / dt and
    M = sum (r_k - O) x m g - (H_{k+1/2} - H_{k-1/2}) / dt, central differences of the
    momenta of every dynamic body of the mechanism, about the analysis' moment point O
    (H_{k+1/2} = sum m (r_k - O) x v_{k+1/2} + I w_{k+1/2} is exactly the mid-step value, as
    v x v = 0): second-order accurate where the motion laws are smooth.

    ``efforts`` (driver name -> effort at each step time ``t0 + k dt``): a torque-driven run.
    No driver constraint is built; before the step that lands on t_k, each actuator applies its
    effort at t_k (pymunk integrates velocities with the forces at the new positions), and
    the drivers' laws are only compared with (``driver_error``). ``measure_with``: a model with
    the same bodies whose masses and moments the loads are measured with (default ``model``).
    ``abort`` = (limit, scale): stop with FloatingPointError as soon as a body, in the frame's
    coordinates, is more than ``limit`` (rad, or ``limit * scale`` m) from the analysed motion
    at an analysis sample (checked every tenth step): a run that came apart ends early.
    ``settle``: steps run before t0 and not recorded (:func:`balpipe.validate.extend.settling_steps`:
    a run-in of a motion moving at t0), from
    :func:`balpipe.validate.extend.start_state`, so that the recorded steps are in steady state.
    ``feedforward`` (a position-driven run only): before each step every moving body gets the
    inertial force and torque of the analysed motion (:mod:`balpipe.validate.feedforward`); the
    drivers impose the motion either way, the solver converges with fewer iterations.
    ``applied``: a :class:`balpipe.validate.applied.AppliedLoads`, whose loads act on the
    bodies before every step (a torque-driven run of a model with loads).
    ``stop_at`` = (limit, travel): the run ends as soon as a driven coordinate's error, relative
    to its ``travel`` (driver name -> rad or m), has reached ``limit`` (or is not finite),
    looked at every :data:`STOP_EVERY` steps over every step since the last look: the returned
    run then holds the steps up to that look (``SimulationRun.stopped``), and its largest
    relative tracking error is at least ``limit``. For a run whose only use is to show an error
    at least that large (the torque-driven run's calibration, :mod:`balpipe.validate.torque`).
    """
    t = np.asarray(analysis.t, dtype=float)
    t0 = float(t[0])
    n = int(round((float(t[-1]) - t0) / dt))
    times = t0 + dt * np.arange(n + 1)
    qs, vh = initial_state(model, analysis, dt, settle)
    gravity = (0.0, 0.0) if floating_base is not None else analysis.gravity
    sim = build_space(
        model, qs, vh, gravity=gravity, iterations=iterations, floating_base=floating_base,
        dt=dt, drive=efforts is None, **build_options,
    )
    space = sim.space
    bodies = sim.moving
    if applied is not None:
        applied = None if sim.floating else applied.bind(sim.bodies)
    everything = bodies + ([sim.base] if sim.floating else [])
    # the loads are measured with the model's masses and moments (a massless body simulated
    # with a floor mass, and the light auxiliary gears of meshes, count for nothing)
    props = [b.mass_properties() for b in (measure_with or model).bodies]
    m = np.array([p[0] for p in props] + [0.0] * len(sim.auxiliary))
    inertia = np.array([p[2] for p in props] + [0.0] * len(sim.auxiliary))
    g = np.asarray(gravity, dtype=float)
    O = np.asarray(analysis.moment_point, dtype=float)
    weight = m.sum() * g
    names = [b.name for b in model.bodies]
    com = {FRAME: (0.0, 0.0), **{b.name: b.mass_properties()[1] for b in model.bodies}}

    every = t0 + dt * np.arange(-settle, n + 1)  # settling steps, then the recorded ones
    target_t = every + dt  # the step landing on every[k] starts at every[k] - dt: target t + 2 dt
    # the drives' targets (a torque-driven run has none: its laws are only compared with)
    targets = {d.name: np.asarray(d.law(target_t)[0], dtype=float) for d in model.drivers} if sim.drives else {}
    laws_now = {d.name: np.asarray(d.law(times)[0], dtype=float) for d in model.drivers}
    boost = np.zeros(settle + n + 1, dtype=bool)
    boost[:startup_steps] = True
    for k in _jumps(model, target_t):  # the solver restarts where a law's acceleration jumps
        boost[max(k - 1, 0) : k + startup_steps] = True

    nb = len(names)
    read = _BatchReader(space, everything)
    check: dict[int, int] = {}
    if abort is not None:
        steps = np.rint((t - t0) / dt).astype(int)
        on = np.abs(t0 + steps * dt - t) <= 1e-9 * max(float(t[-1] - t0), 1e-12)
        at = np.flatnonzero(on & (steps % 10 == 0))
        check = dict(zip(steps[at].tolist(), at.tolist()))  # step k -> analysis sample i
    pending: list[int] = []  # checked steps whose states are not yet compared (a block at a time)
    if settle == 0:
        read()
    start = time.perf_counter()
    iters = np.where(boost, startup_iterations, iterations).tolist()
    # The loop makes the Chipmunk calls of pymunk's properties and step with the same values in
    # the same order, its choices made before it starts: the per-step inputs as Python floats,
    # computed with the same arithmetic, a phase and a summed torque set with the Chipmunk
    # function that the property's setter calls, the states read with _BatchReader's own call,
    # the checked steps and stop_at's looks as the next k to stop at.
    phases, grooves = [], []
    for dr in sim.drives:
        v = targets[dr.driver.name]
        if dr.kind == "phase":  # the joint's phase, offset + scale * law (see _Drive.set)
            phases.append((dr.constraint._constraint, (dr.offset + dr.scale * v).tolist()))
        else:
            grooves.append((dr, v))
    set_phase, set_torque = _cp.cpGearJointSetPhase, _cp.cpBodySetTorque
    updates = sim.meshes + sim.carried
    torques, acts = _actuator_inputs(sim.actuators, efforts, settle, n) if efforts is not None else ([], [])
    torques = [(body._body, tq) for body, tq in torques]
    push = _InertialForces(space, read, model, analysis, every, bodies[:nb], g) if feedforward and efforts is None else None
    each, cspace, getter, data = read.each, read.cspace, read.getter, read.data  # read() is each(cspace, getter, data)
    checks = iter(sorted(check))
    next_check = next(checks, n + 1)  # n + 1: no more checks
    next_look = 0 if stop_at is not None else n + 1
    stepper = _Stepper(space)
    advance: Callable[[Any, float], object]  # the steps after the first: advance(advance_on, dt)
    advance_on: Any
    current = None
    stopped = False
    looked = 0  # recorded rows already looked at by stop_at
    for step in range(settle + n + 1):
        if iters[step] != current:
            current = space.iterations = iters[step]
        for c, v in phases:
            set_phase(c, v[step])
        for dr, v in grooves:
            dr.set(v[step])
        for u in updates:
            u.update(dt)
        k = step - settle
        for b, tq in torques:
            set_torque(b, tq[step])
        if push is not None:
            push(step)
        for act, e in acts:
            act.apply(float(e[max(k, 0)]), dt)
        if applied is not None:
            applied.apply(float(every[step]), dt)
        if step:
            advance(advance_on, dt)
        else:  # the first step through pymunk, which hands the next ones over
            advance, advance_on = stepper.first(dt)
        if k >= -1:
            each(cspace, getter, data)
            read.recorded += 1
        if k == next_check:
            pending.append(k)
            next_check = next(checks, n + 1)
            if len(pending) == CHECK_BLOCK or k == n:
                _check_apart(read.rows(pending), nb, len(bodies) if sim.floating else None,
                             analysis.q[[check[j] for j in pending]], abort, times[pending])
                pending.clear()
        if k == next_look:  # k = 0, STOP_EVERY, 2 STOP_EVERY, ... and n
            next_look = min(k + STOP_EVERY, n)
            upto = read.recorded - 1  # rows 1 .. upto hold the states after steps 0 .. upto - 1
            if _tracking_reached(model, read.rows(list(range(looked, upto))), names, com, laws_now, looked,
                                 stop_at, len(bodies) if sim.floating else None):
                stopped = k < n
                n = k
                times = times[: n + 1]
                break
            looked = upto
    if pending:
        _check_apart(read.rows(pending), nb, len(bodies) if sim.floating else None,
                     analysis.q[[check[j] for j in pending]], abort, times[pending])
    rec = read.rows()
    states = rec[1:]
    # momenta of the mechanism's bodies, measured with the model's masses and moments
    x, y, w = rec[:, : len(bodies), 0] - O[0], rec[:, : len(bodies), 1] - O[1], rec[:, : len(bodies), 5]
    vx, vy = rec[:, : len(bodies), 3], rec[:, : len(bodies), 4]
    P = np.stack([vx @ m, vy @ m], axis=1)
    H = (x * vy - y * vx) @ m + w @ inertia
    force = weight - np.diff(P, axis=0) / dt
    moment = -np.diff(H) / dt
    if g.any():
        moment = moment + (x[1:] * g[1] - y[1:] * g[0]) @ m
    base = states[:, len(bodies), :3].copy() if sim.floating else np.zeros((n + 1, 3))
    total = np.zeros((n + 1, 3))
    if sim.floating:  # the total momentum, with pymunk's own masses (the base's centre of gravity off its origin)
        mm = np.array([b.mass for b in everything])
        ii = np.array([b.moment for b in everything])
        cg = np.array([tuple(b.center_of_gravity) for b in everything])
        th = states[:, :, 2]
        gx = states[:, :, 0] + np.cos(th) * cg[:, 0] - np.sin(th) * cg[:, 1] - O[0]
        gy = states[:, :, 1] + np.sin(th) * cg[:, 0] + np.cos(th) * cg[:, 1] - O[1]
        total = np.stack([states[:, :, 3] @ mm, states[:, :, 4] @ mm,
                          (gx * states[:, :, 4] - gy * states[:, :, 3]) @ mm + states[:, :, 5] @ ii], axis=1)
    poses = states[:, :nb, :3].copy() if record_poses else np.zeros((0, nb, 3))
    derr = _driver_errors(model, states, names, com, laws_now, 0, len(bodies) if sim.floating else None)
    wall = time.perf_counter() - start
    space.iterations = iterations
    return SimulationRun(times, force, moment, poses, base, derr, total, dt, iterations, wall, sim, stopped)


def _driver_errors(model: Model, rows: np.ndarray, names: list[str], com: dict, laws: dict[str, np.ndarray],
                   first: int, base: int | None) -> dict[str, np.ndarray]:
    """Each driven coordinate of the recorded states ``rows`` (the steps ``first``, ``first + 1``,
    ...; the floating base's state at index ``base``, else the frame at rest) less its law
    ``laws`` at those steps (rad or m)."""
    st = {nm: (rows[:, i, 0], rows[:, i, 1], rows[:, i, 2]) for i, nm in enumerate(names)}
    frame = rows[:, base, :3] if base is not None else np.zeros((len(rows), 3))
    st[FRAME] = (frame[:, 0], frame[:, 1], frame[:, 2])
    return {d.name: np.asarray(_driver_coordinate(model, d, st, com), dtype=float) - laws[d.name][first : first + len(rows)]
            for d in model.drivers}


def _tracking_reached(model: Model, rows: np.ndarray, names: list[str], com: dict, laws: dict[str, np.ndarray],
                      first: int, stop_at: tuple[float, dict[str, float]], base: int | None) -> bool:
    """Some driven coordinate of the states ``rows`` (the steps ``first``, ``first + 1``, ...) is
    ``stop_at[0]`` of its travel or more from its law ``laws`` (or not finite)."""
    if not len(rows):
        return False
    limit, travel = stop_at
    return any(not float(np.max(np.abs(err))) / (travel.get(name) or 1.0) < limit
               for name, err in _driver_errors(model, rows, names, com, laws, first, base).items())



class _InertialForces:
    """Before step ``k``: the inertial forces and torques of :mod:`balpipe.validate.feedforward` on
    ``bodies`` at ``every[k]`` (the time the step's velocities are integrated at), set on every body
    of the space (zero on the others: auxiliary gears) with one call into Chipmunk. The rows of
    every step are one buffer; a call starts reading at row k, which is what
    ``pymunk.batch.set_space_bodies`` does from row 0 (1.6 us a step instead of 17 us with a new
    buffer per step, measured with 8 bodies)."""

    FIELDS = pymunk.batch.BodyFields.FORCE | pymunk.batch.BodyFields.TORQUE

    def __init__(self, space: pymunk.Space, read: "_BatchReader", model: Model, analysis: Analysis,
                 every: np.ndarray, bodies: list[pymunk.Body], g: np.ndarray) -> None:
        t = np.asarray(analysis.t, dtype=float)
        times = periodic_times(every, float(t[0]), float(t[-1])) if is_periodic_moving(model, analysis) else every
        f = inertial_forces(analysis, times, np.array([b.mass for b in bodies]),
                            np.array([b.moment for b in bodies]), g)
        rows = np.zeros((len(every), read.count, 3))
        rows[:, read.order[: len(bodies)]] = f
        self.stride = 3 * read.count
        self.buf = pymunk.batch.Buffer()
        self.buf.set_float_buf(rows.reshape(-1))
        self.array = self.buf._float_arr
        ffi, lib = pymunk.batch.ffi, pymunk.batch.lib
        self.data = ffi.new("pmBatchedData *")
        self.data.fields = self.FIELDS.value
        self.data.floatArray = self.array
        self.data.intArray = self.buf._int_arr
        self.each = lib.cpSpaceEachBody
        self.setter = ffi.addressof(lib, "pmSpaceBodySetIteratorFuncBatched")
        self.space = space._space

    def __call__(self, k: int) -> None:
        self.array.num = k * self.stride
        self.each(self.space, self.setter, self.data)


class _Stepper:
    """A run's steps, ``space.step(dt)`` each: ``first(dt)`` steps through pymunk (which checks
    every body's mass and moment) and returns the call of the next steps, ``(fn, arg)`` for
    ``fn(arg, dt)``: straight into Chipmunk's ``cpSpaceStep`` where pymunk's step would only add
    its bookkeeping of bodies and shapes added or removed during a step and of post-step
    callbacks (none pending after its step; a simulation adds and removes nothing and registers
    no callback while it runs), else ``pymunk.Space.step`` (a threaded space). The same
    Chipmunk step; about 3 us a step less, a fifth of a step at 100 solver iterations."""

    def __init__(self, space: pymunk.Space) -> None:
        self.space = space
        self.direct = None if space.threaded else _cp.cpSpaceStep

    def first(self, dt: float) -> tuple[Callable[[Any, float], object], Any]:
        space = self.space
        space.step(dt)
        if (self.direct is None or space._bodies_to_check or space._add_later or space._remove_later
                or space._post_step_callbacks):
            return pymunk.Space.step, space
        return self.direct, space._space


class _BatchReader:
    """Records x, y, angle, vx, vy, w of ``bodies`` after each step with one call into Chipmunk
    (``pymunk.batch``), appended to one buffer (no per-step conversion): ``read()`` records a row
    (``each(cspace, getter, data)``, which :func:`simulate`'s loop calls itself, counting the row);
    ``rows(ks)`` returns the rows of steps ``ks`` (row k + 1 holds the state after step k, row 0
    the state before the first recorded step), every row by default, (len, len(bodies), 6) in the
    order of ``bodies``."""

    FIELDS = (pymunk.batch.BodyFields.POSITION | pymunk.batch.BodyFields.ANGLE
              | pymunk.batch.BodyFields.VELOCITY | pymunk.batch.BodyFields.ANGULAR_VELOCITY)

    def __init__(self, space: pymunk.Space, bodies: list[pymunk.Body]) -> None:
        self.space = space
        self.buf = pymunk.batch.Buffer()
        pymunk.batch.get_space_bodies(space, pymunk.batch.BodyFields.BODY_ID, self.buf)
        ids = list(memoryview(self.buf.int_buf()).cast("P"))
        self.buf.clear()
        self.count = len(ids)
        self.order = np.array([ids.index(b.id) for b in bodies], dtype=int)
        self.recorded = 0
        # what pymunk.batch.get_space_bodies does, its call data made once (not at every step)
        ffi, lib = pymunk.batch.ffi, pymunk.batch.lib
        self.data = ffi.new("pmBatchedData *")
        self.data.fields = self.FIELDS.value
        self.data.floatArray = self.buf._float_arr
        self.data.intArray = self.buf._int_arr
        self.each = lib.cpSpaceEachBody
        self.getter = ffi.addressof(lib, "pmSpaceBodyGetIteratorFuncBatched")
        self.cspace = space._space

    def __call__(self) -> None:
        self.each(self.cspace, self.getter, self.data)
        self.recorded += 1

    def rows(self, ks: list[int] | None = None) -> np.ndarray:
        data = np.frombuffer(self.buf.float_buf(), dtype=float, count=6 * self.count * self.recorded)
        data = data.reshape(self.recorded, self.count, 6)
        if ks is not None:
            data = data[np.asarray(ks, dtype=int) + 1]
        return np.ascontiguousarray(data[:, self.order])  # C order: the sums below as before, bit for bit


def _actuator_inputs(actuators, efforts: dict[str, np.ndarray], settle: int, n: int):
    """The actuators' inputs at every step (``settle`` steps before t0 at t0's effort):
    ([(body, torque at each step)], []) when every actuator is a torque, each body's sum in the
    actuators' order (what ``_Actuator.apply`` adds up, from the zero that pymunk resets the
    torque to after a step, the same sums); otherwise ([], [(actuator, efforts)]), applied
    step by step."""
    acts = [(act, np.asarray(efforts[act.name], dtype=float)) for act in actuators]
    if any(act.kind != "torque" for act in actuators):
        return [], acts
    at = np.maximum(np.arange(settle + n + 1) - settle, 0)
    sums: dict[int, tuple[pymunk.Body, np.ndarray]] = {}
    for act, e in acts:
        for body, sign in ((act.body, 1.0), (act.other, -1.0)):
            if body is None:
                continue
            b, total = sums.get(id(body), (body, np.zeros(len(at))))
            sums[id(body)] = (b, total + e[at] if sign > 0 else total - e[at])
    return [(b, total.tolist()) for b, total in sums.values()], []


def _check_apart(states: np.ndarray, nb: int, base: int | None, q_ref: np.ndarray, abort: tuple[float, float],
                 t: np.ndarray) -> None:
    """FloatingPointError when one of the first ``nb`` bodies of ``states`` (m, bodies, rows x, y,
    angle, ...), in the frame's coordinates (the row ``base``, None: the fixed frame), is more
    than ``abort[0]`` (rad, or times ``abort[1]`` m) from its analysed pose ``q_ref`` (m, nb, 3)
    at the times ``t`` (m,). (Every tenth step of a run with ``simulate(abort=...)``, a block of
    :data:`CHECK_BLOCK` at a time: with the fixed frame, in Python floats, a fifth of numpy's time
    for a block, the same answer: :func:`_strayed_fixed`.)"""
    fixed = base is None and nb > 0 and abort[1] > 0
    bad = _strayed_fixed(states, nb, q_ref, abort) if fixed else _strayed(states, nb, base, q_ref, abort)
    if any(bad):
        raise FloatingPointError(f"the simulation came apart at t = {numbers.num(float(t[bad.index(True)]), 4)} s")


def _strayed(states: np.ndarray, nb: int, base: int | None, q_ref: np.ndarray, abort: tuple[float, float]) -> list[bool]:
    """:func:`_check_apart`'s test of each row of ``states``: a body too far from its analysed pose."""
    frame = states[:, base, :3] if base is not None else np.zeros((len(states), 3))
    q = states[:, :nb, :3]
    rel = rotate(-frame[:, None, 2], q[:, :, :2] - frame[:, None, :2])
    dev_p = np.max(np.abs(rel - q_ref[:, :, :2]), axis=(1, 2)) / abort[1]
    dev_a = np.max(np.abs(q[:, :, 2] - frame[:, None, 2] - q_ref[:, :, 2]), axis=1)
    return (~((dev_p <= abort[0]) & (dev_a <= abort[0]))).tolist()


def _strayed_fixed(states: np.ndarray, nb: int, q_ref: np.ndarray, abort: tuple[float, float]) -> list[bool]:
    """:func:`_strayed` with the fixed frame (``nb`` > 0, ``abort[1]`` > 0), its operations in Python floats (IEEE
    doubles as numpy's): the frame's pose is 0 (x - 0 is x), its rotation cos -0 = 1 and
    sin -0 = -0 (which turns a non-finite coordinate into NaN as numpy's does), and a row's
    largest deviation over ``abort[1]`` is at most ``abort[0]`` exactly when every deviation over
    ``abort[1]`` is (division by a positive number keeps the order; a NaN fails both); tested
    against :func:`_strayed` on non-finite states and ties."""
    limit, scale = abort
    c, si = 1.0, -0.0
    return [not all(abs(c * x - si * y - xr) / scale <= limit and abs(si * x + c * y - yr) / scale <= limit
                    and abs(th - thr) <= limit
                    for (x, y, th), (xr, yr, thr) in zip(row, ref))
            for row, ref in zip(states[:, :nb, :3].tolist(), q_ref.tolist())]


def _relative_poses(run: SimulationRun, idx: np.ndarray | None, t: np.ndarray) -> np.ndarray:
    """Simulated centre-of-mass poses on the analysis grid, in the frame's coordinates."""
    if idx is None:
        idx = np.searchsorted(run.t, t).clip(0, len(run.t) - 1)
    q = run.poses[idx].copy()
    base = run.base[idx]
    rel = q[:, :, :2] - base[:, None, :2]
    q[:, :, :2] = rotate(-base[:, None, 2], rel)
    q[:, :, 2] -= base[:, None, 2]
    return q


def _gear_models(model: Model, floating: bool) -> list[str | None]:
    """Gear models to try: the mesh (implicit, exact), then, with a static frame, the explicit
    carrier (converges easily, but lags where the carrier's acceleration jumps), for models
    with a gear pair whose gears and carrier all move."""

    def moving(n: str) -> bool:
        return n != FRAME or floating

    for j in model.joints:
        if isinstance(j, Gear) and j.ratio not in (0.0, 1.0):
            bodies = {j.a, j.b, j.carrier}
            if len(bodies) == 3 and all(moving(n) for n in bodies):
                return ["mesh"] if floating else ["mesh", "explicit"]
    return [None]


def _run_adaptive(
    model, analysis, dt, iterations, settings, scale, idx, limit=None, max_iterations=None, accept=None, passes=None,
    compare=None, **kw,
) -> tuple[SimulationRun | None, list[str], tuple[float, float]]:
    """Run with solver iterations doubled until the measured loads stop changing.

    A run "comes apart" when its loads are not finite or a body strays more than
    HEALTH_LIMIT (rad, or times the model's size) from the analysed motion. With ``limit`` =
    (force, moment), a run is accepted when it holds together and its loads differ from those
    of the run with half the iterations by at most ``limit`` at every step (the solver has
    converged); without, the first run that holds together is accepted. Iterations go up to
    MAX_ITERATIONS, then the next gear model is tried. This only chooses the solver effort: the
    verdict is the residual criterion of :func:`validate`. ``accept(run) -> bool``: a run that
    holds together and that ``accept`` takes is kept at once, without a rerun: :func:`validate`
    takes a run whose residuals against the analysis are already at most ``limit`` and whose
    balance claims hold, since more solver iterations move the loads towards the exact solution
    and cannot turn it into a failure (see :mod:`balpipe.validate.loads`). Returns the run (None
    if none held together), notes and the last change (force, moment) between doublings (NaN
    when a run was accepted without one). ``passes(run) -> bool``: when a gear model's best run
    passes the verdict without having converged, the next gear model (the explicit carrier, which
    lags where the carrier's acceleration jumps) is not tried: it could only replace a passing
    run by its own. ``compare(run) -> (force, moment)``: the loads whose change between doublings
    is measured (default every step's; :func:`validate` gives the samples that enter its residuals,
    so that a step that never enters the verdict, such as the one after the motion's end, where
    the drive stops the mechanism within a step, does not call for more iterations)."""
    compared = compare or (lambda r: (r.force, r.moment))
    notes: list[str] = []
    t = np.asarray(analysis.t, dtype=float)
    floating = kw.get("floating_base") is not None
    models = [kw.pop("gear_model")] if "gear_model" in kw else _gear_models(model, floating)
    best: tuple | None = None
    for gm in models:
        it = iterations
        prev = None
        label = f" ({gm} gears)" if gm else ""
        while True:
            with np.errstate(all="ignore"):
                try:
                    run = simulate(
                        model, analysis, dt, it, startup_steps=settings.startup_steps, abort=(10 * HEALTH_LIMIT, scale),
                        startup_iterations=max(settings.startup_iterations, it),
                        **({"gear_model": gm} if gm else {}), **kw,
                    )
                    q = _relative_poses(run, idx, t)
                    dpos = float(np.max(np.abs(q[:, :, :2] - analysis.q[:, :, :2]))) / scale
                    dang = float(np.max(np.abs(q[:, :, 2] - analysis.q[:, :, 2])))
                    finite = bool(np.isfinite(run.force).all() and np.isfinite(run.moment).all())
                    healthy = finite and dpos <= HEALTH_LIMIT and dang <= HEALTH_LIMIT
                except (ZeroDivisionError, ValueError, OverflowError, FloatingPointError):
                    run, healthy = None, False
            change = (math.inf, math.inf)
            if healthy and prev is not None:
                (f1, m1), (f0, m0) = compared(run), compared(prev)
                change = (
                    float(np.max(np.linalg.norm(f1 - f0, axis=1), initial=0.0)),
                    float(np.max(np.abs(m1 - m0), initial=0.0)),
                )
            if healthy:
                if limit is None:
                    return run, notes, change
                if accept is not None and accept(run):
                    if gm != models[0]:
                        notes.append(f"gear pairs on moving carriers: {gm} model used")
                    return run, notes, (math.nan, math.nan)
                score = max(change[0] / limit[0], change[1] / limit[1])
                if score <= 1.0:
                    if gm != models[0]:
                        notes.append(f"gear pairs on moving carriers: {gm} model used")
                    return run, notes, change
                if best is None or score < best[0]:
                    best = (score, run, change, gm)
            if it >= (max_iterations or MAX_ITERATIONS):
                state = "came apart" if not healthy else "did not converge"
                notes.append(f"the simulation{label} {state} up to {it} solver iterations")
                break
            prev = run if healthy else None
            it *= 2
        if passes is not None and best is not None and best[3] == gm and gm != models[-1] and passes(best[1]):
            # another gear model could only replace a passing run by its own (less accurate) one
            notes.append(f"the best run{label} passes: no other gear model tried")
            break
    if best is None:
        return None, notes, (math.inf, math.inf)
    _, run, change, gm = best
    notes.append(f"kept the best converged run ({run.iterations} iterations" + (f", {gm} gears)" if gm else ")"))
    return run, notes, change


def model_scale(analysis: Analysis) -> float:
    """The model's size for relative position errors: the largest distance of a body's centre of
    mass from the moment point over the analysis (at least 1 mm)."""
    r = np.linalg.norm(analysis.q[:, :, :2] - np.asarray(analysis.moment_point), axis=2)
    return max(float(r.max()) if r.size else 0.0, 1e-3)




