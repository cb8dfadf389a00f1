"""The second-order cone programme of a partial balancing (DESIGN.md, "Partial balancing is a cone
program"), written with cvxpy and solved by Clarabel (an open-source interior-point conic solver).

Realisable parts: a counterweight of mass m >= 0, first moment s = m c and second moment J about
its body's origin is a mass distribution inside its region R exactly when

* s in m R: for a point v, s = m v and J = m |v|^2 (a point mass); for a segment or a convex
  polygon with vertices v_i, s = sum w_i v_i, m = sum w_i, w >= 0, and J <= sum w_i |v_i|^2 (the
  most spread distribution with that centroid puts its mass on the vertices); for a disc (centre
  c0, radius r), |s - m c0| <= m r (a second-order cone) and J - 2 c0 . s + m |c0|^2 <= m r^2
  (all the mass within r of c0);
* J >= |s|^2 / m (a rotated cone: the centroidal inertia J - m |c|^2 is not negative).

A counter-rotating disc's inertia I >= 0. Every load is affine in z (:mod:`.partial_maps`); its
peak over the samples is an epigraph with one cone per sample, its RMS one cone. Terms are divided
by their unbalanced values, so the objective and the caps are dimensionless. cvxpy is imported by
:class:`Program` only (the spec does not load it).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from . import partial_clarabel
from .partial_maps import Load, Maps

SOLVER_SETTINGS: dict = {"max_iter": 80}  # Clarabel's tolerances (1e-8); zeros are polished; a front point at a boundary may stall
ZERO = 1e-7  # a term whose optimum is below this fraction of its unbalanced value is polished to zero


@dataclass(frozen=True)
class Term:
    """A load measure (``peak`` or ``rms``) of one or several maps (their largest), weighted."""

    maps: tuple[Load, ...]
    kind: str
    weight: float = 1.0
    label: str = ""

    @property
    def scale(self) -> float:
        """The unbalanced mechanism's value (1 when it is zero)."""
        v = max(m.unbalanced(self.kind) for m in self.maps)
        return v if v > 0 else 1.0

    def value(self, z: np.ndarray) -> float:
        return float(max(np.max(m.measure(self.kind, z)) for m in self.maps))


@dataclass
class Outcome:
    """A solved programme: the design ``z`` (None when infeasible), the status, the objective
    (dimensionless), the mass budget's dual value (d objective / d budget, per kg, <= 0)."""

    z: np.ndarray | None
    status: str
    objective: float
    budget_dual: float


