"""The printed force-balance conditions of the planar 4-RRR (paper 001, eqs. 17, 19 and 21) as
linear equations in named mass parameters.

Parameters (:func:`balpipe.mechanisms.rrr4.mass_parameters` reads them from a model): per link
``m{ij}``, ``m{ij}p{ij}``, ``m{ij}q{ij}`` (mass and first moments in the link frame: p along the
link from its proximal joint, q normal, left positive) and the platform's ``m5``, ``m5p5``,
``m5q5`` (first moments about its centre). The paper writes the platform through point masses
mu_5i at C_i (eqs. 2-4) with mu_54 free; eq. 17 only involves

    mu51 - mu53 = m5 p5 / (2 c5) - m5 q5 / (2 d5),
    mu52 + mu53 = m5 / 2 - m5 p5 / (2 c5),
    mu54 + mu53 = m5 / 2 + m5 q5 / (2 d5),

which eqs. 5-7 give whatever mu_54 is, so the conditions are linear in the named parameters.

Eq. 16 has a misprint (PAPERS.md): its term [-c theta21; c theta21] should read
[-c theta21; s theta21]. It does not reach eq. 17: the twelve conditions hold as printed (the
tests check that random designs satisfying them have zero shaking force in the engine).

Each condition of eq. 17 contains exactly one of P11, P31, Q11, Q31, P21, P41, P22, P42, Q21,
Q41, Q22, Q42 (P = m p, Q = m q) with coefficient 1: :func:`solve` uses these as the dependent
parameters. Eqs. 19 (Fig. 5a) and 21 (Fig. 5b) are sums of eq. 17's rows, as Sec. IV says.
"""

from __future__ import annotations

import functools
import operator
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True)
class Geometry:
    """What the conditions depend on: link lengths l[i, j] and the platform's c5, d5."""

    l: dict[tuple[int, int], float]
    c5: float
    d5: float

    @property
    def U(self) -> float:
        return self.c5 / self.d5 + self.d5 / self.c5


@dataclass(frozen=True)
class LinearCondition:
    """sum(coefficients[name] * parameter[name]) = 0."""

    name: str
    source: str
    coefficients: dict[str, float]

    def residual(self, params: dict[str, float]) -> float:
        """sum(coefficient x parameter), added in the coefficients' order (an optimiser's
        constraint: called some 10^5 times a build, hence the cached terms)."""
        keys, coefficients = self._terms
        return float(sum(map(operator.mul, coefficients, map(params.__getitem__, keys))))

    @functools.cached_property
    def _terms(self) -> tuple[tuple[str, ...], tuple[float, ...]]:
        return tuple(self.coefficients), tuple(self.coefficients.values())

    def scale(self, params: dict[str, float]) -> float:
        """Largest |coefficient x parameter| term: the size a residual is compared with."""
        return float(max(abs(c * params[k]) for k, c in self.coefficients.items()))

    def text(self, digits: int = 4) -> str:
        terms = []
        for k, c in self.coefficients.items():
            if c == 0:
                continue
            mag = abs(c)
            coef = "" if abs(mag - 1.0) < 1e-12 else f"{mag:.{digits}g} "
            terms.append(("- " if c < 0 else "+ ") + coef + k)
        s = " ".join(terms) or "0"
        return (s[2:] if s.startswith("+ ") else "-" + s[1:]) + " = 0"


def _cond(name: str, source: str, *terms: tuple[str, float]) -> LinearCondition:
    out: dict[str, float] = {}
    for k, v in terms:
        out[k] = out.get(k, 0.0) + float(v)
    return LinearCondition(name, source, {k: v for k, v in out.items() if v != 0.0})


def _platform_terms(g: Geometry, a_delta: float, a_s2: float, a_s4: float) -> list[tuple[str, float]]:
    """a_delta (mu51 - mu53) + a_s2 (mu52 + mu53) + a_s4 (mu54 + mu53) in m5, m5p5, m5q5."""
    c5, d5 = g.c5, g.d5
    return [
        ("m5p5", a_delta / (2 * c5)), ("m5q5", -a_delta / (2 * d5)),
        ("m5", a_s2 / 2), ("m5p5", -a_s2 / (2 * c5)),
        ("m5", a_s4 / 2), ("m5q5", a_s4 / (2 * d5)),
    ]


