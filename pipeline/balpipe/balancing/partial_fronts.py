"""Pareto fronts of a partial balancing, each a sequence of cone programmes on one compiled problem
(epsilon-constraint: the mass budget or a cap on the other load is a cvxpy parameter, so each
point re-solves without re-compiling):

* shaking force against added mass, and shaking moment against added mass (budget 0 .. max);
* shaking force against shaking moment, and actuator effort against shaking force, at the spec's
  budget (a cap on the second load from its least to its value at the first load's optimum);

and the least added mass of complete balancing in the same regions along the analysed motion
(the force, and the force and the moment together), where it exists: the loads set to zero as
linear equations (:func:`.least_mass.independent_equations`), the added mass minimised.

:func:`fronts` computes them from plain data (the load maps and the settings) on a programme of
its own, so that a build reads them from its cache when those did not change
(:mod:`balpipe.balance_cache`).
"""

from __future__ import annotations

import numpy as np

from .least_mass import independent_equations
from .partial_maps import Maps
from .partial_program import Program, Term

UNBOUNDED = 1e9  # kg: the mass budget when a programme should not be limited by it
RELAX = (1e-9, 1e-7, 1e-5)  # relative slack on an epsilon-constraint, tried in turn


def point(maps: Maps, z: np.ndarray, terms: dict[str, Term]) -> dict:
    """The loads (SI) and added mass of design z."""
    out = {"added_mass": maps.added_mass(z)}
    out.update({name: t.value(z) for name, t in terms.items()})
    return out


def least_complete_mass(program: Program, terms: list[Term]) -> tuple[float, np.ndarray] | None:
    """(least added mass, design) with every load of ``terms`` zero at every sample, or None."""
    cp = program.cp
    maps = program.maps
    A = np.concatenate([L.A.reshape(-1, maps.nz) for t in terms for L in t.maps])
    b = np.concatenate([L.b.reshape(-1) for t in terms for L in t.maps])
    Ar, br, inconsistent = independent_equations(A, -b)
    if inconsistent:
        return None
    scale = max(float(np.max(np.abs(Ar))), 1e-300)
    masses = sum((program.z[p.col] for p in maps.parts), start=0.0)
    prob = cp.Problem(cp.Minimize(masses), program.base + [(Ar / scale) @ program.z == br / scale])
    program.mass_budget.value = UNBOUNDED
    out = program.solve(prob, polish=[Term(tuple(L for t in terms for L in t.maps), "peak")])
    if out.z is None:
        return None
    worst = max(t.value(out.z) / t.scale for t in terms)
    if worst > 1e-6:  # the equations are met only up to the solver's tolerance: not a complete balance
        return None
    return maps.added_mass(out.z), out.z


def mass_front(program: Program, term: Term, masses: np.ndarray, terms: dict[str, Term]) -> list[dict]:
    """min ``term`` for each mass budget (:meth:`Program.least`'s problem: a new solver at the
    first budget, its data updated at the others)."""
    prob = program.least(term)
    pts = []
    for k, M in enumerate(masses):
        program.mass_budget.value = float(M)
        out = program.solve(prob, polish=[term], fresh=k == 0)
        if out.z is not None:
            pts.append({"budget": float(M), **point(program.maps, out.z, terms), "sensitivity": out.budget_dual * term.scale})
    return pts


def tradeoff_front(program: Program, first: Term, second: Term, budget: float, n: int,
                   terms: dict[str, Term]) -> list[dict]:
    """min ``first`` s.t. ``second`` <= eps, eps from the least ``second`` to its value where
    ``first`` is least, at the mass ``budget`` (those two optima by :meth:`Program.least_at`: the
    mass fronts' compiled problems, each optimum solved once for both trade-off fronts)."""
    lo, hi = program.least_at(second, budget), program.least_at(first, budget)
    program.mass_budget.value = float(budget)
    if lo.z is None or hi.z is None:
        return []
    a, b = second.value(lo.z) / second.scale, second.value(hi.z) / second.scale
    prob, _, (eps,) = program.problem([first], eps=[second])
    pts = []
    for e in np.linspace(a, max(a, b), n):
        for slack in RELAX:  # the first cap is the least value itself: feasible only to the solver's tolerance
            eps.value = float(e) * (1 + slack) + slack
            out = program.solve(prob, polish=[first])
            if out.z is not None:
                break
        if out.z is not None:
            pts.append({"cap": float(e) * second.scale, **point(program.maps, out.z, terms)})
    return pts


#: the fronts, slowest first: the order forked workers take them in (results.json lists them the other way round)
FRONTS = ("effort_vs_force", "force_vs_moment", "moment_vs_mass", "force_vs_mass")


def _front(name: str, ctx: tuple) -> list[dict]:
    """One front of :func:`compute` (``ctx``: program, terms, budget, points, mass budgets)."""
    program, terms, budget, n, masses = ctx
    force, moment = terms["shaking_force"], terms["shaking_moment"]
    if name == "force_vs_mass":
        return mass_front(program, force, masses, terms)
    if name == "moment_vs_mass":
        return mass_front(program, moment, masses, terms)
    if name == "force_vs_moment":
        return tradeoff_front(program, force, moment, budget, n, terms)
    return tradeoff_front(program, terms["effort"], force, budget, n, terms)


def compute(program: Program, terms: dict[str, Term], budget: float, n: int, max_mass: float | None) -> dict:
    """Every front and the complete balances' least masses (None where infeasible). The fronts
    are independent sequences of solves (each starts on a new solver): with spare cores
    (:func:`balpipe.pool.spare`) they run in forked processes, the trade-off fronts' ends solved
    here first (once for both, as one after another); the numbers are the same bits."""
    from .. import pool

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
    workers = pool.spare()
    if workers > 1:
        for t in (moment, force, terms.get("effort")):
            if t is not None:
                program.least_at(t, budget)
    fronts = dict(zip(names, pool.forked([(_front, (f,)) for f in names], workers, (program, terms, budget, n, masses))))
    out = {
        "points": n,
        "max_mass": float(top),
        "budget": float(budget),
        "complete_force": None if complete_f is None else point(program.maps, complete_f[1], terms),
        "complete_force_moment": None if complete_fm is None else point(program.maps, complete_fm[1], terms),
        **{f: fronts[f] for f in reversed(FRONTS) if f in fronts},
    }
    program.mass_budget.value = float(budget)
    return out


def fronts(maps: Maps, inertia_budget: float | None, terms: dict[str, Term], budget: float, n: int,
           max_mass: float | None) -> dict:
    """:func:`compute` on a new :class:`Program` of ``maps`` (the spec's motion's; ``terms`` may
    span several motions) with ``inertia_budget``: a function of plain data (the maps, the
    terms' load maps, the numbers), which :func:`balpipe.balance_cache.run` can key. Every
    problem of :func:`compute` is a new one on the programme's variables, so a new programme
    gives the numbers of the one the optimum was solved on."""
    return compute(Program(maps, inertia_budget), terms, budget, n, max_mass)
