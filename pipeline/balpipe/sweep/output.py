"""A sweep's results and what is written from them: the Pareto fronts, sweep.csv, the specs of
chosen designs and the page."""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field

import numpy as np
import yaml

from ..vary import with_values
from .plan import Plan

METRICS = ("added_mass", "added_inertia", "max_shaking_force", "max_shaking_moment", "max_actuator_effort",
           "unbalanced_max_shaking_force", "unbalanced_max_shaking_moment", "force_ratio", "moment_ratio")
UNITS_OF = {"added_mass": "kg", "added_inertia": "kg m^2", "max_shaking_force": "N", "max_shaking_moment": "N m",
            "max_actuator_effort": "N m or N", "unbalanced_max_shaking_force": "N",
            "unbalanced_max_shaking_moment": "N m", "force_ratio": "1", "moment_ratio": "1"}


@dataclass
class SweepResult:
    plan: Plan
    rows: list[dict]
    base_stage: str
    fast: int = 0
    full: int = 0
    failed: int = 0
    notes: list[str] = field(default_factory=list)


def pareto(points: np.ndarray) -> np.ndarray:
    """Mask of the non-dominated rows of ``points`` (D, 2), both objectives minimised."""
    D = len(points)
    keep = np.ones(D, dtype=bool)
    if D == 0:
        return keep
    order = np.lexsort((points[:, 1], points[:, 0]))
    y = points[order, 1]
    best_before = np.concatenate([[math.inf], np.minimum.accumulate(y)[:-1]])  # the best of the designs before
    keep[order] = y < best_before
    return keep


def mark_pareto(rows: list[dict]) -> None:
    """``pareto_moment`` / ``pareto_effort``: on the front of added mass against peak shaking
    moment / peak actuator effort (designs with errors are on neither)."""
    ok = [r for r in rows if "error" not in r]
    for key, metric in (("pareto_moment", "max_shaking_moment"), ("pareto_effort", "max_actuator_effort")):
        for r in rows:
            r[key] = False
        if ok:
            pts = np.array([[r["added_mass"], r[metric]] for r in ok])
            for r, k in zip(ok, pareto(pts)):
                r[key] = bool(k)


def csv_text(res: SweepResult) -> str:
    """The table: one row per design, varied fields in SI units, metrics in SI units."""
    import csv
    import io

    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    names = [v.name for v in res.plan.varies]
    w.writerow(["design", "status", "route", *names, *[f"{m} [{UNITS_OF[m]}]" for m in METRICS],
                "pareto_moment", "pareto_effort", "error"])
    for r in res.rows:
        si = r.get("si") or [""] * len(names)
        vals = [repr(x) if isinstance(x, float) else x for x in si]
        if "error" in r:
            w.writerow([r["design"], "error", r.get("route", ""), *(vals if r.get("si") else list(map(str, r["values"]))),
                        *[""] * len(METRICS), False, False, r["error"]])
        else:
            w.writerow([r["design"], "ok", r["route"], *vals, *[repr(float(r[m])) for m in METRICS],
                        r["pareto_moment"], r["pareto_effort"], ""])
    return buf.getvalue()


def design_spec_text(res: SweepResult, index: int) -> str:
    """The spec of design ``index``: the base spec's YAML with the varied fields set, so that
    ``balpipe build`` gives its full report."""
    row = res.rows[index]
    d = copy.deepcopy(with_values(res.plan.data, [v.path for v in res.plan.varies], row["values"]))  # no sweep block
    d["name"] = f"{d.get('name', 'design')} — sweep design {index}"
    head = (f"# Design {index} of the sweep of {res.plan.file}: "
            + ", ".join(f"{v.name} = {raw}" for v, raw in zip(res.plan.varies, row["values"])) + "\n")
    return head + yaml.safe_dump(d, sort_keys=False, allow_unicode=True)


def write(res: SweepResult, out: str, specs: str = "pareto", parquet: bool = False) -> list[str]:
    """Write sweep.csv, index.html and the designs' specs (``pareto``, ``all`` or ``none``)."""
    from pathlib import Path

    from ..report.sweep_page import render

    o = Path(out)
    (o / "designs").mkdir(parents=True, exist_ok=True)
    written = []
    (o / "sweep.csv").write_text(csv_text(res), encoding="utf-8")
    written.append(str(o / "sweep.csv"))
    if parquet:
        import pyarrow.csv as pacsv
        import pyarrow.parquet as pq

        pq.write_table(pacsv.read_csv(str(o / "sweep.csv")), str(o / "sweep.parquet"))
        written.append(str(o / "sweep.parquet"))
    linked = set()
    for r in res.rows:
        if specs == "all" or (specs == "pareto" and (r.get("pareto_moment") or r.get("pareto_effort"))):
            linked.add(r["design"])
    for i in sorted(linked):
        (o / "designs" / f"design_{i:06d}.yaml").write_text(design_spec_text(res, i), encoding="utf-8")
    (o / "index.html").write_text(render(res, linked), encoding="utf-8")
    written.append(str(o / "index.html"))
    return written
