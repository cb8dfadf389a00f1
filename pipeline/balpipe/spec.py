"""The spec: one YAML file describing a mechanism, its motion, the balancing method and the
analysis. ``balpipe schema`` prints its JSON Schema.

The mechanism and balancing sections are unions of the templates and methods the registry
discovered (:mod:`balpipe.plugins`, :mod:`balpipe.registry`): each is a pydantic model with a
``template`` (``method``) literal that discriminates the union.
"""

from __future__ import annotations

from typing import Annotated, Literal, Union

from pydantic import Field, PrivateAttr, model_validator

from . import registry
from .laws.drives import Drive, common_period, period
from .spec_parts import Strict
from .sweep_spec import SweepSpec
from .units import Duration, Length, count, number, quantity


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


class Motion(Strict):
    """The motion of the driven coordinates: point-to-point laws on one duration, or the laws of
    real machines (constant speed, cam, Fourier, table, cycle of segments, path; docs/motion.md)
    over a duration or a number of cycles."""

    law: Literal["quintic", "cycloidal", "bang_bang", "trapezoidal", "polynomial"] = Field(
        "quintic",
        description="quintic: 3-4-5 polynomial; cycloidal; bang_bang: constant +a then -a; "
        "trapezoidal: constant acceleration, cruise, deceleration; polynomial: the lowest-degree "
        "polynomial meeting the drives' boundary velocities and accelerations",
    )
    duration: Duration | None = Field(None, description="duration of the motion (or give cycles)")
    cycles: number(gt=0, le=10_000) | None = Field(
        None, description="instead of duration: this many periods of the periodic drives (constant speed "
        "in rpm or rad/s: one turn; cam, fourier: their period; cycle: the sum of its segments)")
    accel_fraction: number(gt=0, le=0.5) = Field(
        1 / 3, description="trapezoidal law: fraction of the duration spent accelerating"
    )
    drive: dict[str, Drive] = Field(
        description="driven coordinates by name (the template lists them: e.g. crank, slider, "
        "gripper) with their law: from/to on the point-to-point laws, or law: constant_speed, cam, "
        "fourier, table, cycle, path"
    )
    _period: float | None = PrivateAttr(None)

    @model_validator(mode="after")
    def _duration_from_cycles(self) -> "Motion":
        periods = [p for p in (period(d) for d in self.drive.values()) if p is not None]
        self._period = common_period(periods)
        if self.cycles is not None and self.duration is not None:
            raise ValueError("give either duration or cycles, not both")
        if self.cycles is None and self.duration is None:
            raise ValueError("give the duration of the motion (duration: 1 s) or a number of cycles of its periodic drives (cycles: 2)")
        if self.cycles is not None:
            if self._period is None:
                raise ValueError(
                    "cycles needs a periodic drive (constant speed in rpm or rad/s, cam, fourier, cycle, a closed "
                    "path at constant speed)" if not periods else
                    f"the periodic drives' periods ({', '.join(f'{p:.6g} s' for p in periods)}) have no common multiple "
                    "among them: give the duration instead")
            object.__setattr__(self, "duration", float(self.cycles * self._period))
        return self

    @property
    def period(self) -> float | None:
        """The common period of the periodic drives (s), None when no drive is periodic: a
        motion of whole cycles lasts a multiple of it and is in steady state."""
        return self._period


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
    reactionless: bool | None = Field(None, description="free-floating frame demonstration (default: on for paper specs)")


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
    expect: Literal["agree", "differ"] = Field(
        "agree", description="'differ' when the published value is known not to reproduce (the note says why)"
    )


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
    references: list[Reference] = Field([], description="published values to compare with")
    compare: list[Design] = Field(
        [], description="other balancing designs of the same mechanism, analysed and tabulated beside the main one"
    )
    sweep: SweepSpec | None = Field(
        None, description="a design sweep run by 'balpipe sweep SPEC' (flags override it); 'balpipe build' ignores it"
    )
