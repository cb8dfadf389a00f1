"""Gear meshes with pitch radii: where the tooth force acts and which bearings carry it.

A :class:`~balpipe.model.Gear` constrains relative angles,
(theta_b - theta_c) = ratio (theta_a - theta_c) + phase, so its Lagrange multiplier alone is a
couple shared by a, b and the carrier c. A real mesh passes a *tooth force* between the gears at
the pitch point P on their line of centres; the gears' bearings (the revolute joints that pivot
a and b on the carrier) carry it to the carrier. With the bearings' centres O_a, O_b fixed on the
carrier at distance d, rolling without slip at P is

    t . (v_P(b) - v_P(a)) = 0,   t = perp(u),  u = (O_b - O_a) / d,

which, wherever the bearings are closed, equals -r_b (angle relation) plus a combination of the
bearings' rows when

    external mesh (ratio < 0):  ratio = -r_a / r_b,  d = r_a + r_b,  P = O_a + r_a u;
    internal mesh (ratio > 0):  ratio = +r_a / r_b,  d = |r_a - r_b|, P = O_a + s r_a u
                                (s = +1 when a is the ring, -1 when b is).

The engine (:func:`balpipe.engine.analyse`) writes the gear's generalized force with this row,
so its multiplier is the tangential tooth force and the bearings' multipliers carry it; the
shaking loads and the efforts do not change (the new row is a combination of the old ones).
The radial component, |F_t| tan(pressure angle), pushes external gears apart (pulls an internal
pair's centres together); it is workless and collinear with the two bearings, which absorb it.

A gear pair without pitch radii (a belt, or radii not given) stays a couple: its bearings then
carry no tooth force, and the report says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from ..model import FRAME, Gear, Model, Revolute, Vec2
from ..units import quantity

#: a pressure angle in [0, 90) deg, default 20 deg (standard involute gears)
PressureAngle = quantity("angle", ge=0.0, lt=math.pi / 2)
DEFAULT_PRESSURE_ANGLE = math.radians(20.0)

_RTOL = 1e-6  # relative mismatch allowed between the radii, the ratio and the centre distance


@dataclass(frozen=True)
class Bearing:
    """The revolute joint that pivots a gear on the carrier.

    ``centre_carrier`` and ``centre_gear`` are the joint's points on the carrier and on the gear
    (local frames; global on the frame); ``gear_is_b`` says whether the gear is the joint's body
    b (the joint's reaction is the force on b, so the gear's bearing force is +reaction, else
    -reaction).
    """

    joint: str
    centre_carrier: Vec2
    centre_gear: Vec2
    gear_is_b: bool


@dataclass(frozen=True)
class MeshGeometry:
    """A gear pair that passes tooth forces (see the module docstring)."""

    gear: str
    bearing_a: Bearing
    bearing_b: Bearing
    radius_a: float
    radius_b: float
    external: bool
    side: float  # s: P = O_a + s r_a u
    pressure_angle: float
    distance: float  # d, between the bearings' centres on the carrier
    pitch_a: float  # r_a and r_b as the ratio and d fix them exactly (the declared radii
    pitch_b: float  # agree to 1e-6): the engine uses these, so the row is an exact combination


def bearing(model: Model, gear: str, carrier: str) -> Bearing | None:
    """The first revolute joint between ``gear`` and ``carrier``, or None."""
    for j in model.joints:
        if isinstance(j, Revolute):
            if j.a == carrier and j.b == gear:
                return Bearing(j.name, j.point_a, j.point_b, True)
            if j.b == carrier and j.a == gear:
                return Bearing(j.name, j.point_b, j.point_a, False)
    return None


def mesh_geometry(model: Model, gear: Gear) -> MeshGeometry | None:
    """The tooth-force geometry of ``gear``, or None when it has no pitch radii (couple only).

    Raises ValueError (with what is wrong) when only one radius is given, the radii do not give
    the ratio, a gear is not pivoted on the carrier by a revolute joint, or the bearings' centre
    distance is not the one the radii need.
    """
    ra, rb = gear.radius_a, gear.radius_b
    if ra is None and rb is None:
        return None
    name = f"gear pair {gear.name!r}"
    if ra is None or rb is None:
        raise ValueError(f"{name}: give both pitch radii (radius_a and radius_b) or neither")
    if not (ra > 0 and rb > 0 and math.isfinite(ra) and math.isfinite(rb)):
        raise ValueError(f"{name}: pitch radii must be positive, got {ra:g} and {rb:g} m")
    if not 0.0 <= gear.pressure_angle < math.pi / 2:
        raise ValueError(f"{name}: the pressure angle must be in [0, 90) deg, got {math.degrees(gear.pressure_angle):g} deg")
    external = gear.ratio < 0
    want = (-1.0 if external else 1.0) * ra / rb
    if abs(gear.ratio - want) > _RTOL * abs(want):
        raise ValueError(
            f"{name}: the ratio {gear.ratio:.6g} does not match the pitch radii: an "
            f"{'external' if external else 'internal'} mesh of radii {ra:.6g} and {rb:.6g} m has ratio "
            f"{want:.6g} ({'-' if external else '+'}r_a/r_b)"
        )
    bearings = []
    for g in (gear.a, gear.b):
        br = bearing(model, g, gear.carrier)
        if br is None:
            raise ValueError(
                f"{name}: {'the frame' if g == FRAME else f'gear {g!r}'} is not pivoted on the carrier "
                f"{gear.carrier!r} by a revolute joint, so the tooth force has no bearing to go to "
                "(give the bearing, or omit the pitch radii to model the mesh as a couple)"
            )
        bearings.append(br)
    d = math.dist(bearings[0].centre_carrier, bearings[1].centre_carrier)
    need = ra + rb if external else abs(ra - rb)
    if abs(d - need) > _RTOL * (ra + rb):
        raise ValueError(
            f"{name}: the bearings {bearings[0].joint!r} and {bearings[1].joint!r} are {d:.6g} m apart "
            f"on the carrier but the pitch radii need {need:.6g} m "
            f"({'r_a + r_b' if external else '|r_a - r_b|'})"
        )
    if not d > 1e-9 * (ra + rb):
        raise ValueError(f"{name}: the bearings' centres coincide (coaxial gears cannot mesh)")
    side = 1.0 if external or ra > rb else -1.0
    k = abs(gear.ratio)
    if external:
        pa, pb = d * k / (1.0 + k), d / (1.0 + k)
    else:
        pb = d / abs(k - 1.0)
        pa = k * pb
    return MeshGeometry(gear.name, bearings[0], bearings[1], float(ra), float(rb), external, side,
                        float(gear.pressure_angle), d, pa, pb)


def meshes(model: Model) -> dict[str, MeshGeometry]:
    """Every gear pair of ``model`` that passes tooth forces, by name."""
    out = {}
    for j in model.joints:
        if isinstance(j, Gear):
            g = mesh_geometry(model, j)
            if g is not None:
                out[j.name] = g
    return out


def couple_only(model: Model) -> list[str]:
    """Names of the gear pairs modelled as couples (no pitch radii)."""
    return [j.name for j in model.joints if isinstance(j, Gear) and mesh_geometry(model, j) is None]
