"""The sweep's report page: the Pareto fronts of added mass against peak shaking moment and
against peak actuator effort, and the designs on them with their specs (``balpipe sweep``)."""

from __future__ import annotations

import matplotlib

from ..draw.figures import to_svg  # noqa: E402  (before pyplot: balpipe.runtime.plotting)

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from .render import environment  # noqa: E402


def front_figure(rows: list[dict], metric: str, flag: str, ylabel: str, prefix: str) -> str:
    """Every successful design (added mass, metric) and its Pareto front (both minimised)."""
    ok = [r for r in rows if "error" not in r]
    fig, ax = plt.subplots(figsize=(6.4, 4.2))
    if ok:
        x = np.array([r["added_mass"] for r in ok])
        y = np.array([r[metric] for r in ok])
        ax.scatter(x, y, s=8, color="tab:gray", alpha=0.6, label=f"designs ({len(ok)})")
        on = np.array([r[flag] for r in ok])
        order = np.argsort(x[on])
        ax.plot(x[on][order], y[on][order], "o-", color="tab:red", ms=4, drawstyle="steps-post",
                label=f"Pareto front ({int(on.sum())})")
        ax.legend(loc="best")
    ax.set_xlabel("added mass relative to the unbalanced mechanism (kg)")
    ax.set_ylabel(ylabel)
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    return to_svg(fig, prefix)


def effort_unit(plan) -> str:
    """The unit of the sweep's actuator efforts: 'N m' when every driver of the base spec is a
    torque (revolute joint, angle), 'N' when every one is a force, else 'N m or N'. The varied
    fields are values, so every design has the base spec's drivers."""
    from .. import registry
    from ..spec import validate
    from .present import driver_unit

    try:
        model = registry.unbalanced_model(validate(plan.data))
    except Exception:  # noqa: BLE001  (the base spec was checked; a unit is not worth a failed page)
        return "N m or N"
    units = {driver_unit(model, d.name) for d in model.drivers}
    return units.pop() if len(units) == 1 else "N m or N"


def si_unit(vary) -> str:
    """The SI unit of a varied field's values in the table (the CSV's SI numbers): from the unit
    the vary is written in ('500 g:2 kg' -> kg); 'SI' when it is written without one."""
    from ..units import SI, kinds_of

    for kind in kinds_of(vary.unit) if vary.unit else ():
        if SI.get(kind):
            return SI[kind]
    return "SI"


def render(res, linked: set[int]) -> str:
    rows = res.rows
    unit = effort_unit(res.plan)
    fronts = [
        ("Added mass against peak shaking moment",
         front_figure(rows, "max_shaking_moment", "pareto_moment",
                      "peak shaking moment |M| (N m)\nabout the spec's moment point", "front-m"),
         "pareto_moment"),
        ("Added mass against peak actuator effort",
         front_figure(rows, "max_actuator_effort", "pareto_effort",
                      f"peak actuator effort ({unit})\nlargest over the drivers", "front-e"),
         "pareto_effort"),
    ]
    front_rows = [r for r in rows if r.get("pareto_moment") or r.get("pareto_effort")]
    errors = [r for r in rows if "error" in r]
    return environment().get_template("sweep.html").render(
        res=res, plan=res.plan, fronts=fronts, front_rows=front_rows, errors=errors[:200],
        n_errors=len(errors), linked=linked, effort_unit=unit, var_units=[si_unit(v) for v in res.plan.varies],
    )
