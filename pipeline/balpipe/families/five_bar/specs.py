"""The spec sections of the family's balancing methods: pydantic classes only, so that the schema
(:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them from here.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from .template import GearPart
from ...mechanics.meshes import DEFAULT_PRESSURE_ANGLE, PressureAngle
from ...spec_parts import Strict
from ...units import Inertia, Length, Mass, PositiveNumber


class CounterweightPositions(Strict):
    """Point-mass counterweights on the link axes, positions measured like a link's ``com``."""

    proximal: Length = Field(
        description="counterweights 1, 2: position along A_jB_j from A_j (negative: beyond A_j, "
        "the paper's r_CW1 = r_CW2 = 0.18 m is -0.18 m here)"
    )
    distal: Length = Field(
        description="counterweights 3, 4: position along B_jC from B_j (negative: beyond B_j; "
        "the paper's r_CW3 = r_CW4 = 0.15 m is -0.15 m here)"
    )


class CounterRotation(Strict):
    """Gears 3', 4' fixed on the distal links at B_j, meshing with gears 6, 7 on axes A_j carried
    by the input links (r3' + r6 = l1, r4' + r7 = l2)."""

    ratio: PositiveNumber = Field(1.0, description="U63 = U74 = r3'/r6 = r4'/r7 (the paper: 1)")
    gear_3p: GearPart = Field(
        GearPart(), description="gears 3' and 4' (each), fixed on the distal links at B_j in the full stage"
    )
    planet_mass: Mass = Field(0.0, description="mass of each of gears 6 and 7 (their inertias are computed)")
    gear_1p_inertia: Inertia | None = Field(
        None,
        description="inertia of gears 1' and 2' (each) in the moment-balanced design, if they are "
        "changed for it (the paper lists I1' = I2' = 0.4 kg m^2 only there); default: as in "
        "mechanism.coupling",
    )
    pressure_angle: PressureAngle = Field(
        DEFAULT_PRESSURE_ANGLE, description="pressure angle of the meshes 3'-6 and 4'-7 (default "
        "20 deg): radial tooth force = |tangential| tan of it"
    )


class BalancedInertias(Strict):
    """Centroidal inertias of the balanced links (link + counterweight, gears excluded): the
    I1..I4 of the paper's eq. 17."""

    proximal: Inertia = Field(description="I1 = I2: balanced input links")
    distal: Inertia = Field(description="I3 = I4: balanced distal links")


class FiveBarGearBalancing(Strict):
    """Counterweights (eqs. 9-16) and counter-rotating gears 5, 6, 7 (eqs. 19-21) for the
    fixed-sequence five-bar."""

    method: Literal["five_bar_gear_balancing"] = Field(description="balancing method")
    counterweights: CounterweightPositions
    counter_rotation: CounterRotation = Field(CounterRotation())
    balanced_inertias: BalancedInertias | None = Field(
        None,
        description="the paper's reading of eq. 17: these are the balanced links' centroidal "
        "inertias, realised by giving the counterweights the inertia needed; omitted: point-mass "
        "counterweights on the bare links",
    )
    point_mass_stage: bool = Field(
        False,
        description="with balanced_inertias: also analyse the complete balancing with point-mass "
        "counterweights on the bare links (I5, I6, I7 of eqs. 19-21 recomputed for them), a stage "
        "that can be built",
    )
