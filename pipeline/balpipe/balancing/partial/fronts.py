"""Pareto fronts of a partial balancing, each a sequence of cone programmes (epsilon-constraint:
the mass budget, or a cap on the other load), solved on their active samples
(:class:`.partial_active.ActiveProgram`: a front's points share the samples they need):

* shaking force against added mass, and shaking moment against added mass (budget 0 .. max);
* shaking force against shaking moment, and actuator effort against shaking force, at the spec's
  budget (a cap on the second load from its least to its value at the first load's optimum);

and the least added mass of complete balancing in the same regions along the analysed motion
(the force, and the force and the moment together), where it exists: the loads set to zero as
linear equations (:func:`.least_mass.independent_equations`), the added mass minimised.

:func:`fronts` computes them from plain data (the load maps and the settings) on a programme of
its own, so that a build reads them from its cache when those did not change
(:mod:`balpipe.cache.balance`). Every optimum is the whole programme's to Clarabel's tolerance
(1e-10 of the unbalanced loads, 1e-8 where it stalls); the loads reported are the designs' own,
on every sample.
"""

from __future__ import annotations

import numpy as np

from ..least_mass import independent_equations
from .active import UNBOUNDED, ActiveProgram, relaxed
from .maps import Maps
from .program import ZERO, Term


def point(maps: Maps, z: np.ndarray, terms: dict[str, Term]) -> dict:
    """The loads (SI) and added mass of design z."""
    out = {"added_mass": maps.added_mass(z)}
    out.update({name: t.value(z) for name, t in terms.items()})
    return out


def least_complete_mass(program: ActiveProgram, terms: list[Term]) -> tuple[float, np.ndarray] | None:
    """(least added mass, design) with every load of ``terms`` zero at every sample, or None."""
    maps = program.maps
    A = np.concatenate([L.A.reshape(-1, maps.nz) for t in terms for L in t.maps])
    b = np.concatenate([L.b.reshape(-1) for t in terms for L in t.maps])
    Ar, br, inconsistent = independent_equations(A, -b)
    if inconsistent:
        return None
    out = program.least_mass(Ar, br, polish=[Term(tuple(L for t in terms for L in t.maps), "peak")])
    if out.z is None:
        return None
    worst = max(t.value(out.z) / t.scale for t in terms)
    if worst > 1e-6:  # the equations are met only up to the solver's tolerance: not a complete balance
        return None
    return maps.added_mass(out.z), out.z


def mass_front(program: ActiveProgram, term: Term, masses: np.ndarray, terms: dict[str, Term]) -> list[dict]:
    """min ``term`` for each mass budget; where the optimum leaves part of the budget unused
    (more mass would not lower ``term``: past the complete balance, say), the design of least
    added mass with that optimum (:func:`_least_mass_at`), not an arbitrary one of them."""
    pts = []
    for M in masses:
        out = program.solve([term], float(M), polish=[term])
        if out.z is None:
            continue
        z = out.z
        if program.unused(z, float(M)):
            z = _least_mass_at(program, term, term.value(z) / term.scale, z)
        pts.append({"budget": float(M), **point(program.maps, z, terms), "sensitivity": out.budget_dual * term.scale})
    return pts


def _least_mass_at(program: ActiveProgram, term: Term, value: float, z: np.ndarray) -> np.ndarray:
    """The design of least added mass whose ``term`` is at most ``value`` (in units of its scale;
    a value polished to zero: the least complete balance of ``term``, its equations on every
    sample), or ``z`` if that fails."""
    if value <= ZERO:
        complete = least_complete_mass(program, [term])
        if complete is not None:
            return complete[1]
    return program.lightest([(term, value)], z)


def tradeoff_front(program: ActiveProgram, first: Term, second: Term, budget: float, n: int,
                   terms: dict[str, Term]) -> list[dict]:
    """min ``first`` s.t. ``second`` <= eps at the mass ``budget``, eps from the least ``second``
    to the least ``second`` of the designs where ``first`` is least (the front's two ends: the
    optima by :meth:`ActiveProgram.least_at`, each solved once for both trade-off fronts; the
    second end then by :func:`_least_second`, since several designs may share the least
    ``first`` and only the best of them for ``second`` is on the front). A point whose design
    leaves part of the budget unused is the least added mass with its two values."""
    lo, hi = program.least_at(second, budget), program.least_at(first, budget)
    if lo.z is None or hi.z is None:
        return []
    end = _least_second(program, first, second, budget, first.value(hi.z) / first.scale)
    a, b = second.value(lo.z) / second.scale, second.value(end.z) / second.scale
    pts = []
    for e in np.linspace(a, max(a, b), n):
        out = _capped(program, [first], budget, second, float(e))
        if out.z is None:
            continue
        z = out.z
        if program.unused(z, budget):
            z = program.lightest([(first, first.value(z) / first.scale), (second, second.value(z) / second.scale)], z)
        pts.append({"cap": float(e) * second.scale, **point(program.maps, z, terms)})
    return pts


