"""The ``force_balance`` method, for any model (every template, ``custom`` included): the
force-balance conditions from the linear-momentum regressor (:mod:`.conditions`, paper 001's
route) and the counterweights of least added mass in the regions the spec allows
(:mod:`.least_mass`). Stages: ``unbalanced``, ``counterweights``.
"""

from __future__ import annotations

import numpy as np

from ..display import numbers
from ..model import Model, Vec2
from ..spec_parts import SpecFieldError
from . import conditions as C
from . import least_mass as LM
from . import regressor as R
from .base import BalanceResult, Parameter, Stage
from .context import BalanceContext
from .made_parts import inertia_of, part_for, part_notation
from .parts import add_counterweight
from .specs import CounterweightRegionSpec, FinderSettings, ForceBalance, Point


def body_point(model: Model, body: str, p: Point, path: tuple) -> Vec2:
    """The coordinates, in ``body``'s frame, of a spec point: an (x, y) pair as given, or the name
    of one of the body's points. Raises :class:`SpecFieldError` at ``path`` for an unknown body or
    point."""
    if not isinstance(p, str):
        return (float(p[0]), float(p[1]))
    try:
        b = model.body(body)
    except KeyError:
        raise SpecFieldError(path, f"unknown body {body!r}") from None
    if p not in b.points:
        raise SpecFieldError(path, f"body {body!r} has no point {p!r} (known: {', '.join(b.points) or 'none'})")
    return tuple(b.points[p])


def regions_from_spec(model: Model, specs: list[CounterweightRegionSpec], root: tuple) -> list[LM.Region]:
    names = [b.name for b in model.bodies]
    out, seen = [], set()
    for k, s in enumerate(specs):
        path = root + (k,)
        if s.body not in names:
            raise SpecFieldError(path + ("body",), f"unknown body {s.body!r} (bodies: {', '.join(names)})")
        name = s.name or f"cw_{s.body}"
        if name in seen:
            raise SpecFieldError(path + ("name",), f"counterweight name {name!r} used twice: name them")
        seen.add(name)
        if s.at is not None:
            out.append(LM.Region(name, s.body, "point", (body_point(model, s.body, s.at, path + ("at",)),)))
        elif s.segment is not None:
            pts = tuple(body_point(model, s.body, p, path + ("segment", i)) for i, p in enumerate(s.segment))
            out.append(LM.Region(name, s.body, "segment", pts))
        else:
            c = body_point(model, s.body, s.disc.centre, path + ("disc", "centre"))
            out.append(LM.Region(name, s.body, "disc", (c,), s.disc.radius))
    return out


def made(model: Model, specs: list[CounterweightRegionSpec], placed: list, root: tuple) -> dict:
    """The parts of the counterweights ``placed`` (:class:`.least_mass.Placed`, in the order of
    ``specs``) whose spec entries have a ``part:``, by counterweight name."""
    out = {}
    for k, (s, cw) in enumerate(zip(specs, placed)):
        if s.part is not None:
            axis = body_point(model, cw.region.body, s.part.axis, root + (k, "part", "axis"))
            out[cw.region.name] = part_for(model, cw.region.body, cw.region.name, s.part, cw.mass, cw.position, axis,
                                           root + (k, "part"))
    return out


