"""Counterweights as parts: a shape of a material sized so that its mass and centre of mass are a
design's, with its own centroidal inertia, its outline and whether it fits.

A balancing design gives a counterweight's mass ``m`` and centre of mass ``c`` (in its body's
frame). A part of uniform density ``rho`` and thickness ``t`` (normal to the plane) realises them
when ``rho t area = m`` and its area's centroid is ``c``. The shapes (all prisms of constant
thickness):

* ``disc``: a solid cylinder, axis normal to the plane, centred at ``c``; given its thickness, its
  radius is ``sqrt(m / (rho pi t))``; given its radius, ``t = m / (rho pi r^2)``.
  Centroidal inertia ``m r^2 / 2``.
* ``annular_sector``: on a crank web, between radii ``r_i`` and ``r_o`` about the body's ``axis``
  point, of included angle ``2 a`` symmetric about the direction from the axis to ``c``. Its
  centroid lies at ``d = (2/3) (sin a / a) (r_o^3 - r_i^3) / (r_o^2 - r_i^2)`` from the axis and its
  area is ``a (r_o^2 - r_i^2)``; with ``r_i`` and one of the thickness, the angle or the outer radius
  given, the other two unknowns are solved from both (closed form for a given angle, a
  bracketed root otherwise). Centroidal inertia ``m (r_o^2 + r_i^2) / 2 - m d^2``.
* ``plate``: a rectangle ``length x width`` centred at ``c``, its length along ``orientation``
  (default: normal to the line from the axis to ``c``); two of length, width, thickness given,
  the third from the mass. Centroidal inertia ``m (length^2 + width^2) / 12``.
* ``stack``: a bolted stack of equal plates of that rectangle: the total thickness from the mass,
  the number of plates the least that keeps each at most ``plate_thickness`` (or ``plates``
  given). Its mass, centroid and inertia are the plates' (bolts and their holes are not modelled:
  a bolt that fills its hole leaves them unchanged to the difference in density).

What is exact: the mass and the centroid of every sized shape equal the design's to round-off
(the roots are solved to machine precision), and the inertia is the shape's closed form. The
outline (:attr:`MadePart.outline`) is a closed polyline with circular arcs given by their bulge
(DXF's convention, ``tan(sweep / 4)``), so that the drawn part's area and first moment are the
part's exactly (:func:`outline_moments`).

Fit (:func:`make`): the thickness at most ``max_thickness``; the part's farthest point from the
axis at most ``max_radius`` (its swing radius about a crank's axis); every pivot of the body (its
revolute joints) at least ``clearance`` from the part's material. A part that cannot be made (no
positive mass, no shape that puts the centroid there, a limit exceeded) has its reasons in
:attr:`MadePart.problems`; nothing raises.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from ..display.numbers import num, point

Vec2 = tuple[float, float]
Vertex = tuple[float, float, float]  # x, y, bulge of the segment that starts here

SHAPES = ("disc", "annular_sector", "plate", "stack")


@dataclass(frozen=True)
class Limits:
    """Where a part must fit: ``max_thickness``, ``max_radius`` (from the axis), ``clearance``
    (from every pivot of its body); None: no limit."""

    max_thickness: float | None = None
    max_radius: float | None = None
    clearance: float | None = None


@dataclass(frozen=True)
class MadePart:
    """A sized part: SI ``dimensions`` (those given and those sized), ``mass``, ``centroid`` in
    its body's frame, centroidal ``inertia`` about the normal to the plane, ``outline`` (closed,
    body frame, with bulges; empty when the part cannot be sized) and the ``problems`` that keep
    it from being made (empty: it fits). ``where`` is the spec's path of the part."""

    name: str
    body: str
    shape: str
    material: str
    density: float
    dimensions: dict[str, float]
    mass: float
    centroid: Vec2
    inertia: float
    outline: tuple[Vertex, ...]
    axis: Vec2
    where: str = ""
    problems: tuple[str, ...] = field(default=())
    pivots: tuple[tuple[str, Vec2], ...] = ()  # the body's pivots (name, point), for the drawings

    @property
    def fits(self) -> bool:
        return not self.problems

    @property
    def thickness(self) -> float:
        return float(self.dimensions.get("thickness", 0.0))

    def to_json(self) -> dict[str, Any]:
        """The part's entry in ``results.json`` (SI: m, kg, kg/m^3, kg m^2, rad)."""
        return {"name": self.name, "body": self.body, "shape": self.shape, "material": self.material,
                "density": self.density, "dimensions": dict(sorted(self.dimensions.items())), "mass": self.mass,
                "centroid": list(self.centroid), "inertia": self.inertia, "fits": self.fits,
                "problems": list(self.problems), "where": self.where}


