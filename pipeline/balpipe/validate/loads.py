"""Measuring a stage's shaking loads in the simulation, against the analysis: ``validate``.

Method
    The model is built in pymunk by :mod:`balpipe.validate.space` (bodies at their centres of
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
    difference would straddle it: at a jerk kink the sample is the simulated load extrapolated
    linearly from both sides; at an acceleration jump, the analysed load there plus the
    simulation's error extrapolated linearly from the side the law's value belongs to, from the
    nearest steps outside the ones the jump spoils (the drive aims two steps ahead, the solver
    settles after it: :data:`SPOILED_BEFORE`, :data:`SPOILED_AFTER`), whose other samples are
    left out (``excluded_samples``); both counted in ``extrapolated_samples``. A step of the
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
    * iterations: 100; a run whose residuals are already at most tolerance / 10 and whose
      balance claims hold is kept (``ValidationSettings.early_accept``: more iterations cannot
      change that verdict; a design with an error never passes early); otherwise doubled until
      the loads change by at most tolerance / 10 of the
      unbalanced peaks between two doublings (so at least two runs), up to 3200; the change is
      measured on the samples that enter the residuals (the step after the motion's end, where
      the drive stops the mechanism within a step, kept the idler loop's stages doubling to 3200
      for a change that no verdict reads); a run whose
      bodies stray more than 1e-3 (rad, or of the model's size) from the analysed motion is
      redone with more. The first 10 steps, and those after a jump of a law's acceleration,
      run with 5000 iterations (the solver's warm start is missing or wrong there; with only
      3 start-up steps at 500 the Scott-Russell "full" stage had a 2 % error at t0). Fixed
      counts do not fit all: the 2R arm diverges at 10 iterations with dead-beat joints, the
      Scott-Russell "full" stage needs 3200 (its moment is 2 % off at 400). Cost of a step
      (pymunk 7.3.1, CPU time): 8 us at 100 iterations on paper 003's arm (a
      torque-driven run of 5001 steps in 0.04 s, 0.11 s before the batched state read and the
      drivers' targets and actuators' torques computed before the loop), 0.63 ms at 1600 on
      the 3-RPR with counter-rotations, nearly all of it Chipmunk's solver. Where the solver converges slowly the iterations are what the stage
      needs, not a retry: corrected Scott-Russell spec, dt 1.25e-4, one run per count
      (``benchmarks/validation_settings.py --fixed``), moment residual of the idler loop's
      counterweights stage 8.2e3 / 0.042 / 0.006 at 800 / 1600 / 3200 (apart below 800), of
      its counter-rotations stage 0.010 / 0.0026 at 1600 / 3200 (apart below 1600); where it
      converges, the residual is the step's from the first run that holds together (the
      unbalanced stage: 1.4e-5 / 1.5e-5 at 800 to 3200, apart below 800).
    * inertial forces (``ValidationSettings.feedforward``, :mod:`balpipe.validate.feedforward`):
      each body gets the force and torque of its analysed acceleration before every step; the
      drivers impose the motion either way and the solver only finds the remainder. Measured
      (CPU, one core, validate only; ``benchmarks/validation_settings.py``): idler loop's
      counterweights stage 800 + 1600 iterations, moment residual 0.0025 (was 800 + 1600 + 3200,
      0.0019, not converged); paper 004's counterweights stage 100 iterations (was 400); loads
      at 800 iterations the same with and without to 1e-4 of the unbalanced peaks
      (tests/validate/test_feedforward.py). The table below was measured without it.
    * mass floor 0.1: bodies lighter (of smaller moment) than 0.1 of the heaviest are simulated
      at that floor. A massless idler between two gears otherwise stalls the solver (floor 1e-6:
      comes apart at 3200 iterations; 1e-3: 800 iterations; 1e-2 and 0.1: 200, residuals
      4.7e-5 / 5.7e-5 in all converged cases). The motion is imposed by the drivers, so the
      floors change internal forces only, not the measured loads. Measured, not adopted: every
      body simulated at the largest mass with its own radius of gyration converges with about
      a quarter of the iterations on the idler loop's counterweights stages (paper000 idler loop:
      moment residual 1.3e-3 at 800, 3.4e-4 at 1600, against 2.7e-2 at 1600 and 1.9e-3 at 3200
      with the floor; corrected Scott-Russell spec: 2.2e-3 at 800, 3.8e-4 at 1600), but the
      counter-rotations' meshes come apart with it at every count up to 1600.
    * tolerance 1 % of the unbalanced peaks (the reference loads, :mod:`balpipe.load_reference`, when
      given); balance_tolerance 1 % for the loads a stage claims
      to cancel (``expect``).

Moving starts
    The drivers' laws are continued outside [t0, T] (:mod:`balpipe.validate.extend`): a periodic
    motion moving at t0 starts a run-in of whole sample intervals (at least 20 steps) early, from
    its own cycle's analysed state there, and is checked over the cycle, in steady state (a whole
    settling cycle before); another motion moving at t0 gets a 20-step run-in. Stephenson
    six-bar at 120 rpm (tests/fixtures/six_bar_polynomial_speed.yaml): force / moment residuals 4.2e-5 /
    9.7e-5 unbalanced, 7.2e-8 / 6.1e-5 with counterweights (150 / 15 before: spikes at 0 and T).

Measured residuals (max |sim - analytic| / unbalanced peak) at the defaults, 0.5 s motions,
251 samples, with the wall-clock time of ``validate`` (all runs included)
    ===========================================  =======  =======  ==========  =====
    model (tests/validate/test_validate.py)               force    moment   iterations  s
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
from dataclasses import dataclass, field, replace

import numpy as np
import pymunk

from ..display import numbers
from ..engine import Analysis, analyse
from ..model import Model
from .extend import continued, settling_steps
from .run import SimulationRun, model_scale, _relative_poses, _run_adaptive
from .settings import (MAX_ITERATIONS, Refinement, ValidationSettings, _jumps, _law_kinds, _step_grid,
                       default_settings, refine_step, step_setting)
from .verdict import Verdict

@dataclass
class StageValidation(Verdict):
    """The simulation of one stage against its analysis.

    Curves on the analysis grid ``t``: ``force`` (N, 2), ``moment`` (N,) (simulated, same
    convention as the engine: load of the moving links on the frame, moment about the
    analysis' moment point); ``force_error`` (N,) = |F_sim - F_analytic|, ``moment_error``.
    ``measured`` (N,) marks the samples that enter the residuals.
    Scalars: residuals ``force_residual = max|F_sim - F_analytic| / F0`` and
    ``moment_residual`` (F0, M0: the reference loads ``force_reference``/``moment_reference``,
    the unbalanced stage's analytic peaks or their floor, see :mod:`balpipe.load_reference`;
    ``reference_basis`` says which; ``unbalanced_force_peak``/``..._moment_peak`` the peaks);
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
    force_reference: float = math.nan
    moment_reference: float = math.nan
    reference_basis: str = "force: unbalanced peak; moment: unbalanced peak"
    solver_change: float = math.nan
    unconfirmed: bool = False
    remedy: str = ""
    #: the run the verdict reads: the position-driven run, or a torque-driven run that proves the
    #: same (:mod:`balpipe.validate.shared`)
    proved_by: str = "position-driven run"

    def to_json(self) -> dict:
        """Plain, deterministic summary (no curves, no wall-clock times)."""
        return {
            **self.verdict_json(),
            "force_residual": float(self.force_residual),
            "moment_residual": float(self.moment_residual),
            "force_peak": float(self.force_peak),
            "moment_peak": float(self.moment_peak),
            "unbalanced_force_peak": float(self.unbalanced_force_peak),
            "unbalanced_moment_peak": float(self.unbalanced_moment_peak),
            "force_reference": float(self.force_reference),
            "moment_reference": float(self.moment_reference),
            "reference_basis": self.reference_basis,
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
            "proved_by": self.proved_by,
            "pymunk_version": str(self.pymunk_version),
            "chipmunk_version": str(self.chipmunk_version),
            "method": "momentum",
        }



#: steps k - SPOILED_BEFORE .. k + SPOILED_AFTER around a jump of a law's acceleration between
#: steps k - 1 and k do not follow the analysis: the drive aims two steps ahead, and the solver
#: settles after it. Moment error / the unbalanced peak: the 3-RPR's counter-rotations stage on a
#: bang-bang law (mesh gears, 3200 iterations, the jump on a sample) 2.7e-5 at k - 4, then 4.3e-2,
#: 0.12, 0.12, 3.1e-2, 2.3e-3, 2.1e-2, 1.5e-2, 4.0e-3 at k - 3 .. k + 4, 9.5e-5 at k + 5; the
#: planetary test model on a trapezoidal law (100 iterations, the jump between samples) 7.6e-6 at
#: k - 2, 0.39, 4.9e-3, 2.9e-5 at k - 1 .. k + 1, 3.7e-7 at k + 2
SPOILED_BEFORE, SPOILED_AFTER = 3, 4


def _on_grid(run: SimulationRun, analysis: Analysis, idx: np.ndarray | None, kinds: list[str], skip: int,
             jumps: list[int] = (), at_steps=None):
    """Simulated loads at the analysis samples. Where a law is not smooth the central
    difference straddles the corner: at a jerk kink the sample is the linear extrapolation of
    the simulated loads from both sides, averaged (second order again). ``jumps`` are the
    simulation steps k where a law's acceleration jumps between steps k-1 and k (:func:`_jumps`);
    the samples whose law value is a side of such a jump (kind "left"/"right") add theirs. The
    steps around a jump (:data:`SPOILED_BEFORE`, :data:`SPOILED_AFTER`) cannot be compared with a
    curve that jumps there: a sample at a jump takes the analysis' value there plus the
    simulation's error extrapolated linearly from the two nearest steps outside them on the side
    its value belongs to (``at_steps(steps) -> (len, 3)``: the analysis' Fx, Fy, M at those
    steps; without it, the simulated loads themselves are extrapolated, which over five steps is
    off by their curvature: 1.6e-2 of the reference on a random slider-crank at a bang-bang
    law's jump, where its error was 8.5e-4 at every step around it); any other sample among them is
    excluded from the residuals (``excluded_samples`` counts them), and so is a jump's sample
    whose nearest steps are another jump's. Returns force, moment, measured mask and counts."""
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
    # a sample whose law value is the left limit has its jump after it (step s + 1), the right
    # limit before it (step s): the same steps as _jumps finds, also where it finds none
    steps = set(int(k) for k in jumps)
    for i, kind in enumerate(kinds):
        s = int(idx_f[i])
        if kind in ("left", "mixed"):
            steps.add(s + 1)
        if kind in ("right", "mixed"):
            steps.add(s)
    jump_steps = np.asarray(sorted(steps), dtype=int)

    at_jump: list[tuple[int, int, int, int]] = []  # (sample, its step, the two steps it is extrapolated from)

    def spoiled(step: int) -> bool:
        return bool(jump_steps.size) and bool(np.any((step >= jump_steps - SPOILED_BEFORE) & (step <= jump_steps + SPOILED_AFTER)))

    for i, kind in enumerate(kinds):
        s = int(idx_f[i])
        if s < skip:
            measured[i] = False
        if kind in ("smooth", "kink"):
            if spoiled(s):
                measured[i] = False
                continue
            if kind == "smooth":
                continue
            left = 2 * series[s - 1] - series[s - 2] if s >= 2 + skip else None
            right = 2 * series[s + 1] - series[s + 2] if s + 2 <= n else None
            sides = [v for v in (left, right) if v is not None]
        elif kind in ("left", "right"):
            a = s - SPOILED_BEFORE if kind == "left" else s + SPOILED_AFTER + 1  # the nearest unspoiled step
            b = a - 1 if kind == "left" else a + 1
            if min(a, b) >= skip and max(a, b) <= n and not spoiled(a) and not spoiled(b):
                at_jump.append((i, s, a, b))
            else:
                measured[i] = False
            continue
        else:  # "mixed": jumps with different sides
            sides = []
        if sides:
            vals[i] = np.mean(sides, axis=0)
            extrapolated += 1
        else:
            measured[i] = False
    if at_jump:
        need = sorted({x for _, _, a, b in at_jump for x in (a, b)})
        exact = np.zeros((len(need), 3)) if at_steps is None else np.asarray(at_steps(np.asarray(need)), dtype=float)
        error = {x: series[x] - e for x, e in zip(need, exact)}
        for i, s, a, b in at_jump:
            here = np.zeros(3) if at_steps is None else np.array([*analysis.force[i], analysis.moment[i]])
            vals[i] = here + error[a] + abs(s - a) * (error[a] - error[b])
            extrapolated += 1
    F[:] = vals[:, :2]
    M[:] = vals[:, 2]
    return F, M, measured, extrapolated



def loads_at(model: Model, analysis: Analysis):
    """``times -> (len, 3)``: the analysed Fx, Fy, M of ``model`` at those times (the simulation's
    steps beside a law's jump, see :func:`_on_grid`), the same gravity and moment point as
    ``analysis``; remembered per set of times (every run of a validation asks for the same)."""
    memo: dict[tuple, np.ndarray] = {}

    def at(times: np.ndarray) -> np.ndarray:
        key = tuple(np.asarray(times, dtype=float).tolist())
        if key not in memo:
            a = analyse(model, np.asarray(key), analysis.gravity, analysis.moment_point)
            memo[key] = np.column_stack([a.force, a.moment])
        return memo[key]

    return at


def validate(
    model: Model,
    analysis: Analysis,
    unbalanced_peaks: tuple[float, float],
    settings: ValidationSettings | None = None,
    expect: tuple[str, ...] = (),
    reference=None,
) -> StageValidation:
    """:func:`_validate_once`; a run that fails on its residuals (or came apart) is run again at
    finer steps while each refinement shrinks its largest residual as a second-order error shrinks
    (:func:`.settings.refine_step`; the momentum differences are second order in the step), down
    to ``settings.max_refinement`` times finer, and the last such run is kept, saying so; then
    :func:`_judge` says whether it fails (a residual that does not shrink is the design's or the
    analysis') or is unconfirmed. Not where ``settings.dt`` is given (a spec's ``validation.dt``):
    that step is the one used. The slider-driven slider-crank
    (specs/custom_slider_driven_slider_crank_gravity.yaml) on a 3-4-5 cam with dwells failed at
    2.0e-2 of the reference moment at the default step (the counterweights make its moment 16
    times the reference), 5.0e-3 at half of it and 1.2e-3 at a quarter."""
    settings = settings or ValidationSettings()
    v = _validate_once(model, analysis, unbalanced_peaks, settings, expect, reference)

    def worst(r: StageValidation) -> float:
        return max(r.force_residual, r.moment_residual)

    refinement = Refinement(None, False, None)
    if not v.passed and not settings.dt and (not math.isfinite(worst(v)) or worst(v) > settings.tolerance):
        v, refinement = refine_step(
            v, lambda dt: _validate_once(model, analysis, unbalanced_peaks, replace(settings, dt=dt), expect, reference),
            worst, lambda x: x.passed, "largest residual", settings.max_refinement,
            lambda x: 0.5 * settings.tolerance)
    return _judge(v, refinement, settings)


def _judge(v: StageValidation, refinement: Refinement, settings: ValidationSettings) -> StageValidation:
    """Fail or unconfirmed, for a run that does not pass. It fails where the simulated loads
    contradict the analysis (or a claimed cancellation) by more than the run's own unresolved
    error: its residual does not shrink with the step (or the spec gives the step), and exceeds
    the tolerance by more than the solver's last change between doublings of its iterations
    (``solver_change``). Unconfirmed, with the remedy: a simulation that came apart at every
    count, a residual that still shrinks with the step at the budget's finest step (or was not
    refined: ``max_refinement`` 1), a solver that
    had not converged to within the excess."""
    if v.passed:
        return v
    worst = max(v.force_residual, v.moment_residual)
    excess = max(worst - v.tolerance, max((pk - v.balance_tolerance for what, pk in
                                           (("force", v.force_peak), ("moment", v.moment_peak)) if what in v.expect),
                                          default=-math.inf))
    if not math.isfinite(worst):
        v.unconfirmed = True
        v.remedy = f"a finer validation.dt than {numbers.num(v.dt, 3)} s, or validation: {{iterations: {2 * MAX_ITERATIONS}}}"
    elif refinement.shrinks is not False and refinement.remedy_dt is not None:
        v.unconfirmed = True
        v.remedy = (f"{step_setting(refinement.remedy_dt)} (second order: the residual falls with the square of the step; the "
                    f"validator stopped at {numbers.num(1e3 * v.dt, 4)} ms, {settings.max_refinement:g} times finer at most)")
    elif not excess > (v.solver_change if math.isfinite(v.solver_change) else math.inf):
        v.unconfirmed = True
        v.remedy = (f"validation: {{iterations: {2 * v.iterations}}} (the solver had not converged: its loads still "
                    f"changed by {numbers.num(v.solver_change, 2)} of the reference between the last doublings)")
    return v


def _validate_once(model: Model, analysis: Analysis, unbalanced_peaks: tuple[float, float],
                   settings: ValidationSettings, expect: tuple[str, ...], reference) -> StageValidation:
    """Simulate ``model`` in pymunk along ``analysis``' motion and compare the loads.

    ``unbalanced_peaks`` = (F0, M0): the unbalanced stage's analytic peak force and moment,
    the denominators of every relative number. ``expect`` names the loads this stage claims to
    cancel ("force", "moment"): their simulated peaks must then also be at most
    ``settings.balance_tolerance`` times F0 (M0). Passes when the residuals are at most
    ``settings.tolerance`` and every expectation holds. ``reference``: a
    :class:`balpipe.load_reference.LoadReference`, whose loads then replace ``unbalanced_peaks``
    as the denominators (the unbalanced peaks floored by the model's gross inertial loads).
    """
    wall0 = time.perf_counter()
    model = continued(model, analysis)
    dt_default, it_default = default_settings(model, analysis)
    dt_target = settings.dt or dt_default
    iterations = settings.iterations or it_default
    dt, nsteps, idx = _step_grid(np.asarray(analysis.t, dtype=float), dt_target)
    scale = model_scale(analysis)
    F0, M0 = (float(x) for x in unbalanced_peaks)
    peaks = (F0, M0)
    basis = "force: unbalanced peak; moment: unbalanced peak"
    if reference is not None:
        F0, M0 = float(reference.force), float(reference.moment)
        peaks = (float(reference.force_peak), float(reference.moment_peak))
        basis = f"force: {reference.force_basis}; moment: {reference.moment_basis}"
    refs = {"force_reference": F0, "moment_reference": M0, "reference_basis": basis}
    limit = (
        settings.tolerance / 10.0 * (F0 if F0 > 0 else 1.0),
        settings.tolerance / 10.0 * (M0 if M0 > 0 else 1.0),
    )
    fden = F0 if F0 > 0 else 1.0
    mden = M0 if M0 > 0 else 1.0
    kinds = _law_kinds(model, np.asarray(analysis.t, dtype=float))
    W, Ms = analysis.static_load()
    exact = loads_at(model, analysis)

    measured_runs: dict[int, tuple[SimulationRun, tuple]] = {}

    def measure(run: SimulationRun):
        """:func:`measure_once`, once per run (the acceptance, the convergence test and the
        verdict all ask for the same run's numbers)."""
        hit = measured_runs.get(id(run))
        if hit is None or hit[0] is not run:
            hit = measured_runs[id(run)] = (run, measure_once(run))
        return hit[1]

    def measure_once(run: SimulationRun):
        """Loads on the grid, measured mask and counts, errors, residuals and inertial peaks."""
        F, M, measured, extrapolated = _on_grid(run, analysis, idx, kinds, settings.skip_initial_steps,
                                                _jumps(model, run.t), lambda steps: exact(run.t[steps]))
        ferr = np.linalg.norm(F - analysis.force, axis=1)
        merr = np.abs(M - analysis.moment)
        if not measured.any():
            return F, M, measured, extrapolated, ferr, merr, math.inf, math.inf, math.inf, math.inf
        # the balance claims concern the inertial part: less the links' weight and its moment
        return (F, M, measured, extrapolated, ferr, merr, float(np.max(ferr[measured])) / fden,
                float(np.max(merr[measured])) / mden, float(np.max(np.linalg.norm((F - W)[measured], axis=1))) / fden,
                float(np.max(np.abs((M - Ms)[measured]))) / mden)

    def passing(run: SimulationRun, margin: float = 1.0) -> bool:
        """The run passes with residuals at most ``tolerance / margin`` (and the claims hold)."""
        *_, fres, mres, fpk, mpk = measure(run)
        claims = all(pk <= settings.balance_tolerance for what, pk in (("force", fpk), ("moment", mpk)) if what in expect)
        return fres <= settings.tolerance / margin and mres <= settings.tolerance / margin and claims

    def sampled(run: SimulationRun):
        """The simulated loads that enter the residuals (the measured samples of the grid)."""
        F, M, measured, *_ = measure(run)
        return F[measured], M[measured]

    early = settings.early_accept
    run, notes, change = _run_adaptive(
        model, analysis, dt, iterations, settings, scale, idx, limit=limit, mass_floor=settings.mass_floor,
        settle=settling_steps(model, analysis, nsteps), feedforward=settings.feedforward,
        # the verdict cannot change with more solver iterations when a run passes by ten times over
        accept=(lambda r: passing(r, 10.0)) if early else None, passes=passing if early else None,
        compare=sampled,
    )
    if F0 <= 0 or M0 <= 0:
        notes.append("an unbalanced peak is zero: that residual is absolute")
    solver_change = max(change[0] / fden, change[1] / mden)
    N = len(analysis.t)
    if run is None:
        nan = np.full(N, np.nan)
        return StageValidation(
            analysis.t, np.full((N, 2), np.nan), nan, nan, nan, np.zeros(N, bool), math.inf, math.inf,
            math.inf, math.inf, *peaks, {d.name: math.inf for d in model.drivers}, math.inf, math.inf,
            math.inf, dt, nsteps, MAX_ITERATIONS, settings.tolerance, settings.balance_tolerance,
            tuple(expect), False, ["the simulation failed"], N, 0, [], notes,
            timing={"total_s": time.perf_counter() - wall0}, **refs,
        )
    F, M, measured, extrapolated, ferr, merr, fres, mres, fpk, mpk = measure(run)
    track = {k: float(np.max(np.abs(v))) for k, v in run.driver_error.items()}
    qs = _relative_poses(run, idx, np.asarray(analysis.t, dtype=float))
    dpos = float(np.max(np.linalg.norm(qs[:, :, :2] - analysis.q[:, :, :2], axis=2))) if qs.size else 0.0
    dang = float(np.max(np.abs(qs[:, :, 2] - analysis.q[:, :, 2]))) if qs.size else 0.0
    reasons = []
    tol = settings.tolerance
    if not fres <= tol:
        reasons.append(f"force residual {numbers.num(fres, 3)} > {tol:g}")
    if not mres <= tol:
        reasons.append(f"moment residual {numbers.num(mres, 3)} > {tol:g}")
    for what, pk in (("force", fpk), ("moment", mpk)):
        if what in expect and not pk <= settings.balance_tolerance:
            reasons.append(f"{what} not balanced: simulated peak {numbers.num(pk, 3)} of the reference > {settings.balance_tolerance:g}")
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
        unbalanced_force_peak=peaks[0], unbalanced_moment_peak=peaks[1], tracking_error=track,
        tracking_error_max=max(track.values(), default=0.0), pose_error_position=dpos,
        pose_error_angle=dang, dt=run.dt, steps=nsteps, iterations=run.iterations,
        tolerance=tol, balance_tolerance=settings.balance_tolerance, expect=tuple(expect),
        passed=not reasons, reasons=reasons, excluded_samples=excluded,
        extrapolated_samples=extrapolated, floored_bodies=list(run.sim.floored), notes=notes,
        timing={"simulation_s": run.wall, "total_s": time.perf_counter() - wall0}, solver_change=solver_change, **refs,
    )

