"""A ``custom`` mechanism built in Python, part by part: each builder returns the pydantic
section that the same YAML would give (validated as it: pydantic's ``ValidationError`` for a
value the schema refuses), and ``balpipe.Spec.from_parts`` turns the assembled sections into a
spec through the loader that reads spec files, so a mechanism built here is checked and computed
exactly as its YAML twin (the same located errors for what only the whole spec can tell: a joint
naming a missing body, a pose the joints do not confirm).

Values are numbers in SI units or strings with a unit (``"0.4 kg"``, ``"360 deg"``); points are
``[x, y]`` in the body's frame or the name of one of the body's ``points``::

    from balpipe.families.custom import builders as b

    mech = b.mechanism(
        frame_points={"O2": (0, 0), "O4": (0.30, 0)},
        bodies=[b.body("crank", "0.4 kg", com=(0.04, 0), inertia=0.000213, points={"O2": (0, 0), "A": (0.08, 0)}),
                ...],
        joints=[b.revolute("O2", "frame", "crank", "O2", "O2"), ...],
        drivers=[b.driver("crank", joint="O2")])
    method = b.moment_balance(counterweights=[b.counterweight("crank", segment=((0, 0), (-0.08, 0)))],
                              counter_rotations=[b.counter_rotation("disc", at="O2", geared_to="crank", ratio=-1)])
"""

from __future__ import annotations

from typing import Any, Iterable, Mapping

from ...balancing.specs import (CounterRotationSpec, CounterweightRegionSpec, DiscRegionSpec, ForceBalance,
                                MomentBalance)
from ...model import FRAME
from .template import (CustomAttachment, CustomBody, CustomMechanism, DriverSpec, GearSpec, PrismaticSpec,
                       RevoluteSpec)

Value = float | str  # a number in SI units, or a string with its unit
XY = tuple[Value, Value]


def _given(**fields: Any) -> dict:
    """The fields given (None: left to the schema's default, as a key absent from the YAML)."""
    return {k: v for k, v in fields.items() if v is not None}


def attachment(name: str, mass: Value, position: XY | str = (0.0, 0.0), inertia: Value | None = None,
               kind: str | None = None, radius: Value | None = None) -> CustomAttachment:
    """A part fixed to a body (a counterweight, a carried gear, a payload): ``position`` of its
    centre of mass in the body's frame (or a named point), its centroidal ``inertia``."""
    return CustomAttachment.model_validate(_given(name=name, mass=mass, position=position, inertia=inertia,
                                                  kind=kind, radius=radius))


def body(name: str, mass: Value, *, com: XY | None = None, inertia: Value | None = None,
         points: Mapping[str, XY] | None = None, pose: tuple[Value, Value, Value] | None = None,
         radius: Value | None = None, kind: str | None = None,
         attachments: Iterable[CustomAttachment] = ()) -> CustomBody:
    """A moving body: ``mass``, centre of mass ``com`` and centroidal ``inertia`` in its own
    frame, its named ``points``, and its ``pose`` [x, y, angle] at the start of the motion (the
    assembly confirms it)."""
    return CustomBody.model_validate(_given(
        name=name, mass=mass, com=com, inertia=inertia, points=dict(points) if points is not None else None,
        pose=pose, radius=radius, kind=kind, attachments=list(attachments) or None))


def revolute(name: str, a: str, b: str, point_a: XY | str, point_b: XY | str | None = None) -> RevoluteSpec:
    """A pin joint between bodies ``a`` and ``b`` (``"frame"`` for the frame), at ``point_a`` of
    ``a`` and ``point_b`` of ``b``."""
    return RevoluteSpec.model_validate(_given(type="revolute", name=name, a=a, b=b, point_a=point_a, point_b=point_b))


