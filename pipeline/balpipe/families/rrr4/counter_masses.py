"""Force balancing of the n-RRR by counter-masses: paper 001's recipes.

Stages:

* ``leg_by_leg`` (Sec. II.A, Fig. 2a, eqs. 8-11): the platform's mass is split into point
  masses mu_5i at the joints C_i (eqs. 2-4; with four legs mu_54 is free, the minimum-norm split
  unless ``platform_split`` gives one), then each leg is balanced on its own pivot: link l_i2's
  centre of mass, with mu_5i at C_i, goes to B_i (eqs. 9, 11: q_i2 = 0, m_i2 p_i2 + mu_5i l_i2 =
  0), then link l_i1's, loaded by l_i2 and mu_5i at B_i, to A_i (eqs. 8, 10). Works for 1..4
  legs when the split exists (3 legs: unique; 2 legs: the platform's centre of mass on C_iC_j;
  1 leg: on C_i).
* ``general`` (Sec. III, eq. 17, Fig. 4a, four legs): links l12, l32 and the platform as built,
  the twelve conditions of eq. 17 solved for the first moments of the six other links.
* ``special`` (Sec. IV, eq. 19 / 21, Fig. 6a / 6b / 6c, kinematics ``fig5a`` / ``fig5b`` with a
  platform that does not rotate): the eight printed conditions solved with counter-masses on the
  links l_i1 only (Fig. 6a with the arms crossing, Fig. 6b without) or on l11, l31, l22, l42 (Fig.
  6c).

With four legs and ``topologies``, the designs of Figs. 3 (a selection of ours) and 4b
(:mod:`.topologies`) go to ``details["topologies"]``: their added mass and conditions' residuals
when balanced, their peak shaking force once the stages are analysed (:func:`design_loads`, the
result's ``derived`` hook). The page draws them from those numbers.

A target first moment is realised by one counter-mass at a given distance from the link's
proximal joint (:func:`balpipe.balancing.parts.add_counterweight`), in the direction that the
missing first moment needs; its mass is |missing| / distance.
"""

from __future__ import annotations

from functools import partial

import numpy as np

from .template import RRR4Mechanism, corner, mass_parameters, resolve_legs
from ...display import numbers
from ...model import Model
from ...spec_parts import SpecFieldError
from . import conditions as cond
from . import finder as generic
from . import topologies as topologies
from .placement import realise
from ...balancing.context import BalanceContext, Memo, compute
from ...balancing.base import BalanceResult, Parameter, Stage
from ...balancing.conditions import clarity_text
from ...engine import analyse
from ...engine.load_reference import load_reference
from .specs import RRR4Balancing


def link_name(ij: str) -> str:
    """Paper 001's name of link ij in plain text, its length l_ij (Sec. II): '41' -> 'l₄₁', as the
    pages' tables write it (:func:`balpipe.notation.symbol_text`)."""
    from ...notation import symbol_text

    return symbol_text(f"l_{{{ij}}}")

LEG_BY_LEG_LABEL = "leg-by-leg counter-masses (Fig. 2a, eqs. 8-11)"


