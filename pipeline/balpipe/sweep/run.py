"""Running a sweep's plan (:func:`run`): the designs in chunks, in this process, on a process pool
or on a dask.distributed cluster; the corner designs solved first as the warm start's anchors
(:mod:`balpipe.engine.warmstart`); the designs on a Pareto front of the affine route confirmed by
full analyses; and the progress line."""

from __future__ import annotations

import itertools
import math
import os
import sys
import time
from typing import Callable

import numpy as np

from .evaluate import _error_text, _pick_stage, _settings, _validate, build_design, canonical, evaluate_chunk
from .output import METRICS, SweepResult, mark_pareto
from .plan import Plan

POOL_WORTH = 3.0  # s: estimated remaining in-process work above which jobs=0 starts a process pool


def _chunks(designs: list[tuple], workers: int) -> list[list[tuple[int, tuple]]]:
    items = list(enumerate(designs))
    size = max(1, min(256, math.ceil(len(items) / max(1, 4 * workers))))
    return [items[i : i + size] for i in range(0, len(items), size)]


def run(p: Plan, jobs: int = 0, scheduler: str | None = None,
        progress: Callable[[int, int], None] | None = None, affine: bool = True) -> SweepResult:
    """Evaluate every design of the plan. A mass-only sweep (``affine``, and the probes of
    :func:`balpipe.sweep_affine.build_route` agree) needs no spec per design: its designs'
    parameters are one matrix product. Otherwise every design is built: locally (``jobs``
    processes; 1 = in this process; 0 = all cores, after timing the first chunk in this process,
    if the rest would take more than :data:`POOL_WORTH` seconds) or on the dask.distributed
    scheduler at ``scheduler``."""
    from ..engine import AnalysisError, record_anchors
    from ..balancing.mass_sweep import MassSweep, check_parameters
    from ..spec_parts import SpecFieldError

    paths = [v.path for v in p.varies]
    base_spec = _validate(p.data)
    try:
        from .. import registry

        result = registry.balance_designs(base_spec, page=False)  # the sweep reads the stages only: no page-only work
        base = _pick_stage(result, p.stage)
        t, g, P = _settings(base_spec)
        with record_anchors() as anchors:  # the base's motions: where the other geometries start
            ms = MassSweep.build(base.model, t, g, P)
            ms0 = MassSweep.build(result.stages[0].model, t, g, P)
        base_key, base_name = (ms.key, ms0.key), base.name
    except (SpecFieldError, AnalysisError, ValueError) as exc:  # no fast path: every design in full
        ms, ms0, base_key, base_name, anchors = None, None, (None, None), p.stage or "last", None
        notes = [f"the base spec's stage cannot be analysed ({_error_text(exc)}): no fast path"]
    else:
        notes = []
    total = len(p.designs)
    done = 0
    rows: list[dict] = []

    def take(part: list[dict]) -> None:
        """Collect a chunk's rows and report the progress."""
        nonlocal done
        rows.extend(part)
        done += len(part)
        if progress:
            progress(done, total)

    route, pre, pre_rows = None, {}, []
    if ms is not None and affine:
        from .affine import build_route

        route = build_route(p, base_key, (ms.names, ms0.names), anchors)
    if route is None and anchors is not None:  # designs one by one: more places to start from
        _corner_anchors(p, paths, anchors)
        if len(anchors):
            notes.append(f"Closed loops of a new geometry start from {len(anchors)} fixed motions (the base spec's "
                         f"and the sweep's corner designs'), not from the sequential continuation: each design's "
                         f"numbers depend only on them and on the design, in any chunk or worker; a design whose "
                         f"motion is more than 0.2 rad from all of them, or on another branch, takes the "
                         f"continuation.")
    if route is not None:
        notes.append(f"Mass-only sweep: every design's masses and inertias are affine in the varied values "
                     f"(found and checked on {route.probes} designs built in full); the others were not built "
                     f"one by one but evaluated as matrix products.")  # mass-only: designs as matrix products, no spec built per design
        rows, F = route.rows(p.designs)
        pre = dict(zip(("", "unbalanced_"), route.parameters(F)))
        flagged = set(np.flatnonzero(route.unbuildable(F)).tolist())
        for i in sorted(flagged):  # a design that cannot be built: its own error, as built in full
            rows[i] = evaluate_chunk(p.data, paths, [(i, p.designs[i])], p.stage, base_key, anchors)[0]
        if flagged:
            keep = np.array([i not in flagged for i in range(total)])
            pre = {tag: P[keep] for tag, P in pre.items()}
        pre_rows = [r for r in rows if r["design"] not in flagged]
        if progress:
            progress(total, total)
    elif scheduler:
        from distributed import Client, as_completed

        with Client(scheduler) as client:
            workers = max(1, len(client.scheduler_info()["workers"]))
            chunks = _chunks(p.designs, workers)
            [fdata, fanchors] = client.scatter([p.data, anchors], broadcast=True)
            futures = [client.submit(evaluate_chunk, fdata, paths, c, p.stage, base_key, fanchors, pure=False)
                       for c in chunks]
            for fut in as_completed(futures):
                take(fut.result())
    else:
        workers = jobs or os.cpu_count() or 1
        chunks = _chunks(p.designs, workers)
        if jobs == 0 and len(chunks) > 1:  # all cores only when the work outweighs starting them
            t0 = time.perf_counter()
            part = evaluate_chunk(p.data, paths, chunks[0], p.stage, base_key, anchors)
            take(part)
            per_design = (time.perf_counter() - t0) / len(part)
            chunks = chunks[1:]
            if per_design * (total - done) < POOL_WORTH:
                workers = 1
        if workers == 1 or len(chunks) <= 1:
            for c in chunks:
                take(evaluate_chunk(p.data, paths, c, p.stage, base_key, anchors))
        else:
            from concurrent.futures import ProcessPoolExecutor, as_completed as done_futures

            with ProcessPoolExecutor(max_workers=workers) as pool:
                futs = [pool.submit(evaluate_chunk, p.data, paths, c, p.stage, base_key, anchors) for c in chunks]
                for fut in done_futures(futs):
                    take(fut.result())
    rows.sort(key=lambda r: r["design"])
    for tag, sweep in (("", ms), ("unbalanced_", ms0)):  # the fast path, in blocks of matrix products
        fast = [r for r in rows if tag + "p" in r]
        Pm = np.array([r.pop(tag + "p") for r in fast])
        if tag in pre:  # the affine route's designs: their parameters as one matrix
            fast, Pm = pre_rows + fast, np.concatenate([pre[tag], Pm.reshape(-1, pre[tag].shape[1])])
        if not fast:
            continue
        bad = check_parameters(sweep.names, Pm)
        peaks = sweep.peaks(Pm)
        for k, r in enumerate(fast):
            if bad[k]:
                for key in list(r):
                    if key not in ("design", "values", "route"):
                        r.pop(key)
                r["error"] = bad[k]
            else:
                for key, arr in peaks.items():
                    r[tag + key] = float(arr[k])
    for r in rows:
        if "error" not in r:
            for q in ("force", "moment"):
                ref = r[f"unbalanced_max_shaking_{q}"]
                r[f"{q}_ratio"] = r[f"max_shaking_{q}"] / ref if ref > 0 else 0.0
    res = SweepResult(p, rows, base_name, notes=notes)
    res.fast = sum(r.get("route") == "mass" and "error" not in r for r in rows)
    res.full = sum(r.get("route") == "full" and "error" not in r for r in rows)
    res.failed = sum("error" in r for r in rows)
    mark_pareto(rows)
    if route is not None and not _front_confirmed(p, paths, rows, F, route, base_key, anchors):
        return run(p, jobs, scheduler, progress, affine=False)
    return res