class Unsizable(ValueError):
    """No part of the shape has the design's mass and centroid with the given dimensions."""


def _sinc(a: float) -> float:
    return math.sin(a) / a if a > 1e-8 else 1.0 - a * a / 6.0


def sector_centroid(r_in: float, r_out: float, half_angle: float) -> float:
    """Distance from the axis to the centroid of an annular sector."""
    k = (r_out**3 - r_in**3) / (r_out**2 - r_in**2)
    return 2.0 / 3.0 * _sinc(half_angle) * k


def _root(f, lo: float, hi: float) -> float:
    from scipy.optimize import brentq  # scipy only when a part is sized

    return float(brentq(f, lo, hi, xtol=1e-300, rtol=1e-15, maxiter=500))


def size_sector(mass: float, rho: float, d: float, r_in: float, thickness: float | None = None,
                angle: float | None = None, r_out: float | None = None) -> dict[str, float]:
    """Inner/outer radius, included angle and thickness of the annular sector of ``mass`` whose
    centroid is ``d`` from its axis, given ``r_in`` and one of thickness, angle (included) or
    outer radius. Raises :class:`Unsizable` with the reason."""
    if thickness is not None:
        area = mass / (rho * thickness)
        lo = math.sqrt(r_in**2 + area / math.pi)

        def g(ro: float) -> float:
            return sector_centroid(r_in, ro, min(math.pi, area / (ro**2 - r_in**2))) - d

        if d <= 0:
            ro = lo
        else:
            hi = max(2 * lo, 2 * d + r_in)
            while g(hi) <= 0:
                hi *= 2
            ro = _root(g, lo, hi) if g(lo) < 0 else lo
        a = min(math.pi, area / (ro**2 - r_in**2))
        return {"inner_radius": r_in, "outer_radius": ro, "angle": 2 * a, "thickness": thickness}
    if angle is not None:
        a = angle / 2
        if math.sin(a) <= 1e-12 * a:
            if d > 0:
                raise Unsizable(f"a full ring has its centroid on its axis, the design's is {num(d)} m from it")
            raise Unsizable("a full ring (angle 360 deg): give the thickness or the outer radius instead")
        K = 1.5 * d / _sinc(a)
        if K <= 1.5 * r_in:
            raise Unsizable(f"the centroid {num(d)} m from the axis is too near it for an inner radius of "
                            f"{num(r_in)} m and an angle of {num(math.degrees(angle))} deg (such a sector's centroid is "
                            f"more than {num(r_in * _sinc(a))} m from it): widen the angle or reduce the inner radius")
        ro = 0.5 * ((K - r_in) + math.sqrt((K + 3 * r_in) * (K - r_in)))
        t = mass / (rho * a * (ro**2 - r_in**2))
        return {"inner_radius": r_in, "outer_radius": ro, "angle": angle, "thickness": t}
    assert r_out is not None
    if r_out <= r_in:
        raise Unsizable(f"outer radius {num(r_out)} m not beyond the inner radius {num(r_in)} m")
    s = 1.5 * d * (r_out**2 - r_in**2) / (r_out**3 - r_in**3)
    if s >= 1:
        raise Unsizable(f"the centroid {num(d)} m from the axis is beyond what a sector of outer radius "
                        f"{num(r_out)} m reaches (less than {num(2 / 3 * (r_out**3 - r_in**3) / (r_out**2 - r_in**2))} m)")
    a = math.pi if s <= 0 else _root(lambda x: _sinc(x) - s, 1e-9, math.pi)
    t = mass / (rho * a * (r_out**2 - r_in**2))
    return {"inner_radius": r_in, "outer_radius": r_out, "angle": 2 * a, "thickness": t}