def _capped(program: ActiveProgram, objective: list[Term], budget: float, capped: Term, bound: float):
    """min ``objective`` s.t. ``capped`` / its scale <= ``bound``: a bound that is the least value
    itself is met only to the solver's tolerance, so it is relaxed in turn (:func:`.partial_active.relaxed`)."""
    return relaxed(lambda slack: program.solve(objective, budget, eps=[(capped, bound * (1 + slack) + slack)],
                                               polish=objective))


def _least_second(program: ActiveProgram, first: Term, second: Term, budget: float, least: float):
    """The design of least ``second`` among those whose ``first`` is ``least`` (its least value,
    in units of its scale), at the mass ``budget``: the trade-off front's end."""
    out = _capped(program, [second], budget, first, least)
    return out if out.z is not None else program.least_at(first, budget)


#: the fronts, slowest first: the order forked workers take them in (results.json lists them the other way round)
FRONTS = ("effort_vs_force", "force_vs_moment", "moment_vs_mass", "force_vs_mass")


def _front(name: str, ctx: tuple) -> list[dict]:
    """One front of :func:`compute` (``ctx``: program, terms, budget, points, mass budgets, the
    programme's samples to start from: every front starts from the same ones, in this process or
    a forked one, so that its numbers do not depend on the fronts solved before it)."""
    program, terms, budget, n, masses, start = ctx
    program.active = dict(start)
    force, moment = terms["shaking_force"], terms["shaking_moment"]
    if name == "force_vs_mass":
        return mass_front(program, force, masses, terms)
    if name == "moment_vs_mass":
        return mass_front(program, moment, masses, terms)
    if name == "force_vs_moment":
        return tradeoff_front(program, force, moment, budget, n, terms)
    return tradeoff_front(program, terms["effort"], force, budget, n, terms)


def compute(program: ActiveProgram, terms: dict[str, Term], budget: float, n: int, max_mass: float | None) -> dict:
    """Every front and the complete balances' least masses (None where infeasible). The fronts
    are independent sequences of solves, each from the same samples: with spare cores
    (:func:`balpipe.runtime.pool.spare`) they run in forked processes, the trade-off fronts' ends solved
    here first (once for both); the numbers are the same bits whatever the cores."""
    from ...runtime import pool

    force, moment = terms["shaking_force"], terms["shaking_moment"]
    complete_f = least_complete_mass(program, [force])
    complete_fm = least_complete_mass(program, [force, moment])
    top = max_mass
    if top is None:
        top = max(budget, 1.25 * complete_f[0]) if complete_f is not None else budget
    masses = np.linspace(program.maps.fixed_mass, max(top, program.maps.fixed_mass), n)
    if complete_f is not None and complete_f[0] <= masses[-1]:  # the front's zero lands on a point
        masses[int(np.argmin(np.abs(masses[1:] - complete_f[0]))) + 1] = complete_f[0]
        masses.sort()
    names = [f for f in FRONTS if f != "effort_vs_force" or "effort" in terms]
    for t in (moment, force, terms.get("effort")):  # the trade-off fronts' ends, solved once for both
        if t is not None:
            program.least_at(t, budget)
    ctx = (program, terms, budget, n, masses, dict(program.active))
    fronts = dict(zip(names, pool.forked([(_front, (f,)) for f in names], pool.spare(), ctx)))
    out = {
        "points": n,
        "max_mass": float(top),
        "budget": float(budget),
        "complete_force": None if complete_f is None else point(program.maps, complete_f[1], terms),
        "complete_force_moment": None if complete_fm is None else point(program.maps, complete_fm[1], terms),
        **{f: fronts[f] for f in reversed(FRONTS) if f in fronts},
    }
    return out


def fronts(maps: Maps, inertia_budget: float | None, terms: dict[str, Term], budget: float, n: int,
           max_mass: float | None) -> dict:
    """:func:`compute` on a new :class:`ActiveProgram` of ``maps`` (the spec's motion's; ``terms``
    may span several motions) with ``inertia_budget``: a function of plain data (the maps, the
    terms' load maps, the numbers), which :func:`balpipe.cache.balance.run` can key."""
    return compute(ActiveProgram(maps, inertia_budget, exact=False), terms, budget, n, max_mass)
