"""The torque-driven run: a check of the inverse dynamics, not only of the kinematics.

Why
    The position-driven validation (:mod:`.loads`) imposes the motion and measures the loads
    from the momenta of bodies with the model's own masses: for a mechanism with one degree of
    freedom per driver it checks the kinematics and the momentum bookkeeping, and a wrong mass
    in the model goes unnoticed (the simulation uses the same wrong mass). Here the drivers are
    removed: each actuator applies the effort the engine computed (torque or force, see
    :class:`balpipe.validate.space._Actuator`), pymunk integrates the dynamics of the jointed
    mechanism open loop, and the simulated motion is compared with the planned one. Efforts
    from a model whose masses or inertias differ from the simulated mechanism's accelerate it
    differently, and the motion drifts away from the plan.

Method
    The efforts are the engine's, computed on the simulation's own step times (the analysis
    of the same model on a finer grid; no interpolation). Where a law's acceleration jumps (a
    bang-bang or trapezoidal law's corner, a path's curvature at a rounded corner), the step
    whose velocity window holds the jump gets the window's mean effort (:func:`_average_jumps`):
    the effort at the step's time alone gave that window the wrong impulse, up to the jump
    times dt, and the open-loop run carried it to the end (paper 003's bang-bang plans tracked
    to 4e-4 .. 8.8e-4 of the travel against the 1e-3 tolerance, 2.4e-7 .. 2.0e-6 since). The
    run starts like the position-driven one (one step before t0, so that the first step lands
    on q(t0) with the velocity of t0 + dt/2) and uses its time step and converged solver
    iterations; a run that starts moving leaves its first sample out of the load residuals. Bodies that
    pymunk cannot simulate massless (mass or moment below ``mass_floor`` of the largest) get
    the floor as a real part of the body: the efforts are computed for the model with those
    floor parts, so the floors are compensated exactly and their share of the effort is
    reported (``floor_effort_share``). The loads are measured, as in :mod:`.loads`, from the
    momenta of the bodies with the model's own masses, along the simulated motion.

Pass criterion and why it is meaningful
    ``tracking_error`` of a driver = max |q_sim - q_plan| over the motion / its travel
    |q(T) - q(t0)|. The run passes when the largest is at most ``tracking_tolerance``
    (default 1e-3). Open-loop integration drifts, so the same run is repeated with every
    effort 10 % low (what every mass and inertia 10 % low in the analysis gives: the inverse
    dynamics is linear in them; low rather than high, so that the motion stays inside the
    planned range: overshooting took the Scott-Russell mechanism through its singular
    configuration at 90 deg): ``calibration_error`` is the tracking error that such a model
    error produces, about 0.1 of the travel for a mechanism dominated by inertia (the motion
    scales with the effort). The verdict needs calibration_error / tracking_error >= 10
    as well (``resolution``: the check would see a 1 % error of the whole model's inertia).
    Measured at the defaults (tests/validate/test_torque.py, specs/): see README "Validation".
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field

import numpy as np

from ..display import numbers
from ..engine import Analysis, analyse
from ..model import Attachment, Model
from .loads import _on_grid, loads_at  # the same sampling of the loads as the position-driven check
from .run import SimulationRun, _relative_poses, initial_state, model_scale, simulate
from .extend import continued, is_moving_start
from .settings import (HEALTH_LIMIT, ITERATIONS, ValidationSettings, _jumps, _law_kinds, _step_grid, default_settings,
                       Refinement, jump_times, refine_step, step_setting)
from .applied import COULOMB_NOTE, AppliedLoads
from .space import build_space
from .verdict import Verdict

__all__ = ["TorqueDriven", "torque_driven", "floored_model", "TRACKING_TOLERANCE", "CALIBRATION_FACTOR"]

#: largest tracking error of a driven coordinate, as a fraction of its travel
TRACKING_TOLERANCE = ValidationSettings.tracking_tolerance
#: the calibration run's efforts (every mass and inertia of the analysis 10 % low: the motion stays
#: inside the planned range, away from the workspace limits that overshooting may cross)
CALIBRATION_FACTOR = 0.9
#: calibration_error / tracking_error needed: the run must resolve a tenth of that model error
MIN_RESOLUTION = 10.0
#: the calibration run stops once its tracking error is this many times the run's own: the largest
#: resolution any verdict asks for (:func:`torque_driven`'s cheaper tries keep a run only at ten
#: times :data:`MIN_RESOLUTION`), so a longer run could not change one
CALIBRATION_STOP = 10.0 * MIN_RESOLUTION

#: the calibration run's first steps (and those after a law's jump) at the run's own solver
#: iterations, not the start-up's: its error is that of efforts 10 % off (where it stops, a hundred
#: times the run's own), which the solver's accuracy in the first steps does not move. Measured on
#: specs/: every calibration error and resolution the same to 5.3e-8 (relative), no verdict
#: changed, and the 126 calibration runs (most stopped a few percent of the motion in, where the
#: start-up's 10 steps at 5000 iterations cost more than the rest) 1.71 -> 1.17 s of CPU in the
#: simulated build
CALIBRATION_STARTUP = False

#: the efforts' relative change of the sensitivity run (:func:`_torque_driven_once`): a run off its
#: plan that this change moves by :data:`AMPLIFIED` of its own error is unstable open loop, and
#: its error, explained by a change of the efforts far below any design error, shows nothing false
SENSITIVITY = 1e-4
AMPLIFIED = 0.1


@dataclass
class TorqueDriven(Verdict):
    """One stage driven by its actuators' efforts.

    Curves on the analysis grid ``t``: ``force`` (N, 2), ``moment`` (N,): simulated shaking
    loads; ``tracking`` (driver -> (N,)): q_sim - q_plan (rad or m). Scalars: ``tracking_error``
    (driver -> max |q_sim - q_plan| / travel), ``travel`` (rad or m), ``tracking_error_max``;
    ``calibration_error``: the same with efforts ``CALIBRATION_FACTOR`` times the engine's;
    ``resolution`` = calibration_error / tracking_error_max; ``force_residual``,
    ``moment_residual``: max |simulated - analytic| load / the reference loads; ``force_peak``,
    ``moment_peak``: simulated inertial peaks (less the links' weight and its moment) / the same;
    ``floored_bodies`` and ``floor_effort_share`` (largest effort of the floor parts / peak
    effort).
    """

    t: np.ndarray
    force: np.ndarray
    moment: np.ndarray
    tracking: dict[str, np.ndarray]
    tracking_error: dict[str, float]
    travel: dict[str, float]
    tracking_error_max: float
    calibration_error: float
    resolution: float
    force_residual: float
    moment_residual: float
    force_reference: float
    moment_reference: float
    force_peak: float
    moment_peak: float
    tracking_tolerance: float
    dt: float
    steps: int
    iterations: int
    floored_bodies: list[str]
    floor_effort_share: float
    passed: bool
    reasons: list[str]
    notes: list[str] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)
    unconfirmed: bool = False
    remedy: str = ""
    #: for a run off its plan: how far efforts times (1 + SENSITIVITY) move it, over its own
    #: tracking error (nan where not measured; inf where that run came apart)
    amplification: float = math.nan
    #: the calibration run stopped once its error was CALIBRATION_STOP times the run's: its
    #: ``calibration_error`` and the ``resolution`` are lower bounds
    calibration_stopped: bool = False
    #: the samples that enter the load residuals, the samples whose loads were extrapolated across a
    #: law's corner, and the largest deviation of the simulated centres of mass from the analysis
    #: (m, rad): what a position-driven verdict reads (:mod:`balpipe.validate.shared`)
    measured: np.ndarray | None = None
    extrapolated_samples: int = 0
    pose_error: tuple[float, float] = (math.nan, math.nan)

    def to_json(self) -> dict:
        return {
            **self.verdict_json(),
            "tracking_error": {k: float(v) for k, v in sorted(self.tracking_error.items())},
            "travel": {k: float(v) for k, v in sorted(self.travel.items())},
            "tracking_error_max": float(self.tracking_error_max),
            "tracking_tolerance": float(self.tracking_tolerance),
            "calibration_factor": float(CALIBRATION_FACTOR),
            "calibration_error": float(self.calibration_error),
            "resolution": float(self.resolution),
            "min_resolution": float(MIN_RESOLUTION),
            "calibration_stopped": bool(self.calibration_stopped),
            "force_residual": float(self.force_residual),
            "moment_residual": float(self.moment_residual),
            "force_reference": float(self.force_reference),
            "moment_reference": float(self.moment_reference),
            "force_peak": float(self.force_peak),
            "moment_peak": float(self.moment_peak),
            "dt": float(self.dt),
            "steps": int(self.steps),
            "iterations": int(self.iterations),
            "floored_bodies": ",".join(self.floored_bodies),
            "floor_effort_share": float(self.floor_effort_share),
            "notes": "; ".join(self.notes),
        }


def floored_model(model: Model, mass_floor: float) -> tuple[Model, list[str]]:
    """``model`` with the masses and moments pymunk simulates: a body lighter (of smaller
    moment) than ``mass_floor`` of the largest gets a part at its centre of mass that brings it
    to the floor (the same rule as :func:`balpipe.validate.space.build_space`)."""
    probe = build_space(model, np.zeros((len(model.bodies), 3)), mass_floor=mass_floor, drive=False)
    out = model
    for b, pb in zip(model.bodies, probe.bodies):
        m, com, inertia = b.mass_properties()
        dm, di = pb.mass - m, pb.moment - inertia
        if dm > 0 or di > 0:
            part = Attachment("pymunk floor", max(dm, 0.0), tuple(com), max(di, 0.0), kind="part")
            out = out.replace_body(b.with_attachments(part))
    return out, list(probe.floored)


def auxiliary_gear_parts(sim_model: Model, mass_floor: float, pose: np.ndarray) -> dict[str, list[Attachment]]:
    """The parts that the auxiliary gears of :func:`balpipe.validate.space.build_space` add to
    ``sim_model`` (the model pymunk simulates), by body name: a gear pair whose gears and carrier
    all move and whose gears are coaxial gets two light gears pinned to the carrier and locked to
    the gears (ratio 1), each of ``mass_floor`` times the largest mass and moment. Each is a point
    mass on the carrier at its pivot (it moves with that point) and a pure inertia on the gear it
    is locked to (it turns with it): its kinetic energy, hence its share of every effort, is
    exactly theirs. Uncompensated, a 3R arm's counter-rotating discs on its moving links
    (carrier masses 77 kg and 19 kg) were driven with 7.7 kg and 0.73 kg m^2 of such gears the
    efforts did not know of, and its third joint moved half its travel."""
    probe = build_space(sim_model, pose, mass_floor=mass_floor, drive=False)
    by_body = {id(pb): b for b, pb in zip(sim_model.bodies, probe.bodies)}
    parts: dict[str, list[Attachment]] = {}
    for mesh in probe.meshes:
        if not mesh.auxiliary:
            continue
        carrier = by_body[id(mesh.c)]
        com = carrier.mass_properties()[1]
        for aux, gear, pivot in ((mesh.a, mesh.ta, mesh.oa), (mesh.b, mesh.tb, mesh.ob)):
            geared = by_body[id(gear)]
            at = (com[0] + pivot[0], com[1] + pivot[1])
            parts.setdefault(carrier.name, []).append(
                Attachment(f"pymunk auxiliary gear {mesh.name}", float(aux.mass), at, 0.0, kind="part"))
            parts.setdefault(geared.name, []).append(
                Attachment(f"pymunk auxiliary gear {mesh.name}", 0.0, tuple(geared.mass_properties()[1]),
                           float(aux.moment), kind="part"))
    return parts


def _travel(model: Model, t: np.ndarray) -> dict[str, float]:
    out = {}
    for d in model.drivers:
        q = np.asarray(d.law(t)[0], dtype=float)
        out[d.name] = float(max(abs(q[-1] - q[0]), np.max(np.abs(q - q[0]))))
    return out


def _floor_share(efforts: dict[str, np.ndarray], analysis: Analysis, analytic_model: Model,
                 times: np.ndarray, idx: np.ndarray | None = None) -> float:
    """Largest effort of the floor parts / the peak effort: ``efforts`` (with the floor parts, on
    the step times ``times``) less the analytic model's own. Where the analysis' samples are
    steps (``idx``), at those samples, less the analysis' own efforts, leaving out the samples
    where a law's acceleration jumps (their analysed effort may be the other side's, one ulp of
    time away: a slider's floor moment, which adds nothing, was reported as 64 % of the peak
    effort); else over every step time, the analytic model analysed there (a call of the engine
    per stage for a figure of the page, a twentieth of the simulated build before)."""
    if idx is not None and len(idx) == len(analysis.t):
        smooth = np.array([k in ("smooth", "kink") for k in _law_kinds(analytic_model, np.asarray(analysis.t, dtype=float))])
        if smooth.any():
            at = np.asarray(idx, dtype=int)[smooth]
            bare = {k: np.asarray(v, dtype=float)[smooth] for k, v in analysis.efforts.items()}
            peak = max((float(np.max(np.abs(v))) for v in bare.values()), default=0.0) or 1.0
            return max(float(np.max(np.abs(efforts[k][at] - bare[k]))) for k in bare) / peak
    bare = analyse(analytic_model, times, analysis.gravity, analysis.moment_point).efforts
    peak = max((float(np.max(np.abs(v))) for v in bare.values()), default=0.0) or 1.0
    return max(float(np.max(np.abs(efforts[k] - np.asarray(bare[k], dtype=float)))) for k in bare) / peak


@dataclass
class _Plan:
    """What every torque-driven run of a stage shares: the models (laws continued), the step grid
    and the engine's efforts on it (the analysis of the model with its floor parts on the
    simulation's step times), the floors' share of the effort, the drivers' travel."""

    model: Model
    analytic_model: Model
    sim_model: Model
    floored: list[str]
    efforts: dict[str, np.ndarray]
    share: float
    notes: list[str]
    travel: dict[str, float]
    dt: float
    nsteps: int
    idx: np.ndarray | None
    n: int
    times: np.ndarray
    iterations: int
    applied: AppliedLoads | None = None


