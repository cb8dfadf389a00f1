"""``results.json`` (a public interface, documented in the README) and the CSV time series."""

from __future__ import annotations

import io
import json
import math
from typing import Any

import numpy as np

from .. import __version__
from ..study import Study, stage_metrics

SCHEMA_VERSION = 1


def _clean(x: Any) -> Any:
    """JSON-safe and deterministic: floats rounded to 12 significant digits, NaN -> None."""
    if isinstance(x, dict):
        return {str(k): _clean(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [_clean(v) for v in x]
    if isinstance(x, (bool, np.bool_)):
        return bool(x)
    if isinstance(x, (int, np.integer)):
        return int(x)
    if isinstance(x, (float, np.floating)):
        v = float(x)
        if not math.isfinite(v):
            return None
        return float(f"{v:.12g}")
    return x


def results_dict(study: Study, source: str, input_hash: str, simulated: bool) -> dict:
    spec = study.spec
    tol = spec.analysis.balance_tolerance
    stages = []
    for s in study.stages:
        m = stage_metrics(s, study.unbalanced, tol)
        stages.append(m)
    validation = {}
    for s in study.stages:
        if s.validation is not None:
            validation[s.stage.name] = s.validation.to_json()
    out = {
        "schema_version": SCHEMA_VERSION,
        "balpipe_version": __version__,
        "spec": spec.name,
        "source": source,
        "input_hash": input_hash,
        "status": "ok" if study.ok else "failed",
        "problems": study.problems,
        "mechanism": spec.mechanism.template,
        "method": spec.balancing.method,
        "samples": spec.analysis.samples,
        "duration": spec.motion.duration,
        "gravity": list(study.unbalanced.analysis.gravity),
        "moment_point": list(study.unbalanced.analysis.moment_point),
        "parameters": [
            {"name": p.name, "value": p.value, "unit": p.unit, "source": p.source, "description": p.description}
            for p in study.balance.parameters
        ],
        "stages": stages,
        "checks": study.checks,
        "references": study.references,
        "notes": study.balance.notes,
        "validation": validation if simulated else None,
        "reactionless": study.reactionless.to_json() if study.reactionless is not None else None,
    }
    out["paper"] = spec.paper  # the site index filters by it
    return _clean(out)


def dumps(results: dict) -> str:
    return json.dumps(results, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def joint_load_table(study: Study) -> list[dict]:
    """Peak load of every joint in every stage: |F| for revolutes (bearing load), |N| and |M|
    for prismatic pairs, |T| for gear meshes."""
    rows: dict[str, dict] = {}
    for s in study.stages:
        for j, comps in s.analysis.reactions.items():
            row = rows.setdefault(j, {"joint": j, "kind": "", "unit": "", "peaks": {}})
            if "Fx" in comps:
                row["kind"], row["unit"] = "revolute: |F|", "N"
                peak = float(np.max(np.hypot(comps["Fx"], comps["Fy"])))
            elif "N" in comps:
                row["kind"], row["unit"] = "prismatic: |N| (normal force)", "N"
                peak = float(np.max(np.abs(comps["N"])))
            else:
                row["kind"], row["unit"] = "gear mesh: |T| (torque on the driven gear)", "N m"
                peak = float(np.max(np.abs(comps["T"])))
            row["peaks"][s.stage.name] = peak
    return list(rows.values())


def timeseries_csv(study: Study) -> str:
    """One row per sample: t, then per stage Fx, Fy, |F|, M (about the moment point), every
    actuator effort and every joint reaction (see :func:`balpipe.engine._joint_reactions`);
    SI units, 12 significant digits."""
    cols: list[tuple[str, np.ndarray]] = [("t_s", study.unbalanced.analysis.t)]
    for s in study.stages:
        an, n = s.analysis, s.stage.name
        cols += [
            (f"{n}.Fx_N", an.force[:, 0]),
            (f"{n}.Fy_N", an.force[:, 1]),
            (f"{n}.F_N", np.hypot(an.force[:, 0], an.force[:, 1])),
            (f"{n}.M_Nm", an.moment),
        ]
        for d in sorted(an.efforts):
            cols.append((f"{n}.effort.{d}", an.efforts[d]))
        for j in sorted(an.reactions):
            for comp, values in an.reactions[j].items():
                cols.append((f"{n}.reaction.{j}.{comp}", values))
    buf = io.StringIO()
    buf.write(",".join(c for c, _ in cols) + "\n")
    data = np.column_stack([v for _, v in cols])
    for row in data:
        buf.write(",".join(f"{v:.12g}" for v in row) + "\n")
    return buf.getvalue()
