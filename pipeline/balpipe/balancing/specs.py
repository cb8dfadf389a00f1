"""The spec sections of the generic balancing methods (``force_balance``, ``moment_balance``,
``stages``; ``partial_balance``'s are in :mod:`.partial_spec`): pydantic classes only, so that
the schema (:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them
from here.
"""

from __future__ import annotations

from typing import Literal, Union

from pydantic import Field, model_validator

from ..model import FRAME
from ..spec_parts import Strict
from ..units import Inertia, Length, Mass, Number, PositiveLength, count, number
from .part_spec import PartShapeSpec

RANK_TOLERANCE = 1e-9  # singular values below this fraction of the largest are dropped (conditions.find)
POLYGON_SIDES = 128  # sides of the polygon inscribed in a disc region (least_mass.solve)

Point = Union[str, tuple[Length, Length]]


class DiscRegionSpec(Strict):
    """A disc on the body: centre and radius."""

    centre: Point = Field(description="centre, [x, y] in the body frame or a named point of the body")
    radius: PositiveLength = Field(description="radius")


class CounterweightRegionSpec(Strict):
    """A point-mass counterweight on a body, within one region of the body's frame: ``at`` a
    fixed point, on a ``segment`` [from, to], or in a ``disc``."""

    body: str = Field(description="the body that carries the counterweight")
    name: str | None = Field(None, description="name (default: cw_<body>)")
    at: Point | None = Field(None, description="a fixed position ([x, y] or a named point)")
    segment: tuple[Point, Point] | None = Field(None, description="anywhere on this segment")
    disc: DiscRegionSpec | None = Field(None, description="anywhere in this disc")
    part: PartShapeSpec | None = Field(None, description="made as a part: material, shape and limits (balpipe sizes "
                                       "it, checks its fit and analyses its own inertia; docs/parts.md)")

    @model_validator(mode="after")
    def _one_region(self):
        given = [k for k in ("at", "segment", "disc") if getattr(self, k) is not None]
        if len(given) != 1:
            raise ValueError(f"give exactly one of at, segment, disc (got {', '.join(given) or 'none'})")
        return self


class FinderSettings(Strict):
    """How the conditions are found."""

    rank_tolerance: number(gt=0, lt=1e-3) = Field(RANK_TOLERANCE, description="singular values below this fraction of the largest are dropped")
    samples: count(ge=0, le=10_000) = Field(0, description="sampled states (0: 2 x 4 x bodies + 12)")
    seed: count(ge=0) = Field(0, description="seed of the state sampler")
    polygon_sides: count(ge=8, le=4096) = Field(POLYGON_SIDES, description="sides of the polygon inscribed in each disc region")


class ForceBalance(FinderSettings):
    """Force-balance conditions of any mechanism from its momentum, and the counterweights of
    least added mass in the allowed regions."""

    method: Literal["force_balance"] = Field(description="balancing method")
    counterweights: list[CounterweightRegionSpec] = Field(
        min_length=1, description="where counterweights may go (one counterweight per entry)"
    )


class CounterRotationSpec(Strict):
    """A counter-rotating disc pivoted on ``carrier`` and geared to ``geared_to``:
    w_disc - w_carrier = ratio (w_geared - w_carrier). Its inertia is computed."""

    name: str = Field(min_length=1, description="name of the disc (a new body)")
    carrier: str = Field(FRAME, description="body holding the disc's axis ('frame' for a fixed axis)")
    at: Point = Field(description="the axis: [x, y] in the carrier's frame (global on the frame) or a named point")
    geared_to: str = Field(description="the body the disc is geared to")
    ratio: Number = Field(description="(w_disc - w_carrier) / (w_geared - w_carrier); -r_g / r_disc for an external mesh")
    mass: Mass = Field(0.0, description="mass of the disc (on its axis; counted by the force balance)")
    radius: PositiveLength | None = Field(None, description="radius of the disc, for drawing (the mesh is modelled as a couple)")


class MomentBalance(FinderSettings):
    """Force balance by least-mass counterweights, then moment balance by counter-rotating discs
    whose inertias are solved from the angular-momentum regressor."""

    method: Literal["moment_balance"] = Field(description="balancing method")
    counterweights: list[CounterweightRegionSpec] = Field(
        [], description="where counterweights may go; empty: the mechanism must be force balanced already"
    )
    counter_rotations: list[CounterRotationSpec] = Field(min_length=1, description="the counter-rotating discs")
    gear_signs: Literal["given", "find"] = Field(
        "given", description="given: the ratios as written (where they cannot cancel the moment the error names "
        "signs that do); find: where they cannot, the method uses the first sign combination that does (fewest "
        "reversals first) and says so")