def platform_split(mech: RRR4Mechanism, legs: list[int], given: list[float] | None,
                   fixed: dict[int, float] | None = None) -> np.ndarray:
    """mu_5i (eqs. 2-4): sum mu = m5, sum mu C_i = m5 (p5, q5) in the platform frame; ``fixed``
    holds the mu_5i that independent links set (Sec. II.B-D)."""
    p = mech.platform
    A = np.array([[1.0] * len(legs), [corner(mech, i)[0] for i in legs], [corner(mech, i)[1] for i in legs]])
    b = p.mass * np.array([1.0, p.com[0], p.com[1]])
    scale = max(p.mass * max(p.half_width, p.half_height), 1e-300)
    if fixed:
        free = [k for k, i in enumerate(legs) if i not in fixed]
        mu = np.zeros(len(legs))
        for k, i in enumerate(legs):
            mu[k] = fixed.get(i, 0.0)
        rhs = b - A @ mu
        if free:
            mu[free] = np.linalg.lstsq(A[:, free], rhs, rcond=None)[0]
        r = A @ mu - b
        if np.max(np.abs(r)) > 1e-9 * max(scale, p.mass):
            kept = ", ".join(f"l{i}2 (mu5{i} = {fixed[i]:.4g} kg)" for i in sorted(fixed))
            rest = ", ".join(f"C{legs[k]}" for k in free) or "none"
            raise SpecFieldError(
                ("balancing", "independent"),
                f"with {kept} as built, eqs. 2-4 cannot be met: the platform and those point masses together "
                f"must have their centre of mass where the remaining joints ({rest}) can hold it "
                f"(residuals {r[0]:.3g} kg, {r[1]:.3g} kg m, {r[2]:.3g} kg m; paper 001, Sec. II.B-D)",
            )
        return mu
    if given is not None:
        path = ("balancing", "platform_split")
        if len(given) != len(legs):
            raise SpecFieldError(path, f"one mass per leg present ({len(legs)}: legs {legs}), got {len(given)}")
        mu = np.asarray(given, dtype=float)
        r = A @ mu - b
        if np.max(np.abs(r[1:])) > 1e-9 * scale or abs(r[0]) > 1e-9 * max(p.mass, 1e-300):
            raise SpecFieldError(path, f"eqs. 2-4 do not hold: sum mu = {mu.sum():.6g} kg (m5 = {p.mass:.6g} kg) and "
                                 f"their centre of mass must be the platform's ({p.com[0]:.6g}, {p.com[1]:.6g}) m")
        return mu
    mu = np.linalg.lstsq(A, b, rcond=None)[0]
    if np.max(np.abs(A @ mu - b)) > 1e-9 * max(scale, p.mass):
        raise SpecFieldError(
            ("balancing", "method"),
            f"leg-by-leg balancing needs the platform's mass split over the joints C_i of legs {legs} "
            f"(eqs. 2-4), which requires its centre of mass ({p.com[0]:.6g}, {p.com[1]:.6g}) m "
            + ("on the joint C%d" % legs[0] if len(legs) == 1 else "on the line C%dC%d" % tuple(legs) if len(legs) == 2
               else "in the plane of the joints")
            + "; balance with the general conditions (four legs) instead",
        )
    return mu


def leg_by_leg(mech: RRR4Mechanism, spec: RRR4Balancing, model: Model) -> tuple[Model, list[Parameter]]:
    """Eqs. 8-11 with the split of eqs. 2-4."""
    legs = resolve_legs(mech)
    ids = list(legs)
    fixed = {}
    for k, ij in enumerate(spec.independent):
        i = ij // 10
        if i not in legs:
            raise SpecFieldError(("balancing", "independent", k), f"leg {i} is not part of the mechanism")
        if spec.platform_split is not None:
            raise SpecFieldError(("balancing", "independent"), "give either independent links or platform_split")
        m, c, _ = model.body(f"link{i}2").mass_properties()
        fixed[i] = -m * c[0] / legs[i].l2  # eq. 11 with p_i2 as built
    mu = platform_split(mech, ids, spec.platform_split, fixed)
    params = [Parameter(f"mu5{i}", float(m), "kg", "eqs. 2-7", f"platform mass lumped at C{i}") for i, m in zip(ids, mu)]
    out = model
    for i, m5i in zip(ids, mu):
        leg = legs[i]
        # an independent link keeps its p_i2 (-mu l_i2 is its own first moment); q_i2 = 0 still
        out, m2, pos2 = realise(out, f"link{i}2", -m5i * leg.l2, 0.0, spec.counterweights.distal, f"counter-mass {i}2")
        m2_total = out.body(f"link{i}2").mass_properties()[0]
        out, m1, pos1 = realise(out, f"link{i}1", -(m2_total + m5i) * leg.l1, 0.0, spec.counterweights.proximal,
                                f"counter-mass {i}1")
        for ij, mass, pos, eq in ((f"{i}2", m2, pos2, "eqs. 9, 11"), (f"{i}1", m1, pos1, "eqs. 8, 10")):
            params += [
                Parameter(f"m_cm{ij}", mass, "kg", eq, f"leg-by-leg counter-mass on link {link_name(ij)}"),
                Parameter(f"x_cm{ij}", pos[0], "m", eq, f"its position along {link_name(ij)} from the proximal joint"),
                Parameter(f"y_cm{ij}", pos[1], "m", eq, f"its position normal to {link_name(ij)} (left positive)"),
            ]
    return out, params