def _plan(model: Model, analysis: Analysis, settings: ValidationSettings, analytic_model: Model | None,
          dt: float | None) -> _Plan:
    """The plan of :func:`_torque_driven_once` (see there)."""
    distinct = analytic_model is not None and analytic_model is not model
    model = continued(model, analysis)
    analytic_model = continued(analytic_model, analysis) if distinct else model
    t = np.asarray(analysis.t, dtype=float)
    dt_default, it_default = default_settings(model, analysis)
    dt, nsteps, idx = _step_grid(t, dt or settings.dt or dt_default)
    n = int(round((float(t[-1]) - float(t[0])) / dt))
    times = float(t[0]) + dt * np.arange(n + 1)
    sim_model, floored = floored_model(model, settings.mass_floor)
    effort_model = sim_model
    if distinct:  # the analytic model with the simulated mechanism's floor parts
        effort_model = analytic_model
        for b in sim_model.bodies:
            extra = [a for a in b.attachments if a.name == "pymunk floor"]
            if extra:
                effort_model = effort_model.replace_body(effort_model.body(b.name).with_attachments(*extra))
    auxiliary = auxiliary_gear_parts(sim_model, settings.mass_floor, initial_state(sim_model, analysis, dt)[0])
    for name, parts in sorted(auxiliary.items()):
        effort_model = effort_model.replace_body(effort_model.body(name).with_attachments(*parts))
    fine = analyse(effort_model, times, analysis.gravity, analysis.moment_point)
    efforts = {k: np.asarray(v, dtype=float) for k, v in fine.efforts.items()}
    notes: list[str] = []
    share = 0.0
    if floored or auxiliary:  # before the jumps' averaging, which the bare efforts do not have
        share = _floor_share(efforts, analysis, analytic_model, times, idx)
        loads = (f"the efforts include their inertial loads, {numbers.num(100 * share, 3)} % of the peak effort" if share > 1e-9
                 else "along this motion they add no load to the efforts")
        size = f"{100 * settings.mass_floor:g} % of the largest mass and moment"
        what = (["floor parts (" + ", ".join(floored) + f": {size})"] if floored else []) + (
            [f"the auxiliary gears of coaxial gear pairs on moving carriers ({size})"] if auxiliary else [])
        notes.append("simulated with " + " and ".join(what) + "; " + loads)
    _average_jumps(efforts, effort_model, analysis, times, dt)
    travel = _travel(analytic_model, t)
    applied = AppliedLoads(sim_model, fine, times) if sim_model.loads else None
    if applied is not None and applied.has_coulomb:
        notes.append(COULOMB_NOTE)
    return _Plan(model, analytic_model, sim_model, floored, efforts, share, notes, travel, dt, nsteps, idx, n, times,
                 int(it_default or ITERATIONS), applied)


