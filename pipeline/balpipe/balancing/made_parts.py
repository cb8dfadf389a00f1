"""A balancing design's counterweights made as parts: the spec's ``part:`` sections read against
the model (the body's pivots, the axis point) and sized by
:func:`balpipe.mechanics.part_shapes.make`.

Every method that places a counterweight with a ``part:`` gives the analysed model the part's
own centroidal inertia (not a point mass's, nor the spread inertia of a least-mass programme):
the stage's shaking moment, efforts and joint loads are those of the part that would be made.
A part's second moment about its body's origin is its centroidal inertia (>= 0) plus m |c|^2, so
it is always a realisable second moment in partial balancing's sense (J >= m |c|^2); a moment
balance's counter-rotating discs are solved with it on the body (:mod:`.moment_balance`).
"""

from __future__ import annotations

from ..mechanics.materials import density_of
from ..mechanics.part_shapes import Limits, MadePart, make
from ..model import Model, Revolute, Vec2
from .part_spec import PartShapeSpec


def spec_path(path: tuple) -> str:
    """A spec path as the docs write it: ("balancing", "counterweights", 0, "part") ->
    "balancing.counterweights[0].part"."""
    out = ""
    for k in path:
        out += f"[{k}]" if isinstance(k, int) else (f".{k}" if out else str(k))
    return out


def pivots(model: Model, body: str) -> tuple[tuple[str, Vec2], ...]:
    """The revolute joints of ``body``, by name, at their points in its frame."""
    out = []
    for j in model.joints:
        if isinstance(j, Revolute) and body in (j.a, j.b):
            p = j.point_a if j.a == body else j.point_b
            out.append((j.name, (float(p[0]), float(p[1]))))
    return tuple(out)


def part_for(model: Model, body: str, name: str, spec: PartShapeSpec, mass: float, centroid: Vec2, axis: Vec2,
             path: tuple) -> MadePart:
    """The part ``spec`` describes, realising a counterweight ``name`` of ``mass`` at ``centroid``
    on ``body`` (``axis`` resolved in the body's frame), located at ``path`` in the spec."""
    density = density_of(spec.material, spec.density)
    material = spec.material or f"{density:g} kg/m^3"
    limits = Limits(spec.max_thickness, spec.max_radius, spec.clearance)
    return make(name, body, spec.shape, material, density, spec.given(), float(mass), centroid, axis, limits,
                pivots(model, body), spec_path(path), spec.orientation)


def inertia_of(part: MadePart, fallback: float) -> float:
    """The centroidal inertia the analysis gives the counterweight: the part's when it could be
    sized, else ``fallback`` (the design's own; the part's problems then say why)."""
    return part.inertia if part.outline else fallback


#: the inputs table's symbol and meaning of each field of a ``part:`` section ({n}: the part's name)
_NOTATION = {
    "material": ("`{n}`", "material of `{n}`"), "density": ("ρ_{{{n}}}", "density of `{n}`"),
    "shape": ("`{n}`", "shape of `{n}`"), "thickness": ("t_{{{n}}}", "thickness of `{n}`"),
    "radius": ("r_{{{n}}}", "radius of the disc `{n}`"), "inner_radius": ("r_{{i,{n}}}", "inner radius of `{n}`"),
    "outer_radius": ("r_{{o,{n}}}", "outer radius of `{n}`"), "angle": ("α_{{{n}}}", "included angle of `{n}`"),
    "length": ("l_{{{n}}}", "length of `{n}`"), "width": ("w_{{{n}}}", "width of `{n}`"),
    "plates": ("n_{{{n}}}", "plates of the stack `{n}`"),
    "plate_thickness": ("t_{{p,{n}}}", "the thickest plate of the stack `{n}`"),
    "orientation": ("φ_{{{n}}}", "direction of the length of `{n}`"), "axis": ("`{n}`", "axis `{n}` is laid out about"),
    "max_thickness": ("t_{{max,{n}}}", "the thickest `{n}` that fits"),
    "max_radius": ("r_{{max,{n}}}", "how far `{n}` may reach from its axis"),
    "clearance": ("c_{{{n}}}", "least distance from `{n}` to its body's pivots"),
}


def part_notation(prefix: str, name: str) -> dict:
    """Symbols of the fields of the ``part:`` section at ``prefix`` (e.g.
    "balancing.counterweights[0].part") of the counterweight ``name``."""
    from ..notation import ours

    return {f"{prefix}.{k}": ours(sym.format(n=name), text.format(n=name)) for k, (sym, text) in _NOTATION.items()}