def geometry(mech: RRR4Mechanism) -> cond.Geometry:
    legs = resolve_legs(mech)
    return cond.Geometry({(i, 1): lg.l1 for i, lg in legs.items()} | {(i, 2): lg.l2 for i, lg in legs.items()},
                         mech.platform.half_width, mech.platform.half_height)


def from_conditions(model: Model, spec: RRR4Balancing, conditions, dependent, tag: str) -> tuple[Model, list[float]]:
    """Counter-masses that give the links named in ``dependent`` the first moments the
    conditions solve for, every other parameter as built."""
    out, masses = model, []
    # distal links first: a counter-mass changes its link's mass, which other conditions hold
    links = sorted({d[1:3] for d in dependent}, key=lambda ij: (ij[1] == "1", ij))
    for ij in links:
        target = cond.solve(conditions, mass_parameters(out), dependent)
        dist = spec.counterweights.proximal if ij[1] == "1" else spec.counterweights.distal
        out, m, _ = realise(out, f"link{ij}", target[f"m{ij}p{ij}"], target[f"m{ij}q{ij}"], dist, f"counter-mass {ij} ({tag})")
        masses.append(m)
    return out, masses


def platform_rotates(model: Model, samples: int = 201) -> bool:
    """Whether the platform pose law turns the platform (special kinematics need it fixed)."""
    law = getattr(model.drivers[0].law, "pose", None)
    if law is None:
        return True
    T = max(getattr(law[2], "duration", 1.0), 1e-9)
    th = law[2](np.linspace(0.0, T, samples))[0]
    return bool(np.ptp(th) > 1e-12)


