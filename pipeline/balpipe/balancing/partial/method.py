"""The ``partial_balance`` method, for any model (``custom`` included): counterweights in regions
of named links and counter-rotating discs chosen by a second-order cone programme
(:mod:`.partial_program`, solved by :mod:`.partial_active`) on the affine maps of the loads
(:mod:`.partial_maps`), to global optimality at the analysed motion; Pareto fronts
(:mod:`.partial_fronts`) for the page.

Several motions at once (``motions``: the same machine at other speeds, other trajectories): each
is analysed on its own time grid (the registry rebuilds the unbalanced model with its laws), its
loads are affine maps of the same design variables, and a term over several motions is the
largest of its per-motion measures (:mod:`.partial_motions`).

Stages: ``unbalanced``, ``partial`` (the optimum's parts added). The details for results.json hold
the objective achieved, each term, the active constraints, the budget's sensitivity (the dual
value: d objective / d mass budget), the fronts (read from the build's cache when their inputs
did not change: :mod:`balpipe.cache.balance`) and, per motion, the terms, caps and peaks.

Requests that cannot be met are located errors before any stage is analysed: a region outside
its link (farther than :data:`REACH` x the link's size from the link's frame origin), a non-convex
polygon, a part on a body that neither accelerates nor turns, a name that is not an actuator or a
joint, and caps that no design within the budget meets (the error gives the least mass that does).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import replace

import numpy as np

from ...display import numbers
from ..context import BalanceContext
from ...mechanics.planar import cross
from ...model import Model
from ...notation import COMMON, ours, setting
from ...spec_parts import SpecFieldError
from . import fronts as PF
from . import motions as PMo
from ..load_measures import goal_label, term_notation
from ..base import Aim, BalanceResult, Goal, Parameter, Stage
from ..force_balance import body_point, counterweight_notation, regions_from_spec
from ..moment_balance import add_discs, counter_rotation_notation
from .maps import NO_PART, DiscVars, Maps, PartVars, build, coulomb_friction
from .active import ActiveProgram
from .program import Term
from .spec import PartialBalance, PartialCounterweightSpec
from ..regressor import model_size

REACH = 2.0  # a region must lie within this multiple of its link's size from the link's origin
ACTIVE = 1e-6  # relative slack below which a constraint is reported active
ROOT = ("balancing",)


def _link_size(model: Model, body: str) -> float:
    b = model.body(body)
    r = [math.hypot(*p) for p in b.points.values()] + [math.hypot(*b.com)]
    return max(r + [1e-3 * model_size(model)])


def _polygon(model: Model, s: PartialCounterweightSpec, path: tuple) -> tuple:
    V = np.array([body_point(model, s.body, p, path + ("polygon", i)) for i, p in enumerate(s.polygon)])
    e = np.roll(V, -1, axis=0) - V
    turn = cross(e, np.roll(e, -1, axis=0))
    if not (np.all(turn > 0) or np.all(turn < 0)):
        raise SpecFieldError(path + ("polygon",), "the polygon must be convex with its vertices in order (no three collinear)")
    return tuple(map(tuple, V))


def parts_from_spec(model: Model, method: PartialBalance) -> tuple[Model, list[PartVars], list[DiscVars]]:
    """The model with the discs (zero inertia) and the design variables, every region checked
    (bodies, names and points as :func:`.force_balance.regions_from_spec` checks them; a polygon
    stands there as its first vertex)."""
    root = ROOT + ("counterweights",)
    specs = method.counterweights
    polygons = {k: _polygon(model, s, root + (k,)) for k, s in enumerate(specs) if s.polygon is not None}
    proxies = [s if s.polygon is None else s.model_copy(update={"polygon": None, "at": s.polygon[0]}) for s in specs]
    parts = []
    for k, r in enumerate(regions_from_spec(model, proxies, root)):
        kind, pts = ("polygon", polygons[k]) if k in polygons else (r.kind, r.points)
        far = max(math.hypot(*p) for p in pts) + r.radius
        size = _link_size(model, r.body)
        if far > REACH * size:
            raise SpecFieldError(root + (k, kind if kind != "point" else "at"),
                                 f"the region reaches {far:.4g} m from {r.body!r}'s frame origin, outside the link "
                                 f"(at most {REACH:g} x its size {size:.4g} m)")
        parts.append(PartVars(r.name, r.body, kind, pts, r.radius, specs[k].max_mass, 4 * len(parts)))
    with_discs = add_discs(model, method.counter_rotations, ROOT + ("counter_rotations",))
    discs = [DiscVars(s.name, float(s.mass), s.max_inertia, 4 * len(parts) + k) for k, s in enumerate(method.counter_rotations)]
    return with_discs, parts, discs


def _check_names(motions: Sequence[Maps], method: PartialBalance) -> None:
    maps = motions[0]
    joints = [j.name for j in maps.model.joints]
    for key, terms in (("objective", method.objective), ("caps", method.caps)):
        for k, t in enumerate(terms):
            if t.load == "effort" and t.actuator and t.actuator not in maps.drivers:
                raise SpecFieldError(ROOT + (key, k, "actuator"), f"no actuator {t.actuator!r} (actuators: {', '.join(maps.drivers) or 'none'})")
            if t.load == "effort" and not maps.drivers:
                raise SpecFieldError(ROOT + (key, k, "load"), "the mechanism has no actuator")
            if t.load == "joint" and t.joint not in joints:
                raise SpecFieldError(ROOT + (key, k, "joint"), f"no joint {t.joint!r} (joints: {', '.join(joints)})")
    for k, p in enumerate(maps.parts):
        if not any(m.moving[p.body] for m in motions):
            raise SpecFieldError(ROOT + ("counterweights", k, "body"),
                                 f"{p.body!r} neither accelerates nor turns during the motion{'s' if len(motions) > 1 else ''}: "
                                 "a part on it changes no load")


def _motions(maps: Maps | Sequence[Maps]) -> list[Maps]:
    return [maps] if isinstance(maps, Maps) else list(maps)


def term_of(maps: Maps | Sequence[Maps], t, weight: float = 1.0) -> Term:
    """The term ``t`` of the spec over one motion's maps or several (the largest of theirs)."""
    label = t.load + (f" {t.actuator}" if t.actuator else "") + (f" {t.joint}" if t.joint else "")
    loads = tuple(L for m in _motions(maps) for L in m.load(t.load, t.actuator, t.joint))
    return Term(loads, t.measure, weight, f"{t.measure} {label}")


