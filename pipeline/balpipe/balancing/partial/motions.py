"""Several motions in one partial balancing (``partial_balance``'s ``motions``): the same machine
at other speeds, or other trajectories, that one design must serve.

At fixed geometry each load is affine in the design variables at every time sample of every
motion (:mod:`.partial_maps`), so the motions only stack their samples: a term over several
motions is the largest of its per-motion measures (a peak is then the peak over every sample of
every motion; an RMS the largest of the motions' RMS, each over its own samples, so a motion's
weight does not depend on how finely it is sampled), divided by that largest measure of the
unbalanced mechanism; a cap holds on every motion. The programme stays a second-order cone
programme (every motion's cones bounded by the term's one epigraph variable,
:meth:`.partial_active.ActiveProgram._term_rows`).

Here: the other motions' models (located errors before any analysis), and the report per motion
(each term and cap, and the peaks, on that motion alone).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence

import numpy as np

from ...model import Model
from ...spec_parts import SpecFieldError
from .maps import Maps
from .program import Term
from .spec import MAIN_MOTION, PartialBalance


def names(method: PartialBalance) -> list[str]:
    """The motions' names: the spec's own (:data:`MAIN_MOTION`) first."""
    return [MAIN_MOTION] + [m.name for m in method.motions]


def other_models(method: PartialBalance, models: Callable | None, root: tuple) -> list[tuple[Model, np.ndarray]]:
    """(unbalanced model, time grid) of each further motion, built by ``models(motion, samples,
    path)`` (:func:`balpipe.registry.motion_model`, which locates their errors)."""
    seen = {MAIN_MOTION}
    for k, m in enumerate(method.motions):
        if m.name in seen:
            raise SpecFieldError(root + ("motions", k, "name"), f"the motion name {m.name!r} is taken "
                                 f"({MAIN_MOTION!r} is the spec's motion; names differ from each other)")
        seen.add(m.name)
    if method.motions and models is None:
        raise SpecFieldError(root + ("motions",), "further motions need the spec's mechanism to rebuild the model")
    return [models(m.motion, m.samples, root + ("motions", k, "motion")) for k, m in enumerate(method.motions)]


def restrict(term: Term, maps: Maps) -> Term:
    """``term`` on one motion only: its loads that belong to ``maps``."""
    own = {id(L) for L in maps.loads.values()}
    return Term(tuple(L for L in term.maps if id(L) in own), term.kind, term.weight, term.label)


def per_motion(motions: Sequence[Maps], labels: list[str], objective: list[Term], caps: list[tuple[Term, float]],
               std: dict[str, Term], z: np.ndarray) -> list[dict]:
    """Per motion: its samples and duration, each objective term (SI value, its unbalanced value
    on that motion, their ratio), each cap's value in units of the cap's unbalanced value (over
    every motion, as the cap is), the weighted objective on that motion alone and the peaks."""
    rows = []
    for name, m in zip(labels, motions):
        terms = [(restrict(t, m), t) for t in objective]
        rows.append({
            "name": name,
            "samples": int(len(m.t)),
            "duration": float(m.t[-1] - m.t[0]),
            "objective": float(sum(t.weight * t.value(z) / t.scale for t, _ in terms)),
            "terms": [{"term": t.label, "value": t.value(z), "unbalanced": t.scale, "ratio": t.value(z) / t.scale}
                      for t, _ in terms],
            "caps": [{"term": t.label, "at_most": b, "value": restrict(t, m).value(z) / t.scale} for t, b in caps],
            "peaks": {k: restrict(v, m).value(z) for k, v in std.items()},
            "unbalanced": {k: restrict(v, m).scale for k, v in std.items()},
        })
    return rows


def notes(rows: list[dict]) -> list[str]:
    """One line per motion for the page when there are several."""
    if len(rows) < 2:
        return []
    return [f"Motion {r['name']} ({r['samples']} samples over {r['duration']:.4g} s): "
            + "; ".join(f"{t['term']} {t['value']:.6g} ({t['ratio']:.4g} x its unbalanced value)" for t in r["terms"])
            + "".join(f"; cap {c['term']} at {c['value']:.4g} (at most {c['at_most']:g})" for c in r["caps"])
            for r in rows]
