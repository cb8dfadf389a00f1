"""Paper 001's balance topologies beyond the recipe's stages: Fig. 3 (a selection from the general
conditions), Fig. 4b (the symmetric topology) and the arm layout that tells Fig. 6b from Fig. 6a.

The paper's figures are drawings without numbers; what its text fixes, and what each design here
takes from it:

* **Fig. 3** ("a selection of force balance topologies from the general force balance
  conditions", Sec. III): with every element's mass known, eq. 17 leaves six independent mass
  position parameters (two per loop equation), against three for Fig. 2, and the link centres of
  mass need not lie on the lines through the joints. Eq. 17's twelve rows fix twelve first moments
  once three bodies keep theirs, and :func:`admissible_kept` computes which triples can: no two
  links of one leg (56 of the 84 triples; the test checks this for random geometry). The paper's
  six panels cannot be read from the text, so the selection here is ours and said so on the page:
  the platform and the two distal links l_a2, l_b2 of each of the six pairs of legs (a, b) as
  built, counter-masses on the six other links (:func:`fig3_designs`; the pair (1, 3) is Fig.
  4a's choice).
* **Fig. 4b** ("fully symmetric topology", "more design freedom than Fig. 2a"): every link
  carries a counter-mass, as in Fig. 2a, but from eq. 17 instead of eqs. 8-11, so that the link
  centres of mass may leave the link lines and the platform keeps its mass as built. No leg may
  be privileged: one kept parameter of the same kind in every leg never fixes the design (eq.
  17's 12 x 12 system is then singular, :func:`same_kind_per_leg_ranks`), so the free parameters
  are taken the way that treats every link alike, the first-moment changes of least Euclidean
  norm (:func:`fig4b_design`). When that least-norm design is unique it has every symmetry of the
  mechanism and its mass data. Its freedom against Fig. 2a is counted by
  :func:`freedoms`.
* **Fig. 6b**: the kinematics of Fig. 5a with the arms not crossing ("no arms need to cross one
  another", the prototype of Fig. 7 derives from it), counter-masses on the links l_i1 only as in
  Fig. 6a (eq. 19). :func:`arms_cross` tells the two layouts apart, so a ``fig5a`` spec whose
  arms do not cross is drawn and labelled as Fig. 6b. The prototype's coincident joints (C1 = C2,
  C3 = C4, c5 = 0) are not modelled: eq. 19 divides by c5.
"""

from __future__ import annotations

import itertools
from dataclasses import dataclass

import numpy as np

from .template import mass_parameters
from ...balancing.context import Memo, compute
from ...model import Model
from . import conditions as cond
from .placement import realise

LEGS = (1, 2, 3, 4)
SOLVE_CONDITION = 1e8  # a kept triple whose 12 x 12 system is worse conditioned counts as singular


@dataclass(frozen=True)
class Design:
    """One drawn topology: ``figure`` (e.g. "Fig. 3a"), the bodies kept as built (paper names:
    '11', '5'), the model with its counter-masses, and how its free parameters were chosen."""

    figure: str
    kept: tuple[str, ...]
    model: Model
    assumed: str


def first_moments(body: str) -> tuple[str, str]:
    """The paper's first-moment names of a body: '12' -> ('m12p12', 'm12q12'), '5' -> ('m5p5', 'm5q5')."""
    return (f"m{body}p{body}", f"m{body}q{body}")


BODIES = tuple(f"{i}{j}" for i in LEGS for j in (1, 2)) + ("5",)


def dependent_of(kept: tuple[str, ...]) -> tuple[str, ...]:
    return tuple(n for b in BODIES if b not in kept for n in first_moments(b))


def admissible_kept(g: cond.Geometry) -> list[tuple[str, str, str]]:
    """Every triple of bodies whose first moments, kept as built, leave eq. 17 a regular
    12 x 12 system for the twelve other first moments (condition number below 1e8)."""
    rows = cond.eq17(g)
    out = []
    for kept in itertools.combinations(BODIES, 3):
        M = cond.as_matrix(rows, list(dependent_of(kept)))
        if np.linalg.cond(M) < SOLVE_CONDITION:
            out.append(kept)
    return out


def same_kind_per_leg_ranks(g: cond.Geometry) -> dict[str, int]:
    """Rank of eq. 17's system when every leg keeps the same one of its four first moments
    (p_i1, q_i1, p_i2 or q_i2) and the twelve others are solved for: 12 would fix a design."""
    rows = cond.eq17(g)
    out = {}
    for kind in ("p1", "q1", "p2", "q2"):
        dep = [f"m{i}{j}{pq}{i}{j}" for i in LEGS for j in (1, 2) for pq in "pq" if f"{pq}{j}" != kind]
        out[kind] = int(np.linalg.matrix_rank(cond.as_matrix(rows, dep)))
    return out


