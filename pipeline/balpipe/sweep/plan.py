"""Checking a sweep against its spec before any work: the varies, their paths and values, the
number of designs, every problem located in the spec file (or at its --vary argument)."""

from __future__ import annotations

import copy
import itertools
import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import yaml
from pydantic import ValidationError

from ..sweep_spec import MAX_DESIGNS
from ..vary import SweepError, Vary, get_attr_path, parse_vary, set_path, vary_count
from .evaluate import _validate


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
    from pathlib import Path

    from ..loader import load
    from ..site_files.spec_files import published_names

    name = published_names([spec_file], [Path(spec_file)])[Path(spec_file)]  # what the outputs show of it
    loaded = load(spec_file)
    data = yaml.safe_load(loaded.text)
    data.pop("sweep", None)  # the designs are specs without the block (validated once, above)
    block = loaded.spec.sweep
    if vary_args:
        args, origin = list(vary_args), "--vary"
    elif block is not None:
        args, origin = [f"{k}={v}" for k, v in block.vary.items()], "sweep.vary"
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
    # the size first, from the counts alone: a grid of 10^9 values is refused before one is made
    early = math.prod(vary_count(a) or 1 for a in args) if sample == "grid" else n
    if early > max_designs:
        _too_many(loaded, block, early, max_designs, limit_from_block)
    varies = [parse_vary(a, origin=origin) for a in args]
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
        _too_many(loaded, block, size, max_designs, limit_from_block)
    return Plan(name, loaded.text, data, varies, designs_of(varies, sample, n, seed), stage, sample, seed)


def _too_many(loaded, block, size: int, max_designs: int, limit_from_block: bool) -> None:
    """Raise the sweep-size error: located at the spec's ``sweep.max_designs`` when that is the
    limit, else naming ``--max-designs``."""
    msg = f"the sweep has {size} designs, above the limit of {max_designs}"
    if limit_from_block:
        from ..loader import located as locate

        at = ("sweep", "max_designs") if "max_designs" in block.model_fields_set else ("sweep",)
        raise SweepError(str(locate(str(loaded.path), loaded.node, at, msg + " (sweep.max_designs)")))
    raise SweepError(msg + " (--max-designs)")


def _has(data: Any, path: tuple) -> bool:
    try:
        get_attr_path(data, path)
        return True
    except (KeyError, IndexError, TypeError, AttributeError):
        return False