def balance(ctx: BalanceContext) -> BalanceResult:
    """The stages (unbalanced, leg by leg, least mass, eq. 17's general design, the special
    kinematics' design), their parameters and notes. Without ``ctx.page`` (``balpipe check`` of a
    spec without references) the drawn designs of Figs. 3 and 4b (:func:`topology_designs`:
    parameters, a note, details and their derived peak forces) and the finder's count for
    translating-platform motions (:func:`finder_stage`) are left out: no stage and no error
    depends on them. The searches go through ``ctx.memo``."""
    mech: RRR4Mechanism = ctx.mechanism
    spec: RRR4Balancing = ctx.balancing
    model, page, memo = ctx.model, ctx.page, ctx.memo
    legs = resolve_legs(mech)
    stages = [Stage("unbalanced", "unbalanced", model, f"the {model.name} as given")]
    lbl, params = leg_by_leg(mech, spec, model)
    base_mass = model.total_mass()
    label = LEG_BY_LEG_LABEL
    if spec.independent:
        fig = "Fig. 2" + "abcd"[min(len(spec.independent), 3)]
        label = f"leg-by-leg counter-masses ({fig}, eqs. 8-11; " + ", ".join(link_name(ij) for ij in spec.independent) + " as built)"
    stages.append(Stage("leg_by_leg", label, lbl,
                        "each leg's centre of mass on its base pivot, the platform lumped at the C_i (eqs. 2-11)", "force"))
    params.append(Parameter("added_mass_leg_by_leg", lbl.total_mass() - base_mass, "kg", "eqs. 8-11",
                            "counter-masses of the leg-by-leg balancing"))
    notes = []
    details: dict = {}
    derived = None
    if spec.least_mass or len(legs) == 4:
        found = finder_stage(mech, spec, model, lbl, stages, params, notes, details, page, memo)
    if len(legs) == 4:
        g = geometry(mech)
        rows = cond.eq17(g)
        notes.append(
            "Paper 001's eq. 17 gives twelve general force-balance conditions of the 4-RRR, linear in the mass "
            "parameters m_ij, m_ij p_ij, m_ij q_ij, m5, m5 p5, m5 q5 (the platform's point masses mu_5i enter only "
            "through combinations that eqs. 5-7 fix whatever mu_54 is). They are independent: each holds one "
            "dependent first moment with coefficient 1. Eq. 16's misprint ([-c theta21; c theta21] for "
            "[-c theta21; s theta21]) does not reach eq. 17, whose rows hold as printed: the table below "
            "gives each condition's residual for every stage."
        )
        if spec.topologies:
            gen, masses = from_conditions(model, spec, rows, cond.EQ17_DEPENDENT, "eq. 17")
            stages.append(Stage("general", "general conditions (Fig. 4a, eq. 17)", gen,
                                "links l12, l32 and the platform as built, the first moments of the six other links "
                                "from eq. 17's twelve conditions", "force"))
            params.append(Parameter("added_mass_general", gen.total_mass() - base_mass, "kg", "eq. 17",
                                    "counter-masses of the eq. 17 design (Fig. 4a)"))
            if page:
                designs = topology_designs(model, g, spec, found, base_mass, params, notes, details, memo)
                derived = partial(design_loads, designs, details["topologies"]["designs"], memo=memo)
            if mech.kinematics != "general":
                fig = topologies.fig6_label(mech.kinematics, topologies.arms_cross(model))
                eq = cond.SPECIAL_EQ[mech.kinematics]
                if platform_rotates(model):
                    notes.append(f"The {fig} design ({eq}) is not built: the special kinematics of Fig. 5 balance "
                                 "only a platform that does not rotate, and this motion turns it.")
                else:
                    sp, _ = from_conditions(model, spec, cond.special(g, mech.kinematics),
                                            cond.SPECIAL_DEPENDENT[mech.kinematics], eq)
                    where = "the links l_i1 only" if mech.kinematics == "fig5a" else "links l11, l31, l22 and l42"
                    if fig == "Fig. 6b":
                        notes.append(
                            "Fig. 6b: the kinematics of Fig. 5a with no two links of different legs crossing in the "
                            "initial pose (computed), the layout of the paper's Fig. 6b, from which its prototype "
                            "(Fig. 7) derives; counter-masses on the links l_i1 only, as in Fig. 6a. The paper calls "
                            "its drawn Fig. 6b configuration singular and makes the prototype's joint C1 coincide with "
                            "C2 and C3 with C4; that platform (c5 = 0) is not modelled here (eqs. 17 and 19 divide by "
                            "c5), and the geometry, masses and motion of this spec are assumed.")
                    stages.append(Stage("special", f"special kinematics ({fig}, {eq})", sp,
                                        f"the eight conditions of {eq} (non-rotating platform), counter-masses on {where}",
                                        "force"))
                    params.append(Parameter("added_mass_special", sp.total_mass() - base_mass, "kg", eq,
                                            f"counter-masses of the {fig} design"))
                    notes.append(
                        f"Paper 001 prints eight conditions for the kinematics of Fig. 5 with a translating platform "
                        f"({eq}); they are sums of eq. 17's rows (the table shows them with their residuals) and "
                        "sufficient for balance: the special stage meets them with counter-masses on fewer links "
                        "than eq. 17 needs, and the engine finds its shaking force cancelled although eq. 17 does "
                        "not hold. "
                        + ("They are not all necessary: " if page and found.translating.count < 8 else "")
                        + "the generic finder's count for this motion class (found numerically from its momentum) "
                        "is in the note above."
                    )
        names = list(mass_parameters(model))
        params.append(Parameter("eq17_conditions", len(rows), "", "eq. 17", "number of printed general conditions"))
        params.append(Parameter("eq17_rank", float(np.linalg.matrix_rank(cond.as_matrix(rows, names))), "", "eq. 17",
                                "independent conditions among them (rank of their coefficient matrix)"))
        for st in stages:
            p = mass_parameters(st.model)
            worst = max(abs(r.residual(p)) / max(r.scale(p), 1e-300) for r in rows)
            params.append(Parameter(f"eq17_residual_{st.name}", worst, "", "eq. 17",
                                    f"largest relative residual of eq. 17's twelve conditions, {st.label}"))
    else:
        notes.append(
            f"A {len(legs)}-RRR: the leg-by-leg balancing (eqs. 8-11) applies; eq. 17 is written for four "
            "legs (paper 001 takes legs out by giving them zero mass, which keeps them in the kinematics)."
        )
    return BalanceResult(params, stages, notes, details=details, derived=derived)