def freedoms(g: cond.Geometry) -> dict[str, int]:
    """Free first moments (mass parameters m_ij, m5 given): ``eq17``: of all eighteen under eq.
    17; ``eq17_links``: of the sixteen link ones with the platform as built (Fig. 4b's family);
    ``leg_by_leg``: under eq. 17 with every q_ij = 0, the family of Fig. 2a (eqs. 8-11 with mu_54
    free), platform included; ``leg_by_leg_links``: the same with the platform as built."""
    rows = cond.eq17(g)
    names = [n for b in BODIES for n in first_moments(b)]
    A = cond.as_matrix(rows, names)

    def free(fixed: list[str]) -> int:
        E = np.array([[1.0 if n == f else 0.0 for n in names] for f in fixed]).reshape(len(fixed), len(names))
        return len(names) - int(np.linalg.matrix_rank(np.vstack([A, E])))

    qs = [f"m{b}q{b}" for b in BODIES[:-1]]
    plat = list(first_moments("5"))
    return {"eq17": free([]), "eq17_links": free(plat), "leg_by_leg": free(qs), "leg_by_leg_links": free(qs + plat)}


def _distance(ij: str, proximal: float, distal: float) -> float:
    return proximal if ij[1] == "1" else distal


def realise_all(model: Model, targets: dict[str, tuple[float, float]], proximal: float, distal: float,
                tag: str) -> Model:
    """``model`` with one counter-mass per link of ``targets`` (paper name -> first moments (m p,
    m q) wanted), at the spec's distance from the link's proximal joint, in the direction the
    missing first moment needs (:func:`balpipe.families.rrr4.placement.realise`)."""
    out = model
    for ij, (P, Q) in targets.items():
        out, _, _ = realise(out, f"link{ij}", P, Q, _distance(ij, proximal, distal), f"counter-mass {ij} ({tag})")
    return out


def solve_counter_masses(model: Model, g: cond.Geometry, links: list[str], proximal: float, distal: float,
                         polish: int = 20) -> dict[str, tuple[float, float]]:
    """First moments (m p, m q) of the ``links`` (paper names '11'..'42') that meet eq. 17 when
    each gets one counter-mass at the spec's distance from its proximal joint, every other
    parameter as built: the change s of their first moments of least Euclidean norm (unique when
    the links carry twelve unknowns, as in Fig. 3). A counter-mass adds mass |s_ij| / distance to
    its link and eq. 17 holds the link masses too (m_i2 l_i1), so the conditions r(s) = 0 are
    not linear in s: least norm by scipy's SLSQP from the linear solution (masses as built), then
    Gauss-Newton steps s <- s - J+ r(s) until the conditions hold to round-off."""
    from scipy.optimize import minimize

    rows = cond.eq17(g)
    base = mass_parameters(model)
    cols = [n for ij in links for n in first_moments(ij)]
    A = cond.as_matrix(rows, cols)
    Am = cond.as_matrix(rows, [f"m{ij}" for ij in links])
    dist = np.array([_distance(ij, proximal, distal) for ij in links])
    scale = max(abs(r.scale(base)) for r in rows)

    names = [(f"m{ij}", f"m{ij}p{ij}", f"m{ij}q{ij}") for ij in links]
    spans = dist.tolist()

    def residual(s: np.ndarray) -> np.ndarray:  # SLSQP's constraint: ~3000 calls a design
        S = np.asarray(s, dtype=float).reshape(-1, 2)
        p = dict(base)
        for (m, mp, mq), h, d, (sx, sy) in zip(names, np.hypot(S[:, 0], S[:, 1]).tolist(), spans, S.tolist()):
            p[m] += h / d
            p[mp] += sx
            p[mq] += sy
        return np.array([c.residual(p) for c in rows])

    def jacobian(s: np.ndarray) -> np.ndarray:
        S = s.reshape(-1, 2)
        unit = S / np.maximum(np.hypot(S[:, 0], S[:, 1]), 1e-300)[:, None]
        return A + np.repeat(Am / dist, 2, axis=1) * unit.reshape(-1)

    s0 = -np.linalg.pinv(A) @ residual(np.zeros(len(cols)))
    if len(cols) > len(rows):
        res = minimize(lambda s: float(s @ s), s0, jac=lambda s: 2 * s, method="SLSQP",
                       constraints=[{"type": "eq", "fun": residual, "jac": jacobian}],
                       options={"maxiter": 500, "ftol": 1e-16})
        s = res.x
    else:
        s = s0
    for _ in range(polish):
        r = residual(s)
        if np.max(np.abs(r)) <= 1e-15 * scale:
            break
        s = s - np.linalg.pinv(jacobian(s)) @ r
    return {ij: (base[f"m{ij}p{ij}"] + s[2 * k], base[f"m{ij}q{ij}"] + s[2 * k + 1]) for k, ij in enumerate(links)}


