"""Counterweights of least added mass that meet the force-balance conditions (DESIGN.md,
"Least added mass").

A counterweight k on body b adds (mu_k, mu_k x_k, mu_k y_k) to b's parameters (m, mx, my). Its
position is confined to a region of the body's frame:

* a point: mu_k >= 0, position fixed;
* a segment [a, b]: (mu, mu x) = w_a (1, a) + w_b (1, b), w >= 0 (linear);
* a disc (centre c, radius R): |mu x - mu c| <= mu R is a second-order cone; it is replaced by its
  inscribed regular polygon of N sides, (mu, mu x) = sum_i w_i (1, v_i), w_i >= 0, which is
  inside the disc and reaches within R (1 - cos(pi / N)) of its edge (N = 128: 3.0e-4 R).

The conditions C (p0 + G z) = 0 and the total mass sum mu_k are then linear in z >= 0: a linear
programme. With the moment (:mod:`.moment_balance`), the inertia of each generator's mass about
the body origin, w |v|^2, is linear too, and so are the angular-momentum conditions in the
counter-rotating discs' inertias: one linear programme again, solved by scipy.optimize.linprog (HiGHS)
on the independent combinations of the conditions (:func:`independent_equations`). Its solution is polished by a least-squares
correction on the active variables so that the conditions hold to round-off (the balance claim
is 1e-9 of the unbalanced peak, tighter than the solver's feasibility tolerance). When no
z >= 0 meets the conditions, a second programme minimises the sum of |slack| per condition and
the error names the conditions left with slack.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import Model, Vec2
from .conditions import ForceConditions, scale_of
from . import regressor as R
from . import tie_break
from .specs import POLYGON_SIDES


@dataclass(frozen=True)
class Region:
    """Where counterweight ``name`` may sit on ``body`` (body frame): ``kind`` 'point'
    (points = (p,)), 'segment' (points = (a, b)) or 'disc' (points = (centre,), radius)."""

    name: str
    body: str
    kind: str
    points: tuple[Vec2, ...]
    radius: float = 0.0

    def describe(self) -> str:
        if self.kind == "point":
            return f"at ({self.points[0][0]:.4g}, {self.points[0][1]:.4g}) m"
        if self.kind == "segment":
            a, b = self.points
            return f"on the segment ({a[0]:.4g}, {a[1]:.4g})-({b[0]:.4g}, {b[1]:.4g}) m"
        c = self.points[0]
        return f"in the disc of radius {self.radius:.4g} m about ({c[0]:.4g}, {c[1]:.4g}) m"


@dataclass(frozen=True)
class Placed:
    region: Region
    mass: float
    position: Vec2
    inertia: float = 0.0  # centroidal, when the moment is balanced jointly


@dataclass
class Solution:
    counterweights: list[Placed]
    total_mass: float
    polygon_sides: int
    residual: float  # max |C p| / (total mass x model size) after the counterweights
    disc_inertias: list[float] = None  # with the moment: the counter-rotating discs' inertias
    unique: bool = True  # the least-mass design was unique; else the tie-break chose it (tie_break.RULE)

    @property
    def disc_accuracy(self) -> float:
        """Relative radius lost by the polygonal inner approximation of a disc."""
        return 1.0 - math.cos(math.pi / self.polygon_sides)


class Infeasible(ValueError):
    """No counterweights in the allowed regions meet the conditions; ``conditions`` lists the
    equations left unmet with their least residual."""

    def __init__(self, message: str, conditions: list[tuple[str, float]]):
        super().__init__(message)
        self.conditions = conditions


def _generators(region: Region, sides: int) -> np.ndarray:
    """Columns (m, mx, my, J) of each variable of the region: a point mass of weight w_i at each
    generator v_i (the point; a segment's two ends; the polygon's vertices), J = w |v|^2 about
    the body frame's origin. Any w >= 0 gives a mass at a point of the region (their centroid)."""
    if region.kind == "point":
        v = np.array([region.points[0]], float)
    elif region.kind == "segment":
        v = np.array(region.points, float)
    else:
        c = np.asarray(region.points[0], float)
        phi = 2 * math.pi * np.arange(sides) / sides
        v = c + region.radius * np.stack([np.cos(phi), np.sin(phi)], 1)
    return np.column_stack([np.ones(len(v)), v, np.sum(v * v, axis=1)]).T