def standard_terms(maps: Maps | Sequence[Maps]) -> dict[str, Term]:
    """The peaks the fronts and the tables report: force, moment, effort (all actuators), over
    one motion or several."""
    motions = _motions(maps)
    out = {k: Term(tuple(m.loads[k] for m in motions), "peak", 1.0, f"peak {k}") for k in ("shaking_force", "shaking_moment")}
    if motions[0].drivers:
        out["effort"] = Term(tuple(L for m in motions for L in m.load("effort")), "peak", 1.0, "peak effort")
    return out


def _infeasible(program: ActiveProgram, caps: list, method: PartialBalance) -> SpecFieldError:
    """Why nothing meets the caps within the budget: the least mass that does, if any."""
    out = program.least_mass(caps=caps)
    what = "; ".join(f"{t.label} <= {b:g} x unbalanced" for t, b in caps)
    if out.z is None:
        return SpecFieldError(ROOT + ("caps",), f"no design of these parts (within their bounds) meets the caps ({what}) at any added mass")
    return SpecFieldError(ROOT + ("budget", "mass"),
                          f"a budget of {method.budget.mass:.6g} kg is too small for the caps ({what}): "
                          f"they need at least {program.maps.added_mass(out.z):.6g} kg")


def solve(maps: Maps | Sequence[Maps], method: PartialBalance):
    """The optimum over one motion's maps or several: (program, outcome, objective terms, caps as
    (term, bound)). Where it leaves part of the budget unused (more mass would not help), the
    design is the lightest with each objective term at its optimal value and the caps met, not
    whichever of the optimal designs the solver returned (for one RMS term, exactly: the designs
    with the optimum's load at every sample, :meth:`.active.ActiveProgram.lightest_alike`)."""
    program = ActiveProgram(_motions(maps)[0], method.budget.inertia)
    objective = [term_of(maps, t, t.weight) for t in method.objective]
    caps = []
    for c in method.caps:
        t = term_of(maps, c)
        caps.append((t, c.at_most if c.relative else c.at_most / t.scale))
    budget = float(method.budget.mass)
    out = program.solve(objective, budget, eps=caps, polish=objective)
    if out.z is None:
        raise _infeasible(program, caps, method) if caps else SpecFieldError(
            ROOT + ("budget", "mass"), f"no design within the budget ({out.status})")
    if program.unused(out.z, budget):  # the lightest of the optimal designs
        alike = None
        if len(objective) == 1 and objective[0].kind == "rms" and len(objective[0].maps) == 1:
            alike = program.lightest_alike(objective[0], out.z, caps)
        if alike is not None and alike.z is not None:
            out = replace(out, z=alike.z, precision=alike.precision)
        else:  # the objective's bound relaxed by the solver's tolerance: the design to about its root
            out = replace(out, z=program.lightest([(t, t.value(out.z) / t.scale) for t in objective], out.z, caps),
                          precision=None)
    return program, out, objective, caps


