"""Paper 001's printed conditions against the generic condition finder, and the least-mass
counter-masses of the 4-RRR: every printed condition is checked to lie in the finder's space.

The finder (:func:`balpipe.balancing.conditions.find`) works on the model's parameters
``m[body]``, ``mx[body]``, ``my[body]`` (mass and first moments in the body frame). The 4-RRR's
body frames are the paper's (link l_ij: origin at its proximal joint, x along the link, so
(mx, my) = (m_ij p_ij, m_ij q_ij); the platform: origin at its centre, (mx, my) = (m5 p5,
m5 q5)), so a printed condition of eq. 17 (:mod:`.rrr4_conditions`) maps column by column onto
the finder's parameters (:func:`finder_name`).

A printed condition lies in the computed space when it is a combination of the finder's rows:
:func:`span_residuals` gives each row's distance from that space relative to its length, in the
finder's scaled columns (masses times the model size, first moments as they are).

Special kinematics (Fig. 5a, 5b) with a translating platform: the conditions of that motion class
are the rank of the regressor over states of translating-platform motions only
(:func:`translating_states`). PAPERS.md: 6, not the paper's 8 (eqs. 19, 21). The eight are
sufficient (the six computed conditions are combinations of them) but two of them only fix m5 p5
and m5 q5, which encode how the paper splits m5 into point masses mu_5i at the C_i: with a
translating platform every C_i has the platform's velocity and the split does not matter.
Eliminating m5 p5 and m5 q5 from the eight printed rows leaves six, which span the computed space
(:func:`eliminate`).

Least-mass design (:func:`least_mass`): the generic linear programme
(:func:`balpipe.balancing.least_mass.solve`) with one counter-mass per link, anywhere within the
leg-by-leg design's distance of the link's proximal joint: the positions the leg-by-leg design may
use, so that its masses are a feasible point of the programme and the least-mass one cannot add
more.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ...engine import analyse
from ...model import Model
from ...motion import PROFILES, PointToPoint
from ...balancing import conditions as C
from ...balancing import least_mass as LM
from ...balancing import regressor as R
from ...balancing.parts import add_counterweight
from .conditions import LinearCondition

TRANSLATING_MOVES = 8  # translating-platform motions sampled for the special-kinematics count
MOVE_SAMPLES = 21  # states per move
MOVE_REACH = 0.6  # moves start and end within this fraction of the smaller platform half-size of the start pose


def finder_name(paper: str) -> str:
    """The finder's parameter for one of the paper's: 'm12' -> 'm[link12]', 'm12p12' ->
    'mx[link12]', 'm12q12' -> 'my[link12]', 'm5' -> 'm[platform]', 'm5p5' -> 'mx[platform]'."""
    body, rest = ("platform", paper[2:]) if paper.startswith("m5") else (f"link{paper[1:3]}", paper[3:])
    return {"": "m", "p": "mx", "q": "my"}[rest[:1]] + f"[{body}]"


def to_finder(rows: list[LinearCondition], names: list[str]) -> np.ndarray:
    """The printed conditions as rows over the finder's parameters ``names``."""
    out = np.zeros((len(rows), len(names)))
    for k, r in enumerate(rows):
        for p, c in r.coefficients.items():
            out[k, names.index(finder_name(p))] += c
    return out


def span_residuals(space: np.ndarray, rows: np.ndarray, scale: np.ndarray) -> np.ndarray:
    """|row - its projection on the row space of ``space``| / |row| for each row, in the scaled
    columns ``scale`` (a condition c p = 0 reads (c D) (D^-1 p) = 0)."""
    if rows.shape[0] == 0:
        return np.zeros(0)
    A = rows * scale
    if space.shape[0] == 0:
        return np.ones(len(A))
    Q, _ = np.linalg.qr((space * scale).T)
    res = A - (A @ Q) @ Q.T
    return np.linalg.norm(res, axis=1) / np.maximum(np.linalg.norm(A, axis=1), 1e-300)


def eliminate(rows: np.ndarray, columns: list[int]) -> np.ndarray:
    """The combinations of ``rows`` in which ``columns`` cancel (a basis of them)."""
    sub = rows[:, columns].T
    _, s, vt = np.linalg.svd(sub)
    rank = int(np.sum(s > 1e-12 * max(s[0], 1e-300))) if s.size else 0
    return vt[rank:] @ rows


