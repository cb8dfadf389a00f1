"""The page's "What balancing costs the actuators" table in wide form: one row per stage, one
group of columns (peak |effort|, RMS effort, peak |power|) per driver, so that a stage's cost
reads along its row and a driver's down its columns (4 stages of 3 drivers: 4 rows, not 12)."""

from __future__ import annotations


def effort_table(actuators: list[dict]) -> dict:
    """``results.json``'s ``actuators`` rows (stage, label, driver, unit, peak, rms, power) as
    ``{"drivers": [(driver, unit)], "rows": [{"stage", "label", "cells": [row or None]}]}``,
    drivers and stages in their first appearance's order; a stage without a driver's row (a
    compared design with other drivers) has None there."""
    drivers: dict[str, str] = {}
    stages: dict[str, dict] = {}
    for a in actuators:
        drivers.setdefault(a["driver"], a["unit"])
        stages.setdefault(a["stage"], {"stage": a["stage"], "label": a["label"], "by": {}})["by"][a["driver"]] = a
    rows = [{"stage": s["stage"], "label": s["label"], "cells": [s["by"].get(d) for d in drivers]}
            for s in stages.values()]
    return {"drivers": list(drivers.items()), "rows": rows}