def _arc(c: Vec2, r: float, a0: float, a1: float, pieces: int, closed: bool = False) -> list[Vertex]:
    """Vertices of an arc of centre c from angle a0 to a1 (either way) in ``pieces`` bulged
    segments, then its end vertex (at a1, bulge 0: a straight segment follows) unless ``closed``
    (a whole circle, back to its first vertex)."""
    bulge = math.tan((a1 - a0) / pieces / 4)
    out = [(c[0] + r * math.cos(a0 + (a1 - a0) * k / pieces), c[1] + r * math.sin(a0 + (a1 - a0) * k / pieces), bulge)
           for k in range(pieces)]
    return out if closed else out + [(c[0] + r * math.cos(a1), c[1] + r * math.sin(a1), 0.0)]


def _rotated(c: Vec2, u: Vec2, x: float, y: float) -> Vec2:
    return (c[0] + u[0] * x - u[1] * y, c[1] + u[1] * x + u[0] * y)


def _direction(axis: Vec2, c: Vec2) -> float:
    dx, dy = c[0] - axis[0], c[1] - axis[1]
    return math.atan2(dy, dx) if (dx or dy) else 0.0


def outline_moments(outline: tuple[Vertex, ...] | list[Vertex]) -> tuple[float, float, float]:
    """Area and first moments (A, A x_c, A y_c) of a closed polyline with bulged (circular) segments,
    counter-clockwise positive: the polygon of its vertices (shoelace) plus, per bulged segment,
    its circular segment (area R^2 (s - sin s) / 2 for a sweep s, centroid 4 R sin^3(s/2) /
    (3 (s - sin s)) from the arc's centre). Exact for lines and arcs."""
    A = Sx = Sy = 0.0
    n = len(outline)
    for k in range(n):
        x0, y0, b = outline[k]
        x1, y1, _ = outline[(k + 1) % n]
        cross = x0 * y1 - x1 * y0
        A += cross / 2
        Sx += cross * (x0 + x1) / 6
        Sy += cross * (y0 + y1) / 6
        if b:
            s = 4 * math.atan(b)  # signed sweep, ccw positive
            chord = math.hypot(x1 - x0, y1 - y0)
            R = chord / (2 * math.sin(abs(s) / 2))
            seg = R * R * (abs(s) - math.sin(abs(s))) / 2
            # the arc bulges to the right of the chord for a ccw sweep (outward of a ccw polygon)
            mx, my = (x0 + x1) / 2, (y0 + y1) / 2
            nx, ny = (y1 - y0) / chord, -(x1 - x0) / chord  # right-hand normal of the chord
            h = R * math.cos(abs(s) / 2)  # centre to chord
            sign = 1.0 if s > 0 else -1.0
            cx, cy = mx - sign * nx * h, my - sign * ny * h  # the arc's centre, left of the chord for s > 0
            dist = 4 * R * math.sin(abs(s) / 2) ** 3 / (3 * (abs(s) - math.sin(abs(s)))) if abs(s) > 1e-6 else R
            gx, gy = cx + sign * nx * dist, cy + sign * ny * dist
            A += sign * seg
            Sx += sign * seg * gx
            Sy += sign * seg * gy
    return A, Sx, Sy


