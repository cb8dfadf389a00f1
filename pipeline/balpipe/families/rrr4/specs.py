"""The spec sections of the family's balancing methods: pydantic classes only, so that the schema
(:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them from here.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from ...spec_parts import Strict
from ...units import Mass, PositiveLength


class CounterMassDistances(Strict):
    """Distance of each counter-mass from its link's proximal joint."""

    proximal: PositiveLength = Field(description="on the links l_i1, from A_i")
    distal: PositiveLength = Field(description="on the links l_i2, from B_i")


class RRR4Balancing(Strict):
    """Paper 001's counter-mass balancing of the n-RRR: leg by leg (eqs. 8-11) and, with four
    legs, from the general conditions (eq. 17) and the special kinematics (eqs. 19, 21)."""

    method: Literal["rrr4_counter_masses"] = Field(description="balancing method")
    counterweights: CounterMassDistances
    platform_split: list[Mass] | None = Field(
        None,
        description="mu_5i, the platform's point masses at the C_i of the legs present, in leg order "
        "(eqs. 2-4 must hold); default: the minimum-norm split",
    )
    independent: list[Literal[12, 22, 32, 42]] = Field(
        [],
        description="distal links l_i2 whose centre of mass along the link stays as built (Sec. II.B-D, "
        "Figs. 2b-d): mu_5i = -m_i2 p_i2 / l_i2 (eq. 11) instead of a counter-mass, the other mu_5i from "
        "eqs. 2-4",
    )
    topologies: bool = Field(
        True, description="also build the eq. 17 design (Fig. 4a) and, for fig5a/fig5b kinematics, eq. 19/21's (Fig. 6)"
    )
    least_mass: bool = Field(
        True,
        description="also build the least-mass design: the generic condition finder's conditions met by one "
        "counter-mass per link anywhere within the leg-by-leg distances of its proximal joint (linprog)",
    )
