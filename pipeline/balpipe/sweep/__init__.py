"""Design sweeps over numeric spec fields (issue 13, item 3): ``balpipe sweep SPEC --vary PATH=RANGE``.

A sweep varies fields of one spec (dotted paths, e.g. ``mechanism.crank.mass``), builds every
design's model and balancing, and analyses the chosen stage (default: the last stage of the
spec's method). Designs whose model has the base spec's geometry (only masses, inertias,
counterweights differ) take the fast path: one engine analysis of the base design and a matrix
product per design (:mod:`balpipe.mass_sweep`); the others a full engine analysis. Designs are
evaluated locally on a process pool, or on a dask.distributed cluster.

Ranges (units as in the spec; the first value's unit applies to a second without one):

* ``LO:HI:N``   N evenly spaced values (grid), e.g. ``mechanism.crank.mass=0.5 kg:2 kg:7``;
* ``a,b,c``     the listed values (grid);
* ``LO:HI``     bounds for ``--sample random`` or ``--sample lhs`` (``-n`` designs, ``--seed``).

Every vary is checked before any work: the path must name a field of the spec's schema, its
values must validate (unit of the right kind, bounds), and the number of designs must stay below
the limit (``--max-designs``, default :data:`MAX_DESIGNS`). A design that fails (invalid spec,
no balancing solution, cannot assemble, negative counterweight) is a row with its error.
"""

from __future__ import annotations

import copy
import itertools
import math
import os
import sys
import time
from dataclasses import dataclass, field
from typing import Any, Callable

import numpy as np
import yaml
from pydantic import ValidationError

from ..sweep_spec import MAX_DESIGNS  # noqa: E402  (one limit for --max-designs and sweep.max_designs)
POOL_WORTH = 3.0  # s: estimated remaining in-process work above which jobs=0 starts a process pool
METRICS = ("added_mass", "added_inertia", "max_shaking_force", "max_shaking_moment", "max_actuator_effort",
           "unbalanced_max_shaking_force", "unbalanced_max_shaking_moment", "force_ratio", "moment_ratio")
UNITS_OF = {"added_mass": "kg", "added_inertia": "kg m^2", "max_shaking_force": "N", "max_shaking_moment": "N m",
            "max_actuator_effort": "N m or N", "unbalanced_max_shaking_force": "N",
            "unbalanced_max_shaking_moment": "N m", "force_ratio": "1", "moment_ratio": "1"}

from ..vary import SweepError, Vary, get_attr_path, parse_vary, set_path, with_values  # noqa: E402,F401  (public here too)
from .evaluate import (  # noqa: E402,F401  (balpipe.sweep.build_design etc., as before)
    _GEOMETRIES, MAX_GEOMETRIES, _error_text, _pick_stage, _settings, _validate, build_design, canonical,
    evaluate_chunk,
)


# ------------------------------------------------------------------------------------------
# Checking the sweep against the spec, before any work


@dataclass
class Plan:
    """A checked sweep: the base spec, the varies and the designs (each a tuple of raw values)."""

    file: str
    text: str
    data: dict
    varies: list[Vary]
    designs: list[tuple]
    stage: str | None = None
    sample: str = "grid"
    seed: int = 0


def _located(loaded, path: tuple, message: str, vary: Vary | None = None) -> str:
    """A problem at the spec field ``path``, named after its vary: ``file:line:col: field:
    message (--vary PATH=RANGE)``, or for a vary of the spec's ``sweep:`` block, at that entry:
    ``file:line:col: sweep.vary.PATH: field: message``."""
    from ..loader import format_path as _format_path, located as locate

    if vary is not None and vary.origin != "--vary":
        key = vary.arg.split("=", 1)[0]
        text = message if tuple(path) == vary.path else f"{_format_path(tuple(path))}: {message}"
        return str(locate(str(loaded.path), loaded.node, ("sweep", "vary", key), text, at_key=True))
    where = str(locate(str(loaded.path), loaded.node, path, message))
    return where + (f" ({vary.where})" if vary else "")


def _vary_problem(loaded, v: Vary, message: str) -> str:
    """A problem of the vary itself (not of the field it names)."""
    if v.origin == "--vary":
        return f"{v.where}: {message}"
    return _located(loaded, v.path, message, v)


def _errors_at(loaded, data: dict, exc: ValidationError, vary: Vary) -> list[str]:
    from ..loader import clean_loc as _clean_loc, error_message as _message

    out = []
    for err in exc.errors():
        loc = _clean_loc(err["loc"], data)
        if err["type"] == "extra_forbidden" and loc == vary.path:
            out.append(_located(loaded, vary.path, "unknown path: not a field of the spec schema", vary))
        else:
            out.append(_located(loaded, loc, _message(err), vary))
    return out