def variable_scale(maps: Maps) -> np.ndarray:
    """Units of the unknowns, so that the solver's tolerances are relative: per counterweight
    (1, L, L, L^2) with L the farthest point of its region from its body's origin, per disc the
    largest L^2 (kg, kg m, kg m^2)."""
    d = np.ones(maps.nz)
    Ls = [1e-3]
    for p in maps.parts:
        L = max([float(np.hypot(*v)) for v in p.points] + [1e-3]) + p.radius
        d[p.col : p.col + 4] = (1.0, L, L, L * L)
        Ls.append(L)
    for disc in maps.discs:
        d[disc.col] = max(Ls) ** 2
    return d


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
        self._least: dict[int, tuple] = {}  # id(term) -> (term, compiled problem min term)
        self._least_at: dict[tuple, Outcome] = {}  # (id(term), budget) -> its optimum

    def expression(self, term: Term) -> tuple:
        """The term's measure divided by its unbalanced value: (convex expression of z, the
        constraints that define it). A peak is an epigraph variable u with one cone per sample
        (|load_i| <= u); an RMS one cone over all the samples."""
        cp = self.cp
        out, cons = [], []
        for L in term.maps:
            A, b = L.A / term.scale, L.b / term.scale
            comps = [A[:, k, :] @ self.z + b[:, k] for k in range(A.shape[1])]
            if term.kind == "rms":
                out.append(cp.norm(cp.hstack(comps), 2) / math.sqrt(A.shape[0]))
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

    def least(self, term: Term):
        """The problem min ``term`` (the mass budget a parameter), built once per term: the
        fronts solve it at several budgets (:mod:`.partial_fronts`) and cvxpy compiles it once."""
        if id(term) not in self._least:
            self._least[id(term)] = (term, self.problem([term])[0])  # the term kept: its id stays its own
        return self._least[id(term)][1]

    def least_at(self, term: Term, budget: float) -> Outcome:
        """min ``term`` at the mass ``budget`` (polished as :meth:`solve`), by a new solver on
        :meth:`least`'s problem: the same numbers as a problem compiled for it alone; solved once
        per term and budget (two fronts may ask for the same)."""
        key = (id(term), float(budget))
        if key not in self._least_at:
            problem = self.least(term)
            self.mass_budget.value = float(budget)
            self._least_at[key] = self.solve(problem, polish=[term], fresh=True)
        return self._least_at[key]

    def solve(self, problem, polish: list[Term] = (), fresh: bool = False) -> Outcome:
        """Solve; the terms of ``polish`` that come out below :data:`ZERO` of their unbalanced
        value are brought to round-off by a least-squares step on their equations (see
        :func:`polish_zero`). A problem solved again reuses its Clarabel solver (its data
        updated, only ``b`` where nothing else changed: :mod:`.partial_clarabel`; its
        equilibration is the first data's) unless ``fresh``: then a new solver is set up on
        this data, as for a newly compiled problem."""
        cp = self.cp
        if fresh:
            problem._solver_cache = {}
        try:
            with warnings.catch_warnings():  # OPTIMAL_INACCURATE is reported in the status instead
                warnings.simplefilter("ignore", UserWarning)
                problem.solve(solver=partial_clarabel.solver(), **SOLVER_SETTINGS)
        except cp.error.SolverError as exc:
            return Outcome(None, f"solver error: {exc}", math.inf, 0.0)
        status = problem.status
        if status not in (cp.OPTIMAL, cp.OPTIMAL_INACCURATE) or self.z.value is None:
            return Outcome(None, status, math.inf, 0.0)
        z = np.asarray(self.z.value, dtype=float).copy()
        for t in polish:
            if t.value(z) <= ZERO * t.scale:
                z = polish_zero(self.maps, t, z)
        z = self.maps.realised(z)
        dual = self.budget.dual_value
        return Outcome(z, status, float(problem.value), -float(dual) if dual is not None else 0.0)


def polish_zero(maps: Maps, term: Term, z: np.ndarray) -> np.ndarray:
    """The design nearest to ``z`` whose ``term`` is exactly zero (least-squares correction of the
    variables of the parts with mass, on the term's equations A z + b = 0), if that moves the
    design by less than :data:`ZERO` of its size; otherwise ``z`` unchanged. An interior-point
    solver stops at about 1e-9 of the scale; a balance claim is 1e-9 of the unbalanced peak."""
    big = max([abs(z[p.col]) for p in maps.parts] + [1e-300])
    dirs = []  # directions the correction may take: a point part's mass, any other part's (m, s, J), a disc's I
    for p in maps.parts:
        if z[p.col] <= 1e-9 * big:
            continue
        if p.kind == "point":
            v = np.asarray(p.points[0], dtype=float)
            d = np.zeros(maps.nz)
            d[p.col : p.col + 4] = (1.0, v[0], v[1], float(v @ v))
            dirs.append(d)
        else:
            dirs += [np.eye(maps.nz)[p.col + j] for j in range(4)]
    dirs += [np.eye(maps.nz)[d.col] for d in maps.discs if z[d.col] > 0]
    if not dirs:
        return z
    B = np.array(dirs).T
    A = np.concatenate([L.A.reshape(-1, maps.nz) for L in term.maps])
    b = np.concatenate([L.b.reshape(-1) for L in term.maps])
    out = z.copy()
    for _ in range(2):
        out = out + B @ np.linalg.lstsq(A @ B, -(A @ out + b), rcond=None)[0]
    if np.linalg.norm(out - z) > ZERO * max(np.linalg.norm(z), 1e-300):
        return z
    return out