def solve(model: Model, cond: ForceConditions, regions: list[Region], sides: int = POLYGON_SIDES,
          moment: "MomentConditions | None" = None) -> Solution:
    """The counterweights of least total mass in ``regions`` that balance ``model``'s force and,
    with ``moment``, its moment too, jointly with the inertias of the counter-rotating discs
    named there (>= 0). Force only: each counterweight is a point mass at the centroid of its
    generators. With the moment: a counterweight of that mass and centroid whose centroidal
    inertia is sum w_i |v_i - c|^2 (a part spread over the region, e.g. two masses at a
    segment's ends)."""
    names = cond.names
    p0 = R.parameters(model)
    cols, owner, cost = [], [], []
    for k, reg in enumerate(regions):
        try:
            j0 = names.index(f"m[{reg.body}]")
        except ValueError:
            raise KeyError(f"counterweight {reg.name!r}: model has no body {reg.body!r}") from None
        for col in _generators(reg, sides).T:
            cols.append((j0 // 3, col))
            owner.append(k)
            cost.append(col[0])
    nb = len(names) // 3
    G = np.zeros((3 * nb, len(cols)))
    G4 = np.zeros((4 * nb, len(cols)))
    for i, (b, col) in enumerate(cols):
        G[3 * b : 3 * b + 3, i] = col[:3]
        G4[4 * b : 4 * b + 4, i] = col
    A = cond.matrix @ G
    b = -cond.matrix @ p0
    labels = cond.equations()
    if moment is not None:
        nd = len(moment.discs)
        E = np.zeros((4 * nb, nd))
        for i, d in enumerate(moment.discs):
            E[moment.names.index(f"J[{d}]"), i] = 1.0
        p0a = R.parameters(model, angular=True)
        p0a[E.sum(axis=1) > 0] = 0.0
        A = np.block([[A, np.zeros((A.shape[0], nd))], [moment.matrix @ G4, moment.matrix @ E]])
        b = np.concatenate([b, -moment.matrix @ p0a])
        cost = cost + [0.0] * nd
        labels = labels + moment.equations()
    A_lp, b_lp, inconsistent = independent_equations(A, b)
    if inconsistent:
        raise _infeasible(labels, A, b, regions)
    from scipy.optimize import linprog  # scipy only when a programme is solved (import balpipe.spec stays light)

    res = linprog(np.array(cost), A_eq=A_lp, b_eq=b_lp, bounds=(0, None), method="highs")
    if res.status == 2 or res.x is None:
        raise _infeasible(labels, A, b, regions)
    if res.status != 0:
        raise ValueError(f"least-mass counterweights: the solver stopped: {res.message}")
    D = _design_map(G4, len(cost) - G.shape[1], moment is not None, R.model_size(model))
    z, unique = tie_break.least_norm(A_lp, b_lp, np.array(cost), D, res.x.copy())
    active = z > 1e-12 * max(1.0, float(np.max(z, initial=0.0)))
    for _ in range(3 if active.any() else 0):  # polish: conditions to round-off
        # rcond: directions of the optimal face (singular values at round-off) are not corrections
        dz = np.linalg.lstsq(A_lp[:, active], b_lp - A_lp @ z, rcond=1e-10)[0]
        z[active] += dz
    z = np.maximum(z, 0.0)
    placed = []
    for k, reg in enumerate(regions):
        idx = [i for i, o in enumerate(owner) if o == k]
        bidx = cols[idx[0]][0]
        d = G4[4 * bidx : 4 * bidx + 4, idx] @ z[idx]
        mu = float(d[0])
        pos = (float(d[1] / mu), float(d[2] / mu)) if mu > 0 else tuple(reg.points[0])
        inertia = float(d[3] - mu * (pos[0] ** 2 + pos[1] ** 2)) if moment is not None else 0.0
        if inertia <= 1e-12 * max(float(d[3]), 1e-300):  # a point mass, to round-off
            inertia = 0.0
        placed.append(Placed(reg, mu, pos, inertia))
    p = p0 + G @ z[: G.shape[1]]
    total = float(sum(c.mass for c in placed))
    discs = z[G.shape[1]:] if moment is not None else np.zeros(0)
    return Solution(placed, total, sides, cond.contains(p, scale_of(model)), [float(x) for x in discs], unique)


def tie_note(sol: Solution) -> list[str]:
    """The page's note when the least-mass optimum was not unique (and the rule that chose)."""
    if sol.unique:
        return []
    return [f"The least added mass ({sol.total_mass:.6g} kg) is reached by more than one design: "
            f"balpipe takes, {tie_break.RULE} (a unique choice, symmetric when the mechanism is)."]


def _design_map(G4: np.ndarray, n_discs: int, moment: bool, size: float) -> np.ndarray:
    """Rows (m, mx / L, my / L[, J / L^2]) of the bodies that carry counterweights, as functions
    of the generator weights z (the discs' inertias appended when the moment is balanced): the
    design whose sum of squares :mod:`.tie_break` minimises."""
    w = np.tile(np.array([1.0, 1 / size, 1 / size, 1 / size**2 if moment else 0.0]), G4.shape[0] // 4)
    D = w[:, None] * G4
    D = D[np.any(D != 0, axis=1)]
    if n_discs:
        D = np.block([[D, np.zeros((D.shape[0], n_discs))], [np.zeros((n_discs, G4.shape[1])), np.eye(n_discs) / size**2]])
    return D


EQUATION_TOLERANCE = 1e-9  # relative singular value / right-hand side left outside the kept equations


def independent_equations(A: np.ndarray, b: np.ndarray, tol: float = EQUATION_TOLERANCE
                          ) -> tuple[np.ndarray, np.ndarray, bool]:
    """The equations ``A z = b`` reduced to independent combinations ``U_r^T A z = U_r^T b`` (the
    singular directions of ``A`` above ``tol`` x the largest), and whether ``b`` leaves more than
    ``tol`` x |b| outside them (inconsistent). The force conditions and the angular-momentum
    conditions are each independent, but together, mapped onto the counterweights' variables,
    they repeat one another (a moment condition may be a combination of force ones); each was
    computed from sampled states to about 1e-10, so the repeated rows disagree at that level and
    an LP solver, whose feasibility tolerance is absolute (1e-7), may then call a feasible
    programme infeasible or stop on a point the polish cannot bring to round-off."""
    if A.size == 0:
        return A, b, bool(np.linalg.norm(b) > 0)
    U, sv, _ = np.linalg.svd(A, full_matrices=False)
    r = int(np.sum(sv > tol * sv[0])) if sv.size and sv[0] > 0 else 0
    Ur = U[:, :r]
    nb = float(np.linalg.norm(b))
    outside = float(np.linalg.norm(b - Ur @ (Ur.T @ b)))
    return Ur.T @ A, Ur.T @ b, outside > tol * max(nb, 1e-300) and outside > 0


@dataclass
class MomentConditions:
    """Angular-momentum conditions ``matrix @ p = 0`` over (m, mx, my, J) per body (RREF), with
    the counter-rotating discs whose inertias are unknowns."""

    names: list[str]
    matrix: np.ndarray
    discs: list[str]

    def equations(self) -> list[str]:
        from .conditions import equation

        return [equation(row, self.names) for row in self.matrix]


def _infeasible(labels: list[str], A, b, regions: list[Region]) -> Infeasible:
    """Least sum of |slack| over the conditions: those with slack cannot be met."""
    r, nz = A.shape
    Aeq = np.hstack([A, np.eye(r), -np.eye(r)])
    c = np.concatenate([np.zeros(nz), np.ones(2 * r)])
    from scipy.optimize import linprog  # see above

    res = linprog(c, A_eq=Aeq, b_eq=b, bounds=(0, None), method="highs")
    slack = res.x[nz : nz + r] - res.x[nz + r :] if res.x is not None else b
    scale = max(float(np.max(np.abs(b))), 1e-300)
    bad = [(eq, float(s)) for eq, s in zip(labels, slack) if abs(s) > 1e-9 * scale]
    listing = "; ".join(f"{eq} (left at {s:.4g})" for eq, s in bad) or "(none singled out)"
    where = ", ".join(f"{g.name} on {g.body} {g.describe()}" for g in regions)
    return Infeasible(
        f"no counterweights with positive mass in the allowed regions ({where}) can meet the "
        f"force-balance condition(s): {listing}", bad,
    )
