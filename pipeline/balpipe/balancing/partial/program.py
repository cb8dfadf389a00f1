"""The second-order cone programme of a partial balancing (DESIGN.md, "Partial balancing is a cone
program"): its terms, its variables' units and its answers; :mod:`.partial_active` writes it for
Clarabel (an open-source interior-point conic solver) and solves it on its active samples.

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
by their unbalanced values, so the objective and the caps are dimensionless. The tests write the
same programme with cvxpy (``tests/partial_reference.py``) and compare the optima.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .maps import Load, Maps

#: Clarabel's settings: tolerances of 1e-10 (its defaults 1e-8), "almost solved" at its default
#: tolerances (instead of 5e-5): a flat optimum's design is as sure as its objective to ~sqrt(tol)
#: (at 1e-8 two solver paths gave designs 3e-4 apart, at 1e-10 2e-9). Zeros are polished.
SOLVER_SETTINGS: dict = {"max_iter": 200, "tol_gap_abs": 1e-10, "tol_gap_rel": 1e-10, "tol_feas": 1e-10,
                         "tol_ktratio": 1e-8, "reduced_tol_gap_abs": 1e-8, "reduced_tol_gap_rel": 1e-8,
                         "reduced_tol_feas": 1e-8, "reduced_tol_ktratio": 1e-6}
#: where those stall (a front point at a boundary): Clarabel's own tolerances
FALLBACK_SETTINGS: dict = {"max_iter": 80}
ZERO = 1e-7  # a term whose optimum is below this fraction of its unbalanced value is polished to zero


@dataclass(frozen=True)
class Term:
    """A load measure (``peak`` or ``rms``) of one or several maps (their largest), weighted."""

    maps: tuple[Load, ...]
    kind: str
    weight: float = 1.0
    label: str = ""

    @functools.cached_property
    def scale(self) -> float:
        """The unbalanced mechanism's value (1 when it is zero), computed once (the exchange
        method asks for it at every row and check: 0.17 s of a build of specs/)."""
        v = max(m.unbalanced(self.kind) for m in self.maps)
        return v if v > 0 else 1.0

    def value(self, z: np.ndarray) -> float:
        return float(max(np.max(m.measure(self.kind, z)) for m in self.maps))


@dataclass
class Outcome:
    """A solved programme: the design ``z`` (None when infeasible), the status, the objective
    (dimensionless), the mass budget's dual value (d objective / d budget, per kg, <= 0) and the
    design's relative precision where it was polished on its active set (None: the solver's
    tolerance, about its square root where the optimum is flat)."""

    z: np.ndarray | None
    status: str
    objective: float
    budget_dual: float
    precision: float | None = None


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