def eq17(g: Geometry) -> list[LinearCondition]:
    """The twelve general force-balance conditions of eq. 17, in the printed order."""
    l, c5, d5, U = g.l, g.c5, g.d5, g.U
    l12, l32 = l[1, 2], l[3, 2]
    out = [
        _cond("eq17.1", "eq. 17", ("m11p11", 1), ("m12", l[1, 1]), ("m12p12", -l[1, 1] / l12)),
        _cond("eq17.2", "eq. 17", ("m31p31", 1), ("m32", l[3, 1]), ("m32p32", -l[3, 1] / l32)),
        _cond("eq17.3", "eq. 17", ("m11q11", 1), ("m12q12", -l[1, 1] / l12)),
        _cond("eq17.4", "eq. 17", ("m31q31", 1), ("m32q32", -l[3, 1] / l32)),
    ]

    def p_row(name: str, lead: str, L: float, mass_term: tuple[str, float] | None, side: int):
        """Rows 5-8: legs 2 (side +1, d5/c5, S2) and 4 (side -1, c5/d5, S4)."""
        if side > 0:  # leg 2
            k = d5 / c5
            terms = [("m12q12", -L / (U * l12)), ("m12p12", k * L / (U * l12)),
                     ("m32p32", L / l32), ("m32q32", L / (U * l32)), ("m32p32", -k * L / (U * l32))]
            terms += _platform_terms(g, k * L / U, L, 0.0)
        else:  # leg 4
            k = c5 / d5
            terms = [("m12q12", L / (U * l12)), ("m12p12", k * L / (U * l12)),
                     ("m32p32", L / l32), ("m32q32", -L / (U * l32)), ("m32p32", -k * L / (U * l32))]
            terms += _platform_terms(g, k * L / U, 0.0, L)
        extra = [mass_term] if mass_term else []
        return _cond(name, "eq. 17", (lead, 1), *extra, *terms)

    def q_row(name: str, lead: str, L: float, side: int):
        """Rows 9-12."""
        if side > 0:
            k = d5 / c5
            terms = [("m12p12", L / (U * l12)), ("m12q12", k * L / (U * l12)),
                     ("m32q32", L / l32), ("m32p32", -L / (U * l32)), ("m32q32", -k * L / (U * l32))]
            terms += _platform_terms(g, L / U, 0.0, 0.0)
        else:
            k = c5 / d5
            terms = [("m12p12", -L / (U * l12)), ("m12q12", k * L / (U * l12)),
                     ("m32q32", L / l32), ("m32p32", L / (U * l32)), ("m32q32", -k * L / (U * l32))]
            terms += _platform_terms(g, -L / U, 0.0, 0.0)
        return _cond(name, "eq. 17", (lead, 1), *terms)

    out += [
        p_row("eq17.5", "m21p21", l[2, 1], ("m22", l[2, 1]), +1),
        p_row("eq17.6", "m41p41", l[4, 1], ("m42", l[4, 1]), -1),
        p_row("eq17.7", "m22p22", l[2, 2], None, +1),
        p_row("eq17.8", "m42p42", l[4, 2], None, -1),
        q_row("eq17.9", "m21q21", l[2, 1], +1),
        q_row("eq17.10", "m41q41", l[4, 1], -1),
        q_row("eq17.11", "m22q22", l[2, 2], +1),
        q_row("eq17.12", "m42q42", l[4, 2], -1),
    ]
    return out


# Eqs. 19 and 21 as sums of eq. 17's rows (1-based), in the printed order.
SPECIAL_ROWS = {
    "fig5a": ((1, 8), (5,), (2, 7), (6,), (3, 12), (9,), (4, 11), (10,)),
    "fig5b": ((1, 6), (2, 5), (7,), (8,), (3, 10), (4, 9), (11,), (12,)),
}
SPECIAL_EQ = {"fig5a": "eq. 19", "fig5b": "eq. 21"}


def special(g: Geometry, kind: str) -> list[LinearCondition]:
    """The eight conditions of eq. 19 (Fig. 5a) or eq. 21 (Fig. 5b), non-rotating platform."""
    rows = eq17(g)
    out = []
    for n, combo in enumerate(SPECIAL_ROWS[kind], start=1):
        terms = [t for r in combo for t in rows[r - 1].coefficients.items()]
        src = SPECIAL_EQ[kind]
        out.append(_cond(f"{src.replace('. ', '')}.{n}", src, *terms))
    return out


# The dependent parameter of each condition (coefficient 1, absent from the others).
EQ17_DEPENDENT = ("m11p11", "m31p31", "m11q11", "m31q31", "m21p21", "m41p41", "m22p22", "m42p42",
                  "m21q21", "m41q41", "m22q22", "m42q42")
SPECIAL_DEPENDENT = {
    # Fig. 6a/6b: only the links l_i1 carry counter-masses
    "fig5a": ("m11p11", "m21p21", "m31p31", "m41p41", "m11q11", "m21q21", "m31q31", "m41q41"),
    # Fig. 6c: counter-masses on l11, l31 (paired with l41, l21), l22 and l42
    "fig5b": ("m11p11", "m31p31", "m22p22", "m42p42", "m11q11", "m31q31", "m22q22", "m42q42"),
}


def solve(conditions: list[LinearCondition], params: dict[str, float], dependent: tuple[str, ...]) -> dict[str, float]:
    """``params`` with the ``dependent`` parameters replaced so that every condition holds (a
    square linear solve; the others keep their values)."""
    A = np.array([[c.coefficients.get(d, 0.0) for d in dependent] for c in conditions])
    b = -np.array([sum(v * params[k] for k, v in c.coefficients.items() if k not in dependent) for c in conditions])
    x = np.linalg.solve(A, b)
    out = dict(params)
    out.update({d: float(v) for d, v in zip(dependent, x)})
    return out


def as_matrix(conditions: list[LinearCondition], names: list[str]) -> np.ndarray:
    """The conditions as rows over ``names`` (for comparison with a computed null space)."""
    return np.array([[c.coefficients.get(n, 0.0) for n in names] for c in conditions])
