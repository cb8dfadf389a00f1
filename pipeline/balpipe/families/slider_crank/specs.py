"""The spec sections of the family's balancing methods: pydantic classes only, so that the schema
(:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them from here.
"""

from __future__ import annotations

from typing import Literal

from pydantic import Field

from ...spec_parts import Strict
from ...units import Length, Mass


class SliderCrankCounterweights(Strict):
    """Counterweights on the crank and the coupler cancel the shaking force (eq. 15). For the
    Scott-Russell geometry (offset 0, L1 = L2, eq. 19) the moment condition eq. 20 is then solved
    for the inertia named by ``moment_unknown``."""

    method: Literal["slider_crank_counterweights"] = Field(description="balancing method")
    crank_counterweight: Length = Field(
        description="position of counterweight 1 along the crank from A (the paper's rcp1 L1; "
        "negative: on the far side of A from B)"
    )
    coupler_counterweight: Length = Field(
        description="position of counterweight 2 along the coupler from B (rcp2 L2; negative: on "
        "the far side of B from C)"
    )
    crank_counterweight_mass: Mass | None = Field(
        None, description="as built: use this mass instead of eq. 15's (the page then shows what it leaves)"
    )
    coupler_counterweight_mass: Mass | None = Field(
        None, description="as built: use this mass instead of eq. 15's"
    )
    moment_unknown: Literal["crank_counterweight_inertia", "coupler_counterweight_inertia"] | None = Field(
        None,
        description="Scott-Russell only: the inertia that eq. 20 is solved for, added to that "
        "counterweight as a disc; omit to stop at force balance",
    )
