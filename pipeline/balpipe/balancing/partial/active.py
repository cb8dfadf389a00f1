"""The cone programme of a partial balancing (:mod:`.partial_program`) handed to Clarabel directly
and solved on its active samples: the optimum (:mod:`.partial`) and the fronts' hundreds of
programmes (:mod:`.partial_fronts`).

A peak term has one cone per time sample (|load_n(z)| <= u), yet at an optimum only a few samples
touch the peak. The programme here keeps, per load map, a set of samples; it solves on them, checks
the design on every sample, adds the samples that exceed the bound and solves again, until none does
(an exchange method: each programme is a relaxation of the whole one, so its optimum that every
sample meets is the whole programme's optimum; the check's tolerance, :data:`CHECK`, is ten times
the solver's). The sets carry over from one solve to the next, so a front's later points start
from the samples its earlier points needed.

The realisability constraints, the budgets and the terms are those of :mod:`.partial_program`'s
docstring, written as Clarabel's ``A x + s = b, s in K``; the rotated cone
J m >= |s|^2 is the cone ``(J + m, J - m, 2 s)``. Clarabel's data are built here, without cvxpy's
compilation (65 ms a programme, most of a small programme's cost); the tests compare the optima
with the same programme written with cvxpy on every sample (``tests/partial_reference.py``).
Measured on the five partial specs (``benchmarks/bench_fronts.py``): their fronts take 2.1 s of
CPU on active samples, 18 s on every sample (22.5 s through cvxpy before), the minimised values
the same to 1e-6.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from .maps import Maps
from .polish import polish
from .program import FALLBACK_SETTINGS, SOLVER_SETTINGS, ZERO, Outcome, Term, polish_zero, variable_scale

UNBOUNDED = 1e9  # kg: the mass budget when a programme should not be limited by it
RELAX = (1e-9, 1e-7, 1e-5)  # relative slack on a bound that is an optimum itself, tried in turn
UNUSED = 1e-6  # a budget that a design leaves this fraction (of the budget, or of 1 kg) unused
#: a sample is missing from a programme when its load exceeds the bound by this fraction of the
#: term's unbalanced value: ten times Clarabel's tolerance, below which its answers do not separate
CHECK = 1e-9
#: the samples added per load map and round: the largest local maxima among those that exceed
ADD = 8
#: the samples a load map starts with: the largest local maxima of the mechanism without parts
START = 8
STATUS = {"Solved": "optimal", "AlmostSolved": "optimal_inaccurate", "PrimalInfeasible": "infeasible",
          "AlmostPrimalInfeasible": "infeasible_inaccurate", "DualInfeasible": "unbounded",
          "AlmostDualInfeasible": "unbounded_inaccurate", "MaxIterations": "user_limit", "MaxTime": "user_limit"}
ANSWERED = ("optimal", "optimal_inaccurate")
#: no answer and no proof of infeasibility: tried again at Clarabel's own tolerances
STALLED = ("user_limit", "solver_error")


@dataclass
class Rows:
    """Constraint rows in Clarabel's form ``A x + s = b``, ``s`` in the cones, in order (the blocks
    of rows and the cones need not correspond one to one: only their concatenations must)."""

    n: int
    A: list[np.ndarray] = field(default_factory=list)
    b: list[np.ndarray] = field(default_factory=list)
    cones: list[tuple[str, int]] = field(default_factory=list)

    def add(self, kind: str, G: np.ndarray, h) -> int:
        """``G x + h`` in the cone ``kind`` ('zero', 'nonneg' or 'soc', over all its rows); returns
        the index of its first row."""
        G = np.atleast_2d(G)
        first = self.size
        self.A.append(-G)
        self.b.append(np.atleast_1d(np.asarray(h, dtype=float)))
        self.cones.append((kind, G.shape[0]))
        return first

    def add_cones(self, G: np.ndarray, h: np.ndarray) -> None:
        """``G[i] x + h[i]`` in a second-order cone for every i (G (m, d, n), h (m, d))."""
        self.A.append(-G.reshape(-1, G.shape[2]))
        self.b.append(h.reshape(-1))
        self.cones += [("soc", G.shape[1])] * G.shape[0]

    @property
    def size(self) -> int:
        return sum(c[1] for c in self.cones)


def _local_maxima(v: np.ndarray) -> np.ndarray:
    """Indices of the samples at least as large as their neighbours, largest first."""
    left = np.r_[True, v[1:] >= v[:-1]]
    right = np.r_[v[:-1] >= v[1:], True]
    idx = np.flatnonzero(left & right)
    return idx[np.argsort(-v[idx], kind="stable")]


class ActiveProgram:
    """The partial balancing's programme on ``maps`` (the parts' variables, realisability, mass
    budget, optional inertia budget) for terms whose peaks are checked on every sample."""

    def __init__(self, maps: Maps, inertia_budget: float | None = None, exact: bool = True):
        """``exact``: polish every answer on its active set (:mod:`.polish`); the fronts' hundreds
        of programmes, drawn and not built, keep the solver's answers (a third of the cost)."""
        self.maps = maps
        self.inertia_budget = inertia_budget
        self.exact = exact
        self.D = variable_scale(maps)
        nz = maps.nz
        self.nw = [len(p.points) if p.kind not in ("point", "disc") else 0 for p in maps.parts]
        self.n = nz + sum(self.nw)
        self.active: dict[tuple[int, int], np.ndarray] = {}  # (id(term), map index) -> its samples
        self._terms: dict[int, Term] = {}  # keeps the terms (their ids key the sets) alive
        self._least_at: dict[tuple, Outcome] = {}  # (id(term), budget) -> its optimum
        self.base, self.budget_row = self._base()

    def _z(self, col: int, coef: float = 1.0) -> np.ndarray:
        """A row picking ``coef`` z[col] (z = D x)."""
        r = np.zeros(self.n)
        r[col] = coef * self.D[col]
        return r

    def _base(self) -> tuple[Rows, int]:
        """Realisability of every part, the discs' bounds, the budgets (the mass budget's right-hand
        side set at each solve)."""
        maps, z = self.maps, self._z
        rows = Rows(self.n)
        w0 = maps.nz
        for p, nw in zip(maps.parts, self.nw):
            m, sx, sy, J = (p.col + k for k in range(4))
            rows.add("nonneg", z(m), 0.0)
            if p.max_mass is not None:
                rows.add("nonneg", -z(m), p.max_mass)
            if p.kind == "point":
                v = np.asarray(p.points[0], dtype=float)
                rows.add("zero", np.array([z(sx) - z(m, v[0]), z(sy) - z(m, v[1]), z(J) - z(m, float(v @ v))]), np.zeros(3))
                continue
            rows.add("soc", np.array([z(J) + z(m), z(J) - z(m), z(sx, 2.0), z(sy, 2.0)]), np.zeros(4))
            if p.kind == "disc":
                c0, r = np.asarray(p.points[0], dtype=float), p.radius
                rows.add("soc", np.array([z(m, r), z(sx) - z(m, c0[0]), z(sy) - z(m, c0[1])]), np.zeros(3))
                rows.add("nonneg", z(m, r * r - float(c0 @ c0)) - z(J) + z(sx, 2 * c0[0]) + z(sy, 2 * c0[1]), 0.0)
            else:
                V = np.asarray(p.points, dtype=float)
                W = np.zeros((nw, self.n))
                W[:, w0 : w0 + nw] = np.eye(nw)
                rows.add("nonneg", W, np.zeros(nw))
                rows.add("zero", np.array([W.sum(axis=0) - z(m), V[:, 0] @ W - z(sx), V[:, 1] @ W - z(sy)]), np.zeros(3))
                rows.add("nonneg", np.sum(V * V, axis=1) @ W - z(J), 0.0)
                w0 += nw
        for d in maps.discs:
            rows.add("nonneg", z(d.col), 0.0)
            if d.max_inertia is not None:
                rows.add("nonneg", -z(d.col), d.max_inertia)
        budget = rows.add("nonneg", -sum((z(p.col) for p in maps.parts), start=np.zeros(self.n)), 0.0)
        if self.inertia_budget is not None:
            B = self.inertia_budget
            scale = B if B > 0 else 1.0
            second = sum((z(p.col + 3) for p in maps.parts), start=np.zeros(self.n)) + sum(
                (z(d.col) for d in maps.discs), start=np.zeros(self.n))
            rows.add("nonneg", -second / scale, B / scale)
        return rows, budget

    def _samples(self, term: Term, k: int) -> np.ndarray:
        key = (id(term), k)
        if key not in self.active:
            self._terms[id(term)] = term
            L = term.maps[k]
            start = [_local_maxima(L.samples(np.zeros(self.maps.nz)))[:START]]
            if np.any(L.b0 != L.b):
                start.append(_local_maxima(np.sqrt(np.sum(L.b0 * L.b0, axis=-1)))[:START])
            self.active[key] = np.unique(np.concatenate(start))
        return self.active[key]

    def _term_rows(self, term: Term, col: int, rows: Rows) -> None:
        """Adds to ``rows`` ``term`` / its scale <= x[col], on the samples of each of its maps (a
        peak), or on all of them (an RMS: one cone)."""
        nz = self.maps.nz
        for k, L in enumerate(term.maps):
            S = self._samples(term, k) if term.kind == "peak" else np.arange(L.A.shape[0])
            A = L.A[S] * (self.D / term.scale)  # (n, comps, nz) in x
            b = L.b[S] / term.scale
            if term.kind == "peak":
                G = np.zeros((len(S), A.shape[1] + 1, rows.n))
                G[:, 0, col] = 1.0
                G[:, 1:, :nz] = A
                rows.add_cones(G, np.concatenate([np.zeros((len(S), 1)), b], axis=1))
            else:  # the time average: each sample's components times the root of its weight
                r = np.sqrt(L.weights)
                G = np.zeros((A.shape[0] * A.shape[1] + 1, rows.n))
                G[0, col] = 1.0
                G[1:, :nz] = (A * r[:, None, None]).reshape(-1, nz)
                rows.add("soc", G, np.r_[0.0, (b * r[:, None]).reshape(-1)])

    def _missing(self, term: Term, bound: float, z: np.ndarray) -> bool:
        """Adds to ``term``'s sets the samples that exceed ``bound`` (in units of its scale) at ``z``;
        True when there were any."""
        if term.kind != "peak":
            return False
        added = False
        for k, L in enumerate(term.maps):
            v = L.samples(z) / term.scale
            over = v > bound + CHECK
            if not over.any():
                continue
            S = self._samples(term, k)
            fresh = over.copy()
            fresh[S] = False
            new = [i for i in _local_maxima(np.where(fresh, v, -np.inf)) if fresh[i]][:ADD]
            if new:
                self.active[(id(term), k)] = np.union1d(S, new)
                added = True
        return added

    def solve(self, objective: list[Term], mass_budget: float, eps: list[tuple[Term, float]] = (),
              polish: list[Term] = ()) -> Outcome:
        """min sum w_i term_i / scale_i s.t. the base constraints, added mass <= ``mass_budget`` and
        each ``eps`` term / its scale <= its bound; the terms of ``polish`` that come out below
        :data:`ZERO` of their unbalanced value are brought to round-off
        (:func:`.partial_program.polish_zero`), the design realised (:meth:`.partial_maps.Maps.realised`)."""
        return self._solve(list(objective), list(eps), mass_budget, None, polish)

    def least_at(self, term: Term, budget: float) -> Outcome:
        """min ``term`` at the mass ``budget`` (polished), solved once per term and budget: the two
        trade-off fronts share their ends, and forked workers inherit them."""
        key = (id(term), float(budget))
        if key not in self._least_at:
            self._terms[id(term)] = term
            self._least_at[key] = self.solve([term], budget, polish=[term])
        return self._least_at[key]

    def least_mass(self, A: np.ndarray | None = None, b: np.ndarray | None = None,
                   caps: list[tuple[Term, float]] = (), polish: list[Term] = ()) -> Outcome:
        """The least added mass (no mass budget) with ``A z = b`` and each term of ``caps`` / its
        scale <= its bound, polished as :meth:`solve`."""
        equations = None
        if A is not None:
            scale = max(float(np.max(np.abs(A))), 1e-300)
            equations = (A / scale, b / scale)
        return self._solve([], list(caps), UNBOUNDED, equations, polish)

    def unused(self, z: np.ndarray, budget: float) -> bool:
        """Whether design ``z`` leaves part of the mass ``budget`` unused (by :data:`UNUSED`): more
        mass would not improve its optimum, and other optimal designs are lighter."""
        return self.maps.added_mass(z) < budget - UNUSED * max(budget, 1.0)

    def lightest(self, kept: list[tuple[Term, float]], z: np.ndarray, caps: list[tuple[Term, float]] = ()) -> np.ndarray:
        """The design of least added mass whose terms are at most their values in ``kept`` (units
        of their scales; relaxed by :data:`RELAX` in turn, as a bound that is an optimum itself is
        met only to the solver's tolerance) and that meets ``caps`` as they are, or ``z`` if none
        is found."""
        out = relaxed(lambda slack: self.least_mass(
            caps=[(t, v * (1 + slack) + slack) for t, v in kept] + list(caps), polish=[kept[0][0]]))
        return out.z if out.z is not None else z

    def lightest_alike(self, term: Term, z: np.ndarray, caps: list[tuple[Term, float]] = ()) -> Outcome:
        """The design of least added mass whose load of ``term`` equals design ``z``'s at every
        sample, meeting ``caps`` (its ``z`` None if none is found). An RMS of one load is a Euclidean norm
        of its samples, strictly convex in them: its optimal designs are exactly those with the
        optimum's load at every sample (linear equations), so the lightest optimal design is exact,
        where :meth:`lightest`'s bound relaxed by eps would move it by about sqrt(eps)."""
        nz = self.maps.nz
        A = np.concatenate([L.A.reshape(-1, nz) for L in term.maps])
        _, S, Vt = np.linalg.svd(A, full_matrices=False)
        if not S.size or S[0] <= 0:  # no part changes the load: every design is optimal
            return self.least_mass(caps=list(caps), polish=[term])
        E = Vt[S > 1e-12 * S[0]]  # the row space of the load's map: the same equations, independent
        return self.least_mass(E, E @ z, caps=list(caps), polish=[term])

    def _solve(self, objective: list[Term], eps: list[tuple[Term, float]], mass_budget: float,
               equations: tuple[np.ndarray, np.ndarray] | None, polish) -> Outcome:
        """The optimum by the exchange loop (without ``objective``, the least added mass)."""
        n = self.n + len(objective) + len(eps)  # one epigraph variable per term
        q = np.zeros(n)
        q[self.n : self.n + len(objective)] = [t.weight for t in objective]
        if not objective:
            for p in self.maps.parts:
                q[p.col] = self.D[p.col]
        rows = Rows(n, [_widened(G, n) for G in self.base.A], list(self.base.b),
                    list(self.base.cones))
        if equations is not None:
            G = np.zeros((equations[0].shape[0], n))
            G[:, : self.maps.nz] = equations[0] * self.D
            rows.add("zero", G, -equations[1])
        for j, (_, bound) in enumerate(eps):
            rows.add("nonneg", -np.eye(n)[self.n + len(objective) + j], bound)
        terms = objective + [e[0] for e in eps]
        res, data, cones = self._exchange(q, rows, terms, eps, mass_budget)
        status = STATUS.get(str(res.status), "solver_error")
        if status not in ANSWERED:
            return Outcome(None, status, math.inf, 0.0)
        x, precision = self._polished(res, data, cones, terms, eps)
        z = self.D * x[: self.maps.nz]
        for t in polish:
            if t.value(z) <= ZERO * t.scale:
                z = polish_zero(self.maps, t, z)
        return Outcome(self.maps.realised(z), status, float(q @ x), -float(res.z[self.budget_row]), precision)

    def _polished(self, res, data, cones: list[tuple[str, int]], terms: list[Term],
                  eps: list[tuple[Term, float]]) -> tuple[np.ndarray, float | None]:
        """Clarabel's answer polished on its active set (:func:`.polish.polish`: the design exact
        to round-off, not to the solver's tolerance, where the objective is smooth at the optimum)
        and its relative error, if the polished design meets every term's bound on every sample and
        is no worse; else Clarabel's answer and None."""
        x = np.asarray(res.x, dtype=float)
        if not self.exact:
            return x, None
        _, q, A, b, _ = data
        out = polish(q, A, b, cones, x, np.asarray(res.s, dtype=float), np.asarray(res.z, dtype=float))
        if out is None or q @ out[0] > q @ x + 1e-9 * max(1.0, abs(float(q @ x))):
            return x, None
        z = self.D * out[0][: self.maps.nz]
        objective = len(terms) - len(eps)
        bounds = [(t, out[0][self.n + j]) for j, t in enumerate(terms[:objective])] + list(eps)
        if any(t.value(z) / t.scale > bound + CHECK for t, bound in bounds):
            return x, None
        return out

    def _exchange(self, q: np.ndarray, rows: Rows, terms: list[Term], eps: list[tuple[Term, float]],
                  mass_budget: float):
        """Clarabel's answer to min q' x on ``rows`` and the terms' cones on their
        samples, the samples grown until every sample meets its bound (the terms of ``eps`` their
        caps, the others their epigraph variables), or its answer without a solution; with the
        programme's data and its cones (unmerged)."""
        import clarabel
        import scipy.sparse as sp

        n = rows.n
        objective = len(terms) - len(eps)
        while True:
            full = Rows(n, list(rows.A), list(rows.b), list(rows.cones))
            for j, t in enumerate(terms):
                self._term_rows(t, self.n + j, full)
            b = np.concatenate(full.b)
            b[self.budget_row] = mass_budget - self.maps.fixed_mass
            data = (sp.csc_matrix((n, n)), q, sp.csc_matrix(np.vstack(full.A)), b, _cones(full.cones))
            res = clarabel.DefaultSolver(*data, _settings(SOLVER_SETTINGS)).solve()
            if STATUS.get(str(res.status), "solver_error") in STALLED:
                res = clarabel.DefaultSolver(*data, _settings(FALLBACK_SETTINGS)).solve()
            if STATUS.get(str(res.status)) not in ANSWERED:
                return res, data, full.cones
            x = np.asarray(res.x)
            z = self.D * x[: self.maps.nz]
            bounds = [(t, x[self.n + j]) for j, t in enumerate(terms[:objective])] + eps
            if not any([self._missing(t, bound, z) for t, bound in bounds]):
                return res, data, full.cones