def active_constraints(program: ActiveProgram, z: np.ndarray, method: PartialBalance, caps: list) -> list[str]:
    maps = program.maps
    out = []
    if maps.added_mass(z) >= method.budget.mass * (1 - ACTIVE) - 1e-12:
        out.append(f"mass budget ({method.budget.mass:.6g} kg)")
    if program.inertia_budget is not None:
        used = sum(z[p.col + 3] for p in maps.parts) + sum(z[d.col] for d in maps.discs)
        if used >= method.budget.inertia * (1 - ACTIVE) - 1e-15:
            out.append(f"inertia budget ({method.budget.inertia:.6g} kg m^2)")
    bounds = [(p.name, p.col, p.max_mass) for p in maps.parts] + [(d.name, d.col, d.max_inertia) for d in maps.discs]
    for name, col, bound in bounds:
        if bound is not None and z[col] >= bound * (1 - ACTIVE):
            out.append(f"{name} at its bound ({bound:.6g})")
    for t, bound in caps:
        if t.value(z) / t.scale >= bound * (1 - ACTIVE):
            out.append(f"cap: {t.label} = {bound:g} x unbalanced")
    for p in maps.parts:
        m = z[p.col]
        if p.kind == "disc" and m > 0:
            c = z[p.col + 1 : p.col + 3] / m
            if math.hypot(*(c - np.asarray(p.points[0]))) >= p.radius * (1 - ACTIVE):
                out.append(f"{p.name} on the edge of its disc")
    return out


def motion_maps(ctx: BalanceContext) -> list[Maps]:
    """The load maps of the spec's motion, then of each of ``method.motions`` (their models are
    built by ``ctx.models``, and their errors found, before any analysis), every region and name
    checked; with the context's gravity and moment point."""
    method: PartialBalance = ctx.balancing
    model, t, gravity, point = ctx.model, ctx.t, ctx.gravity, ctx.moment_point
    if coulomb_friction(model):
        raise SpecFieldError(ROOT + ("method",), f"partial_balance needs loads affine in the parts' masses; the Coulomb "
                             f"friction of {', '.join(coulomb_friction(model))} depends on the joints' reactions: give it "
                             "as viscous friction, or balance by another method")
    with_discs, parts, discs = parts_from_spec(model, method)
    others = PMo.other_models(method, ctx.models, ROOT)
    motions = [build(with_discs, model, t, parts, discs, gravity, point)]
    for m, tm in others:
        motions.append(build(add_discs(m, method.counter_rotations, ROOT + ("counter_rotations",)), m, tm, parts, discs,
                             gravity, point))
    _check_names(motions, method)
    return motions


