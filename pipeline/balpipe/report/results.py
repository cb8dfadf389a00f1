"""``results.json`` (a public interface, documented in docs/site.md) and the CSV time series."""

from __future__ import annotations

import json
import math
from typing import Any

import numpy as np

from .. import __version__
from ..mechanics.drivers import driver_unit
from ..mechanics.motion_outputs import motion_columns
from ..balancing.regressor import model_size
from ..display import csv_numbers
from ..study import Study
from . import present
from .frame_mounts import mounts_json
from .mechanism_key import mechanism_key
from .load_table import load_columns, load_summary
from .orders_table import orders_json
from .parts_table import parts_json
from .notation_table import names_for
from .verdict import verdict

SCHEMA_VERSION = 1


def json_safe(x: Any) -> Any:
    """JSON-safe and deterministic: floats rounded to 12 significant digits, NaN -> None."""
    if isinstance(x, dict):
        return {str(k): json_safe(v) for k, v in x.items()}
    if isinstance(x, (list, tuple)):
        return [json_safe(v) for v in x]
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
    stages = [s.metrics.to_json() for s in study.stages]
    for row, s in zip(stages, study.stages):  # an optimised stage's objective and caps: its verdict's measure
        if s.stage.aim is not None:
            row["aim"] = s.stage.aim.to_json()
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
        "unconfirmed": study.unconfirmed,
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
        "warnings": study.warnings,  # dead centres and singularities (balpipe.diagnose.dead_centres)
        "validation": validation if simulated else None,
        "reactionless": study.reactionless.to_json() if study.reactionless is not None else None,
        "torque_driven": {s.stage.name: s.torque.to_json() for s in study.stages if s.torque is not None}
        if simulated else None,
    }
    out["comparison"] = comparison(study)
    # per stage, the harmonics of the shaking force and moment; None unless the motion is periodic
    out["orders"] = {s.stage.name: orders_json(spec.motion, s.analysis) for s in study.stages}
    # what balancing costs a motor: peak, RMS effort and peak power per stage and driver
    out["actuators"] = present.effort_rows(
        [(s.stage.name, s.stage.label, s.stage.model, s.analysis) for s in study.stages])
    names = names_for(spec).names
    for row in out["actuators"]:  # the paper's symbol of the driver, for the index (θ₁ for theta1)
        row["symbol"] = names.text("driver", row["driver"])
    summary = load_summary([(s.stage.name, s.stage.label, s.stage.model, s.analysis) for s in study.stages])
    if summary is not None:  # the spec's loads: peaks, friction energy, frame load beside the shaking load
        out["loads"] = summary
    mounts = mounts_json(study)
    if mounts is not None:  # the spec's frame on its mounts: floor forces, vibration velocity, modes
        out["mounts"] = mounts
    out["moving_mass"] = sum(b.mass_properties()[0] for b in study.unbalanced.stage.model.bodies)
    # the linkage without its drivers, motion, loads and method: specs sharing it are compared on the index
    out["mechanism_key"] = mechanism_key(study.unbalanced.stage.model)
    out["moving_bodies"] = [b.name for b in study.unbalanced.stage.model.bodies]
    out["units"] = "SI"  # every number of this file, whatever units the spec's pages show (report.units)
    out["length_scale"] = model_size(study.unbalanced.stage.model)
    out["inertia_scale"] = inertia_scale(study.unbalanced.stage.model, out["moving_mass"])
    if study.balance.details:
        out["balancing_details"] = study.balance.details
    parts = parts_json(study)
    if parts:  # the counterweights made as parts (docs/parts.md)
        out["parts"] = parts
    out["paper"] = spec.paper  # the site index filters by it
    out["verdict"] = verdict_of(study, out)
    return json_safe(out)


def inertia_scale(model, moving_mass: float) -> float:
    """The scale of the mechanism's inertias (kg m²): its links' declared inertias plus its moving
    mass at its size (:func:`balpipe.balancing.regressor.model_size`) squared. An added inertia
    at most 1e-9 of it is round-off (an optimiser's zero, a re-summed total) and shows as 0."""
    return float(sum(abs(b.inertia) for b in model.bodies) + moving_mass * model_size(model) ** 2)


def verdict_of(study: Study, out: dict) -> dict:
    """The ``verdict`` object (:mod:`balpipe.report.verdict`); with gravity on, each stage's
    weight (total moving mass x g, N) is given apart from its inertial loads."""
    g = math.hypot(*study.unbalanced.analysis.gravity)
    weights = {s.stage.name: s.analysis.total_mass * g for s in study.stages} if g else None
    return verdict(out, weights, main={s.stage.name for s in study.stages if s.stage.design is None})