def translating_states(model: Model, moves: int = TRANSLATING_MOVES, samples: int = MOVE_SAMPLES,
                       seed: int = 0) -> R.States:
    """States of the 4-RRR along ``moves`` straight translations of the platform (angle held at its
    start value) from and to random points near its start pose, each analysed by the engine on
    ``samples`` instants: the motion class of the special kinematics (paper 001, Sec. IV)."""
    pose = model.drivers[0].law.pose
    x0, y0, ph0 = (float(law(np.zeros(1))[0][0]) for law in pose)
    plat = model.body("platform").points
    half = min(max(abs(p[0]) for p in plat.values()), max(abs(p[1]) for p in plat.values()))
    reach = MOVE_REACH * half
    T = float(getattr(pose[0], "duration", 1.0))
    t = np.linspace(0.0, T, samples)
    rng = np.random.default_rng(seed)
    quintic = PROFILES["quintic"]
    analyses = []
    for _ in range(moves):
        a, b = rng.uniform(-reach, reach, 2), rng.uniform(-reach, reach, 2)
        laws = (PointToPoint(x0 + a[0], x0 + b[0], T, quintic), PointToPoint(y0 + a[1], y0 + b[1], T, quintic),
                PointToPoint(ph0, ph0, T, quintic))
        moved = replace(model, drivers=tuple(replace(d, law=replace(d.law, pose=laws)) for d in model.drivers))
        analyses.append(analyse(moved, t))
    return R.states_from_analysis(model, *analyses)


@dataclass
class FinderCheck:
    """The finder's conditions of a 4-RRR and the printed ones checked against them.

    ``general``: conditions for every motion; ``eq17``: each printed row's relative distance from
    their space; ``translating`` (special kinematics only): conditions for translating-platform
    motions, ``special_in_printed``: each computed one's distance from the span of the printed
    eight, ``printed_in_translating``: each printed one's distance from the computed space,
    ``reduced``: the printed eight with m5 p5, m5 q5 eliminated (count and distance from the
    computed space)."""

    general: C.ForceConditions
    eq17: np.ndarray
    scale: np.ndarray
    translating: C.ForceConditions | None = None
    special_in_printed: np.ndarray | None = None
    printed_in_translating: np.ndarray | None = None
    reduced_count: int = 0
    reduced_in_translating: np.ndarray | None = None

    def design_residual(self, model: Model) -> float:
        """Largest |C p| of a design over the general conditions, relative to its total mass x
        the model size (:func:`balpipe.balancing.conditions.scale_of`)."""
        return self.general.contains(R.parameters(model), C.scale_of(model))


def check(model: Model, t: np.ndarray, eq17: list[LinearCondition],
          special: list[LinearCondition] | None = None) -> FinderCheck:
    """The finder on ``model`` (every motion), eq. 17 against it and, with the printed
    ``special`` conditions (eq. 19 or 21), the finder on translating-platform states."""
    general = C.find(model, t)
    scale = C.column_scale(model)
    out = FinderCheck(general, span_residuals(general.matrix, to_finder(eq17, general.names), scale), scale)
    if special is not None:
        tr = C.find(model, t, states=translating_states(model))
        printed = to_finder(special, tr.names)
        reduced = eliminate(printed, [tr.names.index("mx[platform]"), tr.names.index("my[platform]")])
        out.translating = tr
        out.special_in_printed = span_residuals(printed, tr.matrix, scale)
        out.printed_in_translating = span_residuals(tr.matrix, printed, scale)
        out.reduced_count = int(np.linalg.matrix_rank(reduced * scale, tol=1e-9 * np.abs(reduced * scale).max()))
        out.reduced_in_translating = span_residuals(tr.matrix, reduced, scale)
    return out


def least_mass(model: Model, radii: dict[str, float], general: C.ForceConditions) -> tuple[Model, LM.Solution]:
    """Counter-masses of least added mass meeting the ``general`` conditions, one per body of
    ``radii``, anywhere within that distance of the body frame's origin (the link's proximal
    joint): the positions the leg-by-leg design may use (:func:`balpipe.balancing.rrr4.realise`
    puts its counter-mass at that distance, in the direction it needs), so the leg-by-leg masses
    are a feasible point of the programme and the least-mass design adds no more. The discs are
    the generic inscribed 128-gons, whose vertices include the leg-by-leg positions when those
    lie along -x (q_ij = 0, eqs. 8-11)."""
    regions = [LM.Region(f"least-mass {b[4:]}", b, "disc", ((0.0, 0.0),), r) for b, r in radii.items()]
    sol = LM.solve(model, general, regions)
    out = model
    for cw in sol.counterweights:
        if cw.mass > 0:
            out = add_counterweight(out, cw.region.body, cw.region.name, cw.mass, cw.position, radius=None)
    return out, sol