def balance(ctx: BalanceContext) -> BalanceResult:
    """The optimum's stage; ``ctx.models(motion, samples, path)`` gives the unbalanced model and
    time grid of each of ``method.motions`` (:func:`balpipe.registry.motion_model`); the fronts
    go through ``ctx.memo``."""
    method: PartialBalance = ctx.balancing
    model, t = ctx.model, ctx.t
    motions = motion_maps(ctx)
    maps = motions[0]
    program, out, objective, caps = solve(motions, method)
    z = out.z
    std = standard_terms(motions)
    design = maps.design(z)
    active = active_constraints(program, z, method, caps)
    terms = [{"term": t.label, "weight": t.weight, "value": t.value(z), "unbalanced": t.scale,
              "ratio": t.value(z) / t.scale} for t in objective]
    details = {
        "objective": float(sum(t.weight * t.value(z) / t.scale for t in objective)),
        "terms": terms,
        "caps": [{"term": t.label, "at_most": b, "value": t.value(z) / t.scale} for t, b in caps],
        "active": active,
        "budget": {"mass": method.budget.mass, "inertia": method.budget.inertia},
        "sensitivity": out.budget_dual,
        "added_mass": maps.added_mass(z),
        "peaks": {k: v.value(z) for k, v in std.items()},
        "unbalanced": {k: v.scale for k, v in std.items()},
        "status": out.status,
        "solver": "Clarabel, active samples",
        "precision": precision_text(out.precision),
        "relative_error": out.precision,
        "design": design_table(maps, z),
        "motions": PMo.per_motion(motions, PMo.names(method), objective, caps, std, z),
    }
    if method.fronts is not None:
        details["fronts"] = ctx.memo(PF.fronts, maps, method.budget.inertia, std, method.budget.mass,
                                              method.fronts.points, method.fronts.max_mass)
    source = f"cone programme (Clarabel), {precision_text(out.precision)}"
    params = [Parameter(f"{r['name']}.{k}", r[k], u, source, f"{r['name']} on {r['body']}")
              for r in details["design"] for k, u in (("mass", "kg"), ("x", "m"), ("y", "m"), ("inertia", "kg m^2"))
              if k in r]
    params += [
        Parameter("added_mass", details["added_mass"], "kg", "cone programme (Clarabel)", "mass of the parts"),
        Parameter("objective", details["objective"], "", "cone programme (Clarabel)",
                  "sum of weight x term / unbalanced term at the optimum"),
        Parameter("budget_sensitivity", out.budget_dual, "1/kg", "dual value of the mass budget",
                  "change of the objective per kg more budget"),
    ]
    over = f"the {len(t)} time samples" if len(motions) == 1 else (
        f"{len(motions)} motions ({', '.join(f'{n}: {len(m.t)} samples' for n, m in zip(PMo.names(method), motions))}; "
        "a term is the largest of its values on each motion)")
    notes = [
        "Optimal partial balancing by a second-order cone programme over "
        f"{over}: objective {' + '.join(f'{x.weight:g} x {x.label}' for x in objective)} "
        f"(each divided by its unbalanced value) = {details['objective']:.6g} with {details['added_mass']:.6g} kg added; "
        f"active: {', '.join(active) or 'none'}; d objective / d budget = {numbers.num_at(out.budget_dual, 1.0 / max(model.total_mass(), 1e-12))} per kg; "
        f"the design {precision_text(out.precision)}."
    ] + PMo.notes(details["motions"])
    label = method.label or "partial balance"
    stages = [Stage("unbalanced", "unbalanced", model, "the mechanism as given"),
              Stage("partial", label, design, aim=aim_of(maps, method, objective, caps, z, out), description="parts chosen by the cone programme (global optimum at this motion)"
                    if len(motions) == 1 else f"parts chosen by the cone programme (global optimum over {len(motions)} "
                    "motions; analysed and validated on the spec's motion)")]
    return BalanceResult(params, stages, notes, details={"partial_balance": details})


def aim_of(maps: Maps, method: PartialBalance, objective: list[Term], caps: list, z: np.ndarray, out) -> Aim:
    """What the partial stage aimed at: each objective term and cap at the design and unbalanced
    (over every motion), and, where the design adds nothing, why: a zero budget, or no part in
    the regions that lowers the objective within the caps (the optimum is the mechanism as given)."""
    unit = lambda t: t.maps[0].unit  # noqa: E731
    goals = [Goal(goal_label(s), "objective", t.value(z), t.scale, unit(t), None, s.load)
             for s, t in zip(method.objective, objective)]
    goals += [Goal(goal_label(s), "cap", t.value(z), t.scale, unit(t), b, s.load) for s, (t, b) in zip(method.caps, caps)]
    why = ""
    # a part below the solver's round-off (1e-9 of the budget or of 1 kg) is none
    added = (maps.added_mass(z) - maps.fixed_mass > 1e-9 * max(method.budget.mass, 1.0)
             or any(z[d.col] > 1e-12 for d in maps.discs))
    if not added:
        if method.budget.mass <= maps.fixed_mass:
            why = f"the mass budget ({method.budget.mass:g} kg) is zero" if method.budget.mass <= 0 else (
                f"the mass budget ({method.budget.mass:g} kg) is spent on the discs' own mass")
        elif method.budget.inertia is not None and method.budget.inertia <= 0:
            why = "the inertia budget is zero"
        else:
            why = ("no part in these regions lowers the objective" + (" within the caps" if caps else "")
                   + ": the mechanism as given is the optimum, and more budget would not lower it")
    return Aim(tuple(goals), why)


