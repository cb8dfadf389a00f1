"""The validation stage of the pipeline: every balancing stage simulated in pymunk
(:mod:`balpipe.validate`), and the optional free-floating-frame demonstration."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

from .runtime import pool
from .cache import simulation as sim_cache
from .limits import stage_dt
from .study import Study
from .validate import FreeFloating, ValidationSettings, free_floating
from .validate.floating import motion_only
from .validate.run import model_scale
from .validate.shared import stage_runs

#: mass of the free-floating frame (kg)
BASE_MASS = 10.0


def settings_for(study: Study, stage: str | None = None) -> ValidationSettings:
    """The validation settings of the spec, with the time step of the stage named ``stage``
    (:func:`balpipe.limits.stage_dt`; None: the spec's ``validation.dt``)."""
    v = study.spec.validation
    dt = v.dt if stage is None else stage_dt(study.spec, stage)
    return ValidationSettings(dt=dt, iterations=v.iterations, tolerance=v.tolerance, max_refinement=v.max_refinement)


def reactionless_stages(study: Study) -> list[int]:
    """The stages (indices) of the free-floating demonstration: every stage where the spec asks
    for it (``validation.reactionless: true``); none where it turns it off; by default, in a
    paper's spec (one naming a ``paper``), the stages that claim to be reactionless (to cancel
    both the shaking force and the shaking moment) and the stages they are measured against
    (:meth:`balpipe.study.Study.reference_stage`, the unbalanced one: the frame it pushes around
    beside the one they leave at rest), none where no stage claims it. A demonstration of a
    stage that claims neither shows nothing the validation does not (its frame drifts, as the
    unbalanced one's does): before, paper 000's specs ran it for all of their 4 to 7 stages,
    a third of the simulated build's CPU, mostly on stages pymunk could not hold together on a
    free frame."""
    flag = study.spec.validation.reactionless
    every = list(range(len(study.stages)))
    if flag is not None:
        return every if flag else []
    if study.spec.paper is None:
        return []
    claims = [k for k, s in enumerate(study.stages) if "force" in s.stage.balances and "moment" in s.stage.balances]
    keep = set(claims)
    for k in claims:
        ref = study.reference_stage(study.stages[k])
        keep.update(j for j, s in enumerate(study.stages) if s is ref)
    return sorted(keep)


def reactionless_enabled(study: Study) -> bool:
    """Some stage gets the free-floating demonstration (:func:`reactionless_stages`)."""
    return bool(reactionless_stages(study))


@dataclass
class Reactionless:
    """The free-floating runs of every stage, for the page and results.json."""

    labels: list[str]
    names: list[str]
    runs: list[FreeFloating]
    models: list = field(default_factory=list)

    def to_json(self) -> dict:
        return {name: run.to_json() for name, run in zip(self.names, self.runs)}

    @property
    def base_mass(self) -> float:
        return self.runs[0].base_mass

    @property
    def base_inertia(self) -> float:
        return self.runs[0].base_inertia

    def rows(self) -> list[dict]:
        return [
            {"label": lab, "max_drift_m": r.max_drift, "max_rotation_deg": math.degrees(r.max_rotation),
             "method": r.method_label, "base_mass": r.base_mass, "base_inertia": r.base_inertia,
             "massless_drift_m": r.massless_max_drift if r.small_masses else None,
             "massless_rotation_deg": math.degrees(r.massless_max_rotation) if r.small_masses else None,
             "reference_difference_m": r.reference_difference[0],
             "reference_difference_deg": math.degrees(r.reference_difference[1]),
             "notes": "; ".join(r.notes)}
            for lab, r in zip(self.labels, self.runs)
        ]

    @property
    def same_base(self) -> bool:
        """Every stage ran on the same frame (mass and inertia)."""
        return len({(r.base_mass, r.base_inertia) for r in self.runs}) == 1

    def player(self) -> tuple[str, str]:
        """The free-floating runs' player (:func:`balpipe.draw.player.player`): its markup and its
        caption's sentence on the panels' scales and the gears' numbers."""
        from .draw.player import player

        return player([
            {"label": lab, "model": m, "t": r.t, "base": r.base, "poses": r.poses}
            for lab, m, r in zip(self.labels, self.models, self.runs)
        ])


def _stage_runs(k: int, study: Study):
    """Validation and torque-driven run of stage ``k`` (relative to the unbalanced inertial peaks
    (the shaking loads' peaks without gravity) of the stage's own reference (Stage.reference: with
    several trajectories, that trajectory's unbalanced stage; else the first stage), floored by
    that model's gross inertial loads (balpipe.load_reference): the same denominators as the
    stage's ratios)."""
    s = study.stages[k]
    settings = settings_for(study, s.stage.name)
    ref = s.metrics.reference_loads
    F0, M0 = ref.force_peak, ref.moment_peak
    expect = tuple(x for x in ("force", "moment") if x in s.stage.balances)
    model = simulated_model(s.stage.model)
    # the loads imposed on the motion, and the inverse dynamics (the engine's efforts drive the
    # mechanism): one torque-driven run where it proves both (:mod:`balpipe.validate.shared`)
    return sim_cache.run(stage_runs, model, s.analysis, (F0, M0), settings, expect, reference=ref)


def simulated_model(model):
    """``model`` as the simulations read it: without the spec locations of its parts (for error
    messages only), so that the same stage in two specs is one simulation (:mod:`.sim_cache`)."""
    return replace(model, sources={})


def _floating_run(k: int, base_inertia: float, settings: ValidationSettings | None,
                  study: Study) -> FreeFloating:
    s = study.stages[k]
    # the motion alone (:func:`balpipe.validate.floating.motion_only`): one run for every spec of the
    # same mechanism and motion, whatever their gravity and loads
    return sim_cache.run(free_floating, simulated_model(s.stage.model), motion_only(s.analysis), BASE_MASS,
                         base_inertia, settings=settings)


def _parallel(study: Study, workers: int, tasks: list[tuple]) -> list:
    """``fn(*a, study)`` for every ``(fn, a)`` of ``tasks``, results in that order; in ``workers``
    forked processes when more than one (:func:`balpipe.runtime.pool.forked`: one pool, a worker that
    finishes its task takes the next, whatever its kind, so no core waits for the slowest stage
    before the free-frame runs start; the study inherited, not pickled). Each task runs whole
    simulations, which are deterministic: the results do not depend on ``workers``."""
    if workers <= 1 or len(tasks) <= 1:
        return [fn(*a, study) for fn, a in tasks]
    out = []
    for result, keys in pool.forked([(_keyed, (fn, a)) for fn, a in tasks], workers, study):
        sim_cache.mark_used(keys)  # the worker's cache keys: the parent's store prunes the rest
        out.append(result)
    return out


def _keyed(fn, a: tuple, study: Study) -> tuple:
    """``fn(*a, study)`` in a forked worker, with the simulation cache keys it used (:mod:`.sim_cache`)."""
    before = sim_cache.used()
    result = fn(*a, study)
    return result, sim_cache.used() - before


def simulate_study(study: Study, workers: int = 1) -> None:
    """Validate every stage; failures (a claim shown false) become problems of the study (the build
    exits 1), unconfirmed checks (an error not resolved within the validator's budget) its
    ``unconfirmed`` list (exit 0, unless ``build --strict``).
    ``workers`` > 1: the stages' simulations, and the free-frame runs, run in that many forked
    processes from one pool (for a build that leaves cores free); the results, and the order of
    the problems, are the same."""
    n = len(study.stages)
    tasks: list[tuple] = [(_stage_runs, (k,)) for k in range(n)]
    floating = reactionless_enabled(study)
    if floating:
        tasks += _floating_tasks(study, settings_for(study))
    runs = _parallel(study, workers, tasks)
    for s, (v, tq) in zip(study.stages, runs[:n]):
        s.validation, s.torque = v, tq
        for what, r in (("pymunk validation", v), ("torque-driven run", tq)):
            if r.passed:
                continue
            if r.unconfirmed:  # nothing shown false: said, not failed (``build --strict`` fails on it)
                study.unconfirmed.append(f"{what} of stage {s.stage.name!r} unconfirmed: {'; '.join(r.reasons)}; "
                                         f"remedy: {r.remedy}")
            else:
                study.problems.append(f"{what} of stage {s.stage.name!r} fails: {'; '.join(r.reasons)}")
    if floating:
        study.reactionless = _reactionless(study, runs[n:], reactionless_stages(study))


def _floating_tasks(study: Study, settings: ValidationSettings | None, stages: list[int] | None = None) -> list[tuple]:
    """The ``stages`` (default :func:`reactionless_stages`) on the same free-floating frame: mass
    BASE_MASS, the inertia of a square plate reaching the farthest centre of mass of any stage
    of the spec (the same frame whichever stages are shown)."""
    reach = max(model_scale(s.analysis) for s in study.stages)
    base_inertia = (2.0 / 3.0) * BASE_MASS * reach**2
    ks = reactionless_stages(study) if stages is None else stages
    return [(_floating_run, (k, base_inertia, settings)) for k in ks]


def _reactionless(study: Study, runs: list[FreeFloating], stages: list[int]) -> Reactionless:
    shown = [study.stages[k] for k in stages]
    return Reactionless([s.stage.label for s in shown], [s.stage.name for s in shown], runs, [s.stage.model for s in shown])


def reactionless_runs(study: Study, settings: ValidationSettings | None = None, workers: int = 1) -> Reactionless:
    """The free-floating runs of every stage (:func:`_floating_tasks`), asked for or not."""
    every = list(range(len(study.stages)))
    return _reactionless(study, _parallel(study, workers, _floating_tasks(study, settings, every)), every)


def timing(study: Study) -> dict:
    """Wall-clock seconds of the simulations (kept out of the deterministic files), per stage: the
    position-driven check's (``total_s``), the torque-driven run's, the free-floating run's and
    ``all_runs_s``, their sum, which the page's run-time column shows."""
    out = {}
    for s in study.stages:
        if s.validation is not None:
            out[s.stage.name] = dict(s.validation.timing)
        if s.torque is not None:
            out.setdefault(s.stage.name, {})["torque_driven_s"] = float(s.torque.timing.get("total_s", 0.0))
    if study.reactionless is not None:
        for name, r in zip(study.reactionless.names, study.reactionless.runs):
            out.setdefault(name, {})["reactionless_s"] = float(r.timing.get("total_s", 0.0))
    for t in out.values():  # every run of the stage (a stage its torque-driven run proves: that run's, and
        # the validation's are its tries that came apart and its runs with more solver iterations, if any)
        t["all_runs_s"] = t.get("total_s", 0.0) + t.get("torque_driven_s", 0.0) + t.get("reactionless_s", 0.0)
    return out



def timing_script(times: dict) -> str:
    """``timing.js``: fills the page's run-time cells. The only file of a page that changes
    from one identical build to the next, so the page itself stays byte-identical."""
    import json

    totals = {k: round(v["all_runs_s"], 4) for k, v in times.items()}
    return (
        "(function(){var T=" + json.dumps(totals, sort_keys=True) + ";"
        "document.querySelectorAll('[data-timing]').forEach(function(e){"
        "var v=T[e.getAttribute('data-timing')];if(v!=null)e.textContent=v.toFixed(3)+' s';});})();\n"
    )
