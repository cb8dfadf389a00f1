"""The spec's ``frame`` section: the machine's frame as a rigid planar body on elastic mounts,
and the limits its vibration is judged by (:mod:`balpipe.mechanics.mounts` computes the motion).
Coordinates are the frame's (the mechanism's global axes); every number may carry a unit."""

from __future__ import annotations

from typing import TYPE_CHECKING

from pydantic import Field, model_validator

from ..spec_parts import Strict
from ..units import (Damping, Length, OpenFraction, PositiveForce, PositiveInertia, PositiveMass, PositiveVelocity,
                     Stiffness)

if TYPE_CHECKING:
    from ..mechanics.mounts import Frame

_NAME = r"^[A-Za-z0-9_\-]+$"


class MountSpec(Strict):
    """An elastic mount: a linear spring-damper between a point of the frame and the floor, along
    the frame's x and y axes."""

    name: str = Field("", pattern=r"^$|" + _NAME, description="name on the page (default: mount1, mount2, ... in order)")
    at: tuple[Length, Length] = Field(description="the mount's point [x, y] on the frame")
    kx: Stiffness = Field(description="stiffness along x (e.g. 200 kN/m)")
    ky: Stiffness = Field(description="stiffness along y")
    cx: Damping = Field(0.0, description="viscous damping along x (e.g. 400 N s/m)")
    cy: Damping = Field(0.0, description="viscous damping along y")


class FramePoint(Strict):
    """A point of the frame whose vibration velocity is reported (a bearing, a sensor, an operator's seat)."""

    name: str = Field(pattern=_NAME, description="the point's name on the page")
    at: tuple[Length, Length] = Field(description="[x, y] on the frame")


class FrameLimits(Strict):
    """Limits the frame's vibration is compared with (from the standard or the customer the spec
    follows: none is built in)."""

    velocity_rms: PositiveVelocity | None = Field(
        None, description="largest RMS vibration velocity along x or y at any reported point (e.g. 4.5 mm/s)")
    force_peak: PositiveForce | None = Field(
        None, description="largest peak force a mount may put on the floor (e.g. 2 kN)")


class FrameSpec(Strict):
    """The frame as a rigid body on elastic mounts. Its mass and inertia are those of what moves
    with it as one body (housing, block, base); the mechanism's loads on a fixed frame drive it
    (small motions: the frame's motion does not change those loads)."""

    mass: PositiveMass = Field(description="mass of the frame")
    inertia: PositiveInertia = Field(description="centroidal moment of inertia of the frame")
    com: tuple[Length, Length] = Field((0.0, 0.0), description="the frame's centre of mass [x, y]")
    mounts: list[MountSpec] = Field(min_length=1, description="the mounts (together they must resist x, y and rotation)")
    points: list[FramePoint] = Field([], description="further points whose vibration velocity is reported (the centre of mass and the mounts always are)")
    limits: FrameLimits = Field(FrameLimits(), description="limits of the vibration velocity and the floor forces")
    resonance_band: OpenFraction = Field(
        0.2, description="an excitation order within this fraction of a natural frequency is named near resonance")

    @model_validator(mode="after")
    def _held(self) -> "FrameSpec":
        names = [m.name or f"mount{i + 1}" for i, m in enumerate(self.mounts)] + [p.name for p in self.points]
        dup = sorted({n for n in names if names.count(n) > 1})
        if dup:
            raise ValueError(f"names of mounts and points must differ: {', '.join(dup)} used twice")
        reason = self.model().held()
        if reason:
            raise ValueError(reason)
        return self

    def model(self) -> Frame:
        """The frame and its mounts (SI) for :mod:`balpipe.mechanics.mounts` (imported here: a spec
        without a frame does not load it)."""
        from ..mechanics.mounts import Frame, Mount

        return Frame(self.mass, self.inertia, (float(self.com[0]), float(self.com[1])), tuple(
            Mount(m.name or f"mount{i + 1}", (float(m.at[0]), float(m.at[1])), m.kx, m.ky, m.cx, m.cy)
            for i, m in enumerate(self.mounts)))