def force_stage(model: Model, specs: list[CounterweightRegionSpec], settings: FinderSettings,
                t: np.ndarray, root: tuple = ("balancing", "counterweights"), prefix: str = ""):
    """Conditions of ``model``, least-mass counterweights and the counterweighted model; a
    counterweight made as a part has the part's centroidal inertia (a point mass otherwise).

    Returns (model with counterweights, parameters, details for results.json, notes, parts)."""
    cond = C.find(model, t, settings.rank_tolerance, settings.samples, settings.seed)
    p0 = R.parameters(model)
    regions = regions_from_spec(model, specs, root)
    try:
        sol = LM.solve(model, cond, regions, settings.polygon_sides)
    except LM.Infeasible as exc:
        raise SpecFieldError(root, str(exc)) from None
    out = model
    params = [Parameter(f"{prefix}force_conditions", cond.count, "", "counted from the momentum at reachable states",
                        "independent force-balance conditions")]
    parts = made(model, specs, sol.counterweights, root)
    for cw in sol.counterweights:
        if cw.mass > 0:
            inertia = inertia_of(parts[cw.region.name], 0.0) if cw.region.name in parts else 0.0
            out = add_counterweight(out, cw.region.body, cw.region.name, cw.mass, cw.position, inertia)
        d = f"{cw.region.name} on {cw.region.body}, {cw.region.describe()}"
        params += [
            Parameter(f"{prefix}{cw.region.name}.mass", cw.mass, "kg", "least added mass (linprog)", d),
            Parameter(f"{prefix}{cw.region.name}.x", cw.position[0], "m", "least added mass (linprog)", f"{cw.region.name}: x in {cw.region.body}'s frame"),
            Parameter(f"{prefix}{cw.region.name}.y", cw.position[1], "m", "least added mass (linprog)", f"{cw.region.name}: y in {cw.region.body}'s frame"),
        ]
    params.append(Parameter(f"{prefix}counterweight_mass", sol.total_mass, "kg", "least added mass (linprog)", "total mass of the counterweights"))
    details = cond.to_json(p0)
    details.update({
        "counterweights": [
            {"name": c.region.name, "body": c.region.body, "region": c.region.describe(), "mass": c.mass,
             "position": list(c.position)} for c in sol.counterweights
        ],
        "total_mass": sol.total_mass,
        "polygon_sides": sol.polygon_sides,
        "disc_accuracy": sol.disc_accuracy,
        "residual_after": sol.residual,
        "least_mass_unique": sol.unique,
    })
    notes = [
        f"{cond.count} independent force-balance conditions, found numerically from {cond.samples} states the "
        f"mechanism can reach ({cond.dof} degree{'s' if cond.dof != 1 else ''} of freedom; {C.clarity_text(cond.gap)}, "
        f"larger is clearer). The counterweights of least added mass total {sol.total_mass:.6g} kg"
        + (f"; disc regions are replaced by inscribed {sol.polygon_sides}-gons (within "
           f"{numbers.num(sol.disc_accuracy, 2)} of their radius)" if any(r.kind == "disc" for r in regions) else "")
        + "."
    ] + LM.tie_note(sol)
    return out, params, details, notes, tuple(parts.values())


def balance(ctx: BalanceContext) -> BalanceResult:
    method: ForceBalance = ctx.balancing
    model, t = ctx.model, ctx.t
    cw_model, params, details, notes, parts = force_stage(model, method.counterweights, method, t)
    stages = [
        Stage("unbalanced", "unbalanced", model, "the mechanism as given"),
        Stage("counterweights", "least-mass counterweights", cw_model,
              "counterweights of least added mass meeting every force-balance condition", balances="force",
              parts=parts),
    ]
    return BalanceResult(params, stages, notes, details={"force_balance": details})


def counterweight_notation(counterweights: list[CounterweightRegionSpec], root: str = "balancing") -> dict:
    """Symbols of the allowed counterweight regions, named after each counterweight:
    r_<name> for a fixed position, its segment's ends, its disc's centre and radius."""
    from ..notation import ours

    table = {}
    for k, c in enumerate(counterweights):
        p, n = f"{root}.counterweights[{k}]", c.name or f"cw_{c.body}"
        table.update({
            f"{p}.body": ours(f"`{n}`", f"the body that carries `{n}`"),
            f"{p}.at": ours(f"r_{{{n}}}", f"position of `{n}` on `{c.body}` (fixed)"),
            f"{p}.segment[0]": ours(f"`{n}`", f"`{n}` anywhere on a segment of `{c.body}`: first end"),
            f"{p}.segment[1]": ours(f"`{n}`", f"`{n}` anywhere on a segment of `{c.body}`: second end"),
            f"{p}.disc.centre": ours(f"`{n}`", f"`{n}` anywhere in a disc on `{c.body}`: its centre"),
            f"{p}.disc.radius": ours(f"`{n}`", f"`{n}` anywhere in a disc on `{c.body}`: its radius"),
            **part_notation(f"{p}.part", n),
        })
    return table


def notation(method: ForceBalance) -> dict:
    """Symbols of this method's inputs, named after the spec's counterweights."""
    return counterweight_notation(method.counterweights)