def _distance_segment(p: Vec2, a: Vec2, b: Vec2) -> float:
    dx, dy = b[0] - a[0], b[1] - a[1]
    L2 = dx * dx + dy * dy
    s = 0.0 if L2 == 0 else max(0.0, min(1.0, ((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / L2))
    return math.hypot(p[0] - a[0] - s * dx, p[1] - a[1] - s * dy)


def distance_to(shape: str, dims: dict[str, float], centroid: Vec2, axis: Vec2, direction: float, p: Vec2) -> float:
    """Distance from point ``p`` to the part's material (0 inside it), exact for each shape."""
    if shape == "disc":
        return max(0.0, math.hypot(p[0] - centroid[0], p[1] - centroid[1]) - dims["radius"])
    if shape in ("plate", "stack"):
        c, s = math.cos(direction), math.sin(direction)
        x, y = p[0] - centroid[0], p[1] - centroid[1]
        lx, ly = c * x + s * y, -s * x + c * y
        return math.hypot(max(abs(lx) - dims["length"] / 2, 0.0), max(abs(ly) - dims["width"] / 2, 0.0))
    ri, ro, a = dims["inner_radius"], dims["outer_radius"], dims["angle"] / 2
    x, y = p[0] - axis[0], p[1] - axis[1]
    rho = math.hypot(x, y)
    phi = math.remainder(math.atan2(y, x) - direction, 2 * math.pi) if rho else 0.0
    if abs(phi) <= a:
        return max(ri - rho, rho - ro, 0.0)
    edges = [((axis[0] + r * math.cos(direction + e), axis[1] + r * math.sin(direction + e)) for r in (ri, ro))
             for e in (-a, a)]
    return min(_distance_segment(p, *tuple(e)) for e in edges)


def reach(shape: str, dims: dict[str, float], centroid: Vec2, axis: Vec2, direction: float) -> float:
    """The farthest point of the part from the axis."""
    if shape == "disc":
        return math.hypot(centroid[0] - axis[0], centroid[1] - axis[1]) + dims["radius"]
    if shape == "annular_sector":
        return dims["outer_radius"]
    u = (math.cos(direction), math.sin(direction))
    corners = [_rotated(centroid, u, sx * dims["length"] / 2, sy * dims["width"] / 2) for sx in (-1, 1) for sy in (-1, 1)]
    return max(math.hypot(q[0] - axis[0], q[1] - axis[1]) for q in corners)


def outline_of(shape: str, dims: dict[str, float], centroid: Vec2, axis: Vec2, direction: float) -> tuple[Vertex, ...]:
    """The part's closed outline in its body's frame, counter-clockwise, arcs as bulges (each at
    most a quarter turn)."""
    if shape == "disc":
        return tuple(_arc(centroid, dims["radius"], 0.0, 2 * math.pi, 4, closed=True))
    if shape in ("plate", "stack"):
        u = (math.cos(direction), math.sin(direction))
        L, W = dims["length"] / 2, dims["width"] / 2
        return tuple((*_rotated(centroid, u, x, y), 0.0) for x, y in ((-L, -W), (L, -W), (L, W), (-L, W)))
    ri, ro, a = dims["inner_radius"], dims["outer_radius"], dims["angle"] / 2
    pieces = max(1, math.ceil(2 * a / (math.pi / 2) - 1e-12))
    outer = _arc(axis, ro, direction - a, direction + a, pieces)
    if ri > 0:
        return tuple(outer + _arc(axis, ri, direction + a, direction - a, pieces))
    return tuple(outer) + ((axis[0], axis[1], 0.0),)


def _size(shape: str, given: dict[str, float], mass: float, rho: float, d: float) -> dict[str, float]:
    """The dimensions of the shape of ``mass`` (the given ones and those sized)."""
    if shape == "disc":
        if "thickness" in given:
            t = given["thickness"]
            return {"thickness": t, "radius": math.sqrt(mass / (rho * math.pi * t))}
        r = given["radius"]
        return {"radius": r, "thickness": mass / (rho * math.pi * r * r)}
    if shape == "annular_sector":
        return size_sector(mass, rho, d, given.get("inner_radius", 0.0), given.get("thickness"), given.get("angle"),
                           given.get("outer_radius"))
    if shape == "plate":
        dims: dict[str, float] = {k: given[k] for k in ("length", "width", "thickness") if k in given}
        (missing,) = [k for k in ("length", "width", "thickness") if k not in dims]
        prod = math.prod(dims.values())
        dims[missing] = mass / (rho * prod)
        return dims
    L, W = given["length"], given["width"]
    T = mass / (rho * L * W)
    n = int(given["plates"]) if "plates" in given else max(1, math.ceil(T / given["plate_thickness"] * (1 - 1e-12)))
    return {"length": L, "width": W, "thickness": T, "plates": float(n), "plate_thickness": T / n}


def _inertia(shape: str, dims: dict[str, float], mass: float, d: float) -> float:
    if shape == "disc":
        return mass * dims["radius"] ** 2 / 2
    if shape == "annular_sector":
        return max(0.0, mass * (dims["outer_radius"] ** 2 + dims["inner_radius"] ** 2) / 2 - mass * d * d)
    return mass * (dims["length"] ** 2 + dims["width"] ** 2) / 12


def make(name: str, body: str, shape: str, material: str, density: float, given: dict[str, float], mass: float,
         centroid: Vec2, axis: Vec2 = (0.0, 0.0), limits: Limits = Limits(),
         pivots: tuple[tuple[str, Vec2], ...] = (), where: str = "", orientation: float | None = None) -> MadePart:
    """The part of ``shape`` and ``density`` realising a counterweight of ``mass`` at ``centroid``
    (its body's frame), sized from the ``given`` dimensions (SI), with its fit against ``limits``
    and the body's ``pivots`` (name, point). Never raises for a design that cannot be made: its
    reasons are the part's ``problems``."""
    c = (float(centroid[0]), float(centroid[1]))
    d = math.hypot(c[0] - axis[0], c[1] - axis[1])
    direction = _direction(axis, c)
    if shape in ("plate", "stack"):
        direction = orientation if orientation is not None else direction + math.pi / 2

    def unmade(reason: str, dims: dict[str, float] | None = None) -> MadePart:
        return MadePart(name, body, shape, material, density, dict(dims or given), float(mass), c, 0.0, (), axis,
                        where, (reason,), pivots)

    if mass == 0:
        return unmade("mass 0 kg: the design puts no counterweight here, so there is no part to make "
                      "(remove the part, or the counterweight)")
    if not mass > 0:
        return unmade(f"mass {num(mass)} kg: a part needs a positive mass")
    try:
        dims = _size(shape, given, float(mass), density, d)
    except Unsizable as exc:
        return unmade(str(exc))
    if shape in ("plate", "stack"):
        dims["orientation"] = math.remainder(direction, 2 * math.pi)
    problems = []
    t = dims["thickness"]
    if limits.max_thickness is not None and t > limits.max_thickness:
        problems.append(f"thickness {num(t * 1e3)} mm exceeds max_thickness {num(limits.max_thickness * 1e3)} mm")
    r = reach(shape, dims, c, axis, direction)
    if limits.max_radius is not None and r > limits.max_radius:
        problems.append(f"reaches {num(r * 1e3)} mm from the axis {point(axis)} m, beyond max_radius "
                        f"{num(limits.max_radius * 1e3)} mm")
    if limits.clearance is not None:
        for pivot, p in pivots:
            gap = distance_to(shape, dims, c, axis, direction, p)
            if gap < limits.clearance:
                what = "covers" if gap == 0 else f"is {num(gap * 1e3)} mm from"
                problems.append(f"{what} pivot {pivot!r} at {point(p)} m (clearance "
                                f"{num(limits.clearance * 1e3)} mm)")
    return MadePart(name, body, shape, material, density, dims, float(mass), c, _inertia(shape, dims, float(mass), d),
                    outline_of(shape, dims, c, axis, direction), axis, where, tuple(problems), pivots)
