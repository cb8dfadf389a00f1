"""The sweep's report page: the Pareto fronts of added mass against peak shaking moment and
against peak actuator effort, and the designs on them with their specs (``balpipe sweep``)."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from .figures import to_svg  # noqa: E402
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


def render(res, linked: set[int]) -> str:
    rows = res.rows
    fronts = [
        ("Added mass against peak shaking moment",
         front_figure(rows, "max_shaking_moment", "pareto_moment",
                      "peak shaking moment |M| about the spec's moment point (N m)", "front-m"),
         "pareto_moment"),
        ("Added mass against peak actuator effort",
         front_figure(rows, "max_actuator_effort", "pareto_effort",
                      "peak actuator effort, largest over the drivers (N m or N)", "front-e"),
         "pareto_effort"),
    ]
    front_rows = [r for r in rows if r.get("pareto_moment") or r.get("pareto_effort")]
    errors = [r for r in rows if "error" in r]
    return environment().get_template("sweep.html").render(
        res=res, plan=res.plan, fronts=fronts, front_rows=front_rows, errors=errors[:200],
        n_errors=len(errors), linked=linked,
    )