def precision_text(error: float | None) -> str:
    """How exact a design is: polished on its active set, its relative error bounded by ``error``;
    else the interior-point solver's own (its tolerance, 1e-10, on the objective)."""
    if error is not None:
        return (f"exact to {'round-off (relative error below 1e-9' if error <= numbers.FLOOR else numbers.num(error, 2) + ' (relative'}"
                "; optimality equations solved on the active set)")
    return ("to the solver's tolerance (objective to 1e-10; a design where the optimum is flat to about "
            "its square root, 1e-5)")


def design_table(maps: Maps, z: np.ndarray) -> list[dict]:
    """Each part of design z: mass, centre of mass, centroidal inertia (counterweights), inertia (discs)."""
    rows = []
    big = max([abs(z[p.col]) for p in maps.parts] + [1e-300])
    for p in maps.parts:
        m, sx, sy, J = (float(v) for v in z[p.col : p.col + 4])
        if m <= NO_PART * big:  # no part (as Maps.design): its position is undefined, show the region's first point
            m, (sx, sy), J = 0.0, p.points[0], 0.0
            x, y = sx, sy
        else:
            x, y = sx / m, sy / m
        rows.append({"name": p.name, "body": p.body, "region": p.kind, "mass": m, "x": x, "y": y,
                     "inertia": max(0.0, J - m * (x * x + y * y))})
    for d in maps.discs:
        rows.append({"name": d.name, "body": d.name, "region": "counter-rotation", "mass": d.mass,
                     "inertia": max(0.0, float(z[d.col]))})
    return rows


def notation(method: PartialBalance) -> dict:
    """Symbols of this method's inputs, named after its parts and terms."""
    table = {**counterweight_notation(method.counterweights),
             **counter_rotation_notation(method.counter_rotations, "balancing.counter_rotations"),
             **term_notation("balancing.objective", method.objective, "objective term"),
             **term_notation("balancing.caps", method.caps, "cap")}
    for k, c in enumerate(method.counterweights):
        n = c.name or f"cw_{c.body}"
        table[f"balancing.counterweights[{k}].max_mass"] = ours(f"m_{{{n},max}}", f"upper bound on the mass of `{n}`")
        table[f"balancing.counterweights[{k}].polygon"] = ours(f"`{n}`", f"`{n}` anywhere in a polygon on `{c.body}`")
    for k, d in enumerate(method.counter_rotations):
        table[f"balancing.counter_rotations[{k}].max_inertia"] = ours(f"I_{{{d.name},max}}", f"upper bound on the inertia of `{d.name}`")
    for k, m in enumerate(method.motions):  # a further motion's inputs read as the spec's motion's, named
        pre = f"balancing.motions[{k}]"
        table[f"{pre}.samples"] = setting(f"N_{{{m.name}}}", f"time samples over the motion `{m.name}`")
        table.update({f"{pre}.{key}": replace(sym, text=f"{sym.text} (motion `{m.name}`)")
                      for key, sym in COMMON.items() if key.startswith("motion.")})
    table.update({
        "balancing.budget.mass": ours("M_{max}", "added mass at most (counterweights and discs)"),
        "balancing.budget.inertia": ours("I_{max}", "added inertia at most (discs, counterweights' second moments)"),
        "balancing.fronts.points": setting("points", "points of each Pareto front"),
        "balancing.fronts.max_mass": ours("M_{front}", "the mass fronts' largest budget"),
        "balancing.label": setting("label", "label of the optimised stage"),
    })
    return table