def _average_jumps(efforts: dict[str, np.ndarray], model: Model, analysis: Analysis, times: np.ndarray,
                   dt: float) -> None:
    """Where a law's acceleration jumps at t_j inside the velocity window [t_k - dt/2, t_k + dt/2]
    of the step landing on t_k (pymunk's velocities live at half steps), the effort there is the
    window's mean: the effort just before t_j over its first part, just after over the rest (in
    place). The effort at t_k alone gives the window the wrong impulse, up to the jump times dt,
    which the open-loop run carries to the end of the motion."""
    jumps = jump_times(model, times)
    if not jumps:
        return
    eps = 1e-9 * (float(times[-1] - times[0]) or 1.0)
    at = np.array([[tj - eps, tj + eps] for tj in jumps]).reshape(-1)
    side = analyse(model, at, analysis.gravity, analysis.moment_point).efforts
    for j, tj in enumerate(jumps):
        k = int(round((tj - float(times[0])) / dt))
        if not 0 <= k < len(times):
            continue
        w = (tj - (float(times[k]) - 0.5 * dt)) / dt  # the window's part before the jump
        for name, e in efforts.items():
            e[k] = w * side[name][2 * j] + (1.0 - w) * side[name][2 * j + 1]


def _torque_driven_once(
    model: Model,
    analysis: Analysis,
    settings: ValidationSettings | None = None,
    *,
    analytic_model: Model | None = None,
    reference: tuple[float, float] | None = None,
    dt: float | None = None,
    iterations: int | None = None,
    calibrate: bool = True,
    trial: bool = False,
    plan: _Plan | None = None,
    calibration_stop: float | None = CALIBRATION_STOP,
) -> TorqueDriven:
    """Drive ``model`` in pymunk by the efforts of ``analytic_model`` (default ``model``) and
    compare the motion with ``analysis`` (the analysis of ``analytic_model``: the planned
    motion and loads).

    ``reference`` = (force, moment): the denominators of the load residuals (default the
    analysis' peaks). ``dt``/``iterations``: those of the position-driven validation (default
    :func:`default_settings`; ``settings.iterations``). ``calibrate``: also run with the efforts
    times ``CALIBRATION_FACTOR`` (``calibration_error``; NaN when False). ``trial``: a try of
    :func:`torque_driven`'s cheaper solver efforts, which only a pass by ten times over keeps: the
    run stops as soon as a body strays ten times :data:`~balpipe.validate.settings.HEALTH_LIMIT`
    (rad, or of the model's size) from the plan, and a run that came apart gets no calibration run.
    ``plan``: the efforts and step grid (:func:`_plan`), shared by the tries of one stage.
    ``calibration_stop``: the calibration run stops once its tracking error is this many times the
    run's own (default :data:`CALIBRATION_STOP`, all that any verdict reads; ``calibration_error``
    and ``resolution`` are then lower bounds, ``calibration_stopped``); None: it runs to the end.
    """
    settings = settings or ValidationSettings()
    wall0 = time.perf_counter()
    if plan is None:
        plan = _plan(model, analysis, settings, analytic_model, dt)
    model, analytic_model, sim_model, floored = plan.model, plan.analytic_model, plan.sim_model, plan.floored
    efforts, share, travel, notes = plan.efforts, plan.share, plan.travel, list(plan.notes)
    t = np.asarray(analysis.t, dtype=float)
    dt, nsteps, idx, n, times = plan.dt, plan.nsteps, plan.idx, plan.n, plan.times
    iterations = int(iterations or settings.iterations or plan.iterations or ITERATIONS)

    def run(factor: float, abort: tuple[float, float] | None = None, stop_at: float | None = None,
            boost: bool = True) -> SimulationRun | None:
        with np.errstate(all="ignore"):
            try:
                r = simulate(
                    sim_model, analysis, dt, iterations, startup_steps=settings.startup_steps,
                    startup_iterations=max(settings.startup_iterations if boost else 0, iterations),
                    efforts={k: factor * v for k, v in efforts.items()}, measure_with=model,
                    mass_floor=settings.mass_floor, abort=abort, applied=plan.applied,
                    stop_at=None if stop_at is None else (stop_at, travel),
                )
            except (ZeroDivisionError, ValueError, OverflowError, FloatingPointError):
                return None
        ok = np.isfinite(r.force).all() and all(np.isfinite(v).all() for v in r.driver_error.values())
        return r if ok else None

    def relative_error(r: SimulationRun | None) -> float:
        if r is None:
            return math.inf
        return max((float(np.max(np.abs(e))) / (travel[k] or 1.0) for k, e in r.driver_error.items()), default=0.0)

    main = run(1.0, (10 * HEALTH_LIMIT, model_scale(analysis)) if trial else None)
    calib, partial = math.nan, False
    if calibrate and not (trial and main is None):
        # the calibration only has to show an error CALIBRATION_STOP times the run's own (every verdict
        # asks for at most that resolution): it stops there, and its error is then a lower bound. It
        # runs at its own solver effort from the start (no start-up boost: :data:`CALIBRATION_STARTUP`)
        own = relative_error(main)
        enough = (calibration_stop * own if calibration_stop is not None and main is not None and 0.0 < own < math.inf
                  else None)
        low = run(CALIBRATION_FACTOR, stop_at=enough, boost=CALIBRATION_STARTUP)
        calib, partial = relative_error(low), low is not None and low.stopped
        if partial:
            notes.append(f"the calibration run stopped at t = {numbers.num(low.t[-1], 4)} s, once its tracking error was "
                         f"{calibration_stop:g} times the run's (what the verdict needs): its error and the "
                         f"resolution are lower bounds")
    F0, M0 = reference if reference is not None else (analysis.max_inertial_force, analysis.max_inertial_moment)
    F0 = F0 if F0 > 0 else 1.0
    M0 = M0 if M0 > 0 else 1.0
    N = len(t)
    grid = idx if idx is not None else np.searchsorted(times, t).clip(0, n)
    reasons: list[str] = []
    if main is None:
        nan = np.full(N, np.nan)
        reasons.append("the torque-driven simulation came apart")
        return TorqueDriven(
            t, np.full((N, 2), np.nan), nan, {}, {d.name: math.inf for d in model.drivers}, travel, math.inf,
            calib, 0.0, math.inf, math.inf, F0, M0, math.inf, math.inf, settings.tracking_tolerance, dt, nsteps, iterations, floored,
            share, False, reasons, notes, {"total_s": time.perf_counter() - wall0},
        )
    kinds = _law_kinds(analytic_model, t)
    # a run that starts moving starts on the constraints: its first step lacks the correction that
    # a running simulation's velocities carry (extend.settling_steps), and an open-loop run has no
    # run-in to settle it: the first sample's load is left out of the residuals (not the tracking)
    skip = 1 if is_moving_start(analysis) else 0
    if skip:
        notes.append("moving at the start: the first sample is left out of the load residuals (pymunk's first step "
                     "lacks the correction of a running simulation)")
    exact = loads_at(analytic_model, analysis)
    F, M, measured, extrapolated = _on_grid(main, analysis, idx, kinds, skip, _jumps(analytic_model, main.t),
                                            lambda steps: exact(main.t[steps]))
    qs = _relative_poses(main, idx, t)
    pose_error = (float(np.max(np.linalg.norm(qs[:, :, :2] - analysis.q[:, :, :2], axis=2))) if qs.size else 0.0,
                  float(np.max(np.abs(qs[:, :, 2] - analysis.q[:, :, 2]))) if qs.size else 0.0)
    ferr = np.linalg.norm(F - analysis.force, axis=1)[measured]
    merr = np.abs(M - analysis.moment)[measured]
    fres = float(np.max(ferr)) / F0 if ferr.size else math.inf
    mres = float(np.max(merr)) / M0 if merr.size else math.inf
    W, Ms = analysis.static_load()
    fpk = float(np.max(np.linalg.norm((F - W)[measured], axis=1))) / F0 if measured.any() else math.inf
    mpk = float(np.max(np.abs((M - Ms)[measured]))) / M0 if measured.any() else math.inf
    tracking = {k: np.asarray(v, dtype=float)[grid] for k, v in main.driver_error.items()}
    rel = {k: float(np.max(np.abs(v))) / (travel[k] or 1.0) for k, v in main.driver_error.items()}
    worst = max(rel.values(), default=0.0)
    resolution = calib / worst if worst > 0 else math.inf
    tol = settings.tracking_tolerance
    amplification = math.nan
    if not worst <= tol:
        reasons.append(f"tracking error {numbers.num(worst, 3)} of the travel > {tol:g}")
        nudged = run(1.0 + SENSITIVITY)
        amplification = (math.inf if nudged is None else max(
            (float(np.max(np.abs(np.asarray(nudged.driver_error[k]) - np.asarray(e)))) / (travel[k] or 1.0)
             for k, e in main.driver_error.items()), default=0.0) / worst)
    if calibrate and not resolution >= MIN_RESOLUTION:
        reasons.append(
            f"the run does not resolve a model error: efforts times {CALIBRATION_FACTOR:g} give only "
            f"{numbers.num(resolution, 3)} times its tracking error (< {MIN_RESOLUTION:g})"
        )
    return TorqueDriven(
        t=t, force=F, moment=M, tracking=tracking, tracking_error=rel, travel=travel, tracking_error_max=worst,
        calibration_error=calib, resolution=resolution, force_residual=fres, moment_residual=mres,
        force_reference=F0, moment_reference=M0, force_peak=fpk, moment_peak=mpk, tracking_tolerance=tol, dt=dt, steps=nsteps,
        iterations=iterations, floored_bodies=floored, floor_effort_share=share, passed=not reasons,
        reasons=reasons, notes=notes + list(main.sim.notes),
        timing={"simulation_s": main.wall, "total_s": time.perf_counter() - wall0}, amplification=amplification,
        calibration_stopped=partial, measured=measured, extrapolated_samples=extrapolated, pose_error=pose_error,
    )



