"""The partial balancing's cone programme written with cvxpy, on every time sample: the reference
that :class:`balpipe.balancing.partial.active.ActiveProgram` (the same programme written for
Clarabel by hand, solved on its active samples) is compared with. cvxpy compiles the constraints
itself (its own canonicalisation of the rotated cone, the norms and the epigraphs), so an error
in the hand-written rows shows as a different optimum.

This was balpipe's own formulation until the fronts moved to the active samples (issue 23); the
constraints are those of :mod:`balpipe.balancing.partial.program`'s docstring.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from balpipe.balancing.partial.maps import Maps
from balpipe.balancing.partial.program import SOLVER_SETTINGS, ZERO, Outcome, Term, polish_zero, variable_scale


class Program:
    """Variables and realisability constraints of ``maps``' parts, the mass budget (a parameter,
    for fronts) and optional inertia budget; problems built on them share the variables."""

    def __init__(self, maps: Maps, inertia_budget: float | None = None):
        import cvxpy as cp

        self.cp = cp
        self.maps = maps
        self.z = cp.multiply(variable_scale(maps), cp.Variable(maps.nz, name="z_scaled"))  # O(1) unknowns
        self.mass_budget = cp.Parameter(nonneg=True, name="mass_budget")
        z = self.z
        cons = []
        self.part_caps = []
        for p in maps.parts:
            m, s, J = z[p.col], z[p.col + 1 : p.col + 3], z[p.col + 3]
            cons.append(m >= 0)
            if p.max_mass is not None:
                c = m <= p.max_mass
                cons.append(c)
                self.part_caps.append((p.name, c, p.max_mass))
            if p.kind == "point":
                v = np.asarray(p.points[0], dtype=float)
                cons += [s == m * v, J == m * float(v @ v)]
                continue
            cons.append(cp.quad_over_lin(s, m) <= J)
            if p.kind == "disc":
                c0 = np.asarray(p.points[0], dtype=float)
                cons += [cp.norm(s - m * c0) <= m * p.radius,
                         J - 2 * (c0 @ s) + m * float(c0 @ c0) <= m * p.radius**2]
            else:
                V = np.asarray(p.points, dtype=float)
                w = cp.Variable(len(V), nonneg=True, name=f"w_{p.name}")
                cons += [cp.sum(w) == m, V.T @ w == s, J <= np.sum(V * V, axis=1) @ w]
        for d in maps.discs:
            cons.append(z[d.col] >= 0)
            if d.max_inertia is not None:
                c = z[d.col] <= d.max_inertia
                cons.append(c)
                self.part_caps.append((d.name, c, d.max_inertia))
        masses = sum((z[p.col] for p in maps.parts), start=0.0) if maps.parts else 0.0
        self.budget = masses + maps.fixed_mass <= self.mass_budget
        cons.append(self.budget)
        self.inertia_budget = None
        if inertia_budget is not None:
            second = [z[p.col + 3] for p in maps.parts] + [z[d.col] for d in maps.discs]
            scale = inertia_budget if inertia_budget > 0 else 1.0  # the solver's tolerance relative to the budget
            self.inertia_budget = sum(second, start=0.0) / scale <= inertia_budget / scale
            cons.append(self.inertia_budget)
        self.base = cons

    def expression(self, term: Term) -> tuple:
        """The term's measure divided by its unbalanced value: (convex expression of z, the
        constraints that define it). A peak is an epigraph variable u with one cone per sample
        (|load_i| <= u); an RMS one cone over all the samples."""
        cp = self.cp
        out, cons = [], []
        for L in term.maps:
            A, b = L.A / term.scale, L.b / term.scale
            comps = [A[:, k, :] @ self.z + b[:, k] for k in range(A.shape[1])]
            if term.kind == "rms":  # the time average: the samples weighted by the trapezoidal rule
                r = np.sqrt(L.weights)
                out.append(cp.norm(cp.hstack([cp.multiply(r, c) for c in comps]), 2))
                continue
            u = cp.Variable()
            if len(comps) == 1:
                cons += [comps[0] <= u, -u <= comps[0]]
            else:
                cons.append(cp.SOC(u * np.ones(A.shape[0]), cp.vstack(comps), axis=0))
            out.append(u)
        return (out[0] if len(out) == 1 else cp.maximum(*out)), cons

    def problem(self, objective: list[Term], caps: list[tuple[Term, float]] = (), eps: list[Term] = ()):
        """min sum w_i term_i s.t. the parts' constraints, the budget, ``caps`` (term <= bound, in
        units of the unbalanced value) and ``eps`` (term <= a parameter, for epsilon-constraint
        fronts). Returns (problem, cap constraints, eps parameters)."""
        cp = self.cp
        cons = list(self.base)
        obj = 0.0
        for t in objective:
            e, c = self.expression(t)
            obj, cons = obj + t.weight * e, cons + c
        cap_cons = []
        for t, bound in caps:
            e, c = self.expression(t)
            cap_cons.append(e <= bound)
            cons += c
        params = [cp.Parameter(nonneg=True) for _ in eps]
        for t, p in zip(eps, params):
            e, c = self.expression(t)
            cons += c + [e <= p]
        return cp.Problem(cp.Minimize(obj), cons + cap_cons), cap_cons, params

    def solve(self, problem, polish: list[Term] = ()) -> Outcome:
        """Solve with cvxpy's own Clarabel interface, on every sample; the terms of ``polish`` below
        :data:`ZERO` of their unbalanced value polished to zero, the design realised, as
        :meth:`balpipe.balancing.partial.active.ActiveProgram.solve` does."""
        cp = self.cp
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", UserWarning)
            problem.solve(solver=cp.CLARABEL, **SOLVER_SETTINGS)
        if problem.status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or self.z.value is None:
            return Outcome(None, problem.status, math.inf, 0.0)
        z = np.asarray(self.z.value, dtype=float).copy()
        for t in polish:
            if t.value(z) <= ZERO * t.scale:
                z = polish_zero(self.maps, t, z)
        dual = self.budget.dual_value
        return Outcome(self.maps.realised(z), problem.status, float(problem.value), -float(dual) if dual is not None else 0.0)
