"""Force-balance conditions of any model: the row space of its linear-momentum regressor
(paper 001, eqs. 12-17: the conditions are the coefficients of the independent velocity terms of
the linear momentum, which the null space of the sampled regressor gives without the loop
algebra).

A design p (per body m, mx, my; see :mod:`.regressor`) is force balanced for every motion when
Y_P p = 0 at every feasible state; the rows of Y_P span a space of dimension r (the number of
independent conditions), and any basis C of it gives the conditions C p = 0. The basis shown is
the reduced row echelon form of C with the first moments (mx, my) ordered before the masses, so
that each condition reads "first moment of a body = a combination of masses", like eq. 15 of
paper 000 and eq. 17 of paper 001; coefficients are printed as integers or small fractions when
they are so to 1e-9.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from fractions import Fraction

import numpy as np

from ..display import numbers
from ..model import Model
from . import regressor as R
from .specs import RANK_TOLERANCE


@dataclass
class ForceConditions:
    """Independent force-balance conditions ``matrix @ p = 0`` (rows in RREF, pivot 1).

    ``names``: parameter names (columns); ``pivots``: the pivot column of each row;
    ``singular``: singular values of the scaled regressor; ``gap``: last kept / first dropped."""

    names: list[str]
    matrix: np.ndarray
    pivots: list[int]
    singular: np.ndarray
    tolerance: float
    gap: float
    samples: int
    dof: int

    @property
    def count(self) -> int:
        return len(self.pivots)

    def residuals(self, p: np.ndarray) -> np.ndarray:
        """C p: how far a design is from each condition (unit of the pivot parameter)."""
        return self.matrix @ p

    def unit(self, k: int) -> str:
        return "kg" if self.names[self.pivots[k]].startswith("m[") else "kg m"

    def equations(self) -> list[str]:
        return [equation(row, self.names) for row in self.matrix]

    def contains(self, p: np.ndarray, scale: float = 1.0) -> float:
        """Largest |C p| relative to ``scale`` (e.g. the design's largest first moment)."""
        return float(np.max(np.abs(self.residuals(p)))) / scale if self.count else 0.0

    def to_json(self, p: np.ndarray) -> dict:
        """The conditions for results.json: each with its residual for design ``p`` and its
        ``scale`` (same unit): the size of its terms (sum of |coefficient x parameter|) or the
        design's largest parameter of its unit (mass or first moment), whichever is larger; a
        residual at most 1e-9 of it is round-off."""
        res = self.residuals(p)
        mass = np.array([n.startswith("m[") for n in self.names])
        largest = {u: float(np.max(np.abs(p[sel]), initial=0.0)) for u, sel in (("kg", mass), ("kg m", ~mass))}
        scales = [max(float(t), largest[self.unit(k)])
                  for k, t in enumerate(np.abs(self.matrix) @ np.abs(p))]
        return {
            "count": self.count,
            "rank_tolerance": self.tolerance,
            "singular_value_gap": self.gap,
            "singular_values": [float(s) for s in self.singular],
            "samples": self.samples,
            "mobility": self.dof,
            "parameters": self.names,
            "conditions": [
                {"equation": eq, "residual": float(r), "scale": float(sc), "unit": self.unit(k),
                 "coefficients": {self.names[j]: float(v) for j, v in enumerate(row)
                                  if abs(v) > 1e-10 * float(np.max(np.abs(row)))}}
                for k, (eq, r, sc, row) in enumerate(zip(self.equations(), res, scales, self.matrix))
            ],
        }


def column_scale(model: Model, angular: bool = False) -> np.ndarray:
    """Scale of each column so that all parameters have one unit: masses times the model size."""
    L = R.model_size(model)
    per = [L, 1.0, 1.0] + ([1.0 / L] if angular else [])
    return np.tile(per, len(model.bodies))


def find(model: Model, t: np.ndarray, tolerance: float = RANK_TOLERANCE, samples: int = 0,
         seed: int = 0, states: R.States | None = None) -> ForceConditions:
    """The force-balance conditions of ``model`` sampled around its motion on the grid ``t``."""
    st = states if states is not None else R.sample_states(model, t, samples, seed)
    Y = R.linear_regressor(st)
    rs = R.row_space(Y, column_scale(model), tolerance)
    names = R.param_names(model)
    matrix, pivots = rref(rs.basis, _pivot_order(names), pivot_tolerance(rs.gap))
    return ForceConditions(names, matrix, pivots, rs.singular, tolerance, rs.gap, st.count, st.dof)


def _pivot_order(names: list[str]) -> list[int]:
    """First moments first (body order), then masses."""
    first = [k for k, n in enumerate(names) if not n.startswith("m[")]
    return first + [k for k, n in enumerate(names) if n.startswith("m[")]


def clarity_text(gap: float) -> str:
    """How clearly numerically found conditions stand out from round-off, in words: the
    singular-value gap (last kept / first dropped) as 'clear of round-off by a factor over 10¹⁴'
    (larger is clearer), or 'no direction near round-off' when nothing was dropped."""
    if not math.isfinite(gap):
        return "no direction near round-off"
    if gap < 10:
        return f"clear of round-off by a factor {numbers.num(gap, 3)}"
    return f"clear of round-off by a factor over {numbers.beyond(gap)}"


def pivot_tolerance(gap: float) -> float:
    """The smallest pivot (relative to the remaining rows' largest entry) that :func:`rref` may
    divide by for a row space whose singular-value gap is ``gap``: the basis from the sampled
    regressor is accurate to about 1 / gap, so an entry below 100 / gap may be noise, and
    pivoting on it turns the row into noise times 1/pivot (seen: a 1e-10 pivot on mx[platform]
    of a random idler loop's angular momentum, coefficients of 1e12, and a least-mass programme
    that was then called infeasible). At least 1e-10, at most 1e-6."""
    if not math.isfinite(gap) or gap <= 0:
        return 1e-10
    return min(1e-6, max(1e-10, 100.0 / gap))


def rref(A: np.ndarray, order: list[int], tol: float = 1e-10) -> tuple[np.ndarray, list[int]]:
    """Reduced row echelon form of the full-row-rank ``A`` with pivots searched in the column
    ``order``. The entries are kept as computed (the conditions are used to round-off); only
    :func:`equation` rounds them for reading."""
    M = A.copy()
    rows = M.shape[0]
    pivots: list[int] = []
    r = 0
    for col in order:
        if r == rows:
            break
        k = r + int(np.argmax(np.abs(M[r:, col])))
        if abs(M[k, col]) <= tol * np.max(np.abs(M[r:])):
            continue
        M[[r, k]] = M[[k, r]]
        M[r] /= M[r, col]
        for i in range(rows):
            if i != r:
                M[i] -= M[i, col] * M[r]
        pivots.append(col)
        r += 1
    return M[: len(pivots)], pivots


def _snap(x: float) -> float:
    """x, or the nearby simple fraction (denominator <= 64) when within 1e-9 relative."""
    f = Fraction(x).limit_denominator(64)
    return float(f) if abs(float(f) - x) <= 1e-9 * max(1.0, abs(x)) else float(x)


def fmt_coefficient(x: float) -> str:
    """A short decimal (up to 4 significant digits: 0.08, 1.5) when exact, else a fraction with a
    small denominator (4/11) when exact, else 6 significant digits."""
    short = f"{x:.4g}"
    if float(short) == x and "e" not in short:
        return short
    f = Fraction(x).limit_denominator(64)
    if float(f) == x:
        return str(f.numerator) if f.denominator == 1 else f"{f.numerator}/{f.denominator}"
    return f"{x:.6g}"


def equation(row: np.ndarray, names: list[str], tol: float = 1e-10) -> str:
    """'mx[crank] + 0.2 m[coupler] - 1/2 my[slider] = 0': entries below ``tol`` x the row's
    largest are left out, the others snapped to simple fractions when within 1e-9."""
    terms = []
    big = float(np.max(np.abs(row))) if len(row) else 0.0
    for v, n in zip(row, names):
        v = 0.0 if abs(v) <= tol * big else _snap(float(v))
        if v == 0.0:
            continue
        sign = "-" if v < 0 else "+"
        mag = abs(v)
        body = n if mag == 1.0 else f"{fmt_coefficient(mag)} {n}"
        terms.append((sign, body))
    if not terms:
        return "0 = 0"
    head = ("-" if terms[0][0] == "-" else "") + terms[0][1]
    return " ".join([head] + [f"{s} {b}" for s, b in terms[1:]]) + " = 0"


def scale_of(model: Model) -> float:
    """A first-moment scale for relative residuals: total mass times the model size."""
    return max(model.total_mass(), 1e-12) * R.model_size(model)


def is_finite(x: float) -> bool:
    return math.isfinite(x)
