"""One run for both checks of a stage, where it proves both: the torque-driven run first.

The position-driven run (:mod:`.loads`) imposes the analysed motion and measures the loads on the
frame from the simulated momenta; the torque-driven run (:mod:`.torque`) applies the engine's
efforts, lets pymunk integrate the motion and measures the same loads the same way, on the same
samples. Where the torque-driven run

* starts from rest (a moving start leaves its first sample out of the load residuals, which the
  position-driven run measures after its run-in),
* follows its plan to a tenth of the tracking tolerance with ten times the resolution a verdict
  asks for (what :func:`.torque.torque_driven` keeps from its cheapest try),
* and has load residuals at most a tenth of the tolerance, with the simulated peak of every load
  the stage claims to cancel within the balance tolerance (what :func:`.loads.validate` keeps
  from its first run without doubling the iterations),

pymunk's mechanism, left to move under the computed efforts, puts the analysed loads on the frame
along the planned motion: the position-driven run would show nothing more, and is not run. Its
verdict (pass) is then read from the torque-driven run (:func:`validation_from_torque`, which
says so in its notes and ``proved_by``). Anything less, and always for a design whose loads differ
from its analysis (a counterweight or counter-rotation off by 1 %: its residual is the error's
effect, far above a tenth of the tolerance), runs the position-driven validation as before, and
the torque-driven check at its step and solver effort, reusing this try where it is that run.

Where the first run that holds together is within the tolerance but not ten times within, it is
made again with twice the solver iterations: that run proves the stage where it is ten times
within, or within and the same as the run with half its iterations to a tenth of the tolerance
(the position-driven run's convergence test, :func:`converged`); a run within the tolerance whose
loads still change is doubled again, up to MAX_ITERATIONS, as the position-driven run is.

A try that comes apart is made again at :data:`APART_STEP` times its solver effort, and the first
try that holds together proves the stage where it passes by ten times over, like the first.

Measured on specs/: 97 of 134 stages proved by their torque-driven run; paper 000's idler-loop
counterweights stage, whose position-driven run converges at 1600-3200 solver iterations, at 100
(tracking 6.2e-6 of the travel, moment residual 3.7e-4), its counter-rotations stage at 1600
(100 and 400 come apart, 1600 gives 4.9e-4; 800, which holds together at 2.4e-3, is not tried).
"""

from __future__ import annotations

import numpy as np

from ..display import numbers
from ..engine import Analysis
from ..model import Model
from .extend import is_moving_start
from .loads import StageValidation, validate
from .settings import ITERATIONS, MAX_ITERATIONS, ValidationSettings
from .torque import MIN_RESOLUTION, TorqueDriven, _torque_driven_once, _plan, torque_driven

#: the solver effort of the next try after a try that came apart: four times its effort (tries at 100,
#: 400 and 1600 iterations, as far as MAX_ITERATIONS / 2). A try that comes apart stops within a few
#: steps, so skipping an effort costs little; the first effort at which pymunk holds a stiff
#: mechanism together can be marginal, its loads within the tolerance but not ten times within, and
#: then it is made again at twice that effort. Measured on specs/: paper 000's idler-loop
#: counter-rotation stages came apart at 100, 200 and 400 iterations, held at 800 (moment residual
#: 2.4e-3) and were proved at 1600 (4.9e-4): now 100 and 400 come apart and 1600 proves, without
#: the 800 run (0.46 s of CPU each); paper 002's and paper 004's six stages that came apart at 100,
#: proved at 200 (four) or at 400 after 200 came apart too (two), are proved at 400 (+0.01-0.02 s
#: each); the simulated build's simulations 12.7 -> 11.6 s of CPU
APART_STEP = 4

#: the margins of a proof: the torque-driven run's tracking error and load residuals at most this
#: fraction of their tolerances (the early acceptance of both runs), its resolution this many
#: times the verdict's
MARGIN = 10.0


