"""Parts that balancing methods add to a generic :class:`~balpipe.model.Model`.

Every method builds its stages from these two transformations, so a counterweight or a
counter-rotation means the same thing on a template's mechanism and on a ``custom`` one:

* :func:`add_counterweight`: a rigid part (point mass or disc) fixed to a body;
* :func:`add_counter_rotation`: a disc pivoted on a carrier (the frame or a moving link) and
  geared to another body, ``(theta_disc - theta_c) = ratio (theta_geared - theta_c)``, so the
  mesh couple lands on the carrier (../shared/DESIGN.md, "Conventions").
"""

from __future__ import annotations

import math

import numpy as np

from ..mechanics.meshes import DEFAULT_PRESSURE_ANGLE
from ..model import FRAME, Attachment, Body, Gear, Model, Revolute, Vec2, rot


def add_counterweight(
    model: Model, body: str, name: str, mass: float, position: Vec2, inertia: float = 0.0,
    radius: float | None = None,
) -> Model:
    """``model`` with a counterweight of ``mass`` (centroidal ``inertia``) fixed to ``body`` at
    ``position`` in the body's frame."""
    b = model.body(body)
    part = Attachment(name, float(mass), (float(position[0]), float(position[1])), float(inertia),
                      "counterweight", radius)
    return model.replace_body(b.with_attachments(part))


def carrier_point_global(model: Model, carrier: str, at: Vec2) -> tuple[float, float]:
    """Global position at t = 0 (from ``model.initial``) of the carrier's local point ``at``."""
    if carrier == FRAME:
        return float(at[0]), float(at[1])
    x, y, th = model.initial[carrier]
    p = np.array([x, y]) + rot(th) @ np.asarray(at, dtype=float)
    return float(p[0]), float(p[1])


def add_counter_rotation(
    model: Model, name: str, *, carrier: str, at: Vec2, geared_to: str, ratio: float,
    inertia: float, mass: float = 0.0, radius: float | None = None, radius_geared: float | None = None,
    pressure_angle: float = DEFAULT_PRESSURE_ANGLE,
) -> Model:
    """``model`` with a counter-rotating disc ``name`` pivoted on ``carrier`` at its local point
    ``at`` (global on the frame) and geared to ``geared_to`` through a mesh held by ``carrier``:
    w_disc - w_c = ``ratio`` (w_geared - w_c). A disc of ``inertia`` about its centre, centre of
    mass on the pivot; ``radius``/``radius_geared`` are the pitch radii: given both, the mesh
    passes its tooth force (radial part from ``pressure_angle``) to the disc's pivot and to the
    geared body's bearing on the carrier, which must then be r + r_geared apart (external mesh,
    ratio < 0) or |r - r_geared| (internal); omitted, the mesh is a couple (:mod:`balpipe.mechanics.meshes`).
    """
    if not math.isfinite(ratio) or ratio == 0:
        raise ValueError(f"counter-rotation {name!r}: the gear ratio must be finite and non-zero, got {ratio}")
    pivot = carrier_point_global(model, carrier, at)
    disc = Body(name, float(mass), (0.0, 0.0), float(inertia), {"axis": (0.0, 0.0)}, radius=radius, kind="gear")
    joints = (
        Revolute(f"{carrier}-{name}", carrier, name, (float(at[0]), float(at[1])), (0.0, 0.0)),
        Gear(f"{geared_to}-{name}", geared_to, name, carrier, float(ratio), None, radius_geared, radius,
             float(pressure_angle)),
    )
    return model.add((disc,), joints, {name: (pivot[0], pivot[1], 0.0)})