def torque_driven(
    model: Model,
    analysis: Analysis,
    settings: ValidationSettings | None = None,
    *,
    economic: bool = False,
    **kw,
) -> TorqueDriven:
    """The torque-driven run (:func:`_torque_driven_once`, whose keywords it takes).

    ``economic``: first with :data:`ITERATIONS` solver iterations, doubled while that run comes
    apart (``trial``: it stops early), and the first run that holds together is kept when it
    passes by ten times over (tracking error at most a tenth of ``tracking_tolerance``,
    resolution at least ten times :data:`MIN_RESOLUTION`: more iterations cannot change that
    verdict); otherwise the run with ``iterations`` (the position-driven validation's), as
    without. Tried only with ``settings.early_accept`` and when ``iterations`` is at least four
    times :data:`ITERATIONS`. On the idler loop's counterweights stage both give a tracking error
    of 6.2e-6 of the travel; 100 iterations take a sixth of the time of 3200. On the corrected
    Scott-Russell spec's idler-loop counter-rotations stage the runs with 100-400 iterations come
    apart within a few steps and 800 passes (tracking error 4.908e-6 of the travel, 4.909e-6 at
    1600), at a quarter of the cost of 3200. ``tried``: a run :func:`_torque_driven_once` already
    made with these arguments (:mod:`balpipe.validate.shared`'s try), used instead of the run at
    its step and iterations when it held together."""
    settings = settings or ValidationSettings()
    iterations = kw.get("iterations")
    tried = kw.pop("tried", None)
    spent = 0.0
    if "plan" not in kw:  # computed once for every try
        wall0 = time.perf_counter()
        kw["plan"] = _plan(model, analysis, settings, kw.get("analytic_model"), kw.get("dt"))
        spent = time.perf_counter() - wall0
    if tried is not None and (tried.dt != kw["plan"].dt or not math.isfinite(tried.tracking_error_max)):
        tried = None  # another step, or it came apart (a trial without its calibration): not reusable

    def once(it: int | None, trial: bool) -> TorqueDriven:
        """The run at ``it`` iterations; ``tried`` where it is that run (a trial that held together is
        the same run, bit for bit, as one without the trial's early stop)."""
        if tried is not None and tried.iterations == int(it or settings.iterations or kw["plan"].iterations or ITERATIONS):
            return tried
        return _torque_driven_once(model, analysis, settings, **{**kw, "iterations": it, "trial": trial})

    if economic and settings.early_accept and iterations is not None and iterations >= 4 * ITERATIONS:
        it = ITERATIONS
        while it < iterations:
            first = once(it, True)
            spent += first.timing.get("total_s", 0.0)
            if (first.passed and first.tracking_error_max <= settings.tracking_tolerance / 10.0
                    and first.resolution >= 10.0 * MIN_RESOLUTION):
                first.timing["total_s"] = spent
                return first
            if math.isfinite(first.tracking_error_max):  # it held together: the validation's effort
                break
            it *= 2
    r = once(iterations, False)
    r.timing["total_s"] = r.timing.get("total_s", 0.0) + spent
    return _finer_steps(r, model, analysis, settings, kw)


