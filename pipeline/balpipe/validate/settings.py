"""Numerical settings of the pymunk validation and the time grid of a run.

``ValidationSettings`` (what a spec can change), ``default_settings`` (the step and the first
solver iteration count for a model and motion, and why: see :mod:`balpipe.validate.loads`),
and the helpers that place the simulation's steps on the analysis grid and find the corners
of the motion laws.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..display import numbers
from ..engine import Analysis
from ..model import Model

#: default number of steps over the motion (the step is also kept below 0.01 / w_max)
STEPS_PER_MOTION = 1000
#: first solver iteration count; doubled (up to MAX_ITERATIONS) until the loads converge
ITERATIONS = 100
MAX_ITERATIONS = 3200
#: deviation from the analysed motion (rad, or relative to the model's size) that makes a run retry
HEALTH_LIMIT = 1e-3
#: the finest step the validator tries on its own, as a fraction of the first (three halvings)
MAX_REFINEMENT = 8


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
    the internal forces only. ``tracking_tolerance``: the torque-driven run
    (:mod:`balpipe.validate.torque`) passes when every driven coordinate stays within this
    fraction of its travel of the planned motion. ``early_accept``: keep the first run whose
    residuals are at most ``tolerance / 10`` and whose balance claims hold, without doubling
    the iterations (more iterations cannot change that verdict); False: always double until
    the loads converge (the measurement of the settings in benchmarks/README.md).
    ``feedforward``: the position-driven run applies each body's inertial force m (a - g) and
    torque I alpha of the analysed motion before every step (:mod:`balpipe.validate.feedforward`):
    the motion is imposed by the drivers either way, and the solver is left with a small
    remainder (the idler loop's stages converge at 800-1600 iterations instead of 3200).
    ``max_refinement``: the validator's own budget for a run that cannot resolve its error at the
    first step: steps down to the first divided by this (:func:`refine_step`); a run still
    unresolved there is *unconfirmed*, with the step that would resolve it (1: no refinement).
    ``shared_runs``: a stage starting from rest is first run torque-driven at the first solver
    effort, and where that run proves what the position-driven run would (both pass by ten times
    over), it is the only run (:mod:`balpipe.validate.shared`; with ``early_accept`` only).
    """

    dt: float | None = None
    iterations: int | None = None
    tolerance: float = 0.01
    balance_tolerance: float = 0.01
    skip_initial_steps: int = 0
    startup_steps: int = 10
    startup_iterations: int = 5000
    mass_floor: float = 0.1
    tracking_tolerance: float = 1e-3
    early_accept: bool = True
    feedforward: bool = True
    max_refinement: float = MAX_REFINEMENT
    shared_runs: bool = True


#: how much a halving must shrink the error for it to be the step's (second order: 4x); a
#: refinement by a factor r must shrink it by STEP_ERROR_RATIO / 4 of r^2
STEP_ERROR_RATIO = 3.0


@dataclass
class Refinement:
    """What :func:`refine_step` found. ``shrinks``: the error shrank with the step as an
    integration error of second order shrinks (the last refinement tried; None when none was
    tried); ``exhausted``: the budget's finest step was reached without resolving the run;
    ``remedy_dt``: where it shrinks, the step at which the second-order error reaches the target
    (the setting that would resolve the run), else None."""

    shrinks: bool | None
    exhausted: bool
    remedy_dt: float | None


def _error_at(e: float) -> float:
    return e if math.isfinite(e) else math.inf


