"""The spec: one YAML file describing a mechanism, its motion, the balancing method and the
analysis. ``balpipe schema`` prints its JSON Schema.

The mechanism and balancing sections are unions of the templates and methods the registry
discovered (:mod:`balpipe.plugins`, :mod:`balpipe.registry`): each is a pydantic model with a
``template`` (``method``) literal that discriminates the union.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, field_validator

from . import registry
from .display.units import display_units
from .laws.frame_spec import FrameSpec
from .laws.load_spec import LoadSpec
from .laws.motion_spec import Motion
from .spec_parts import Strict
from .sweep_spec import SweepSpec
from .units import Length, count, number, quantity


class NoBalancing(Strict):
    """Analyse the mechanism as given."""

    method: Literal["none"] = Field(description="balancing method")


Mechanism = Annotated[
    Union[registry.template_specs()],
    Field(discriminator="template", description="the mechanism: a template with its parameters"),
]
Balancing = Annotated[
    Union[(NoBalancing, *registry.method_specs())],
    Field(discriminator="method", description="the balancing method and its design choices"),
]


class Design(Strict):
    """Another balancing design of the same mechanism, analysed beside the main one."""

    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_\-]+$", description="short name, prefixes its stages (name:stage)")
    label: str = Field("", description="label in figures and tables (default: the name)")
    balancing: Balancing


class AnalysisSettings(Strict):
    """How the motion is sampled and the loads are expressed."""

    samples: count(ge=3, le=200_000) = Field(501, description="number of time samples over the motion")
    gravity: bool = Field(False, description="gravity along -y; most papers work in a horizontal plane")
    g: quantity("acceleration", gt=0) = Field(9.80665, description="gravitational acceleration")
    moment_point: tuple[Length, Length] = Field((0.0, 0.0), description="point about which shaking moments are taken")
    balance_tolerance: number(gt=0, lt=1) = Field(
        1e-9,
        description="a stage counts as balanced when its peak is below this fraction of the reference load (the unbalanced peak, floored by 1 % of the gross inertial load)",
    )
    claim_tolerance: dict[str, number(gt=0, lt=1)] = Field(
        {}, description="the tolerance of a stage's claims by stage name (default: balance_tolerance for computed "
        "designs; for stages typed by hand, balance_tolerance plus what the rounding of their numbers allows)")


class ValidationSpec(Strict):
    """Settings of the pymunk validation of every stage."""

    enabled: bool = Field(True, description="simulate every stage in pymunk")
    dt: quantity("time", gt=0) | None = Field(None, description="time step in s (default chosen per mechanism); at least duration / 1e6 (a limit: one million steps)")
    iterations: count(ge=1, le=10_000) | None = Field(None, description="solver iterations per step")
    tolerance: number(gt=0, le=0.01) = Field(0.01, description="pass when residuals are below this fraction of the reference loads: the unbalanced peaks, floored by 1 % of the gross inertial load (at most 1 %)")
    reactionless: bool | None = Field(None, description="free-floating frame demonstration of every stage (default: in paper specs, the stages claiming to cancel force and moment and their reference stage)")
    max_refinement: number(ge=1, le=64) = Field(8, description="the validator's own budget: a run that cannot resolve its error at the first step is rerun at finer steps, down to the first divided by this; still unresolved, it is 'unconfirmed' with the setting that would resolve it (1: no refinement)")


class Reference(Strict):
    """A published value to compare with a computed one."""

    name: str = Field(
        description="a computed parameter's name (e.g. mcp1), or stage.metric for a stage result "
        "(e.g. unbalanced.max_shaking_force)"
    )
    published: number() = Field(description="the value printed in the paper, in SI units")
    unit: str = Field("", description="unit of the value, for display")
    tolerance: number(ge=0) = Field(0.005, description="relative tolerance for 'agrees'")
    note: str = Field("", description="what the paper says, misprints, how to read it")
    expect: Literal["agree", "differ", "misprint", "assumption"] = Field(
        "agree", description="'differ' when the published value is known not to reproduce (the note says why); "
        "'misprint' when the printed value is a misprint the note explains (counted apart, never lowering the "
        "verdict); 'assumption' when it reproduces within the stated tolerance only under assumptions the paper "
        "does not state (the note states them)"
    )


class ReportSettings(Strict):
    """How the study's pages show it (results.json and the CSV files stay SI)."""

    units: str | dict[str, str] | None = Field(
        None, description="the units every number on the pages uses: 'SI' (default) or 'engineering' (mm, kg, kN, "
        "kN m, rpm, deg, kW), or a mapping {quantity: unit} over SI (or over 'preset'): length m/mm/cm, mass kg/g, "
        "force N/kN, moment N m/kN m/N mm, speed rad/s/rpm, angle rad/deg, power W/kW")

    @field_validator("units")
    @classmethod
    def _known_units(cls, v: str | dict[str, str] | None) -> str | dict[str, str] | None:
        display_units(v)  # a ValueError names the quantity or unit
        return v


class Spec(Strict):
    """A balancing study: mechanism, motion, method, analysis and references."""

    name: str = Field(min_length=1, description="title of the study")
    description: str = Field("", description="what the spec reproduces and which values are assumed")
    paper: str | None = Field(None, description="the paper the spec reproduces, if any")
    mechanism: Mechanism
    motion: Motion
    balancing: Balancing = Field(NoBalancing(method="none"))
    analysis: AnalysisSettings = Field(AnalysisSettings())
    validation: ValidationSpec = Field(ValidationSpec())
    loads: list[LoadSpec] = Field(
        [], description="springs, dampers, force laws, gas pressures, torsional springs, applied forces and torques, "
        "joint friction: counted in the efforts, reactions and frame loads, never in the shaking loads")
    frame: FrameSpec | None = Field(
        None, description="the frame as a rigid body on elastic mounts: its vibration and the forces on the floor per stage")
    references: list[Reference] = Field([], description="published values to compare with")
    compare: list[Design] = Field(
        [], description="other balancing designs of the same mechanism, analysed and tabulated beside the main one"
    )
    report: ReportSettings = Field(ReportSettings(), description="how the pages show the study: their units")
    sweep: SweepSpec | None = Field(
        None, description="a design sweep run by 'balpipe sweep SPEC' (flags override it); 'balpipe build' ignores it"
    )
