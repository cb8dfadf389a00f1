"""What a driver drives, for the tables: the unit of its actuator effort."""

from __future__ import annotations

from .model import Model, Prismatic, Revolute


def driver_unit(model: Model, name: str) -> str:
    """'N m' for a driver of a revolute joint or of an absolute angle, 'N' for a prismatic
    joint or a point coordinate (x, y)."""
    for d in model.drivers:
        if d.name != name:
            continue
        kind = d.target[0]
        if kind == "joint":
            j = model.joint(d.target[1])
            if isinstance(j, Prismatic):
                return "N"
            if isinstance(j, Revolute):
                return "N m"
            return "N m"
        return "N m" if kind == "angle" else "N"
    return ""