class PartSpec(Strict):
    """A rigid part fixed to a body: counterweight, carried gear, payload."""

    body: str = Field(description="the body that carries the part")
    name: str = Field(min_length=1, description="name, unique on the body (a later stage may change it by name)")
    mass: Mass = Field(description="mass")
    position: Point = Field((0.0, 0.0), description="centre of mass, [x, y] in the body frame or a named point")
    inertia: Inertia = Field(0.0, description="centroidal moment of inertia")
    kind: Literal["counterweight", "gear", "payload", "part"] = Field("counterweight", description="for drawing and accounting")
    radius: PositiveLength | None = Field(None, description="drawn as a disc of this radius")
    part: PartShapeSpec | None = Field(None, description="made as a part: material, shape and limits; its inertia is "
                                       "then the shape's (give no inertia; docs/parts.md)")

    @model_validator(mode="after")
    def _inertia_or_part(self):
        if self.part is not None and self.inertia:
            raise ValueError("inertia: a part's inertia is its shape's; give no inertia with part")
        return self


class GivenCounterRotation(CounterRotationSpec):
    """A counter-rotating disc with a given inertia."""

    inertia: Inertia = Field(description="centroidal inertia of the disc")


class LoadTerm(Strict):
    """One load over the motion's time samples, measured by its peak or its RMS."""

    load: Literal["shaking_force", "shaking_moment", "frame_force", "frame_moment", "effort", "joint"] = Field(
        description="shaking_force |F|, shaking_moment |M| (about the analysis' moment point; inertial, loads do not "
        "change them), frame_force, frame_moment: everything the frame feels (the shaking load plus the external "
        "loads), effort |tau| of an actuator, joint: the load a joint carries (|F| of a revolute, |N| of a "
        "prismatic pair, |T| of a gear); efforts, joint and frame loads count the spec's loads"
    )
    measure: Literal["peak", "rms"] = Field("peak", description="peak over the samples, or root mean square")
    actuator: str | None = Field(None, description="effort: the driver's name (default: every actuator, the largest)")
    joint: str | None = Field(None, description="joint: the joint's name")

    @model_validator(mode="after")
    def _names(self):
        if self.load == "joint" and not self.joint:
            raise ValueError("a joint load names its joint (joint: NAME)")
        if self.load != "joint" and self.joint:
            raise ValueError("joint: only with load: joint")
        if self.load != "effort" and self.actuator:
            raise ValueError("actuator: only with load: effort")
        return self


class StageStep(Strict):
    """One stage: parts added or changed relative to the stage before."""

    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_\-]+$", description="short name (CSV columns, references)")
    label: str = Field("", description="label in figures and tables (default: the name)")
    description: str = Field("", description="what the stage does")
    balances: Literal["", "force", "moment", "force+moment"] = Field(
        "", description="what the stage claims to cancel (checked against the analysis)"
    )
    parts: list[PartSpec] = Field([], description="parts added (or changed, by body and name)")
    remove: list[str] = Field([], description="parts removed, as body.name")
    counter_rotations: list[GivenCounterRotation] = Field([], description="counter-rotating discs added")
    aim: list[LoadTerm] = Field(
        [], description="the loads the stage is designed to lower (a crank counterbalance: the peak gearbox torque): "
        "the stage is judged on them, each against the unbalanced mechanism, and the shaking force and moment it does "
        "not name are side effects; a stage claims a balance (balances) or aims, not both"
    )
    tolerance: number(gt=0, lt=1) | None = Field(
        None, description="tolerance of the stage's claims, a fraction of the reference load; default: "
        "analysis.balance_tolerance plus what the rounding of the entered numbers allows (numbers of "
        "four or more significant digits are taken as rounded at their last digit)")

    @model_validator(mode="after")
    def _claim_or_aim(self):
        if self.aim and self.balances:
            raise ValueError("a stage claims a balance (balances) or aims at loads (aim), not both")
        return self


class Stages(Strict):
    """Balancing stages written by hand, each relative to the one before."""

    method: Literal["stages"] = Field(description="balancing method")
    stages: list[StageStep] = Field(min_length=1, description="the stages after the unbalanced one, in order")
