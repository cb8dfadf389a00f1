"""Presentation helpers shared by the pages, the index and the diff page: the unit of each
actuator effort and the cost of balancing (what a motor is sized by).

Presentation only: ``results.json`` keeps full precision; these derive display rows from a
study's analyses.
"""

from __future__ import annotations

import numpy as np

from ..mechanics.drivers import driver_unit  # noqa: F401  (present.driver_unit, as before)
from ..model import Model


def driver_rate(analysis, model: Model, name: str) -> np.ndarray | None:
    """The rate of the driven coordinate (rad/s or m/s) from the driver's law q(t), q'(t), q''(t);
    an actuator's joint rate from the analysis."""
    if name in (analysis.actuator_rates or {}):
        return analysis.actuator_rates[name]
    for d in model.drivers:
        if d.name == name:
            t = np.asarray(analysis.t, dtype=float)
            return np.asarray(d.law(t)[1], dtype=float) * np.ones_like(t)
    return None


def effort_rows(stages: list) -> list[dict]:
    """Per stage and driver: peak |effort|, RMS effort and, where the law gives the rate, peak
    |effort x rate| (the actuator's peak power). ``stages``: (name, label, model, analysis)."""
    rows = []
    for name, label, model, an in stages:
        for d in sorted(an.efforts):
            e = np.asarray(an.efforts[d], dtype=float)
            rate = driver_rate(an, model, d)
            rows.append({
                "stage": name, "label": label, "driver": d, "unit": driver_unit(model, d),
                "peak": float(np.max(np.abs(e))), "rms": float(np.sqrt(np.mean(e * e))),
                "power": float(np.max(np.abs(e * rate))) if rate is not None and rate.shape == e.shape else None,
            })
    return rows