def _widened(G: np.ndarray, n: int) -> np.ndarray:
    """``G`` (m, k) with n - k zero columns appended (``np.pad``'s result, without its 50 us of
    argument handling: some 13000 calls in a build of specs/)."""
    out = np.zeros((G.shape[0], n))
    out[:, : G.shape[1]] = G
    return out


def relaxed(attempt) -> Outcome:
    """``attempt(slack)`` for each slack of :data:`RELAX` until one gives a design: the first that
    does, else the last answer."""
    for slack in RELAX:
        out = attempt(slack)
        if out.z is not None:
            break
    return out


def _settings(values: dict):
    """Clarabel's settings with ``values``, quiet."""
    import clarabel

    settings = clarabel.DefaultSettings()
    settings.verbose = False
    for key, value in values.items():
        setattr(settings, key, value)
    return settings


def _cones(cones: list[tuple[str, int]]) -> list:
    """Clarabel's cone objects, consecutive zero and nonnegative blocks merged."""
    import clarabel

    out: list = []
    for kind, size in cones:
        if out and kind != "soc" and out[-1][0] == kind:
            out[-1] = (kind, out[-1][1] + size)
        else:
            out.append((kind, size))
    make = {"zero": clarabel.ZeroConeT, "nonneg": clarabel.NonnegativeConeT, "soc": clarabel.SecondOrderConeT}
    return [make[k](s) for k, s in out]
