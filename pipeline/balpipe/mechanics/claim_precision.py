"""Claims judged at the design's precision: a computed design at round-off, a design typed by
hand within the rounding of its own numbers.

A stage claims to cancel the shaking force (moment) when its inertial peak is at most a
tolerance times the reference load. Computed designs are exact to round-off and keep the
analysis' tolerance (``analysis.balance_tolerance``, 1e-9). A design typed by hand (the
``stages`` method) is only as exact as its numbers: a counterweight written ``1.53333 kg`` is
1.533333... rounded at its last digit. Its default tolerance adds the worst case of those
roundings, propagated through the loads, which are linear in every part's mass and inertia and
smooth in its position (the kinematics are prescribed, so they do not depend on the masses):

    F = -m a_P,   M = -(r_P - O) x m a_P - I alpha,   a_P = a_B + alpha J R p - omega^2 R p,

    dF <= |a_P| dm + m |alpha J R e_i - omega^2 R e_i| dp_i,
    dM <= |(r_P - O) x a_P| dm + |d/dp_i [(r_P - O) x a_P]| m dp_i + |alpha| dI,

with dm, dp_i, dI half a unit of the last digit of the entered numbers (a number of four or more
significant digits is taken as rounded; shorter ones, such as 80 mm or 1.5 kg, as chosen
exactly). The tolerance is analysis.balance_tolerance + max_t(bound) / reference. A spec may set
a stage's tolerance outright (``tolerance:`` of a hand-written stage, or
``analysis.claim_tolerance: {stage: value}``).
"""

from __future__ import annotations

from dataclasses import dataclass
from decimal import Decimal

import numpy as np

from .planar import cross

#: numbers with at least this many significant digits are taken as rounded at their last digit
ROUNDED_DIGITS = 4


def half_unit(value: float) -> float:
    """Half a unit of the last digit of ``value`` as written (to 12 significant digits, which
    undoes unit conversions such as 1533.33 g -> 1.53333 kg), or 0 for a number of fewer than
    :data:`ROUNDED_DIGITS` significant digits (taken as exact)."""
    if value == 0:
        return 0.0
    d = Decimal(f"{abs(value):.12g}").normalize().as_tuple()
    if len(d.digits) < ROUNDED_DIGITS:
        return 0.0
    return 0.5 * 10.0 ** d.exponent


@dataclass(frozen=True)
class Rounding:
    """The precision of one entered part: half-units of its mass, position (body frame) and
    inertia; ``part`` None for a body's own inertia (a counter-rotating disc)."""

    body: str
    part: str | None
    mass: float = 0.0
    x: float = 0.0
    y: float = 0.0
    inertia: float = 0.0
    text: str = ""  # what was entered, for the page

    @property
    def exact(self) -> bool:
        return not (self.mass or self.x or self.y or self.inertia)


def rounding_bounds(model, an, roundings: tuple[Rounding, ...]) -> tuple[float, float]:
    """Peak over the motion of the worst-case change of the inertial shaking force (N) and
    moment (N m, about the analysis' moment point) that the roundings allow."""
    N = len(an.t)
    dF, dM = np.zeros(N), np.zeros(N)
    O = np.asarray(an.moment_point, dtype=float)
    fp = an.frame_pose
    for r in roundings:
        if r.exact:
            continue
        k = an.names.index(r.body)
        th, w, al = fp[:, k, 2], an.v[:, k, 2], an.a[:, k, 2]
        dM += abs(r.inertia) * np.abs(al)
        if r.part is None:
            continue
        part = next(a for a in model.body(r.body).attachments if a.name == r.part)
        c, s = np.cos(th), np.sin(th)
        d = an.q[:, k, :2] - fp[:, k, :2]  # r_S - r_O, world
        J = lambda u: np.stack([-u[:, 1], u[:, 0]], axis=1)  # noqa: E731
        aO = an.a[:, k, :2] - al[:, None] * J(d) + (w**2)[:, None] * d
        px, py = part.position
        dp = np.stack([c * px - s * py, s * px + c * py], axis=1)  # R p
        rP = fp[:, k, :2] + dp
        aP = aO + al[:, None] * J(dp) - (w**2)[:, None] * dp
        dF += np.hypot(aP[:, 0], aP[:, 1]) * r.mass
        dM += np.abs(cross(rP - O, aP)) * r.mass
        for e, h in (((c, s), r.x), ((-s, c), r.y)):  # R e_x, R e_y
            if not h:
                continue
            Re = np.stack(e, axis=1)
            da = al[:, None] * J(Re) - (w**2)[:, None] * Re  # d a_P / d p_i
            dF += part.mass * np.hypot(da[:, 0], da[:, 1]) * h
            dM += part.mass * np.abs(cross(Re, aP) + cross(rP - O, da)) * h
    return float(np.max(dF)) if N else 0.0, float(np.max(dM)) if N else 0.0


def claim_tolerances(stage, model, an, reference, tol: float, overrides: dict | None = None) -> dict:
    """The tolerances (fractions of the reference loads) at which ``stage``'s claims are judged:
    the spec's value for the stage, else ``tol`` plus the roundings' bound (hand-written
    designs), else ``tol``. Returns {"force", "moment", "source"}."""
    given = (overrides or {}).get(stage.name, getattr(stage, "tolerance", None))
    if given is not None:
        return {"force": float(given), "moment": float(given), "source": "spec"}
    roundings = tuple(r for r in getattr(stage, "rounding", ()) if not r.exact)
    if not roundings:
        return {"force": tol, "moment": tol, "source": "analysis.balance_tolerance"}
    bF, bM = rounding_bounds(model, an, roundings)
    F0, M0 = reference.force, reference.moment
    return {"force": tol + (bF / F0 if F0 > 0 else 0.0), "moment": tol + (bM / M0 if M0 > 0 else 0.0),
            "source": "precision of the entered numbers: " + ", ".join(r.text for r in roundings)}
