"""The spec sections of the family's balancing methods: pydantic classes only, so that the schema
(:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them from here.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from ...spec_parts import LinkSpec, Strict
from ...units import Length, Sign


class IdlerCounterweights(Strict):
    """Positions of the eight counterweights (signed lengths along the links)."""

    cylinder: Length = Field(description="mcp1 on each cylinder, from A_i towards C_i (rcp1 L1; negative: beyond A_i)")
    piston: Length = Field(description="mcp2 on each piston, from B_i towards C_i (rcp2 L1; beyond C_i when > L1)")
    link5: Length = Field(description="mcp5 on link 5, from E towards F (rcp5 L5; negative: beyond E)")
    link6: Length = Field(description="mcp6 on link 6, from F towards P (rcp6 L6; negative: beyond F)")


class Rpr3IdlerLoop(Strict):
    """Idler loop E-F-P, counterweights (eqs. 5a-d) and chained counter-rotations (eqs. 9a-d)."""

    method: Literal["rpr3_idler_loop"] = Field(description="balancing method")
    E: tuple[Length, Length] = Field((0.0, 0.0), description="base pivot E of the idler loop (the paper: O)")
    link5: LinkSpec = Field(description="link 5, EF (length L5, centre of mass r5 L5 from E)")
    link6: LinkSpec = Field(description="link 6, FP (length L6, centre of mass r6 L6 from F)")
    branch: Sign = Field(
        1, description="+1: F on the left of the line E -> P at t = 0, -1: on its right (the paper: -1, F above E)"
    )
    counterweights: IdlerCounterweights


class ScottRussellCounterweights(Strict):
    """Positions of the four counterweights of each leg (signed lengths along the links)."""

    crank: Length = Field(description="mcp1 on the crank, from A_i towards B (rcp1 L1; negative: beyond A_i)")
    coupler: Length = Field(description="mcp2 on the coupler, from B towards C (rcp2 L2; negative: beyond B)")
    piston: Length = Field(description="mcp3 on the piston, from C towards C_i (rcp3 L3; negative: away from C_i)")
    cylinder: Length = Field(description="mcp4 on the cylinder, from A_i towards C_i (rcp4 L3; negative: beyond A_i)")


MomentUnknown = Literal["crank_inertia", "coupler_inertia", "crank_counterweight_inertia", "coupler_counterweight_inertia"]


class Rpr3ScottRussell(Strict):
    """Scott-Russell legs (eq. 19), counterweights (eqs. 30a-d), eq. 30e, counter-rotations (eq. 30f)."""

    method: Literal["rpr3_scott_russell"] = Field(description="balancing method")
    crank: LinkSpec = Field(description="link 1, AB, pivoted on the base at A_i (the paper's L1, m1, r1, I1)")
    coupler: LinkSpec = Field(description="link 2, BC, pinned to the piston at C (L2 = L1, m2, r2, I2)")
    branch: Sign = Field(1, description="+1: B on the left of the leg axis A_i -> C_i, -1: on its right")
    counterweights: ScottRussellCounterweights
    moment_unknown: MomentUnknown | None = Field(
        None,
        description="what eq. 30e is solved for: the crank's or coupler's inertia (the link is redesigned "
        "in every stage), or the inertia of the crank's or coupler's counterweight (a disc); omit to "
        "keep the design as given (the page then shows eq. 30e's residual)",
    )