def topology_designs(model: Model, g: cond.Geometry, spec: RRR4Balancing, found: generic.FinderCheck,
                     base_mass: float, params: list, notes: list, details: dict,
                     memo: Memo = compute) -> list[topologies.Design]:
    """Figs. 3 (our selection) and 4b from eq. 17 (:mod:`.topologies`): each design's added
    mass, eq. 17's largest residual and the finder's, in ``details["topologies"]`` (the page
    draws them from there); returns the designs for :func:`design_loads`."""
    cw = spec.counterweights
    designs = topologies.designs(model, g, cw.proximal, cw.distal, memo)
    free = topologies.freedoms(g)
    out = []
    for d in designs:
        tag, name = topologies.tag(d.figure), topologies.whose(d.figure)
        added = d.model.total_mass() - base_mass
        res17, resf = topologies.eq17_residual(d.model, g), found.design_residual(d.model)
        params += [Parameter(f"added_mass_{tag}", added, "kg", "eq. 17", f"counter-masses of {name}"),
                   Parameter(f"eq17_residual_{tag}", res17, "", "eq. 17", f"largest relative residual of eq. 17, {name}"),
                   Parameter(f"finder_residual_{tag}", resf, "", "counted from the momentum at reachable states",
                             f"largest residual over the finder's conditions / (total mass x model size), {name}")]
        if max(res17, resf) > 1e-9:
            notes.append(f"{name[0].upper() + name[1:]}: the counter-masses found do not meet the conditions (eq. 17 residual "
                         f"{res17:.2g}, finder {resf:.2g}); the figure draws the design, which is not balanced.")
        out.append({"figure": d.figure, "design": name, "kept": [f"l{b}" if b != "5" else "platform" for b in d.kept],
                    "assumed": d.assumed, "added_mass": added, "eq17_residual": res17, "finder_residual": resf,
                    "counter_masses": [{"body": b.name, "mass": a.mass, "position": list(a.position)}
                                       for b in d.model.bodies for a in b.attachments if a.kind == "counterweight"]})
    details["topologies"] = {"designs": out, "freedoms": free, "admissible_kept": len(topologies.admissible_kept(g)),
                             "same_kind_per_leg_ranks": topologies.same_kind_per_leg_ranks(g)}
    notes.append(
        f"Figs. 3 and 4b from eq. 17: with the masses given, eq. 17 leaves {free['eq17']} first moments free "
        f"({free['eq17_links']} with the platform as built), the leg-by-leg family of Fig. 2a (every q_ij = 0) "
        f"{free['leg_by_leg']} ({free['leg_by_leg_links']}): the paper's six against three. Keeping three bodies as "
        f"built fixes the rest for {details['topologies']['admissible_kept']} of the 84 triples (no two links of one "
        "leg). The drawn designs and what each assumes are in the figures below."
    )
    return designs


def design_loads(designs: list[topologies.Design], rows: list[dict], stages: list, memo: Memo = compute) -> list[Parameter]:
    """The ``derived`` hook of the topology designs: each design analysed by the engine on the
    stages' time grid, with their gravity and moment point; its peak inertial shaking force and
    that peak over the reference force of the stage ratios (the unbalanced stage's inertial peak,
    :func:`balpipe.engine.load_reference.load_reference`), the stages' ``force_ratio``. Written
    into each design's row of ``details["topologies"]["designs"]`` (``rows``, in the order of
    ``designs``) and returned as parameters ``peak_force_ratio_<fig>``. ``stages``: the analysed
    stages (``StageResult``), the unbalanced one first; each analysis through ``memo``."""
    base = stages[0]
    an0 = base.analysis
    ref = load_reference(base.stage.model, an0).force
    out = []
    for d, row in zip(designs, rows, strict=True):
        peak = memo(peak_inertial_force, d.model, an0.t, an0.gravity, an0.moment_point)
        ratio = peak / ref if ref > 0 else 0.0
        row["peak_inertial_force"] = peak
        row["force_ratio"] = ratio
        out.append(Parameter(f"peak_force_ratio_{topologies.tag(d.figure)}", ratio, "", "engine",
                             f"peak inertial shaking force of {topologies.whose(d.figure)} / the reference force"))
    return out


def peak_inertial_force(model: Model, t: np.ndarray, gravity, moment_point) -> float:
    """The peak inertial shaking force of ``model`` analysed by the engine on ``t`` (a function of
    plain data: :func:`design_loads` reads it from the build's cache, :mod:`balpipe.cache.balance`)."""
    return analyse(model, t, gravity, moment_point).max_inertial_force


