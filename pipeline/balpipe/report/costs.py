"""What balancing costs, as factors against the unbalanced mechanism: moving mass x, peak and
RMS actuator effort x, peak power x, largest joint load x (the numbers a designer sizes motors
and bearings by). Pure functions of ``results.json``'s rows (``actuators``, ``comparison``,
``stages``, ``moving_mass``).

Added inertia counts only the parts that can be built: a stage with a negative mass or inertia
(:mod:`balpipe.mechanics.realisable`) is flagged instead, its "added inertia" never shown as a cost.
"""

from __future__ import annotations

from ..display import numbers


def _factor(new: float | None, old: float | None) -> float | None:
    if new is None or old is None or old == 0:
        return None
    return float(new) / float(old)


def cost_factors(results: dict, reference: str, final: str) -> dict:
    """Factors of stage ``final`` against stage ``reference`` (its unbalanced mechanism).

    ``effort``/``rms``/``power``: the largest factor over the drivers, with the driver;
    ``joint_load``: the largest bearing load of the final stage over that of the reference.
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
        best = None
        for a0 in (a for a in acts if a["stage"] == reference):
            a1 = next((a for a in acts if a["stage"] == final and a["driver"] == a0["driver"]), None)
            f = _factor(a1 and a1.get(key), a0.get(key))
            if f is not None and (best is None or f > best[0]):
                best = (f, a0["driver"])
        name = {"peak": "effort", "rms": "rms", "power": "power"}[key]
        out[name] = best[0] if best else None
        out[f"{name}_driver"] = best[1] if best else ""
    rows = {r["stage"]: r for r in (results.get("comparison") or {}).get("rows") or []}
    r0, r1 = rows.get(reference), rows.get(final)
    out["joint_load"] = _factor((r1 or {}).get("max_joint_load"), (r0 or {}).get("max_joint_load"))
    out["joint"] = (r1 or {}).get("max_joint_load_joint", "")
    return out


def factor_text(x: float | None) -> str:
    """One format for every cost factor: '× 1.85' (:func:`balpipe.display.numbers.factor`)."""
    return numbers.factor(x)