def proves_loads(tq: TorqueDriven, settings: ValidationSettings, expect: tuple[str, ...],
                 residual_margin: float = MARGIN, calibrated: bool = True) -> bool:
    """``tq`` proves what a position-driven run would (see the module's docstring): it passes by
    :data:`MARGIN` over (its resolution too, where ``calibrated``), its loads match the analysis
    to the tolerance over ``residual_margin`` on every sample a position-driven run measures,
    and the loads ``expect`` claims to cancel stay within the balance tolerance."""
    if not tq.passed or tq.measured is None:
        return False
    claims = all(pk <= settings.balance_tolerance for what, pk in (("force", tq.force_peak), ("moment", tq.moment_peak))
                 if what in expect)
    return bool(tq.tracking_error_max <= settings.tracking_tolerance / MARGIN
                and (not calibrated or tq.resolution >= MARGIN * MIN_RESOLUTION)
                and tq.force_residual <= settings.tolerance / residual_margin
                and tq.moment_residual <= settings.tolerance / residual_margin and claims)


def converged(a: TorqueDriven, b: TorqueDriven, limit: float) -> bool:
    """The loads of two runs (``b`` with twice ``a``'s solver iterations) differ by at most
    ``limit`` of the reference loads on every sample both measure (the same samples): the
    position-driven run's convergence test (:func:`.run._run_adaptive`)."""
    if a.measured is None or b.measured is None or not np.array_equal(a.measured, b.measured) or not a.measured.any():
        return False
    m = a.measured
    df = float(np.max(np.linalg.norm(b.force[m] - a.force[m], axis=1))) / (a.force_reference or 1.0)
    dm = float(np.max(np.abs(b.moment[m] - a.moment[m]))) / (a.moment_reference or 1.0)
    return bool(np.isfinite(df) and np.isfinite(dm) and df <= limit and dm <= limit)


def validation_from_torque(tq: TorqueDriven, analysis: Analysis, peaks: tuple[float, float],
                           settings: ValidationSettings, expect: tuple[str, ...],
                           halved: TorqueDriven | None = None, reference=None, seconds: float = 0.0) -> StageValidation:
    """The position-driven verdict read from a torque-driven run that proves it
    (:func:`proves_loads`): its loads, residuals and simulated peaks (the same definitions, the
    same reference loads), its step and solver iterations; ``tracking_error`` is the driven
    coordinates' (rad or m) under the efforts, not under a drive; ``reference`` (a
    :class:`balpipe.load_reference.LoadReference`) says what the reference loads are, as in
    :func:`.loads.validate`. ``halved``: the run with half
    its solver iterations, whose loads it matches to a tenth of the tolerance (its residuals are
    then within the tolerance, not a tenth of it). ``seconds``: the wall time of the other runs
    made for this proof, the tries that came apart before ``tq``'s first try and the runs with
    more solver iterations than it (its ``timing``: the page's run time of the stage adds it to
    the torque-driven run's)."""
    measured = np.asarray(tq.measured, dtype=bool)
    basis = ("force: unbalanced peak; moment: unbalanced peak" if reference is None
             else f"force: {reference.force_basis}; moment: {reference.moment_basis}")
    ferr = np.linalg.norm(tq.force - analysis.force, axis=1)
    merr = np.abs(tq.moment - analysis.moment)
    track = {k: float(np.max(np.abs(v))) for k, v in tq.tracking.items()}
    how = ("a tenth of the tolerance or less" if halved is None else
           f"within the tolerance, and the run with {halved.iterations} solver iterations gave the same loads to a "
           f"tenth of the tolerance (the solver converged)")
    note = (f"proved by the torque-driven run: under the engine's efforts pymunk followed the plan to "
            f"{numbers.num(tq.tracking_error_max, 2)} of the travel, and its loads on the frame match the analysis to "
            f"{numbers.num(max(tq.force_residual, tq.moment_residual), 2)} of the reference, {how}: "
            f"no position-driven run needed")
    return StageValidation(
        t=np.asarray(analysis.t, dtype=float), force=tq.force, moment=tq.moment, force_error=ferr, moment_error=merr,
        measured=measured, force_residual=tq.force_residual, moment_residual=tq.moment_residual,
        force_peak=tq.force_peak, moment_peak=tq.moment_peak, unbalanced_force_peak=float(peaks[0]),
        unbalanced_moment_peak=float(peaks[1]), tracking_error=track, tracking_error_max=max(track.values(), default=0.0),
        pose_error_position=tq.pose_error[0], pose_error_angle=tq.pose_error[1], dt=tq.dt, steps=tq.steps,
        iterations=tq.iterations, tolerance=settings.tolerance, balance_tolerance=settings.balance_tolerance,
        expect=tuple(expect), passed=True, reasons=[], excluded_samples=int(np.count_nonzero(~measured)),
        extrapolated_samples=tq.extrapolated_samples, floored_bodies=list(tq.floored_bodies), notes=[note],
        timing={"simulation_s": 0.0, "total_s": float(seconds)}, force_reference=tq.force_reference,
        moment_reference=tq.moment_reference, proved_by="torque-driven run", reference_basis=basis,
    )


