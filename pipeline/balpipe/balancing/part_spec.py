"""The ``part:`` section of a counterweight: the material and shape balpipe sizes it as
(:mod:`balpipe.mechanics.part_shapes`), and the limits it must fit. Pydantic classes only (the
schema loads no computing code)."""

from __future__ import annotations

import math
from typing import Literal, Union

from pydantic import Field, model_validator

from ..mechanics.materials import DENSITIES
from ..spec_parts import Strict
from ..units import Angle, Density, Length, NonNegativeLength, PlateCount, PositiveLength

#: which dimensions each shape takes: (required, exactly one of, two of, optional)
SHAPE_FIELDS: dict[str, tuple[tuple[str, ...], tuple[str, ...], tuple[str, ...], tuple[str, ...]]] = {
    "disc": ((), ("thickness", "radius"), (), ()),
    "annular_sector": ((), ("thickness", "angle", "outer_radius"), (), ("inner_radius",)),
    "plate": ((), (), ("length", "width", "thickness"), ("orientation",)),
    "stack": (("length", "width"), ("plates", "plate_thickness"), (), ("orientation",)),
}
DIMENSIONS = ("thickness", "radius", "inner_radius", "outer_radius", "angle", "length", "width", "plates",
              "plate_thickness", "orientation")


class PartShapeSpec(Strict):
    """A counterweight made as a part: a shape of a material, sized by balpipe so that its mass
    and centre of mass are the design's, its own centroidal inertia used in the analysis, checked
    against the limits given."""

    material: str | None = Field(None, description="a named material (" + ", ".join(
        f"{k} {v:g} kg/m^3" for k, v in DENSITIES.items()) + ") or, with density, any name")
    density: Density | None = Field(None, description="density (default: the named material's)")
    shape: Literal["disc", "annular_sector", "plate", "stack"] = Field(
        description="disc: a solid cylinder, axis normal to the plane, centred on the centre of mass; annular_sector: "
        "a crank web sector between two radii about the axis, symmetric about the direction to the centre of mass; "
        "plate: a rectangle centred on the centre of mass; stack: a bolted stack of equal rectangular plates")
    thickness: PositiveLength | None = Field(None, description="thickness normal to the plane (disc, annular_sector, plate)")
    radius: PositiveLength | None = Field(None, description="disc: its radius (or give the thickness)")
    inner_radius: NonNegativeLength | None = Field(None, description="annular_sector: inner radius about the axis (default 0)")
    outer_radius: PositiveLength | None = Field(None, description="annular_sector: outer radius (or give the thickness or the angle)")
    angle: Angle | None = Field(None, description="annular_sector: included angle, at most 360 deg (or give the thickness "
                                "or the outer radius)")
    length: PositiveLength | None = Field(None, description="plate, stack: length, along orientation")
    width: PositiveLength | None = Field(None, description="plate, stack: width")
    plates: PlateCount | None = Field(None, description="stack: number of plates (or give plate_thickness)")
    plate_thickness: PositiveLength | None = Field(None, description="stack: the thickest plate allowed (the fewest "
                                                   "equal plates that keep to it)")
    orientation: Angle | None = Field(None, description="plate, stack: direction of the length in the body's frame "
                                      "(default: normal to the line from the axis to the centre of mass)")
    axis: Union[str, tuple[Length, Length]] = Field(
        (0.0, 0.0), description="the point the part is laid out about, [x, y] in the body's frame or a named point "
        "(default: the body's origin, a crank's axis): the annular sector's centre, and where max_radius is measured from")
    max_thickness: PositiveLength | None = Field(None, description="the thickest part that fits")
    max_radius: PositiveLength | None = Field(None, description="the farthest the part may reach from the axis (its swing radius)")
    clearance: NonNegativeLength | None = Field(None, description="the least distance from the part to every pivot "
                                                "(revolute joint) of its body")

    @model_validator(mode="after")
    def _dimensions(self):
        if self.density is None and self.material not in DENSITIES:
            known = ", ".join(DENSITIES)
            raise ValueError(f"unknown material {self.material!r}: name one of {known}, or give its density"
                             if self.material else f"give a material ({known}) or a density")
        required, one_of, two_of, optional = SHAPE_FIELDS[self.shape]
        given = [k for k in DIMENSIONS if getattr(self, k) is not None]
        allowed = set(required) | set(one_of) | set(two_of) | set(optional)
        stray = [k for k in given if k not in allowed]
        if stray:
            raise ValueError(f"a {self.shape} takes no {', '.join(stray)} (it takes {', '.join(sorted(allowed))})")
        missing = [k for k in required if k not in given]
        if missing:
            raise ValueError(f"a {self.shape} needs {', '.join(missing)}")
        if one_of and sum(k in given for k in one_of) != 1:
            raise ValueError(f"a {self.shape} takes exactly one of {', '.join(one_of)}: balpipe sizes the rest from "
                             "the design's mass and centre of mass")
        if two_of and sum(k in given for k in two_of) != 2:
            raise ValueError(f"a {self.shape} takes exactly two of {', '.join(two_of)}: balpipe sizes the third "
                             "from the design's mass")
        if self.angle is not None and not 0 < self.angle <= 2 * math.pi + 1e-12:
            raise ValueError("angle: more than 0 and at most 360 deg")
        if (self.outer_radius is not None and self.inner_radius is not None
                and self.outer_radius <= self.inner_radius):
            raise ValueError("outer_radius: must exceed inner_radius")
        return self

    def given(self) -> dict[str, float]:
        """The dimensions given, SI."""
        return {k: float(getattr(self, k)) for k in DIMENSIONS if getattr(self, k) is not None and k != "orientation"}
