"""Evaluating a sweep's designs, in worker processes or dask workers: each design's spec, its
chosen stage and its loads, through the mass-only fast path or one engine analysis per geometry."""

from __future__ import annotations

from typing import Any

import numpy as np
from pydantic import ValidationError

from ..vary import get_attr_path, with_values


def _validate(data: dict):
    from ..spec import validate

    return validate(data)


def _pick_stage(result, stage: str | None):
    if stage is None:  # the main method's last stage (not one of a compared design)
        return [s for s in result.stages if s.design is None][-1]
    for s in result.stages:
        if s.name == stage:
            return s
    raise ValueError(f"no stage {stage!r}; stages: {', '.join(s.name for s in result.stages)}")


def _settings(spec) -> tuple[np.ndarray, tuple, tuple]:
    from .. import registry
    from ..study import gravity_vector

    return registry.time_grid(spec), gravity_vector(spec), tuple(spec.analysis.moment_point)


def build_design(data: dict, paths: list[tuple], values: tuple, stage: str | None):
    """Spec, chosen stage and unbalanced model of one design (raises on an invalid design)."""
    from .. import registry

    spec = _validate(with_values(data, paths, values))
    result = registry.balance_designs(spec, page=False)  # the sweep reads the stages only: no page-only work
    return spec, _pick_stage(result, stage), result.stages[0]


def _error_text(exc: BaseException) -> str:
    from ..spec_parts import SpecFieldError

    if isinstance(exc, ValidationError):
        from ..loader import error_message as _message, format_path as _format_path

        return "; ".join(f"{_format_path(tuple(e['loc']))}: {_message(e)}" for e in exc.errors())
    if isinstance(exc, SpecFieldError):
        return f"{'.'.join(map(str, exc.path))}: {exc.message}"
    return f"{type(exc).__name__}: {exc}" if not str(exc) else str(exc)


_GEOMETRIES: dict[tuple, Any] = {}  # geometry key -> MassSweep of the canonical model (per process)
MAX_GEOMETRIES = 32


def canonical(model):
    """The model with every body's mass 1 kg, centre of mass at its frame origin, inertia
    1 kg m^2, and massless attachments (:func:`balpipe.engine.fastpath.frame_model`): its
    :class:`balpipe.balancing.mass_sweep.MassSweep` depends on the geometry alone, so every design of that
    geometry gets the same numbers, in any chunk or worker."""
    from ..engine.fastpath import frame_model

    return frame_model(model)


def _stage_loads(model, key: tuple | None, t, g, P, tag: str, row: dict) -> str:
    """Fast path: the design's parameter vector ``row[tag + 'p']`` (the parent does the product).
    Otherwise one engine analysis per geometry (a :class:`balpipe.balancing.mass_sweep.MassSweep` of the
    canonical model, cached in this process: the design's other stage and the other designs of
    that geometry reuse it) and the design's peaks through its regressors, in ``row``. Returns the
    route taken."""
    from ..balancing.regressor import parameters
    from ..balancing.mass_sweep import MassSweep, geometry_key

    gkey = geometry_key(model, t, g, P)
    if key is not None and gkey == key:
        row[tag + "p"] = parameters(model, angular=True)
        return "mass"
    for b in model.bodies:  # as the engine refuses it (compile_model)
        m, _, i = b.mass_properties()
        if m < 0 or i < 0:
            raise ValueError(f"body {b.name!r} has a negative mass or inertia")
    ms = _GEOMETRIES.get(gkey)
    if ms is None:
        try:
            ms = MassSweep.build(canonical(model), t, g, P)
        except Exception:  # the design's own analysis says why (or succeeds)
            from ..engine import analyse

            an = analyse(model, t, g, P)
            row[tag + "max_shaking_force"] = an.max_force
            row[tag + "max_shaking_moment"] = an.max_moment
            row[tag + "max_actuator_effort"] = max((float(np.max(np.abs(e))) for e in an.efforts.values()), default=0.0)
            return "full"
        if len(_GEOMETRIES) >= MAX_GEOMETRIES:
            _GEOMETRIES.clear()
        _GEOMETRIES[gkey] = ms
    peaks = ms.peaks(parameters(model, angular=True)[None, :])
    for name, arr in peaks.items():
        row[tag + name] = float(arr[0])
    return "full"


def evaluate_chunk(data: dict, paths: list[tuple], chunk: list[tuple[int, tuple]], stage: str | None,
                   keys: tuple, anchors=None) -> list[dict]:
    """Rows of one chunk of designs. For the chosen stage and the design's unbalanced stage
    (``keys``: their base geometries, or None), a design with the base geometry returns its
    parameter vector for the parent's fast path; any other is analysed here by the engine, once
    per geometry (:func:`_stage_loads`), a closed loop starting from the fixed motions
    ``anchors`` (:func:`run`; :mod:`balpipe.engine.warmstart`: no sequential continuation, and
    the same numbers in any chunk or worker)."""
    from ..engine import warm_start
    from ..runtime.threads import blas_threads

    with warm_start(anchors), blas_threads():  # one BLAS thread in any worker, whatever it imported first
        return _evaluate(data, paths, chunk, stage, keys)


def _evaluate(data: dict, paths: list[tuple], chunk: list[tuple[int, tuple]], stage: str | None,
              keys: tuple) -> list[dict]:
    from ..study import total_inertia

    rows = []
    for index, values in chunk:
        row: dict[str, Any] = {"design": index, "values": values}
        try:
            spec, sr, base = build_design(data, paths, values, stage)
            row["si"] = [float(get_attr_path(spec, p)) for p in paths]
            row["added_mass"] = sr.model.total_mass() - base.model.total_mass()
            row["added_inertia"] = total_inertia(sr.model) - total_inertia(base.model)
            t, g, P = _settings(spec)
            row["route"] = _stage_loads(sr.model, keys[0], t, g, P, "", row)
            _stage_loads(base.model, keys[1], t, g, P, "unbalanced_", row)
        except Exception as exc:  # a failing design is a row with its error, not a crashed sweep
            row = {"design": index, "values": values, "error": _error_text(exc)}
        rows.append(row)
    return rows
