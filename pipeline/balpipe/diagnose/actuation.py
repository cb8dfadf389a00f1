"""Actuated joints named by a spec, distinct from the prescribed coordinates: the
motors' efforts are computed at the joints that carry them.

A spec prescribes what moves (its drivers: joint laws, a point, a pose) and may name the joints
that carry the motors (``mechanism.actuators``). The engine then computes the motors' efforts
from M q'' + h = B tau + Phi_q^T lambda (DESIGN.md, "Real machines"; :mod:`balpipe.engine.dynamics`):
a torque in N m at a revolute joint, a force in N along a prismatic one. More actuators than
degrees of freedom: the minimum-norm efforts (redundant actuation). Fewer: not realisable, a
located error. Without actuators each driver is its own actuator, and an effort at a driver of
a point or a pose is a virtual one (no motor applies it).
"""

from __future__ import annotations

from dataclasses import replace

from ..model import Actuator, Gear, Model, Prismatic
from ..spec_parts import SpecFieldError

DESCRIPTION = (
    "joints that carry the motors (revolute: torque in N m; prismatic: force in N), distinct from "
    "the prescribed motion: the efforts are reported at these joints, the minimum-norm ones when "
    "there are more actuators than degrees of freedom. Omitted: each driver is its own actuator "
    "(a driver of a point or a pose then has a virtual effort)"
)


def degrees_of_freedom(model: Model) -> int:
    """3 per moving body less one per joint constraint equation (revolute 2, prismatic 2, gear
    1): the mobility of a mechanism whose joints are independent (the engine checks that)."""
    rows = sum(1 if isinstance(j, Gear) else 2 for j in model.joints)
    return 3 * len(model.bodies) - rows


def with_actuators(model: Model, names: list[str] | tuple[str, ...] | None, path: tuple) -> Model:
    """``model`` with an actuator at each named joint (the actuator takes the joint's name).
    Raises :class:`~balpipe.spec_parts.SpecFieldError` at ``path`` (or its item) for an unknown
    joint, a gear pair, a joint named twice, or fewer actuators than degrees of freedom."""
    if not names:
        return model
    joints = {j.name: j for j in model.joints}
    seen: set[str] = set()
    for k, n in enumerate(names):
        j = joints.get(n)
        if j is None:
            known = ", ".join(sorted(m for m, jt in joints.items() if not isinstance(jt, Gear)))
            raise SpecFieldError(path + (k,), f"unknown joint {n!r}; the actuated joints are among: {known}")
        if isinstance(j, Gear):
            raise SpecFieldError(path + (k,), f"{n!r} is a gear pair: actuate one of its bodies' revolute joints")
        if n in seen:
            raise SpecFieldError(path + (k,), f"joint {n!r} is named twice")
        seen.add(n)
    dof = degrees_of_freedom(model)
    if len(names) < dof:
        raise SpecFieldError(
            path, f"not realisable: the mechanism has {dof} degrees of freedom but only {len(names)} "
            f"actuator{'s are' if len(names) != 1 else ' is'} named ({', '.join(names)}); name at least {dof}",
        )
    return replace(model, actuators=tuple(Actuator(n, n) for n in names))


def virtual_note(model: Model) -> str | None:
    """The page's note when the efforts are not motors': drivers of a point or a pose and no
    actuator named. None when every effort is a motor's."""
    if model.actuators:
        return None
    virtual = [d.name for d in model.drivers if d.target[0] != "joint"]
    if not virtual:
        return None
    return (
        f"Virtual efforts: no actuated joint is named (mechanism.actuators), so the efforts of "
        f"{', '.join(virtual)} are the forces or torques that would impose the prescribed "
        "coordinates directly, not those of motors. Name the motors' joints to get their torques."
    )