def design(model: Model, g: cond.Geometry, kept: tuple[str, ...], proximal: float, distal: float, figure: str,
           assumed: str, memo: Memo = compute) -> Design:
    """The bodies ``kept`` as built, one counter-mass on every other link (:func:`solve_counter_masses`,
    through ``memo``: the build's cache)."""
    links = [b for b in BODIES[:-1] if b not in kept]
    targets = memo(solve_counter_masses, model, g, links, proximal, distal)
    return Design(figure, kept, realise_all(model, targets, proximal, distal, figure), assumed)


def fig3_designs(model: Model, g: cond.Geometry, proximal: float, distal: float, memo: Memo = compute) -> list[Design]:
    """Fig. 3 (our selection): for each pair of legs (a, b), the platform and the distal links
    l_a2, l_b2 as built, counter-masses on the six other links from eq. 17 (the pair (1, 3) is
    Fig. 4a's choice)."""
    out = []
    for letter, (a, b) in zip("abcdef", itertools.combinations(LEGS, 2)):
        kept = (f"{a}2", f"{b}2", "5")
        out.append(design(model, g, kept, proximal, distal, f"Fig. 3{letter}",
                          f"l{a}2, l{b}2 and the platform as built (our choice of the six free parameters)", memo))
    return out


def fig4b_design(model: Model, g: cond.Geometry, proximal: float, distal: float, memo: Memo = compute) -> Design:
    """Fig. 4b: a counter-mass on every link, the platform as built, the sixteen link first
    moments changed by the least Euclidean norm that meets eq. 17."""
    return design(model, g, ("5",), proximal, distal, "Fig. 4b",
                  "the platform as built; the four free link first moments chosen by the least Euclidean norm of "
                  "the sixteen first-moment changes (every link treated alike)", memo)


def designs(model: Model, g: cond.Geometry, proximal: float, distal: float, memo: Memo = compute) -> list[Design]:
    """Every drawn design from eq. 17: Fig. 3's six (:func:`fig3_designs`), then Fig. 4b's
    (:func:`fig4b_design`)."""
    return fig3_designs(model, g, proximal, distal, memo) + [fig4b_design(model, g, proximal, distal, memo)]


def whose(figure: str) -> str:
    """A design's name that says whose it is: Fig. 3's six are our selection ("our design a, not
    the paper's Fig. 3a": the paper's panels cannot be read from its text), Fig. 4b is our reading
    of the paper's words ("Fig. 4b as we read it")."""
    if figure.startswith("Fig. 3"):
        return f"our design {figure[-1]}, not the paper's {figure}"
    return f"{figure} as we read it"


def tag(figure: str) -> str:
    """A design's tag in parameter names: "Fig. 3a" -> "fig3a"."""
    return figure.replace("Fig. ", "fig").lower()


def arms_cross(model: Model) -> bool:
    """Whether any two links of different legs cross in the model's initial pose (its body
    frames' ``initial`` poses): Fig. 1's and Fig. 6a's layout; Fig. 6b's has none."""
    segs = {}
    for b in model.bodies:
        if not b.name.startswith("link"):
            continue
        x, y, th = model.initial[b.name]
        R = np.array([[np.cos(th), -np.sin(th)], [np.sin(th), np.cos(th)]])
        a, c = (np.array([x, y]) + R @ np.asarray(b.points[n], float) for n in b.outline[:2])
        segs[b.name] = (a, c)

    def segments_cross(p, q):
        (a, b), (c, d) = p, q

        def orient(u, v, w):
            return (v[0] - u[0]) * (w[1] - u[1]) - (v[1] - u[1]) * (w[0] - u[0])

        o1, o2, o3, o4 = orient(a, b, c), orient(a, b, d), orient(c, d, a), orient(c, d, b)
        return o1 * o2 < 0 and o3 * o4 < 0

    names = sorted(segs)
    return any(segments_cross(segs[u], segs[v]) for u, v in itertools.combinations(names, 2) if u[4] != v[4])


def fig6_label(kinematics: str, crossing: bool) -> str:
    """The paper's figure of a special-kinematics design: Fig. 6a (Fig. 5a, arms crossing), Fig.
    6b (Fig. 5a, arms not crossing), Fig. 6c (Fig. 5b)."""
    if kinematics == "fig5b":
        return "Fig. 6c"
    return "Fig. 6a" if crossing else "Fig. 6b"


def eq17_residual(model: Model, g: cond.Geometry) -> float:
    """Largest residual of eq. 17's twelve rows for a design, relative to the largest term of
    any row (a row whose own terms all vanish is not divided by round-off)."""
    p = mass_parameters(model)
    rows = cond.eq17(g)
    return max(abs(r.residual(p)) for r in rows) / max(max(r.scale(p) for r in rows), 1e-300)


__all__ = ["Design", "admissible_kept", "same_kind_per_leg_ranks", "freedoms", "fig3_designs", "fig4b_design",
           "arms_cross", "fig6_label", "eq17_residual"]
