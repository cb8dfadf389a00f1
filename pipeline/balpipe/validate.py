"""Independent check of a stage's shaking loads with a pymunk simulation of the jointed mechanism.

Public API
    ``validate(model, analysis, unbalanced_peaks, settings=None, expect=()) -> StageValidation``
    ``free_floating(model, analysis, base_mass=10.0, base_inertia=None, settings=None,
    simulate_pymunk=True) -> FreeFloating``
    ``ValidationSettings``, ``default_settings(model, analysis)``, and, lower down,
    ``simulate(model, analysis, dt, iterations, ...) -> SimulationRun`` and
    :func:`balpipe.pymunk_model.build_space` (the translation of a model into pymunk).

Method
    The model is built in pymunk by :mod:`balpipe.pymunk_model` (bodies at their centres of
    mass, PivotJoint, GrooveJoint + rotation lock, gear pairs, dead-beat drivers) and driven
    along the analysis' motion laws. The load on the frame is measured from momenta:
    F = sum m g - dP/dt, M_O = sum (r - O) x m g - dH_O/dt, about the analysis' moment point,
    with the model's masses and moments on the simulated motion. pymunk's symplectic Euler
    keeps velocities half a step after positions, so P and H after a step are mid-step values
    and their central differences give the loads at the step times to second order (PYMUNK.md's
    first-order errors came from reading those velocities as values at the step time). The run
    starts one step before t0 at q(t0) - dt v(t0 - dt/2), v(t0 - dt/2) = v(t0) - a(t0) dt/2, so
    that the first step lands exactly on q(t0); nothing is excluded (``skip_initial_steps`` = 0).
    At the grid samples where a law has a corner (its jerk jumps, at t0 and T for the quintic
    and cycloidal laws; its acceleration jumps, for bang-bang and trapezoidal laws) the central
    difference would straddle it: the sample is the simulated load extrapolated linearly from
    the side the law's value belongs to (counted in ``extrapolated_samples``). A step of the
    simulation divides each interval of the analysis grid (non-uniform grids are interpolated).

Gear pairs
    Carried by the frame: one GearJoint; its missing (1 - ratio) couple is the frame's, which
    the momentum measurement includes by construction. On a moving carrier (planetary): a
    mesh, two gears pinned to the carrier touching at the pitch point through a GrooveJoint
    re-placed every step (implicit and momentum-conserving), falling back to an explicit
    carrier (one GearJoint whose phase follows the carrier's extrapolated angle) when the mesh
    does not converge. Measured on the planetary test model (moment residual): mesh 5.5e-5,
    explicit 2.0e-4 (4.0e-2 with a bang-bang law: the extrapolation lags where the carrier's
    acceleration jumps); a single absolute GearJoint (PYMUNK.md's trap) comes apart (the
    planet follows the wrong angle). On the free base the absolute GearJoint changes the total
    angular momentum by 0.11 N m s (8 % of the arm's peak), the mesh by 3e-7.

Defaults and why (measured with pymunk 7.3.1 on a 2-core machine)
    * dt = min(T / 1000, 0.01 / w_max), rounded down to divide the grid: the residual is
      second order, 57 dt^2 / T^2-ish for the 2R arm (T = 0.5 s):
      dt 2e-3: 9.1e-4, 1e-3: 2.3e-4, 5e-4: 5.7e-5, 2.5e-4: 1.4e-5, 1.25e-4: 3.6e-6;
      slider-crank dt 1e-3: 4.5e-4, 5e-4: 1.1e-4, 2.5e-4: 2.8e-5.
    * iterations: 100, doubled until the loads change by at most tolerance / 10 of the
      unbalanced peaks between two doublings (so at least two runs), up to 3200; a run whose
      bodies stray more than 1e-3 (rad, or of the model's size) from the analysed motion is
      redone with more. The first 10 steps, and those after a jump of a law's acceleration,
      run with 5000 iterations (the solver's warm start is missing or wrong there; with only
      3 start-up steps at 500 the Scott-Russell "full" stage had a 2 % error at t0). Fixed
      counts do not fit all: the 2R arm diverges at 10 iterations with dead-beat joints, the
      Scott-Russell "full" stage needs 3200 (its moment is 2 % off at 400), pymunk's C solver
      is cheap next to the Python step loop (100 -> 800 iterations costs ~2x).
    * mass floor 0.1: bodies lighter (of smaller moment) than 0.1 of the heaviest are simulated
      at that floor. A massless idler between two gears otherwise stalls the solver (floor 1e-6:
      comes apart at 3200 iterations; 1e-3: 800 iterations; 1e-2 and 0.1: 200, residuals
      4.7e-5 / 5.7e-5 in all converged cases). The motion is imposed by the drivers, so the
      floors change internal forces only, not the measured loads.
    * tolerance 1 % of the unbalanced peaks; balance_tolerance 1 % for the loads a stage claims
      to cancel (``expect``).

Measured residuals (max |sim - analytic| / unbalanced peak) at the defaults, 0.5 s motions,
251 samples, with the wall-clock time of ``validate`` (all runs included)
    ===========================================  =======  =======  ==========  =====
    model (tests/test_validate.py)               force    moment   iterations  s
    ===========================================  =======  =======  ==========  =====
    2R arm, joint drivers                        5.7e-5   5.5e-5   200         0.13
    five-bar, gravity on                         7.6e-6   2.9e-5   200         0.23
    slider-crank (prismatic), crank driven       3.4e-5   5.0e-5   200         0.25
    slider-crank driven by the slider's x        6.6e-5   1.0e-4   200         0.19
    rotating guide + prismatic driver            6.0e-5   6.4e-5   200         0.19
    disc geared to the frame, ratio -1           4.7e-5   5.7e-5   200         0.20
    planetary gear (carrier: a moving link)      5.7e-5   5.5e-5   200         0.27
    planetary gear, bang-bang law                1.0e-4   2.8e-4   200         0.30
    massless idler and disc (floors)             4.7e-5   5.7e-5   200         0.17
    force-balanced 2R arm (of unbalanced peak)   1.4e-10  1.2e-4   200         0.15
    reactionless 2R arm (counter-rotations)      2.0e-8   1.8e-5   400         0.51
    ===========================================  =======  =======  ==========  =====
    specs/ (stage: force, moment, iterations, s): offset slider-crank unbalanced 7.9e-5,
    6.1e-5, 200, 0.26; counterweights 3.6e-11, 1.0e-3, 200, 0.25. Paper 004 five-bar
    unbalanced 2.7e-4, 1.1e-4, 200, 0.23; counterweights 2.2e-6, 9.5e-5, 800, 0.57; full
    2.6e-6, 3.4e-6, 400, 0.77. Scott-Russell unbalanced 3.3e-5, 5.7e-5, 800, 0.53;
    counterweights 2.0e-7, 2.6e-4, 800, 0.58; full 5.4e-8, 1.4e-4, 3200, 1.27.
    Driven coordinates track their laws to 1e-12 rad (revolute, angle) and 1e-7 m (prismatic).

Free-floating frame
    The frame becomes a free body, no gravity; the mechanism moves relative to it along the
    analysed motion. pymunk result when it holds together (massless bodies excluded: a floor
    mass would move the base), else the exact conservation solution (constant total momentum
    and angular momentum along the analysed relative motion), which is always computed and
    compared. 2R arm on a 10 kg base: drift 57 mm, rotation 9.6 deg; pymunk and the
    conservation solution differ by 1.6e-7 m and 6e-7 rad. Force-balanced arm: drift 7e-16 m,
    still 36 deg of rotation. Reactionless arm: 2e-17 m and 9e-14 rad (conservation solution;
    its meshes do not converge in pymunk on the free base). 0.1-0.2 s per stage.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np
import pymunk

from .engine import Analysis
from .model import FRAME, Gear, Model, Prismatic, Revolute
from .pymunk_model import SimModel, build_space

__all__ = [
    "ValidationSettings",
    "StageValidation",
    "FreeFloating",
    "SimulationRun",
    "default_settings",
    "simulate",
    "validate",
    "free_floating",
]

#: default number of steps over the motion (the step is also kept below 0.01 / w_max)
STEPS_PER_MOTION = 1000
#: first solver iteration count; doubled (up to MAX_ITERATIONS) until the loads converge
ITERATIONS = 100
MAX_ITERATIONS = 3200
#: deviation from the analysed motion (rad, or relative to the model's size) that makes a run retry
HEALTH_LIMIT = 1e-3


@dataclass(frozen=True)
class ValidationSettings:
    """Numerical settings of the simulation and the pass criterion.

    ``dt``: time step (None: :func:`default_settings`); it is rounded down so that a whole
    number of steps fits each interval of the analysis grid. ``iterations``: pymunk solver
    iterations to start from (None: :data:`ITERATIONS`); they are doubled until two runs'
    loads differ by at most ``tolerance / 10`` of the unbalanced peaks (see
    :func:`_run_adaptive`).
    ``tolerance``: the stage passes when both residuals are at most this fraction of the
    unbalanced peaks. ``balance_tolerance``: for the loads a stage claims to cancel (``expect``
    of :func:`validate`), the simulated peak must also be at most this fraction of the
    unbalanced peak. ``skip_initial_steps``: simulation steps at the start whose samples are
    excluded from the residuals (none are needed: see the start-up in :func:`simulate`).
    ``startup_steps``/``startup_iterations``: the first steps, and the steps after a jump of a
    law's acceleration, run with more solver iterations, because the solver has no previous
    impulses to start from (warm start) or they are suddenly wrong.
    ``mass_floor``: bodies lighter (of smaller moment) than this fraction of the heaviest are
    simulated at that floor, so that pymunk's iterative solver converges (a massless idler
    between two gears otherwise stalls it). The loads are measured with the model's own
    masses and moments on the simulated motion, which the drivers impose: the floors change
    the internal forces only.
    """

    dt: float | None = None
    iterations: int | None = None
    tolerance: float = 0.01
    balance_tolerance: float = 0.01
    skip_initial_steps: int = 0
    startup_steps: int = 10
    startup_iterations: int = 5000
    mass_floor: float = 0.1


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


@dataclass
class StageValidation:
    """The simulation of one stage against its analysis.

    Curves on the analysis grid ``t``: ``force`` (N, 2), ``moment`` (N,) (simulated, same
    convention as the engine: load of the moving links on the frame, moment about the
    analysis' moment point); ``force_error`` (N,) = |F_sim - F_analytic|, ``moment_error``.
    ``measured`` (N,) marks the samples that enter the residuals.
    Scalars: residuals ``force_residual = max|F_sim - F_analytic| / F0`` and
    ``moment_residual`` (F0, M0: the unbalanced stage's analytic peaks, also stored);
    ``force_peak``/``moment_peak``: simulated inertial peaks (less the links' weight and its
    moment) / F0, M0; ``tracking_error``: max abs
    error of each driven coordinate (rad or m) and its maximum ``tracking_error_max``;
    ``pose_error_position`` (m) / ``pose_error_angle`` (rad): largest deviation of the
    simulated centres of mass from the analysis; ``dt``, ``steps``, ``iterations``, pymunk
    and Chipmunk versions; ``passed``. ``timing`` (wall-clock seconds) is kept out of
    :meth:`to_json` so that results files are deterministic.
    """

    t: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    force_error: np.ndarray
    moment_error: np.ndarray
    measured: np.ndarray
    force_residual: float
    moment_residual: float
    force_peak: float
    moment_peak: float
    unbalanced_force_peak: float
    unbalanced_moment_peak: float
    tracking_error: dict[str, float]
    tracking_error_max: float
    pose_error_position: float
    pose_error_angle: float
    dt: float
    steps: int
    iterations: int
    tolerance: float
    balance_tolerance: float
    expect: tuple[str, ...]
    passed: bool
    reasons: list[str]
    excluded_samples: int
    extrapolated_samples: int
    floored_bodies: list[str]
    notes: list[str]
    pymunk_version: str = pymunk.version
    chipmunk_version: str = pymunk.chipmunk_version
    timing: dict[str, float] = field(default_factory=dict)

    @property
    def status(self) -> str:
        return "pass" if self.passed else "fail"

    def to_json(self) -> dict:
        """Plain, deterministic summary (no curves, no wall-clock times)."""
        return {
            "passed": bool(self.passed),
            "status": self.status,
            "reasons": "; ".join(self.reasons),
            "force_residual": float(self.force_residual),
            "moment_residual": float(self.moment_residual),
            "force_peak": float(self.force_peak),
            "moment_peak": float(self.moment_peak),
            "unbalanced_force_peak": float(self.unbalanced_force_peak),
            "unbalanced_moment_peak": float(self.unbalanced_moment_peak),
            "tracking_error": {k: float(v) for k, v in sorted(self.tracking_error.items())},
            "tracking_error_max": float(self.tracking_error_max),
            "pose_error_position": float(self.pose_error_position),
            "pose_error_angle": float(self.pose_error_angle),
            "dt": float(self.dt),
            "steps": int(self.steps),
            "iterations": int(self.iterations),
            "tolerance": float(self.tolerance),
            "balance_tolerance": float(self.balance_tolerance),
            "expect": ",".join(self.expect),
            "samples": int(len(self.t)),
            "excluded_samples": int(self.excluded_samples),
            "extrapolated_samples": int(self.extrapolated_samples),
            "floored_bodies": ",".join(self.floored_bodies),
            "notes": "; ".join(self.notes),
            "pymunk_version": str(self.pymunk_version),
            "chipmunk_version": str(self.chipmunk_version),
            "method": "momentum",
        }


@dataclass
class FreeFloating:
    """The mechanism on a free base without gravity (reactionless demonstration).

    ``t`` (N,) analysis grid; ``base`` (N, 3): pose (x, y, angle) of the frame's origin, so a
    frame point p is drawn at base[:2] + R(base[2]) p; ``drift`` (N, 2): displacement of the
    base's centre of gravity; ``rotation`` (N,) = base[:, 2] (rad); ``poses`` (N, nb, 3):
    global pose of each body's own frame (for drawing, like ``Analysis.pose``).
    ``method``: "pymunk" (the simulation) or "momentum" (the exact solution from the
    conservation of the total momentum and angular momentum along the analysed relative
    motion, used when the simulation did not hold together; ``notes`` says why). The
    conservation solution is always computed: ``reference_max_drift``/``..._rotation`` and
    ``reference_difference`` (largest |drift| and |rotation| difference) compare the two.
    ``momentum_drift``: change of the simulated total linear (N s) and angular (N m s) momentum
    of base + mechanism, zero in physics (a check of the simulation; zeros for "momentum").
    """

    t: np.ndarray
    names: list[str]
    base: np.ndarray
    drift: np.ndarray
    rotation: np.ndarray
    poses: np.ndarray
    base_mass: float
    base_inertia: float
    base_centre: tuple[float, float]
    method: str
    max_drift: float
    max_rotation: float
    reference_max_drift: float
    reference_max_rotation: float
    reference_difference: tuple[float, float]
    momentum_drift: tuple[float, float]
    dt: float
    iterations: int
    notes: list[str] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)

    def to_json(self) -> dict:
        return {
            "method": self.method,
            "base_mass": float(self.base_mass),
            "base_inertia": float(self.base_inertia),
            "max_drift": float(self.max_drift),
            "max_rotation": float(self.max_rotation),
            "max_rotation_deg": float(math.degrees(self.max_rotation)),
            "final_drift": float(np.linalg.norm(self.drift[-1])),
            "final_rotation": float(self.rotation[-1]),
            "reference_max_drift": float(self.reference_max_drift),
            "reference_max_rotation": float(self.reference_max_rotation),
            "reference_difference_drift": float(self.reference_difference[0]),
            "reference_difference_rotation": float(self.reference_difference[1]),
            "linear_momentum_drift": float(self.momentum_drift[0]),
            "angular_momentum_drift": float(self.momentum_drift[1]),
            "dt": float(self.dt),
            "iterations": int(self.iterations),
            "notes": "; ".join(self.notes),
        }


# ----------------------------------------------------------------------------------------------
# Simulation


def default_settings(model: Model, analysis: Analysis) -> tuple[float, int]:
    """Default (dt, iterations) for a model and motion.

    dt = min(T / STEPS_PER_MOTION, 0.01 / w_max) with T the motion's duration and w_max the
    largest angular speed of any body (pymunk's joints follow straight lines during a step,
    so their error is ~ (w dt)^2 times the lever arm); iterations = :data:`ITERATIONS`.
    """
    T = float(analysis.t[-1] - analysis.t[0])
    w = float(np.max(np.abs(analysis.v[:, :, 2]))) if analysis.v.size else 0.0
    dt = T / STEPS_PER_MOTION if T > 0 else 1e-3
    if w > 0:
        dt = min(dt, 0.01 / w)
    return dt, ITERATIONS


def _driver_coordinate(model: Model, d, poses: dict[str, tuple[float, float, float]], com: dict) -> float:
    """The driven coordinate measured on simulated poses (centre-of-mass poses for bodies, the
    origin's pose for the frame), in the frame's coordinates."""

    def world(body: str, p) -> tuple[float, float]:
        x, y, th = poses[body]
        c = com[body]
        lx, ly = p[0] - c[0], p[1] - c[1]
        cs, sn = math.cos(th), math.sin(th)
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
            e = (math.cos(thg) * ax[0] - math.sin(thg) * ax[1], math.sin(thg) * ax[0] + math.cos(thg) * ax[1])
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
    cs, sn = math.cos(th0), math.sin(th0)
    loc = (cs * rel[0] + sn * rel[1], -sn * rel[0] + cs * rel[1])
    return loc[0] if kind == "x" else loc[1]


def _step_grid(t: np.ndarray, dt_target: float) -> tuple[float, int, np.ndarray | None]:
    """Step, number of steps and the step index of each analysis sample (None when the grid is
    not uniform: the samples are then interpolated linearly)."""
    t0, t1 = float(t[0]), float(t[-1])
    if len(t) > 1:
        h = np.diff(t)
        if np.allclose(h, h[0], rtol=1e-9, atol=0.0):
            sub = max(1, int(math.ceil(h[0] / dt_target - 1e-9)))
            return (t1 - t0) / ((len(t) - 1) * sub), (len(t) - 1) * sub, np.arange(len(t)) * sub
    n = max(1, int(math.ceil((t1 - t0) / dt_target - 1e-9)))
    return (t1 - t0) / n, n, None


def _jumps(model: Model, times: np.ndarray) -> list[int]:
    """Indices k where some law's acceleration jumps between times[k-1] and times[k]."""
    out: set[int] = set()
    for d in model.drivers:
        a = np.asarray(d.law(times)[2], dtype=float)
        if len(a) < 3:
            continue
        diff = np.abs(np.diff(a))
        tiny = 1e-9 * (float(np.max(np.abs(a))) or 1.0)
        out.update(int(k) + 1 for k in np.flatnonzero(diff > 50.0 * float(np.median(diff)) + tiny))
    return sorted(out)


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
    """
    t = np.asarray(analysis.t, dtype=float)
    t0 = float(t[0])
    n = int(round((float(t[-1]) - t0) / dt))
    times = t0 + dt * np.arange(n + 1)
    q0, v0, a0 = analysis.q[0], analysis.v[0], analysis.a[0]
    vh = v0 - 0.5 * dt * a0
    qs = q0 - dt * vh
    gravity = (0.0, 0.0) if floating_base is not None else analysis.gravity
    sim = build_space(
        model, qs, vh, gravity=gravity, iterations=iterations, floating_base=floating_base,
        dt=dt, **build_options,
    )
    space = sim.space
    bodies = sim.moving
    everything = bodies + ([sim.base] if sim.floating else [])
    # the loads are measured with the model's masses and moments (a massless body simulated
    # with a floor mass, and the light auxiliary gears of meshes, count for nothing)
    props = [b.mass_properties() for b in model.bodies]
    m = np.array([p[0] for p in props] + [0.0] * len(sim.auxiliary))
    inertia = np.array([p[2] for p in props] + [0.0] * len(sim.auxiliary))
    g = np.asarray(gravity, dtype=float)
    O = np.asarray(analysis.moment_point, dtype=float)
    weight = m.sum() * g
    names = [b.name for b in model.bodies]
    com = {FRAME: (0.0, 0.0), **{b.name: b.mass_properties()[1] for b in model.bodies}}

    target_t = times + dt  # the step landing on times[k] starts at times[k] - dt: target t + 2 dt
    targets = {d.name: np.asarray(d.law(target_t)[0], dtype=float) for d in model.drivers}
    laws_now = {d.name: np.asarray(d.law(times)[0], dtype=float) for d in model.drivers}
    boost = np.zeros(n + 1, dtype=bool)
    boost[:startup_steps] = True
    for k in _jumps(model, target_t):  # the solver restarts where a law's acceleration jumps
        boost[max(k - 1, 0) : k + startup_steps] = True

    def momenta(group, masses=None, moments=None) -> tuple[float, float, float]:
        px = py = h = 0.0
        for i, b in enumerate(group):
            mk = b.mass if masses is None else masses[i]
            ik = b.moment if moments is None else moments[i]
            p = b.local_to_world(b.center_of_gravity)
            v = b.velocity
            px += mk * v.x
            py += mk * v.y
            h += mk * ((p.x - O[0]) * v.y - (p.y - O[1]) * v.x) + ik * b.angular_velocity
        return px, py, h

    force = np.zeros((n + 1, 2))
    moment = np.zeros(n + 1)
    poses = np.zeros((n + 1, len(names), 3)) if record_poses else np.zeros((0, len(names), 3))
    base = np.zeros((n + 1, 3))
    total = np.zeros((n + 1, 3))
    derr = {d.name: np.zeros(n + 1) for d in model.drivers}
    px0, py0, h0 = momenta(bodies, m, inertia)
    start = time.perf_counter()
    for k in range(n + 1):
        space.iterations = startup_iterations if boost[k] else iterations
        sim.prepare({name: v[k] for name, v in targets.items()}, dt)
        space.step(dt)
        px, py, h = momenta(bodies, m, inertia)
        gm = 0.0
        if g.any():
            for b, mk in zip(bodies, m):
                p = b.position
                gm += mk * ((p.x - O[0]) * g[1] - (p.y - O[1]) * g[0])
        force[k, 0] = weight[0] - (px - px0) / dt
        force[k, 1] = weight[1] - (py - py0) / dt
        moment[k] = gm - (h - h0) / dt
        px0, py0, h0 = px, py, h
        st = {nm: (b.position.x, b.position.y, b.angle) for nm, b in zip(names, sim.bodies)}
        bo = sim.base.position
        st[FRAME] = (bo.x, bo.y, sim.base.angle)
        base[k] = st[FRAME]
        if sim.floating:
            total[k] = momenta(everything)
        if record_poses:
            poses[k] = [st[nm] for nm in names]
        for d in model.drivers:
            derr[d.name][k] = _driver_coordinate(model, d, st, com) - laws_now[d.name][k]
    wall = time.perf_counter() - start
    space.iterations = iterations
    return SimulationRun(times, force, moment, poses, base, derr, total, dt, iterations, wall, sim)


# ----------------------------------------------------------------------------------------------
# Sampling the simulation on the analysis grid


def _law_kinds(model: Model, times: np.ndarray) -> list[str]:
    """Smoothness of the motion at each analysis sample: "smooth", "kink" (a jump of some
    law's jerk: the central difference straddling it is only first order), "left"/"right"
    (a jump of some law's acceleration, the law's value at the sample being the left/right
    limit) or "mixed" (jumps with different sides)."""
    T = float(times[-1] - times[0]) or 1.0
    delta = 1e-6 * T
    kinds = ["smooth"] * len(times)
    for d in model.drivers:
        _, _, a_m = d.law(times - delta)
        _, _, a_0 = d.law(times)
        _, _, a_p = d.law(times + delta)
        a_m, a_0, a_p = (np.asarray(x, dtype=float) for x in (a_m, a_0, a_p))
        scale = float(np.max(np.abs(a_0))) or 1.0
        # a smooth law changes its acceleration by ~ jerk * delta ~ 1e-6 scale across the
        # sample, and its jerk by ~ 1e-6 jerk: a thousand times that is a corner
        dm, dp = a_0 - a_m, a_p - a_0
        jump = np.maximum(np.abs(dm), np.abs(dp)) > 1e-3 * scale
        left_ok = np.abs(dm) <= 1e-3 * scale
        kink = np.abs(dp - dm) > 1e-9 * scale
        for i in range(len(times)):
            if jump[i]:
                side = "left" if left_ok[i] else "right"
                kinds[i] = side if kinds[i] in ("smooth", "kink", side) else "mixed"
            elif kink[i] and kinds[i] == "smooth":
                kinds[i] = "kink"
    return kinds


def _on_grid(run: SimulationRun, analysis: Analysis, idx: np.ndarray | None, kinds: list[str], skip: int,
             jumps: list[int] = ()):
    """Simulated loads at the analysis samples. Where a law is not smooth the central
    difference straddles the corner: the sample is then the linear extrapolation of the
    simulated loads from the side(s) the law's value belongs to (both sides averaged for a
    jerk kink), which is second-order again. ``jumps`` are the simulation steps k where a law's
    acceleration jumps between steps k-1 and k (:func:`_jumps`): a corner that falls between
    analysis samples spoils the steps around it (the drive aims two steps ahead, the solver
    settles after it), so a sample within three steps of one is excluded from the residuals
    (``excluded_samples`` counts them). Returns force, moment, measured mask and counts."""
    n = len(run.t) - 1
    N = len(analysis.t)
    F = np.zeros((N, 2))
    M = np.zeros(N)
    measured = np.ones(N, dtype=bool)
    extrapolated = 0
    series = np.column_stack([run.force, run.moment])
    if idx is None:
        vals = np.column_stack([np.interp(analysis.t, run.t, series[:, c]) for c in range(3)])
        idx_f = np.searchsorted(run.t, analysis.t).clip(0, n)
    else:
        vals = series[idx].copy()
        idx_f = idx
    # corners on analysis samples are handled by their kind; the rest fall between samples
    on_grid = {int(idx_f[i]) + d for i, k in enumerate(kinds) if k in ("left", "right", "mixed") for d in (0, 1)}
    jump_steps = np.asarray(sorted(set(jumps) - on_grid), dtype=int)
    for i, kind in enumerate(kinds):
        s = int(idx_f[i])
        if s < skip:
            measured[i] = False
        if kind == "smooth" and jump_steps.size:
            # a corner between analysis samples: the drive anticipates it by two steps and the
            # solver settles after it, so the steps around it cannot be compared with a curve
            # that jumps there; the sample is left out of the residuals (and counted)
            if np.any((jump_steps >= s - 3) & (jump_steps <= s + 4)):
                measured[i] = False
                continue
        if kind == "smooth":
            continue
        if kind == "kink":  # linear extrapolation from the two nearest steps
            left = 2 * series[s - 1] - series[s - 2] if s >= 2 + skip else None
            right = 2 * series[s + 1] - series[s + 2] if s + 2 <= n else None
        else:  # from the 2nd and 3rd: the first step after an acceleration jump carries an
            # O(dt) error (the joints' position corrections follow the jump one step late)
            left = 3 * series[s - 2] - 2 * series[s - 3] if s >= 3 + skip else None
            right = 3 * series[s + 2] - 2 * series[s + 3] if s + 3 <= n else None
        if kind == "kink":
            sides = [v for v in (left, right) if v is not None]
        elif kind == "left":
            sides = [left] if left is not None else []
        elif kind == "right":
            sides = [right] if right is not None else []
        else:
            sides = []
        if sides:
            vals[i] = np.mean(sides, axis=0)
            extrapolated += 1
        else:
            measured[i] = False
    F[:] = vals[:, :2]
    M[:] = vals[:, 2]
    return F, M, measured, extrapolated


# ----------------------------------------------------------------------------------------------
# Validation


def _relative_poses(run: SimulationRun, idx: np.ndarray | None, t: np.ndarray) -> np.ndarray:
    """Simulated centre-of-mass poses on the analysis grid, in the frame's coordinates."""
    if idx is None:
        idx = np.searchsorted(run.t, t).clip(0, len(run.t) - 1)
    q = run.poses[idx].copy()
    base = run.base[idx]
    rel = q[:, :, :2] - base[:, None, :2]
    q[:, :, :2] = _rotate(-base[:, None, 2], rel)
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
    model, analysis, dt, iterations, settings, scale, idx, limit=None, max_iterations=None, **kw
) -> tuple[SimulationRun | None, list[str], tuple[float, float]]:
    """Run with solver iterations doubled until the measured loads stop changing.

    A run "comes apart" when its loads are not finite or a body strays more than
    HEALTH_LIMIT (rad, or times the model's size) from the analysed motion. With ``limit`` =
    (force, moment), a run is accepted when it holds together and its loads differ from those
    of the run with half the iterations by at most ``limit`` at every step (the solver has
    converged); without, the first run that holds together is accepted. Iterations go up to
    MAX_ITERATIONS, then the next gear model is tried. This only chooses the solver effort: the
    verdict is the residual criterion of :func:`validate`. Returns the run (None if none held
    together), notes and the last change (force, moment) between doublings."""
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
                        model, analysis, dt, it, startup_steps=settings.startup_steps,
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
                change = (
                    float(np.max(np.linalg.norm(run.force - prev.force, axis=1))),
                    float(np.max(np.abs(run.moment - prev.moment))),
                )
            if healthy:
                if limit is None:
                    return run, notes, change
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
    if best is None:
        return None, notes, (math.inf, math.inf)
    _, run, change, gm = best
    notes.append(f"kept the best converged run ({run.iterations} iterations" + (f", {gm} gears)" if gm else ")"))
    return run, notes, change


def _model_scale(analysis: Analysis) -> float:
    r = np.linalg.norm(analysis.q[:, :, :2] - np.asarray(analysis.moment_point), axis=2)
    return max(float(r.max()) if r.size else 0.0, 1e-3)


def validate(
    model: Model,
    analysis: Analysis,
    unbalanced_peaks: tuple[float, float],
    settings: ValidationSettings | None = None,
    expect: tuple[str, ...] = (),
) -> StageValidation:
    """Simulate ``model`` in pymunk along ``analysis``' motion and compare the loads.

    ``unbalanced_peaks`` = (F0, M0): the unbalanced stage's analytic peak force and moment,
    the denominators of every relative number. ``expect`` names the loads this stage claims to
    cancel ("force", "moment"): their simulated peaks must then also be at most
    ``settings.balance_tolerance`` times F0 (M0). Passes when the residuals are at most
    ``settings.tolerance`` and every expectation holds.
    """
    settings = settings or ValidationSettings()
    wall0 = time.perf_counter()
    dt_default, it_default = default_settings(model, analysis)
    dt_target = settings.dt or dt_default
    iterations = settings.iterations or it_default
    dt, nsteps, idx = _step_grid(np.asarray(analysis.t, dtype=float), dt_target)
    scale = _model_scale(analysis)
    F0, M0 = (float(x) for x in unbalanced_peaks)
    limit = (
        settings.tolerance / 10.0 * (F0 if F0 > 0 else 1.0),
        settings.tolerance / 10.0 * (M0 if M0 > 0 else 1.0),
    )
    run, notes, change = _run_adaptive(
        model, analysis, dt, iterations, settings, scale, idx, limit=limit, mass_floor=settings.mass_floor
    )
    fden = F0 if F0 > 0 else 1.0
    mden = M0 if M0 > 0 else 1.0
    if F0 <= 0 or M0 <= 0:
        notes.append("an unbalanced peak is zero: that residual is absolute")
    N = len(analysis.t)
    if run is None:
        nan = np.full(N, np.nan)
        return StageValidation(
            analysis.t, np.full((N, 2), np.nan), nan, nan, nan, np.zeros(N, bool), math.inf, math.inf,
            math.inf, math.inf, F0, M0, {d.name: math.inf for d in model.drivers}, math.inf, math.inf,
            math.inf, dt, nsteps, MAX_ITERATIONS, settings.tolerance, settings.balance_tolerance,
            tuple(expect), False, ["the simulation failed"], N, 0, [], notes,
            timing={"total_s": time.perf_counter() - wall0},
        )
    kinds = _law_kinds(model, np.asarray(analysis.t, dtype=float))
    F, M, measured, extrapolated = _on_grid(run, analysis, idx, kinds, settings.skip_initial_steps,
                                            _jumps(model, run.t))
    ferr = np.linalg.norm(F - analysis.force, axis=1)
    merr = np.abs(M - analysis.moment)
    fres = float(np.max(ferr[measured])) / fden if measured.any() else math.inf
    mres = float(np.max(merr[measured])) / mden if measured.any() else math.inf
    # the balance claims concern the inertial part: less the links' weight and its moment
    W, Ms = analysis.static_load()
    fpk = float(np.max(np.linalg.norm((F - W)[measured], axis=1))) / fden if measured.any() else math.inf
    mpk = float(np.max(np.abs((M - Ms)[measured]))) / mden if measured.any() else math.inf
    track = {k: float(np.max(np.abs(v))) for k, v in run.driver_error.items()}
    qs = _relative_poses(run, idx, np.asarray(analysis.t, dtype=float))
    dpos = float(np.max(np.linalg.norm(qs[:, :, :2] - analysis.q[:, :, :2], axis=2))) if qs.size else 0.0
    dang = float(np.max(np.abs(qs[:, :, 2] - analysis.q[:, :, 2]))) if qs.size else 0.0
    reasons = []
    tol = settings.tolerance
    if not fres <= tol:
        reasons.append(f"force residual {fres:.3g} > {tol:g}")
    if not mres <= tol:
        reasons.append(f"moment residual {mres:.3g} > {tol:g}")
    for what, pk in (("force", fpk), ("moment", mpk)):
        if what in expect and not pk <= settings.balance_tolerance:
            reasons.append(f"{what} not balanced: simulated peak {pk:.3g} of the unbalanced > {settings.balance_tolerance:g}")
    notes = notes + list(run.sim.notes)
    if run.sim.floored:
        notes.append(
            f"simulated with mass/moment floors ({settings.mass_floor:g} of the largest): "
            + ", ".join(run.sim.floored)
        )
    excluded = int(np.count_nonzero(~measured))
    return StageValidation(
        t=np.asarray(analysis.t, dtype=float), force=F, moment=M, force_error=ferr, moment_error=merr,
        measured=measured, force_residual=fres, moment_residual=mres, force_peak=fpk, moment_peak=mpk,
        unbalanced_force_peak=F0, unbalanced_moment_peak=M0, tracking_error=track,
        tracking_error_max=max(track.values(), default=0.0), pose_error_position=dpos,
        pose_error_angle=dang, dt=run.dt, steps=nsteps, iterations=run.iterations,
        tolerance=tol, balance_tolerance=settings.balance_tolerance, expect=tuple(expect),
        passed=not reasons, reasons=reasons, excluded_samples=excluded,
        extrapolated_samples=extrapolated, floored_bodies=list(run.sim.floored), notes=notes,
        timing={"simulation_s": run.wall, "total_s": time.perf_counter() - wall0},
    )


# ----------------------------------------------------------------------------------------------
# Reactionless demonstration


def _rotate(phi: np.ndarray, x: np.ndarray) -> np.ndarray:
    c, s = np.cos(phi), np.sin(phi)
    return np.stack([c * x[..., 0] - s * x[..., 1], s * x[..., 0] + c * x[..., 1]], -1)


def _cross(u: np.ndarray, w: np.ndarray) -> np.ndarray:
    return u[..., 0] * w[..., 1] - u[..., 1] * w[..., 0]


def _conservation_solution(model: Model, analysis: Analysis, mb: float, ib: float, centre: np.ndarray):
    """Base motion from the conservation of momentum along the analysed relative motion.

    The analysis gives every body's centre of mass rho_k, angle theta_k and their rates in the
    frame's coordinates. With the base at angle phi and the total centre of mass r_G (moving
    uniformly with the initial momentum), r_k = r_G + R(phi) d_k, d_k = rho_k - s,
    s = (m_B c_B + sum m_k rho_k) / M; the angular momentum about r_G is
    sum m_k d_k x d_k' + phi' (sum m_k |d_k|^2 + sum I_k + I_B) + sum I_k theta_k' (base
    included in the sums of m), constant, which gives phi' (integrated by trapezoids).
    Returns (phi (N,), base origin (N, 2))."""
    t = np.asarray(analysis.t, dtype=float)
    q, v = analysis.q, analysis.v
    props = [b.mass_properties() for b in model.bodies]
    m = np.array([p[0] for p in props])
    inertia = np.array([p[2] for p in props])
    M = mb + m.sum()
    s = (mb * centre + np.einsum("k,nkd->nd", m, q[:, :, :2])) / M
    sd = np.einsum("k,nkd->nd", m, v[:, :, :2]) / M
    d = q[:, :, :2] - s[:, None, :]
    dd = v[:, :, :2] - sd[:, None, :]
    dB = centre[None, :] - s
    num = np.einsum("k,nk->n", m, _cross(d, dd)) + mb * _cross(dB, -sd) + v[:, :, 2] @ inertia
    den = np.einsum("k,nk->n", m, np.sum(d**2, axis=-1)) + mb * np.sum(dB**2, axis=-1) + inertia.sum() + ib
    phid = (num[0] - num) / den
    phi = np.concatenate([[0.0], np.cumsum(0.5 * (phid[1:] + phid[:-1]) * np.diff(t))])
    p0 = np.einsum("k,kd->d", m, v[0, :, :2])
    rG = s[0][None, :] + np.outer(t - t[0], p0 / M)
    origin = rG - _rotate(phi, s)
    return phi, origin


def free_floating(
    model: Model,
    analysis: Analysis,
    base_mass: float = 10.0,
    base_inertia: float | None = None,
    settings: ValidationSettings | None = None,
    simulate_pymunk: bool = True,
) -> FreeFloating:
    """The mechanism moving on a free base, without gravity.

    The frame becomes a body of mass ``base_mass`` (default 10 kg) whose centre of gravity is
    the analysis' moment point, with moment of inertia ``base_inertia`` (default
    (2/3) base_mass reach^2, a square plate of side 2 reach; reach = the largest distance of a
    centre of mass from that point during the motion). Every driver and frame joint acts on the
    base; gear pairs carried by the frame mesh on it (``gear_model="mesh"``, which conserves
    angular momentum). The base starts at rest. A reactionless stage leaves it where it is.
    When the simulation does not hold together (a mesh between gears of large inertia and
    small mass or radius converges slowly in pymunk's solver), or ``simulate_pymunk`` is False,
    the exact conservation solution is returned instead (``method = "momentum"``).
    """
    settings = settings or ValidationSettings()
    wall0 = time.perf_counter()
    reach = _model_scale(analysis)
    bi = float(base_inertia) if base_inertia is not None else (2.0 / 3.0) * base_mass * reach**2
    centre = np.asarray(analysis.moment_point, dtype=float)
    names = [b.name for b in model.bodies]
    t = np.asarray(analysis.t, dtype=float)
    phi_ref, origin_ref = _conservation_solution(model, analysis, float(base_mass), bi, centre)
    drift_ref = origin_ref + _rotate(phi_ref, np.broadcast_to(centre, origin_ref.shape)) - centre
    notes: list[str] = []
    run = None
    dt, it = 0.0, 0
    massless = [b.name for b in model.bodies if b.mass_properties()[0] <= 0.0]
    if simulate_pymunk and massless:
        simulate_pymunk = False
        notes.append(
            "massless bodies (" + ", ".join(massless) + "): pymunk needs a mass, which would move "
            "the free base; conservation solution used"
        )
    if simulate_pymunk:
        dt_default, it_default = default_settings(model, analysis)
        dt, nsteps, idx = _step_grid(t, settings.dt or dt_default)
        it = settings.iterations or it_default
        run, notes, _ = _run_adaptive(
            model, analysis, dt, it, settings, reach, idx, max_iterations=4 * it,
            floating_base=(float(base_mass), bi, (float(centre[0]), float(centre[1]))),
        )
        if run is not None:
            mom = run.momentum - run.momentum[0]
            dp = float(np.max(np.linalg.norm(mom[:, :2], axis=1)))
            dh = float(np.max(np.abs(mom[:, 2])))
            # gross momenta of the mechanism (sums of magnitudes: a balanced stage nets zero)
            mk = np.array([b.mass_properties()[0] for b in model.bodies])
            ik = np.array([b.mass_properties()[2] for b in model.bodies])
            speed = np.linalg.norm(analysis.v[:, :, :2], axis=2)
            arm = np.linalg.norm(analysis.q[:, :, :2] - centre, axis=2)
            p_scale = float(np.max(speed @ mk)) or 1.0
            h_scale = float(np.max((arm * speed) @ mk + np.abs(analysis.v[:, :, 2]) @ ik)) or 1.0
            if dh > 1e-3 * h_scale or dp > 1e-3 * p_scale:
                notes.append(f"the simulation lost {dh:.3g} N m s of angular momentum")
                run = None
        if run is None:
            notes.append("pymunk did not hold the mechanism together: conservation solution used")
    if run is not None:
        if idx is None:
            idx = np.searchsorted(run.t, t).clip(0, len(run.t) - 1)
        base = run.base[idx]
        poses = run.poses[idx].copy()
        method = "pymunk"
        momentum_drift = (dp, dh)
        it = run.iterations
    else:
        base = np.column_stack([origin_ref, phi_ref])
        poses = analysis.q.copy()
        poses[:, :, :2] = origin_ref[:, None, :] + _rotate(phi_ref[:, None], analysis.q[:, :, :2])
        poses[:, :, 2] = analysis.q[:, :, 2] + phi_ref[:, None]
        method = "momentum"
        momentum_drift = (0.0, 0.0)
    for k, b in enumerate(model.bodies):  # centre-of-mass poses -> body frame poses
        cl = np.asarray(b.mass_properties()[1])
        poses[:, k, :2] -= _rotate(poses[:, k, 2], cl)
    drift = base[:, :2] + _rotate(base[:, 2], np.broadcast_to(centre, base[:, :2].shape)) - centre
    rotation = base[:, 2].copy()
    return FreeFloating(
        t=t, names=names, base=base, drift=drift, rotation=rotation, poses=poses,
        base_mass=float(base_mass), base_inertia=bi, base_centre=(float(centre[0]), float(centre[1])),
        method=method, max_drift=float(np.max(np.linalg.norm(drift, axis=1))),
        max_rotation=float(np.max(np.abs(rotation))),
        reference_max_drift=float(np.max(np.linalg.norm(drift_ref, axis=1))),
        reference_max_rotation=float(np.max(np.abs(phi_ref))),
        reference_difference=(
            float(np.max(np.linalg.norm(drift - drift_ref, axis=1))), float(np.max(np.abs(rotation - phi_ref)))
        ),
        momentum_drift=momentum_drift, dt=dt, iterations=it, notes=notes,
        timing={"total_s": time.perf_counter() - wall0, **({"simulation_s": run.wall} if run is not None else {})},
    )
