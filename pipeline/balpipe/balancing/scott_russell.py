"""Eq. 20 of the slider-crank paper: the inertia condition of a force-balanced Scott-Russell
mechanism, shared by the slider-crank's counterweights and the 3-RPR's Scott-Russell legs
(eq. 30e)."""

from __future__ import annotations


def eq20_lhs(I1: float, m1: float, p1: float, mcp1: float, c1: float, L1: float,
             I2: float, m2: float, p2: float, mcp2: float, c2: float) -> float:
    """Left-hand side of eq. 20 (= eq. 28's Ieq2 and eq. 30e for a 3-RPR leg) in lengths:
    I1 + m1 p1^2 + mcp1 c1^2 + (m2 + mcp2) L1^2 - I2 - m2 p2^2 - mcp2 c2^2, the coefficient of the
    crank's rotation relative to the guide in the angular momentum of a force-balanced
    Scott-Russell mechanism (p: centres of mass, c: counterweights, from A and from B)."""
    return I1 + m1 * p1**2 + mcp1 * c1**2 + (m2 + mcp2) * L1**2 - I2 - m2 * p2**2 - mcp2 * c2**2