def refine_step(first, rerun, error, good, what: str, budget: float = MAX_REFINEMENT, target=None):
    """The run at a finer step, where ``first`` fails on its numbers alone: ``rerun(dt)`` at a
    finer step while each refinement shrinks ``error`` as an integration error of second order
    shrinks (by at least ``STEP_ERROR_RATIO / 4`` of the step ratio squared), until ``good(run)``
    or the finest step ``first.dt / budget``. The step is chosen from the error itself: with
    ``target(run)`` (the error that would resolve the run), the step ratio is the power of two
    at or above sqrt(error / target) (second order: one rerun where the error is the step's),
    else 2. A run that came apart (error infinite) is retried at half the step; one that holds
    together there counts as shrinking. Returns the last run that shrank so, with a note of each
    step's ``what`` ("tracking error 0.007 at 0.625 ms, 0.0017 at 0.3125 ms (the step's error,
    second order): kept the run at 0.3125 ms"), or ``first`` noted that a finer step does not
    shrink it; and a :class:`Refinement`. Runs have ``dt``, ``notes`` and ``timing["total_s"]``
    (summed)."""
    best, spent = first, first.timing.get("total_s", 0.0)
    trail = [(first.dt, error(first))]
    finest = first.dt / max(float(budget), 1.0)
    shrinks: bool | None = None
    while not good(best):
        room = best.dt / finest
        if room < 1.5:
            break
        e = _error_at(error(best))
        want = 2.0
        goal = target(best) if target is not None and math.isfinite(e) else None
        if goal is not None and goal > 0 and e > goal:
            want = 2.0 ** math.ceil(math.log2(math.sqrt(e / goal)) - 1e-9)
        factor = min(max(want, 2.0), room)
        finer = rerun(best.dt / factor)
        spent += finer.timing.get("total_s", 0.0)
        ef = _error_at(error(finer))
        trail.append((finer.dt, ef))
        ratio = (best.dt / finer.dt) ** 2 * STEP_ERROR_RATIO / 4.0
        shrinks = (math.isfinite(ef) and not math.isfinite(e)) or (math.isfinite(ef) and ef * ratio <= e)
        if not shrinks:
            break
        best = finer
    steps = ", ".join(f"{numbers.num(e, 2)} at {numbers.num(1e3 * dt, 4)} ms" for dt, e in trail)
    if len(trail) > 1:
        if best is first:
            first.notes.append(f"{what} {steps}: a finer step does not shrink it as an integration error shrinks")
        else:
            best.notes.append(f"{what} {steps} (the step's error, second order): kept the run at {numbers.num(1e3 * best.dt, 4)} ms")
    best.timing["total_s"] = spent
    resolved = good(best)
    remedy = None
    if not resolved and shrinks is not False and target is not None:
        e = _error_at(error(best))
        goal = target(best)
        if math.isfinite(e) and goal is not None and goal > 0 and e > goal:
            remedy = best.dt * math.sqrt(goal / e)
        elif not math.isfinite(e):
            remedy = best.dt / 2.0
    return best, Refinement(shrinks, not resolved and best.dt / finest < 1.5, remedy)


def step_setting(dt: float) -> str:
    """A step as a spec would give it, rounded down to two significant digits: "validation: {dt: 1.2e-06 s}"."""
    exponent = math.floor(math.log10(dt))
    mantissa = math.floor(dt / 10.0**exponent * 10.0) / 10.0
    return f"validation: {{dt: {mantissa:g}e{exponent:+03d} s}}"


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


JUMP = 1e-3  # an acceleration step above this fraction of a law's largest acceleration is a jump
#: :func:`_find_jumps` cuts each candidate interval in this many sections a round (one call of each
#: law for all of them: the calls, not the points, are what a law costs), SECTION_ROUNDS rounds
SECTIONS = 32
SECTION_ROUNDS = 12


class _ByLaws:
    """The last few results of a function of a model's driver laws and a time grid, remembered:
    every run of a stage, and every measurement of its loads, asks again for the same laws and
    step times, on the stage's model and on the model with pymunk's floor parts, which shares its
    laws. Keyed by the laws' identity (all that such a function reads of the model: they are
    functions, kept alive by the entry) and the times by value; ``size`` entries, the oldest
    forgotten first."""

    def __init__(self, size: int) -> None:
        self.size = size
        self.entries: dict[tuple, tuple[tuple, np.ndarray, object]] = {}

    def get(self, model: Model, times: np.ndarray, compute):
        """``compute(model, times)``, or the result remembered for the same laws and times."""
        times = np.asarray(times, dtype=float)
        laws = tuple(d.law for d in model.drivers)
        k = (tuple(id(law) for law in laws), times.shape, hash(times.tobytes()))
        hit = self.entries.get(k)
        if hit is None or any(a is not b for a, b in zip(hit[0], laws)) or not np.array_equal(hit[1], times):
            if len(self.entries) >= self.size:
                self.entries.pop(next(iter(self.entries)))
            hit = (laws, times.copy(), compute(model, times))
            self.entries[k] = hit
        return hit[2]

    def clear(self) -> None:
        self.entries.clear()


#: :func:`_find_jumps` by laws and times (the bisection evaluates each law 120 times: 7 % of the
#: simulated build's CPU before it was remembered; by model, a third of paper 003's finds were the
#: other model's)
_JUMPS_MEMO = _ByLaws(32)
#: :func:`_find_law_kinds` by laws and times (three evaluations of every law on the analysis grid
#: and a loop over the samples, for every run of a stage: 1,900 calls in the simulated build of specs/)
_KINDS_MEMO = _ByLaws(32)


