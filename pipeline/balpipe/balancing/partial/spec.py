"""The spec of the ``partial_balance`` method (DESIGN.md, "Partial balancing is a cone program"):
the parts the optimiser may add, what it minimises, and under which budget and caps.

This module only describes the input; :mod:`.partial` solves it (no solver is imported here)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, model_validator

from ...laws.motion_spec import Motion
from ...spec_parts import Strict
from ...units import Inertia, Mass, count, number
from ..part_spec import PartShapeSpec
from ..specs import CounterRotationSpec, CounterweightRegionSpec, LoadTerm, Point

LOADS = ("shaking_force", "shaking_moment", "effort", "joint")
MAIN_MOTION = "motion"  # the name of the spec's own motion in the report


class PartialCounterweightSpec(CounterweightRegionSpec):
    """A counterweight of free mass on a body, its centre of mass within one region of the body's
    frame (``at`` a point, a ``segment``, a ``disc`` or a convex ``polygon``) and its mass spread
    within that region (any realisable inertia)."""

    polygon: list[Point] | None = Field(None, min_length=3, description="anywhere in this convex polygon (vertices in order)")
    max_mass: Mass | None = Field(None, description="upper bound on this counterweight's mass")
    part: PartShapeSpec | None = Field(None, description="refused here: partial_balance chooses each counterweight's "
                                       "spread inertia; make parts in a force_balance, moment_balance or stages "
                                       "design (docs/parts.md)")

    @model_validator(mode="after")
    def _one_region(self):
        if self.part is not None:
            raise ValueError("part: partial_balance chooses each counterweight's spread inertia and does not size "
                             "parts; make them in a force_balance, moment_balance or stages design (compare)")
        given = [k for k in ("at", "segment", "disc", "polygon") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of at, segment, disc, polygon (got {', '.join(given) or 'none'})")
        return self


class PartialCounterRotationSpec(CounterRotationSpec):
    """A counter-rotating disc whose inertia (>= 0) the optimiser chooses."""

    max_inertia: Inertia | None = Field(None, description="upper bound on the disc's inertia")


class WeightedTerm(LoadTerm):
    """An objective term: ``weight`` x the load's measure / the unbalanced mechanism's."""

    weight: number(gt=0) = Field(1.0, description="weight of this term (terms are divided by their unbalanced values)")


class Cap(LoadTerm):
    """A cap on a load: at most ``at_most`` (x the unbalanced value when ``relative``)."""

    at_most: number(ge=0) = Field(description="the cap")
    relative: bool = Field(True, description="at_most is a multiple of the unbalanced mechanism's value")


class Budget(Strict):
    """What the parts may add."""

    mass: Mass = Field(description="added mass at most (counterweights and the discs' own masses)")
    inertia: Inertia | None = Field(
        None, description="added inertia at most: the discs' inertias plus the counterweights' second moments "
        "about their bodies' frame origins (a bound on their centroidal inertias)"
    )


class FrontSettings(Strict):
    """Pareto fronts drawn on the page, each a sequence of cone programmes."""

    points: count(ge=2, le=1000) = Field(30, description="points per front")
    max_mass: Mass | None = Field(
        None, description="the mass fronts' range [0, max_mass] (default: 1.25 x the complete force balance's "
        "least mass in the allowed regions, or the budget when larger)"
    )


class OtherMotion(Strict):
    """Another motion of the same mechanism that the design must also serve (the same machine at
    another speed, another trajectory), with the schema of the spec's ``motion`` section."""

    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_\-]+$", description="its name in the report (e.g. 600rpm; not 'motion', the spec's own)")
    motion: Motion = Field(description="the motion, as the spec's motion section")
    samples: count(ge=3, le=200_000) | None = Field(None, description="time samples over it (default: analysis.samples)")


class PartialBalance(Strict):
    """Optimal partial balancing: counterweights and counter-rotating discs chosen by a convex
    (second-order cone) programme that minimises peaks or RMS of the loads under a mass budget and
    caps, globally optimal at the analysed motion."""

    method: Literal["partial_balance"] = Field(description="balancing method")
    counterweights: list[PartialCounterweightSpec] = Field([], description="counterweights the optimiser may add")
    counter_rotations: list[PartialCounterRotationSpec] = Field([], description="counter-rotating discs the optimiser may add")
    motions: list[OtherMotion] = Field(
        [], description="further motions the design must serve with the spec's own: a peak is the largest over "
        "every motion's samples, an RMS the largest of the motions' RMS, each term divided by its unbalanced value "
        "so measured, and a cap holds on every motion; the pymunk validation runs the spec's motion")
    objective: list[WeightedTerm] = Field(min_length=1, description="terms minimised (their weighted sum)")
    budget: Budget
    caps: list[Cap] = Field([], description="caps on loads (e.g. peak effort at most 1.2 x the unbalanced)")
    fronts: FrontSettings | None = Field(FrontSettings(), description="Pareto fronts for the page (null: none)")
    label: str = Field("", description="label of the optimised stage (default: 'partial balance')")

    @model_validator(mode="after")
    def _parts(self):
        if not self.counterweights and not self.counter_rotations:
            raise ValueError("give counterweights or counter_rotations: the parts the optimiser may add")
        return self
