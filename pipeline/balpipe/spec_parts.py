"""Building blocks shared by the spec sections of every mechanism template and method."""

from __future__ import annotations

from typing import Any, Literal

from pydantic import BaseModel, ConfigDict, Field

from .units import AccelFraction, Inertia, Length, Mass, PositiveLength, Rate, RateRate


def paper_id(paper: str | None) -> str:
    """A spec's ``paper`` field to the paper's number: '000: complete shaking ...' -> '000'; ''
    without a paper."""
    return (paper or "").split(":", 1)[0].strip()


class SpecFieldError(ValueError):
    """A semantic error found after schema validation, attached to a field path of the spec.

    ``path`` is a tuple of keys and list indices from the document root, e.g.
    ``("motion", "drive", "crank", "to")``; the loader turns it into a file line and column.
    """

    def __init__(self, path: tuple[str | int, ...], message: str):
        super().__init__(message)
        self.path = tuple(path)
        self.message = message


class Strict(BaseModel):
    """Base of every spec section: unknown keys are errors, values are immutable."""

    model_config = ConfigDict(extra="forbid", frozen=True, populate_by_name=True, allow_inf_nan=False, defer_build=True)


class LinkSpec(Strict):
    """A bar-shaped link between its proximal joint (origin of its frame) and distal joint (at
    ``length`` along its x axis). Mass parameters are those of the bare link."""

    length: PositiveLength = Field(description="distance between the link's two joints")
    mass: Mass = Field(description="mass of the bare link")
    com: Length = Field(
        description="position of the centre of mass along the link, measured from the proximal "
        "joint towards the distal one (negative: beyond the proximal joint)"
    )
    com_offset: Length = Field(0.0, description="offset of the centre of mass normal to the link (left positive)")
    inertia: Inertia = Field(description="centroidal moment of inertia of the bare link")


class BodySpec(Strict):
    """A rigid body that is not a bar (slider, platform): mass, centre of mass, inertia."""

    mass: Mass = Field(description="mass of the body")
    com: tuple[Length, Length] = Field((0.0, 0.0), description="centre of mass in the body frame")
    inertia: Inertia = Field(0.0, description="centroidal moment of inertia")


class DriveSpec(Strict):
    """Start and end of one driven coordinate. The unit depends on the coordinate (an angle for a
    crank, a length for a slider, a point [x, y] for a gripper); numbers are SI."""

    start: Any = Field(alias="from", description="value at t = 0 (angle, length or [x, y] point)")
    end: Any = Field(alias="to", description="value at t = duration")
    start_velocity: Rate = Field(0.0, description="polynomial law only: velocity at t = 0 (SI, or with a unit: rad/s, deg/s, rpm, m/s, mm/s)")
    end_velocity: Rate = Field(0.0, description="polynomial law only: velocity at the end (SI or with a unit)")
    start_acceleration: RateRate = Field(0.0, description="polynomial law only: acceleration at t = 0 (SI, or with a unit: rad/s^2, deg/s^2, m/s^2, mm/s^2)")
    end_acceleration: RateRate = Field(0.0, description="polynomial law only: acceleration at the end (SI or with a unit)")
    law: Literal["quintic", "cycloidal", "bang_bang", "trapezoidal", "polynomial"] | None = Field(
        None, description="this drive's own law (quintic, cycloidal, bang_bang, trapezoidal, polynomial); "
        "default: motion.law"
    )
    accel_fraction: AccelFraction | None = Field(
        None, description="trapezoidal law: this drive's acceleration fraction (default: motion.accel_fraction)"
    )