def prismatic(name: str, guide: str, slider: str, point_guide: XY | str, axis: tuple[float, float],
              point_slider: XY | str | None = None, angle: Value | None = None) -> PrismaticSpec:
    """A sliding pair: ``slider`` moves along the ``axis`` through ``point_guide`` of ``guide``."""
    return PrismaticSpec.model_validate(_given(type="prismatic", name=name, guide=guide, slider=slider,
                                               point_guide=point_guide, axis=axis, point_slider=point_slider,
                                               angle=angle))


def gear(name: str, a: str, b: str, ratio: float, carrier: str | None = None, radius_a: Value | None = None,
         radius_b: Value | None = None, pressure_angle: Value | None = None) -> GearSpec:
    """A gear pair: (w_b - w_c) / (w_a - w_c) = ``ratio`` on ``carrier`` (default the frame)."""
    return GearSpec.model_validate(_given(type="gear", name=name, a=a, b=b, ratio=ratio, carrier=carrier,
                                          radius_a=radius_a, radius_b=radius_b, pressure_angle=pressure_angle))


def driver(name: str, joint: str | None = None, body: str | None = None, coordinate: str | None = None,
           point: str | None = None) -> DriverSpec:
    """A prescribed coordinate: a ``joint``'s, or a ``body``'s ``coordinate`` (x, y, angle; of
    its ``point``). Its motion is the spec's ``motion.drive[name]``."""
    return DriverSpec.model_validate(_given(name=name, joint=joint, body=body, coordinate=coordinate, point=point))


def mechanism(bodies: Iterable[CustomBody], joints: Iterable[Any], drivers: Iterable[DriverSpec],
              frame_points: Mapping[str, XY] | None = None, actuators: list[str] | None = None) -> CustomMechanism:
    """The ``mechanism`` section of a custom spec: its bodies, joints and drivers, and the frame's
    named points."""
    return CustomMechanism.model_validate(_given(
        template="custom", frame_points=dict(frame_points) if frame_points is not None else None,
        bodies=list(bodies), joints=list(joints), drivers=list(drivers), actuators=actuators))


def counterweight(body: str, name: str | None = None, *, at: XY | str | None = None,
                  segment: tuple[XY | str, XY | str] | None = None,
                  disc: tuple[XY | str, Value] | None = None) -> CounterweightRegionSpec:
    """Where a balancing method may place a counterweight on ``body``: ``at`` a fixed point,
    anywhere on a ``segment``, or anywhere in a ``disc`` given as (centre, radius)."""
    region = DiscRegionSpec.model_validate({"centre": disc[0], "radius": disc[1]}) if disc is not None else None
    return CounterweightRegionSpec.model_validate(_given(body=body, name=name, at=at, segment=segment, disc=region))


def counter_rotation(name: str, *, at: XY | str, geared_to: str, ratio: float, carrier: str = FRAME,
                     mass: Value | None = None, radius: Value | None = None) -> CounterRotationSpec:
    """A counter-rotating disc on ``carrier``'s axis ``at``, geared to ``geared_to`` at ``ratio``;
    the moment balance solves its inertia."""
    return CounterRotationSpec.model_validate(_given(name=name, carrier=carrier, at=at, geared_to=geared_to,
                                                     ratio=ratio, mass=mass, radius=radius))


def force_balance(counterweights: Iterable[CounterweightRegionSpec], **settings: Any) -> ForceBalance:
    """The ``force_balance`` method: counterweights of least added mass in their regions that
    cancel the shaking force (``settings``: the finder's, as in the YAML)."""
    return ForceBalance.model_validate({"method": "force_balance", "counterweights": list(counterweights), **settings})


def moment_balance(counterweights: Iterable[CounterweightRegionSpec],
                   counter_rotations: Iterable[CounterRotationSpec], **settings: Any) -> MomentBalance:
    """The ``moment_balance`` method: the force balance, then counter-rotating discs whose
    inertias cancel the shaking moment."""
    return MomentBalance.model_validate({"method": "moment_balance", "counterweights": list(counterweights),
                                         "counter_rotations": list(counter_rotations), **settings})