def finder_grid(model: Model, samples: int = 9) -> np.ndarray:
    """Instants of the platform's move (the finder samples states around the configurations there)."""
    law = getattr(model.drivers[0].law, "pose", (None,))[0]
    return np.linspace(0.0, float(getattr(law, "duration", 1.0)), samples)


def finder_stage(mech: RRR4Mechanism, spec: RRR4Balancing, model: Model, lbl: Model, stages: list,
                 params: list, notes: list, details: dict, page: bool = True,
                 memo: Memo = compute) -> generic.FinderCheck:
    """The generic condition finder on the model: its count, eq. 17's rows and the
    leg-by-leg design checked against its space, the translating-platform count of the special
    kinematics (with ``page`` only: its parameters, note and details are shown, no stage uses
    it), and (``spec.least_mass``) the least-mass stage after the leg-by-leg one."""
    legs = resolve_legs(mech)
    four = len(legs) == 4
    g = geometry(mech) if four else None
    special = page and four and mech.kinematics != "general" and not platform_rotates(model)
    found = memo(generic.check, model, finder_grid(model), cond.eq17(g) if four else [],
                 cond.special(g, mech.kinematics) if special else None)  # the build's cache
    gen = found.general
    src = "counted from the momentum at reachable states"
    params += [
        Parameter("finder_conditions", gen.count, "", src, "independent force-balance conditions found by the generic "
                  "condition finder (every motion)"),
        Parameter("finder_gap", gen.gap, "", src, "how clearly the conditions stand out from round-off (larger is clearer)"),
        Parameter("leg_by_leg_in_finder_space", found.design_residual(lbl), "", src,
                  "largest residual of the leg-by-leg design over the finder's conditions / (total mass x model size)"),
    ]
    details["finder"] = gen.to_json(generic.R.parameters(model))
    if four:
        params.append(Parameter("eq17_in_finder_space", float(found.eq17.max()), "", "eq. 17",
                                "largest distance of eq. 17's printed rows from the finder's space (relative)"))
        details["finder"]["eq17_in_space"] = {r.name: float(v) for r, v in zip(cond.eq17(g), found.eq17)}
    if special:
        tr = found.translating
        eq = cond.SPECIAL_EQ[mech.kinematics]
        params += [
            Parameter("translating_conditions", tr.count, "", src, "independent force-balance conditions for "
                      "translating-platform motions (finder on states of such motions only)"),
            Parameter("translating_gap", tr.gap, "", src, "last kept / first dropped singular value, translating"),
            Parameter("translating_in_printed_span", float(found.special_in_printed.max()), "", eq,
                      f"largest distance of the finder's translating conditions from the span of {eq}'s eight"),
            Parameter("printed_reduced_conditions", found.reduced_count, "", eq,
                      f"{eq}'s eight with m5 p5 and m5 q5 eliminated: independent combinations left"),
            Parameter("printed_reduced_in_translating", float(found.reduced_in_translating.max()), "", eq,
                      "their largest distance from the finder's translating space"),
        ]
        details["finder_translating"] = tr.to_json(generic.R.parameters(model))
        details["finder_translating"]["printed_in_space"] = {
            r.name: float(v) for r, v in zip(cond.special(g, mech.kinematics), found.printed_in_translating)}
        notes.append(
            f"Special kinematics ({mech.kinematics}) with a translating platform: the generic finder, run on states "
            f"of translating-platform motions only, finds {tr.count} independent conditions where the paper prints "
            f"{len(cond.SPECIAL_ROWS[mech.kinematics])} ({eq}). The printed ones are sufficient: each computed "
            f"condition is a combination of them (distance {numbers.num_at(found.special_in_printed.max(), 1.0, 2)}). Two of them only "
            "fix m5 p5 and m5 q5, i.e. how the paper splits the platform's mass m5 into point masses mu_5i at the "
            "joints C_i; with a translating platform every C_i has the platform's velocity, so the split does not "
            f"matter. Eliminating m5 p5 and m5 q5 from the printed rows leaves {found.reduced_count} combinations, "
            f"which span the computed space (distance {numbers.num_at(found.reduced_in_translating.max(), 1.0, 2)})."
        )
    if spec.least_mass:
        radii = {f"link{i}{j}": (spec.counterweights.proximal if j == 1 else spec.counterweights.distal)
                 for i in legs for j in (1, 2)}
        lm, sol = generic.least_mass(model, radii, gen)
        k = [s.name for s in stages].index("leg_by_leg") + 1
        stages.insert(k, Stage("least_mass", "least-mass counter-masses (generic conditions)", lm,
                               "one counter-mass per link within the leg-by-leg distance of its proximal joint "
                               "(proximal %.4g m, distal %.4g m), least total mass meeting the finder's %d conditions"
                               % (spec.counterweights.proximal, spec.counterweights.distal, gen.count), "force"))
        added_lbl = lbl.total_mass() - model.total_mass()
        params.append(Parameter("added_mass_least_mass", sol.total_mass, "kg", "least added mass (linprog)",
                                "counter-masses of the least-mass design"))
        for cw in sol.counterweights:
            ij = cw.region.body[4:]
            params += [
                Parameter(f"m_lm{ij}", cw.mass, "kg", "least added mass (linprog)", f"least-mass counter-mass on {link_name(ij)}"),
                Parameter(f"x_lm{ij}", cw.position[0], "m", "least added mass (linprog)", f"its position along {link_name(ij)}"),
                Parameter(f"y_lm{ij}", cw.position[1], "m", "least added mass (linprog)", f"its position normal to {link_name(ij)}"),
            ]
        saved = added_lbl - sol.total_mass
        same = abs(saved) <= 1e-9 * max(added_lbl, 1e-300)
        notes.append(
            f"Generic condition finder: {gen.count} independent force-balance conditions ({clarity_text(gen.gap)})" + (f"; each of eq. 17's twelve printed conditions lies in their space (largest "
                                 f"distance {numbers.num_at(found.eq17.max(), 1.0, 2)})" if four else "")
            + f"; the leg-by-leg design meets them (residual {numbers.num_at(found.design_residual(lbl), 1.0, 2)}). The least-mass "
            f"counter-masses within the same distances of the proximal joints add {sol.total_mass:.6g} kg, the "
            f"leg-by-leg ones {added_lbl:.6g} kg: "
            + ("the same mass: the leg-by-leg design is already of least mass for these positions." if same
               else f"{saved:.6g} kg less.")
        )
        details["least_mass"] = {"total_mass": sol.total_mass, "leg_by_leg_mass": added_lbl,
                                 "counter_masses": [{"body": c.region.body, "mass": c.mass, "position": list(c.position),
                                                     "region": c.region.describe()} for c in sol.counterweights]}
    return found


