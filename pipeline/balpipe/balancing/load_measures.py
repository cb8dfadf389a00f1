"""A load over a motion measured as a balancing objective is: its peak or its time RMS, from an
analysis of the engine, named in words. Shared by the methods that aim at loads other than the
shaking force and moment: ``partial_balance`` (its objective and caps) and hand-written ``stages``
(their ``aim``), so that both judge a stage by the same measure.

Definitions (the same as partial balancing's, docs/partial-balancing.md): ``shaking_force`` |F|
and ``shaking_moment`` |M| (inertial: loads do not change them); ``frame_force`` and
``frame_moment``, everything the frame feels (the shaking load plus the external loads);
``effort`` |tau| of one actuator, or the largest of every actuator's measure; ``joint`` the load a
joint carries: |F| of a revolute, |N| of a prismatic pair, |T| of a gear. The RMS is over time
(the trapezoidal rule on the samples), so a cycle's shared end instant counts once.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..engine import Analysis
from ..mechanics.drivers import driver_unit
from ..model import Model
from ..notation import ours
from ..spec_parts import SpecFieldError


def goal_label(term: Any) -> str:
    """'peak effort of crank', 'RMS shaking force', 'peak load of joint O2': a load term in words."""
    what = {"shaking_force": "shaking force", "shaking_moment": "shaking moment", "frame_force": "frame force",
            "frame_moment": "frame moment", "effort": "effort", "joint": "load"}[term.load]
    of = f" of {term.actuator}" if term.actuator else f" of joint {term.joint}" if term.joint else ""
    return f"{'RMS' if term.measure == 'rms' else 'peak'} {what}{of}"


def time_rms(x: np.ndarray, t: np.ndarray) -> float:
    """The root mean square of ``x`` over time: sqrt(integral x^2 dt / duration), trapezoidal."""
    if len(t) < 2 or t[-1] <= t[0]:
        return float(np.sqrt(np.mean(x * x)))
    y = x * x
    return float(np.sqrt(np.sum((y[1:] + y[:-1]) * np.diff(t)) / 2.0 / (t[-1] - t[0])))


def _series(an: Analysis, model: Model, term: Any, path: tuple) -> list[tuple[np.ndarray, str]]:
    """The magnitude series a term measures (several for the efforts of every actuator), with units."""
    if term.load == "shaking_force":
        return [(np.hypot(an.force[:, 0], an.force[:, 1]), "N")]
    if term.load == "shaking_moment":
        return [(np.abs(an.moment), "N m")]
    if term.load in ("frame_force", "frame_moment"):
        F, M = an.frame_load
        return [(np.hypot(F[:, 0], F[:, 1]), "N")] if term.load == "frame_force" else [(np.abs(M), "N m")]
    if term.load == "effort":
        names = [term.actuator] if term.actuator else list(an.efforts)
        unknown = [n for n in names if n not in an.efforts]
        if unknown:
            raise SpecFieldError(path + ("actuator",), f"no actuator {unknown[0]!r} (actuators: {', '.join(an.efforts)})")
        return [(np.abs(an.efforts[n]), driver_unit(model, n)) for n in names]
    r = an.reactions.get(term.joint)
    if r is None:
        raise SpecFieldError(path + ("joint",), f"no joint {term.joint!r} (joints: {', '.join(an.reactions)})")
    if "Fx" in r:
        return [(np.hypot(r["Fx"], r["Fy"]), "N")]
    if "N" in r:
        return [(np.abs(r["N"]), "N")]
    return [(np.abs(r["T"]), "N m")]


def measure(an: Analysis, model: Model, term: Any, path: tuple = ()) -> tuple[float, str]:
    """(value, unit) of ``term`` (a :class:`~balpipe.balancing.specs.LoadTerm`) over the analysis'
    samples: the peak or the time RMS, the largest over the actuators for an effort that names
    none. Raises :class:`SpecFieldError` at ``path`` for an unknown actuator or joint."""
    values = [(float(np.max(x)) if term.measure == "peak" else time_rms(x, an.t), u) for x, u in _series(an, model, term, path)]
    return max(values, key=lambda vu: vu[0])


def term_notation(root: str, terms: list, what: str) -> dict:
    """The inputs table's symbols of the load terms at ``root`` (``balancing.objective``): each
    term's load, measure, actuator, joint, weight and cap, named ``what`` and its number."""
    table = {}
    for k, t in enumerate(terms):
        p, name = f"{root}[{k}]", f"{t.measure} {t.load}" + (f" {t.actuator}" if t.actuator else "") + (f" {t.joint}" if t.joint else "")
        table.update({
            f"{p}.load": ours(f"{what} {k + 1}", f"the load of {what} {k + 1} ({name})"),
            f"{p}.measure": ours(f"{what} {k + 1}", f"peak or RMS over the samples ({name})"),
            f"{p}.actuator": ours(f"{what} {k + 1}", f"the actuator whose effort is meant ({name})"),
            f"{p}.joint": ours(f"{what} {k + 1}", f"the joint whose load is meant ({name})"),
            f"{p}.weight": ours(f"w_{{{k + 1}}}", f"weight of objective term {k + 1} ({name}, divided by its unbalanced value)"),
            f"{p}.at_most": ours(f"c_{{{k + 1}}}", f"cap {k + 1}: {name} at most this"),
            f"{p}.relative": ours(f"c_{{{k + 1}}}", f"cap {k + 1} is a multiple of the unbalanced value"),
        })
    return table
