"""One counter-mass on a link, at a given distance from its proximal joint, realising the first
moments a balance condition asks for (paper 001, eqs. 8-11, 17, 19 and 21 all end here)."""

from __future__ import annotations

import numpy as np

from ...balancing.parts import add_counterweight
from ...model import Model


def realise(model: Model, body: str, P: float, Q: float, distance: float, name: str) -> tuple[Model, float, tuple[float, float]]:
    """``model`` with a counter-mass on ``body`` bringing its first moments (m c_x, m c_y) to
    (P, Q); returns the model, the counter-mass and its position (0 and None when not needed)."""
    m, c, _ = model.body(body).mass_properties()
    s = np.array([P - m * c[0], Q - m * c[1]])
    norm = float(np.hypot(*s))
    if norm <= 1e-14 * max(abs(P), abs(Q), m * distance, 1e-300):
        return model, 0.0, (0.0, 0.0)
    pos = (float(s[0] / norm * distance), float(s[1] / norm * distance))
    mass = norm / distance
    return add_counterweight(model, body, name, mass, pos, radius=None), mass, pos
