"""What a driver or an actuator drives, for the tables: the unit of its effort."""

from __future__ import annotations

from ..model import Model, Prismatic, Revolute


def effort_unit(model: Model, name: str) -> str | None:
    """'N' for an actuator at a prismatic joint, 'N m' at a revolute, None when ``name`` is not
    one of the model's actuators."""
    for a in model.actuators:
        if a.name == name:
            return "N" if isinstance(model.joint(a.joint), Prismatic) else "N m"
    return None


def driver_unit(model: Model, name: str) -> str:
    """'N m' for a driver of a revolute joint or of an absolute angle, 'N' for a prismatic
    joint or a point coordinate (x, y); an actuator's by its joint."""
    unit = effort_unit(model, name)
    if unit is not None:
        return unit
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