def stage_runs(model: Model, analysis: Analysis, peaks: tuple[float, float], settings: ValidationSettings,
               expect: tuple[str, ...] = (), reference=None) -> tuple[StageValidation, TorqueDriven]:
    """The position-driven validation and the torque-driven run of a stage:
    :func:`.loads.validate` (``peaks``, ``expect``, ``reference`` as there) and
    :func:`.torque.torque_driven` at its step and iterations, or, where the torque-driven run at
    the first solver effort proves both (:func:`proves_loads`; ``settings.shared_runs``), that run
    alone for both verdicts."""
    loads_ref = ((float(reference.force), float(reference.moment)) if reference is not None
                 else (float(peaks[0]), float(peaks[1])))
    tried = None
    plan = None
    if settings.shared_runs and settings.early_accept and not is_moving_start(analysis):
        plan = _plan(model, analysis, settings, None, None)
        tried = _torque_driven_once(model, analysis, settings, reference=loads_ref, iterations=ITERATIONS,
                                    trial=True, plan=plan)
        it, apart = ITERATIONS, 0.0  # apart: the run time of the tries that came apart
        while not np.isfinite(tried.tracking_error_max) and it * APART_STEP <= MAX_ITERATIONS // 2:  # came apart
            it *= APART_STEP
            apart += tried.timing.get("total_s", 0.0)
            tried = _torque_driven_once(model, analysis, settings, reference=loads_ref, iterations=it, trial=True,
                                        plan=plan)
        if proves_loads(tried, settings, expect):  # the first try that held together proves both
            return validation_from_torque(tried, analysis, peaks, settings, expect, reference=reference,
                                          seconds=apart), tried
        # within the tolerance but not ten times over: twice the solver effort, which proves it where
        # its loads match the analysis ten times over (more iterations cannot change that, as for the
        # position-driven run's first run), or within the tolerance and the same as the run with half
        # its effort to a tenth of it (the position-driven run's own convergence test); while a run is
        # within the tolerance and its loads still change, twice again, up to MAX_ITERATIONS, as the
        # position-driven run does (paper 000's Scott-Russell stage: 200 -> 400 converged, where the
        # position-driven run it fell back on took 200 to 1600); the torque-driven verdict is the first
        # run's, which passes by ten times over (calibrated)
        half, spent = tried, apart
        while proves_loads(half, settings, expect, residual_margin=1.0, calibrated=half is tried) and it < MAX_ITERATIONS:
            it *= 2
            twice = _torque_driven_once(model, analysis, settings, reference=loads_ref, iterations=it,
                                        calibrate=False, plan=plan)
            spent += twice.timing.get("total_s", 0.0)
            if proves_loads(twice, settings, expect, calibrated=False):
                return validation_from_torque(twice, analysis, peaks, settings, expect, reference=reference,
                                              seconds=spent), tried
            if (proves_loads(twice, settings, expect, residual_margin=1.0, calibrated=False)
                    and converged(half, twice, settings.tolerance / MARGIN)):
                return validation_from_torque(twice, analysis, peaks, settings, expect, halved=half, reference=reference,
                                              seconds=spent), tried
            half = twice  # within the tolerance, still changing with the solver effort: twice again
    v = validate(model, analysis, peaks, settings, expect, reference=reference)
    same_step = plan is not None and plan.dt == v.dt
    tq = torque_driven(model, analysis, settings, economic=True, reference=loads_ref, dt=v.dt, iterations=v.iterations,
                       **({"plan": plan, "tried": tried} if same_step else {}))
    return v, tq