MAX_CORNERS = 16  # corner designs solved up front as anchors (2^k for k varied fields)


def _corner_anchors(p: Plan, paths: list[tuple], anchors) -> None:
    """Add to ``anchors`` the closed-loop motions of the sweep's corner designs (the first and
    last value of every varied field, at most :data:`MAX_CORNERS`), solved here by the
    continuation: every design then starts from the nearest of the base and the corners, which
    covers sweeps that reach far from the base spec. Fixed before any design is evaluated, so
    the numbers do not depend on chunks or workers. A corner that cannot be built or analysed is
    left out (its design reports the error)."""
    from ..engine import analyse, record_anchors

    ends = [(v.values[0], v.values[-1]) if v.values else (v.raw(v.lo), v.raw(v.hi)) for v in p.varies]
    corners = list(dict.fromkeys(itertools.product(*ends)))
    if len(corners) > MAX_CORNERS:
        return
    with record_anchors(into=anchors):
        for values in corners:
            try:
                spec, sr, base = build_design(p.data, paths, values, p.stage)
                t, g, P = _settings(spec)
                for model in (sr.model, base.model):
                    analyse(canonical(model), t, g, P)
            except Exception:  # noqa: BLE001 - the design's own row says why
                continue


def _front_confirmed(p: Plan, paths: list[tuple], rows: list[dict], F: np.ndarray, route, keys: tuple,
                     anchors=None) -> bool:
    """The affine route's designs on a Pareto front (at most 64), built in full, have the
    predicted parameters (to the route's tolerance); else the sweep is run design by design."""
    from .affine import TOL

    front = [r["design"] for r in rows if "error" not in r and (r["pareto_moment"] or r["pareto_effort"])][:64]
    scale = np.maximum(np.abs(F).max(axis=0), 1e-300)
    for i in front:
        full = evaluate_chunk(p.data, paths, [(i, p.designs[i])], p.stage, keys, anchors)[0]
        if "error" in full or "unbalanced_p" not in full:
            return False
        got = np.concatenate([full["p"], full["unbalanced_p"]])
        want = np.concatenate(route.parameters(F[i : i + 1]), axis=1)[0]
        if np.any(np.abs(got - want) > 1e-9 * scale[2 : 2 + got.size]):
            return False
    return True


def progress_printer(quiet: bool) -> Callable[[int, int], None]:
    """A one-line progress bar on stderr (nothing with quiet)."""
    def show(done: int, total: int) -> None:
        if quiet:
            return
        width = 30
        k = int(width * done / max(1, total))
        end = "\n" if done >= total else ""
        print(f"\rsweep [{'#' * k}{'.' * (width - k)}] {done}/{total} designs", end=end, file=sys.stderr, flush=True)
    return show