def comparison(study: Study) -> dict:
    """Every stage (the main design's and those of ``compare``) side by side: what it adds and
    what it costs. Joint loads are the peak bearing load over the revolute joints (and the
    normal force of prismatic pairs), with the joint that carries it."""
    table = joint_load_table(study)
    rows = []
    before: dict[str | None, float] = {}  # per design: peak moment of its latest stage without counter-rotations
    for s in study.stages:
        m = s.metrics
        loads = [(row["peaks"].get(s.stage.name, 0.0), row["joint"]) for row in table if row["unit"] == "N"]
        peak, joint = max(loads) if loads else (0.0, "")
        design = s.stage.design
        discs = counter_rotations(s.stage.model, study.unbalanced.stage.model)
        if discs == 0:
            before[design] = m.max_shaking_moment
        rows.append({
            "stage": s.stage.name, "label": s.stage.label, "design": design or "main", "balances": s.stage.balances,
            "added_mass": m.added_mass, "added_inertia": m.added_inertia,
            "max_actuator_effort": m.max_actuator_effort, "max_joint_load": peak, "max_joint_load_joint": joint,
            "max_shaking_force": m.max_shaking_force, "max_shaking_moment": m.max_shaking_moment,
            "force_ratio": m.force_ratio, "moment_ratio": m.moment_ratio,
            "counter_rotations": discs,
            "moment_before_counter_rotations": before.get(design, study.unbalanced.analysis.max_moment),
        })
    return {"reference": study.unbalanced.stage.name, "rows": rows}


def counter_rotations(model, unbalanced) -> int:
    """Counter-rotating discs (gear bodies) that a stage adds to the unbalanced mechanism."""
    had = {b.name for b in unbalanced.bodies if b.kind == "gear"}
    return sum(1 for b in model.bodies if b.kind == "gear" and b.name not in had)