def _finer_steps(r: TorqueDriven, model: Model, analysis: Analysis, settings: ValidationSettings,
                 kw: dict) -> TorqueDriven:
    """A run that fails on its own numbers (its tracking error above the tolerance, or too large
    to resolve the calibration's model error: ``resolution`` below :data:`MIN_RESOLUTION`, or it
    came apart) is run again at finer steps chosen from its error (:func:`.settings.refine_step`:
    second order, so the step ratio is about sqrt(error / target), the target being the smaller
    of the tolerance and the calibration error / :data:`MIN_RESOLUTION`, halved for a margin), while
    the error shrinks as the integrator's does, down to ``settings.max_refinement`` times finer;
    the last such run is kept and says so. Then :func:`_judge`. Not where ``settings.dt`` is given
    (a spec's ``validation.dt``): that step is the one used. Open loop, a step's error is carried
    and amplified to the end: a Stephenson six-bar on a cam law with dwells, two cycles, tracked
    to 7.0e-3 of its travel at the position-driven check's step (0.625 ms), 1.7e-3 at half of it;
    a V-twin at 6000 rpm, whose crank and counterweights are a flywheel (efforts 10 % low move it
    only 3.7e-5 of a turn off), tracked to 1.9e-5 at 9.3 us, 1.2e-6 at a quarter of it."""
    tol = settings.tracking_tolerance
    refinement = Refinement(None, False, None)
    if not r.passed and not settings.dt:
        def target(x: TorqueDriven) -> float:
            calib = x.calibration_error / MIN_RESOLUTION if math.isfinite(x.calibration_error) else math.inf
            return 0.5 * min(tol, calib)

        r, refinement = refine_step(
            r, lambda dt: _torque_driven_once(model, analysis, settings, **{**kw, "dt": dt, "plan": None}),
            lambda x: x.tracking_error_max, lambda x: x.passed, "tracking error", settings.max_refinement, target)
    return _judge(r, refinement, settings)