def eq17_residuals(mech: RRR4Mechanism, model: Model) -> list[tuple[cond.LinearCondition, float]]:
    """Eq. 17's twelve conditions for this geometry, each with its residual (kg m) for the mass
    distribution of ``model`` (a stage of a four-legged n-RRR)."""
    p = mass_parameters(model)
    return [(r, r.residual(p)) for r in cond.eq17(geometry(mech))]


def _notation() -> dict:
    from ...notation import Sym, ours, setting

    return {
        "balancing.counterweights.proximal": ours("d_{i1}", "distance of the counter-mass on each link l_{i1} from A_i (Fig. 2a)"),
        "balancing.counterweights.distal": ours("d_{i2}", "distance of the counter-mass on each link l_{i2} from B_i (Fig. 2a)"),
        "balancing.platform_split[<k>]": Sym("μ_{5,<k>}", "the platform's point mass at C of the <k>-th leg present (eqs. 2-4)"),
        "balancing.platform_split": Sym("μ_{5i}", "the platform's point masses at the C_i (eqs. 2-4)"),
        "balancing.independent": Sym("p_{i2} kept", "distal links whose p_{i2} stays as built (Sec. II.B-D, Figs. 2b-d)"),
        "balancing.topologies": setting("eq. 17 / 19 designs", "also build the eq. 17 design (Fig. 4a) and eq. 19/21's (Fig. 6)"),
        "balancing.least_mass": setting("least mass", "also build the least-mass design (generic condition finder + linprog)"),
    }

#: Paper 001's symbols (eqs. 2-11, Fig. 2) for this method's inputs.
NOTATION = _notation()