def _located_jumps(model: Model, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_find_jumps`, remembered (:data:`_JUMPS_MEMO`). The arrays returned are copies."""
    ks, tj = _JUMPS_MEMO.get(model, times, _find_jumps)
    return ks.copy(), tj.copy()


def _find_jumps(model: Model, times: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(k, t_j) of every acceleration jump of a driver law between times[k-1] and times[k]. The
    intervals where some law's acceleration changes by more than 50 times the median change are
    candidates; each is cut in :data:`SECTIONS` (all at once), the section with the largest change
    kept, down to round-off (:data:`SECTION_ROUNDS` rounds: the 2^-60 of the interval that 60
    bisections reach, in a fifth of the laws' calls), and kept where the acceleration
    still steps by more than :data:`JUMP` of the law's largest across the last interval: a fast
    but smooth change (a path's arc, where the acceleration turns with the tangent) shrinks to
    nothing and is no jump."""
    cand: set[int] = set()
    laws = [d.law for d in model.drivers]
    accs = [np.asarray(law(times)[2], dtype=float) for law in laws]
    for a in accs:
        if len(a) < 3:
            continue
        diff = np.abs(np.diff(a))
        tiny = 1e-9 * (float(np.max(np.abs(a))) or 1.0)
        cand.update(int(k) + 1 for k in np.flatnonzero(diff > 50.0 * float(np.median(diff)) + tiny))
    ks = np.asarray(sorted(cand), dtype=int)
    if ks.size == 0:
        return ks, np.zeros(0)
    scale = np.array([float(np.max(np.abs(a))) or 1.0 for a in accs])

    def acc(t: np.ndarray) -> np.ndarray:  # (laws, intervals), in units of each law's largest
        return np.array([np.asarray(law(t)[2], dtype=float).reshape(-1) for law in laws]) / scale[:, None]

    a, b = times[ks - 1].astype(float), times[ks].astype(float)
    fa, fb = acc(a), acc(b)
    inner = np.arange(1, SECTIONS)[:, None] / SECTIONS
    for _ in range(SECTION_ROUNDS):  # SECTIONS ** SECTION_ROUNDS = 2^60: the bisection's 60 halvings
        if not np.any(b > np.nextafter(a, np.inf)):
            # every interval is down to two adjacent floats, where its nodes are its ends and a
            # round keeps it: the same jumps as after the remaining rounds (a step of 1e-4 s at
            # t ~ 1 s gets there in 9 of the 12; the laws' calls, not the rounds, are the cost)
            break
        nodes = np.concatenate([a[None], a + (b - a) * inner, b[None]])  # (SECTIONS + 1, intervals)
        f = np.concatenate([fa[:, None], acc(nodes[1:-1].reshape(-1)).reshape(len(laws), SECTIONS - 1, -1),
                            fb[:, None]], axis=1)  # (laws, SECTIONS + 1, intervals)
        j = np.argmax(np.max(np.abs(np.diff(f, axis=1)), axis=0), axis=0)  # the section with the step (the first)
        cols = np.arange(len(a))
        a, b, fa, fb = nodes[j, cols], nodes[j + 1, cols], f[:, j, cols], f[:, j + 1, cols]
    real = np.max(np.abs(fb - fa), axis=0) > JUMP
    return ks[real], (0.5 * (a + b))[real]


def _jumps(model: Model, times: np.ndarray) -> list[int]:
    """Indices k where some law's acceleration jumps between times[k-1] and times[k]."""
    return _located_jumps(model, times)[0].tolist()


def jump_times(model: Model, times: np.ndarray) -> list[float]:
    """The instants (to round-off) where some driver law's acceleration jumps."""
    return _located_jumps(model, times)[1].tolist()


def _law_kinds(model: Model, times: np.ndarray) -> list[str]:
    """:func:`_find_law_kinds`, remembered (:data:`_KINDS_MEMO`); the list returned is a copy."""
    return list(_KINDS_MEMO.get(model, times, _find_law_kinds))


def _find_law_kinds(model: Model, times: np.ndarray) -> list[str]:
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
        # sample: a thousand times that is a jump
        dm, dp = a_0 - a_m, a_p - a_0
        jump = np.maximum(np.abs(dm), np.abs(dp)) > 1e-3 * scale
        left_ok = np.abs(dm) <= 1e-3 * scale
        # its jerk changes across the sample by snap * delta, a kink's by the jerk's jump: a
        # kink is a change of more than 1e-3 of the law's largest jerk (at least scale / T).
        # (Not 1e-9 of the acceleration: the snap of a fast rise inside a long motion passed
        # that, and a cam's 3-4-5 rises of 0.175 s in a 1 s motion were 180 "kinks", each
        # extrapolated from steps across the true kink at the rise's end.)
        smooth_jerk = np.maximum(np.abs(dm), np.abs(dp))[~jump] / delta
        jerk_scale = max(float(np.max(smooth_jerk)) if smooth_jerk.size else 0.0, scale / T)
        kink = np.abs(dp - dm) / delta > 1e-3 * jerk_scale
        for i in range(len(times)):
            if jump[i]:
                side = "left" if left_ok[i] else "right"
                kinds[i] = side if kinds[i] in ("smooth", "kink", side) else "mixed"
            elif kink[i] and kinds[i] == "smooth":
                kinds[i] = "kink"
    return kinds

