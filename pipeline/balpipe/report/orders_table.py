"""The orders of each stage's shaking force and moment, for ``results.json`` and the page.

Only a periodic motion has orders: every drive periodic (constant angular speed without a ramp,
cam, Fourier, cycle, ...) and the motion given as a whole number of ``cycles``; otherwise there are
none (``None`` in ``results.json``, a sentence on the page). The harmonics are those of
:func:`balpipe.mechanics.orders.orders_of` (peak amplitudes in N and N m, phases in rad at the
start of the motion), orders 1..:data:`ORDERS` of the cycle frequency, fewer when the grid's
Nyquist order is lower.
"""

from __future__ import annotations

from typing import Any

from ..laws.drives import period
from ..mechanics.orders import Order, orders_of

#: the highest order reported
ORDERS = 8


def periodic_cycles(motion: Any) -> int | None:
    """The whole number of cycles of a periodic motion, None when the motion has no orders."""
    cycles = motion.cycles
    if cycles is None or motion.period is None or abs(cycles - round(cycles)) > 1e-9 * cycles:
        return None
    if any(period(d) is None for d in motion.drive.values()):
        return None
    return int(round(cycles))


def stage_orders(motion: Any, analysis: Any) -> list[Order] | None:
    """Orders 1..ORDERS of one stage's shaking force and moment, None for a non-periodic motion."""
    cycles = periodic_cycles(motion)
    if cycles is None:
        return None
    return orders_of(analysis.t, analysis.force, analysis.moment, cycles, ORDERS)


def orders_json(motion: Any, analysis: Any) -> dict | None:
    """What ``results.json`` holds per stage under ``orders``: the cycle frequency (Hz) and the
    orders' harmonics (SI: N, N m, rad)."""
    orders = stage_orders(motion, analysis)
    if orders is None:
        return None
    return {"frequency": 1.0 / motion.period, "cycles": periodic_cycles(motion),
            "orders": [o.to_json() for o in orders]}
