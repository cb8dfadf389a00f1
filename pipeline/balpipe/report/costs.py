"""What balancing costs, as factors against the unbalanced mechanism: moving mass x, peak and
RMS actuator effort x, peak power x, largest joint load x (the numbers a designer sizes motors
and bearings by). Pure functions of ``results.json``'s rows (``actuators``, ``comparison``,
``stages``, ``moving_mass``).

Added inertia counts only the parts that can be built: a stage with a negative mass or inertia
(:mod:`balpipe.mechanics.realisable`) is flagged instead, its "added inertia" never shown as a cost.
"""

from __future__ import annotations

from typing import Any, Callable

from ..display import numbers


def _factor(new: float | None, old: float | None) -> float | None:
    if new is None or old is None or old == 0:
        return None
    return float(new) / float(old)


#: the actuators' rows' key -> the cost's name (effort, rms, power)
DRIVER_COSTS = {"peak": "effort", "rms": "rms", "power": "power"}


def cost_factors(results: dict, reference: str, final: str) -> dict:
    """Factors of stage ``final`` against stage ``reference`` (its unbalanced mechanism).

    ``effort``/``rms``/``power``: the largest factor over the drivers, ``<name>_driver`` the
    driver that has it and ``<name>_drivers`` every driver's ``{driver, factor}``, the worst
    first; ``joint_load``: the largest bearing load of the final stage over that of the reference.
    """
    stages = {s["name"]: s for s in results.get("stages") or []}
    fin = stages.get(final, {})
    mm = results.get("moving_mass") or 0.0
    out: dict = {
        "added_mass": fin.get("added_mass"),
        "moving_mass": _factor(mm + (fin.get("added_mass") or 0.0), mm) if mm else None,
        "realisable": fin.get("realisable", True) is not False,
        "not_realisable": fin.get("not_realisable_parts") or "",
    }
    out["added_inertia"] = fin.get("added_inertia") if out["realisable"] else None
    acts = results.get("actuators") or []
    for key in ("peak", "rms", "power"):
        per: list[dict] = []
        for a0 in (a for a in acts if a["stage"] == reference):
            a1 = next((a for a in acts if a["stage"] == final and a["driver"] == a0["driver"]), None)
            f = _factor(a1 and a1.get(key), a0.get(key))
            if f is not None:
                per.append({"driver": a0["driver"], "factor": f})
        per.sort(key=lambda d: -d["factor"])  # stable: drivers of equal factors in the table's order
        name = DRIVER_COSTS[key]
        out[name] = per[0]["factor"] if per else None
        out[f"{name}_driver"] = per[0]["driver"] if per else ""
        out[f"{name}_drivers"] = per
    rows = {r["stage"]: r for r in (results.get("comparison") or {}).get("rows") or []}
    r0, r1 = rows.get(reference), rows.get(final)
    out["joint_load"] = _factor((r1 or {}).get("max_joint_load"), (r0 or {}).get("max_joint_load"))
    out["joint"] = (r1 or {}).get("max_joint_load_joint", "")
    return out


def factor_text(x: float | None) -> str:
    """One format for every cost factor: '× 1.85' (:func:`balpipe.display.numbers.factor`)."""
    return numbers.factor(x)


def drivers_text(costs: dict, name: str, label: Callable[[str], Any] = str) -> Any:
    """Which driver a cost factor ``name`` (effort, rms, power) is, that it is the worst, and
    every other driver's factor: 'q3, the worst of 3 drivers; q1 × 0.5, q2 × 1.2' ('q3' alone
    with one driver, '' with none). ``label(driver)`` names a driver (markup on a page: the
    paper's symbol; the result is markup then)."""
    per = costs.get(f"{name}_drivers") or []
    if not per:
        return label(costs[f"{name}_driver"]) if costs.get(f"{name}_driver") else ""
    head = label(per[0]["driver"])
    if len(per) == 1:
        return head
    rest = [label(d["driver"]) + f" {factor_text(d['factor'])}" for d in per[1:]]
    out = head + f", the worst of {len(per)} drivers; "
    for k, r in enumerate(rest):
        out = out + (", " if k else "") + r
    return out
