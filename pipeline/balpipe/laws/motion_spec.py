"""The ``motion`` section of a spec: the laws of the driven coordinates over a duration or a
number of cycles. Here, below the spec, so that a balancing method can take further motions of
the same schema (``partial_balance``'s ``motions``)."""

from __future__ import annotations

from typing import Literal

from pydantic import Field, PrivateAttr, model_validator

from ..spec_parts import Strict
from ..units import AccelFraction, Cycles, Duration
from .drives import Drive, common_period, period


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
    cycles: Cycles | None = Field(
        None, description="instead of duration: this many periods of the periodic drives (constant speed "
        "in rpm or rad/s: one turn; cam, fourier: their period; cycle: the sum of its segments)")
    accel_fraction: AccelFraction = Field(
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