def designs_of(varies: list[Vary], sample: str, n: int, seed: int) -> list[tuple]:
    """The designs: the grid's Cartesian product, or n seeded random / Latin-hypercube points."""
    if sample == "grid":
        return list(itertools.product(*[v.values for v in varies]))
    if n < 1:
        raise SweepError(f"--sample {sample} needs -n N >= 1 designs")
    if sample == "random":
        u = np.random.default_rng(seed).uniform(size=(n, len(varies)))
    elif sample == "lhs":
        from scipy.stats import qmc

        u = qmc.LatinHypercube(d=len(varies), seed=seed).random(n)
    else:
        raise SweepError(f"unknown --sample {sample!r} (grid, random, lhs)")
    out = []
    for row in u:
        vals = []
        for v, x in zip(varies, row):
            if v.values:  # a list: pick one of its values
                vals.append(v.values[min(int(x * len(v.values)), len(v.values) - 1)])
            else:
                vals.append(v.raw(v.lo + x * (v.hi - v.lo)))
        out.append(tuple(vals))
    return out


def plan(spec_file: str, vary_args: list[str] | None = None, sample: str | None = None, n: int | None = None,
         seed: int | None = None, max_designs: int | None = None, stage: str | None = None) -> Plan:
    """Parse and check everything; raises :class:`SweepError` (all problems, located) or the
    loader's ``SpecErrors`` for an invalid base spec. What is not given (None, or no
    ``vary_args``) comes from the spec's ``sweep:`` block (:class:`balpipe.sweep_spec.SweepSpec`),
    else the defaults (grid, seed 0, :data:`MAX_DESIGNS`, the method's last stage)."""
    from ..loader import load

    loaded = load(spec_file)
    data = yaml.safe_load(loaded.text)
    data.pop("sweep", None)  # the designs are specs without the block (validated once, above)
    block = loaded.spec.sweep
    if vary_args:
        varies = [parse_vary(a) for a in vary_args]
    elif block is not None:
        varies = [parse_vary(f"{k}={v}", origin="sweep.vary") for k, v in block.vary.items()]
    else:
        raise SweepError("nothing to vary: give at least one --vary PATH=RANGE, or a sweep: block in the spec")
    limit_from_block = max_designs is None and block is not None
    if block is not None:
        sample = sample if sample is not None else block.sample
        n = n if n is not None else block.designs
        seed = seed if seed is not None else block.seed
        max_designs = max_designs if max_designs is not None else block.max_designs
        stage = stage if stage is not None else block.stage
    sample = sample or "grid"
    n, seed = n or 0, seed or 0
    max_designs = MAX_DESIGNS if max_designs is None else max_designs
    problems: list[str] = []
    seen = set()
    for v in varies:
        if v.path in seen:
            problems.append(_vary_problem(loaded, v, f"{v.name} is varied twice"))
        seen.add(v.path)
        if sample == "grid" and not v.values:
            problems.append(_vary_problem(loaded, v, "a grid needs LO:HI:N or a,b,c (LO:HI is for random and lhs samples)"))
            continue
        for raw in v.extremes():
            trial = copy.deepcopy(data)
            try:
                set_path(trial, v.path, raw)
            except KeyError as exc:
                bad = exc.args[0]
                problems.append(_located(loaded, bad, f"unknown path: {'.'.join(map(str, bad))} is not in the spec", v))
                break
            old = get_attr_path(data, v.path) if _has(data, v.path) else None
            if isinstance(old, (dict, list, bool)):
                problems.append(_located(loaded, v.path, "not a numeric field", v))
                break
            try:
                spec = _validate(trial)
                value = get_attr_path(spec, v.path)
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    problems.append(_located(loaded, v.path, "not a numeric field", v))
                    break
            except ValidationError as exc:
                problems.extend(_errors_at(loaded, trial, exc, v))
                break
            except (AttributeError, KeyError, IndexError, TypeError):
                problems.append(_located(loaded, v.path, "not a numeric field", v))
                break
    if problems:
        raise SweepError("\n".join(dict.fromkeys(problems)))
    size = math.prod(len(v.values) for v in varies) if sample == "grid" else n
    if size > max_designs:
        msg = f"the sweep has {size} designs, above the limit of {max_designs}"
        if limit_from_block:
            from ..loader import located as locate

            at = ("sweep", "max_designs") if "max_designs" in block.model_fields_set else ("sweep",)
            raise SweepError(str(locate(str(loaded.path), loaded.node, at, msg + " (sweep.max_designs)")))
        raise SweepError(msg + " (--max-designs)")
    return Plan(str(loaded.path), loaded.text, data, varies, designs_of(varies, sample, n, seed), stage, sample, seed)


def _has(data: Any, path: tuple) -> bool:
    try:
        get_attr_path(data, path)
        return True
    except (KeyError, IndexError, TypeError, AttributeError):
        return False


# ------------------------------------------------------------------------------------------
# Running


@dataclass
class SweepResult:
    plan: Plan
    rows: list[dict]
    base_stage: str
    fast: int = 0
    full: int = 0
    failed: int = 0
    notes: list[str] = field(default_factory=list)


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
    from .mass import MassSweep, check_parameters
    from ..spec_parts import SpecFieldError

    paths = [v.path for v in p.varies]
    base_spec = _validate(p.data)
    try:
        from .. import registry

        result = registry.balance_designs(base_spec)
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


# ------------------------------------------------------------------------------------------
# Output


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
