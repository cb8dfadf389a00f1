"""Limits of a spec that are checked before any work starts, and the check that the computed
loads are finite.

Per-field magnitudes are bounded by :data:`balpipe.units.MAX_ABS` and by the fields' own bounds
(``analysis.samples`` <= 200 000, ``validation.iterations`` <= 10 000, file size and nesting in
:mod:`balpipe.loader`); the limits here involve several fields. Each refusal names the field and
the limit (docs/limits.md).
"""

from __future__ import annotations

import math
from typing import Any

from .spec_parts import SpecFieldError

#: Simulation steps of one stage: validation.dt must be at least duration / MAX_SIM_STEPS.
MAX_SIM_STEPS = 1_000_000


def check_limits(spec: Any) -> None:
    """Raise :class:`SpecFieldError` for a spec whose fields together exceed a limit."""
    T = spec.motion.duration
    steps_of = [(("validation", "dt"), spec.validation.dt)] + [
        (("validation", "stage_dt", name), dt) for name, dt in spec.validation.stage_dt.items()]
    for where, dt in steps_of:
        if dt is None:
            continue
        steps = T / dt
        if not math.isfinite(steps) or steps > MAX_SIM_STEPS:
            raise SpecFieldError(
                where,
                f"a time step of {dt:.3g} s takes {steps:.3g} steps over the {T:.4g} s motion "
                f"(limit {MAX_SIM_STEPS:,} steps: dt >= {T / MAX_SIM_STEPS:.3g} s)",
            )
        if dt > T:
            raise SpecFieldError(where, f"the time step {dt:.4g} s is longer than the motion ({T:.4g} s)")


def check_finite(study: Any) -> None:
    """Raise :class:`SpecFieldError` when a stage's loads are not finite numbers (an overflow:
    magnitudes, or a motion too fast for its duration)."""
    for s in study.stages:
        an = s.analysis
        for what, peak in (("shaking force", an.max_force), ("shaking moment", an.max_moment)):
            if not math.isfinite(peak):
                raise SpecFieldError(
                    ("motion", "duration"),
                    f"stage {s.stage.name!r}: the {what} overflows ({peak}); the motion is too fast for "
                    "its duration or the masses and lengths are too large",
                )


def stage_dt(spec: Any, stage: str) -> float | None:
    """The time step the spec gives the stage named ``stage``: its ``validation.stage_dt``, else
    ``validation.dt``; None: the default (:func:`balpipe.validate.default_settings`)."""
    v = spec.validation
    return v.stage_dt.get(stage, v.dt)


def check_simulation(study: Any) -> None:
    """Before the pymunk validation starts: the number of steps of each stage's simulation,
    duration / dt with the spec's dt or the default one (which shrinks with the fastest body's
    angular speed), is at most :data:`MAX_SIM_STEPS`."""
    spec = study.spec
    if not spec.validation.enabled:
        return
    from .validate import default_settings  # balpipe.validate loads only its settings for this: no pymunk

    T = spec.motion.duration
    for s in study.stages:
        given = stage_dt(spec, s.stage.name)
        dt = given or default_settings(s.stage.model, s.analysis)[0]
        steps = T / dt if dt > 0 else math.inf
        if not math.isfinite(steps) or steps > MAX_SIM_STEPS:
            where = (("validation", "stage_dt", s.stage.name) if s.stage.name in spec.validation.stage_dt
                     else ("validation", "dt") if given else ("motion", "duration"))
            raise SpecFieldError(
                where,
                f"stage {s.stage.name!r}: the simulation would take {steps:.3g} steps of {dt:.3g} s "
                f"(limit {MAX_SIM_STEPS:,}); the motion is too fast for its duration: lengthen it, or set "
                "validation.enabled: false",
            )