def _judge(r: TorqueDriven, refinement: Refinement, settings: ValidationSettings) -> TorqueDriven:
    """Fail or unconfirmed, for a run that does not pass. It fails only where the motion leaves
    the plan by more than the tolerance at an error that is resolved: one that does not shrink
    with the step (the efforts', a model error), or at the step a spec gives. Everything else is
    unconfirmed, with the remedy: a run that came apart, an error that still shrinks with the
    step at the budget's finest step, a resolution below :data:`MIN_RESOLUTION` (nothing is
    shown false by a run that cannot see a model error), and a run unstable open loop: one that
    efforts times 1 + :data:`SENSITIVITY` move by :data:`AMPLIFIED` of its own error or more (its
    error is then explained by a change of the efforts far below any design error)."""
    if r.passed:
        return r
    tol = settings.tracking_tolerance
    apart = not math.isfinite(r.tracking_error_max)
    off_plan = not apart and r.tracking_error_max > tol
    unstable = off_plan and not r.amplification < AMPLIFIED
    if off_plan and (refinement.shrinks is False or settings.dt) and not unstable:
        return r  # the efforts do not drive the mechanism along its plan: fails
    r.unconfirmed = True
    if unstable:
        moved = "came apart" if math.isinf(r.amplification) else f"moved by {numbers.num(r.amplification, 3)} times its tracking error"
        r.remedy = (f"none at this step: the run is unstable open loop (efforts times 1 + {SENSITIVITY:g} {moved}), so its "
                    f"tracking error cannot show the efforts wrong; the position-driven check stands. A driven shaft "
                    f"with its real inertia (a flywheel, a motor's rotor seen through its reduction) steadies it")
    elif refinement.remedy_dt is not None:
        r.remedy = (f"{step_setting(refinement.remedy_dt)} (second order: the tracking error falls with the square of the step; "
                    f"the validator stopped at {numbers.num(1e3 * r.dt, 4)} ms, {settings.max_refinement:g} times finer at most)")
    elif settings.dt:
        goal = 0.5 * min(tol, r.calibration_error / MIN_RESOLUTION if math.isfinite(r.calibration_error) else tol)
        r.remedy = f"a finer validation.dt than the spec's {settings.dt:g} s"
        if not apart and goal > 0 and r.tracking_error_max > goal:  # second order, if the error is the step's
            r.remedy += f", {step_setting(r.dt * math.sqrt(goal / r.tracking_error_max))} if the error is the step's"
    elif apart:
        r.remedy = f"validation: {{iterations: {2 * r.iterations}}} or a finer validation.dt"
    else:
        r.remedy = (f"none found within the budget: the error does not shrink with the step; "
                    f"validation: {{iterations: {4 * r.iterations}}} may")
    return r