def dumps(results: dict) -> str:
    return json.dumps(results, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def joint_load_series(analysis) -> list[tuple[str, str, str, str, np.ndarray]]:
    """Every joint's load over time, as (joint, component, kind, unit, values): |F| for a revolute
    (bearing load, tooth forces included), |N| for a prismatic pair, |T| for a gear mesh and, for a
    mesh with pitch radii, |Ft| (tangential) and Fr (radial, >= 0) tooth forces; from the
    reactions of :func:`balpipe.engine._joint_reactions`."""
    out = []
    for j, comps in analysis.reactions.items():
        if "Fx" in comps:
            out.append((j, "F", "revolute: |F|", "N", np.hypot(comps["Fx"], comps["Fy"])))
        elif "N" in comps:
            out.append((j, "N", "prismatic: |N| (normal force)", "N", np.abs(comps["N"])))
        elif "Ft" in comps:
            out += [(j, "T", "gear mesh: |T| (torque on the driven gear)", "N m", np.abs(comps["T"])),
                    (j, "Ft", "gear mesh: |Ft| (tangential tooth force)", "N", np.abs(comps["Ft"])),
                    (j, "Fr", "gear mesh: Fr (radial tooth force)", "N", np.asarray(comps["Fr"], dtype=float))]
        else:
            out.append((j, "T", "gear pair without pitch radii, a couple only: |T| (torque on the driven gear)",
                        "N m", np.abs(comps["T"])))
    return out


def joint_load_table(study: Study) -> list[dict]:
    """Peak load of every joint in every stage (:func:`joint_load_series`), a row per joint and
    component, with ``scale``: the largest peak of any joint in that unit (a peak at most 1e-9 of
    it is round-off, shown as 0)."""
    rows: dict[tuple[str, str], dict] = {}
    for s in study.stages:
        for joint, comp, kind, unit, values in joint_load_series(s.analysis):
            row = rows.setdefault((joint, comp), {"joint": joint, "kind": kind, "unit": unit, "peaks": {}})
            row["peaks"][s.stage.name] = float(np.max(values))
    largest: dict[str, float] = {}
    for row in rows.values():
        largest[row["unit"]] = max([largest.get(row["unit"], 0.0), *row["peaks"].values()])
    for row in rows.values():
        row["scale"] = largest[row["unit"]]
    return list(rows.values())


def timeseries_csv(study: Study) -> str:
    """One row per sample, the columns of :func:`timeseries_columns`; SI units, 12 significant
    digits: :func:`timeseries_file`'s text, whole."""
    return timeseries_file(study).text()


class CsvFile:
    """A CSV file's header and columns, written :data:`ROWS` rows at a time (:meth:`write_to`):
    the text of 20,000 samples of a 21-body machine is 220 MB, its columns a third of that and
    shared with the study; the same bytes as :meth:`text` encoded. Picklable (its columns are
    arrays)."""

    ROWS = 1000

    def __init__(self, header: str, columns: list[np.ndarray]):
        self.header, self.columns = header, columns

    def pieces(self):
        """The text, header first, then :data:`ROWS` rows per piece."""
        yield self.header + "\n"
        n = len(self.columns[0]) if self.columns else 0
        for a in range(0, n, self.ROWS):
            yield csv_rows([np.asarray(v, dtype=float).reshape(n)[a : a + self.ROWS] for v in self.columns])

    def write_to(self, f) -> None:
        """Write the text, UTF-8, to the binary file ``f`` piece by piece."""
        for piece in self.pieces():
            f.write(piece.encode("utf-8"))

    def text(self) -> str:
        return "".join(self.pieces())


def timeseries_file(study: Study) -> CsvFile:
    """``timeseries.csv`` (:func:`timeseries_columns`), to be written by pieces."""
    cols = timeseries_columns(study)
    return CsvFile(",".join(c for c, _ in cols), [v for _, v in cols])


#: a joint reaction's unit by component (:func:`balpipe.engine.dynamics.joint_reactions`), as
#: timeseries.csv's column names write it: forces in N, the moments and gear torques in N m
REACTION_UNITS = {"Fx": "N", "Fy": "N", "N": "N", "Ft": "N", "Fr": "N", "M": "Nm", "T": "Nm"}


def _unit_tag(unit: str) -> str:
    """A unit as the CSV column names end with it: 'N m' -> 'Nm', 'm/s' -> 'm_s'."""
    return unit.replace(" ", "").replace("/", "_")


def timeseries_columns(study: Study) -> list[tuple[str, np.ndarray]]:
    """The columns of ``timeseries.csv`` as (name, values), in its order, every name ending in
    its SI unit (``_N``, ``_Nm``, ``_m``, ``_rad_s``, ...): t, then per stage Fx,
    Fy, |F|, M (about the moment point), every actuator effort (``effort.<driver>_Nm`` or
    ``_N``), every joint reaction (``reaction.<joint>.<component>_N`` or ``_Nm``, see
    :func:`balpipe.engine.dynamics.joint_reactions`), with loads the frame load and every load's
    series (:func:`.load_table.load_columns`), the total centre of mass, every body's pose and
    every named point's path with their velocities
    (:func:`balpipe.mechanics.motion_outputs.motion_columns`), a body's pose or point path
    that equals the same column of an earlier stage (bit for bit: the stages share the motion)
    left out, read under that earlier stage's name; SI units, full precision."""
    cols: list[tuple[str, np.ndarray]] = [("t_s", study.unbalanced.analysis.t)]
    motion: dict[str, list[np.ndarray]] = {}
    for s in study.stages:
        an, n = s.analysis, s.stage.name
        cols += [
            (f"{n}.Fx_N", an.force[:, 0]),
            (f"{n}.Fy_N", an.force[:, 1]),
            (f"{n}.F_N", np.hypot(an.force[:, 0], an.force[:, 1])),
            (f"{n}.M_Nm", an.moment),
        ]
        model = s.stage.model
        for d in sorted(an.efforts):
            cols.append((f"{n}.effort.{d}_{_unit_tag(driver_unit(model, d))}", an.efforts[d]))
        for j in sorted(an.reactions):
            for comp, values in an.reactions[j].items():
                cols.append((f"{n}.reaction.{j}.{comp}_{REACTION_UNITS[comp]}", values))
        cols += load_columns(n, an)
        for name, values in motion_columns(s.stage.model, an):
            # a body's pose or point path the same as an earlier stage's (the stages share their
            # motion): written once, under the earliest stage's name
            if name.startswith(("pose.", "point.")) and any(np.array_equal(values, v) for v in motion.get(name, ())):
                continue
            motion.setdefault(name, []).append(values)
            cols.append((f"{n}.{name}", values))
    return cols


def csv_rows(columns: list[np.ndarray]) -> str:
    """The rows of equal-length ``columns`` as CSV text, %.12g, no "-0"
    (:func:`balpipe.display.csv_numbers.rows`: the same text as one format per row)."""
    return csv_numbers.rows(columns)
