"""The ``moment_balance`` method, for any model: counterweights of least added mass for the force
(:mod:`.force_balance`), then counter-rotating discs geared to the bodies the spec names, whose
inertias cancel the angular momentum.

Once the force is balanced the angular momentum H is the same about every point and the shaking
moment is -dH/dt. Each disc d, pivoted at its centre on a carrier c (the frame or a moving link)
and geared to body g, w_d - w_c = ratio (w_g - w_c), adds J_d w_d to H; with the angular-momentum
regressor Y_H at sampled feasible states (:mod:`.regressor`),

    Y_H p + sum_d J_d Y_H[:, J_d] = 0

is a linear system in the disc inertias J_d, solved by least squares over the samples; its
relative residual |Y_H p_full| / |Y_H p_counterweights| says whether the chosen gears can cancel
the moment at all (the chained counter-rotations of paper 000 and the gears of papers 002 and
004 are instances). The discs' masses sit on their pivots and are counted by the force balance.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..display import numbers
from ..model import FRAME, Model
from ..spec_parts import SpecFieldError
from . import regressor as R
from . import conditions as C
from .base import BalanceResult, Parameter, Stage
from .context import BalanceContext
from . import least_mass as LM
from . import gear_signs as GS
from .force_balance import body_point, made, regions_from_spec
from .made_parts import inertia_of
from .parts import add_counter_rotation, add_counterweight
from .specs import CounterRotationSpec, MomentBalance

MOMENT_TOLERANCE = 1e-9  # relative least-squares residual below which the moment counts as cancelled


def add_discs(model: Model, specs: list[CounterRotationSpec], root: tuple) -> Model:
    names = [b.name for b in model.bodies]
    out = model
    for k, s in enumerate(specs):
        path = root + (k,)
        if s.name in names or s.name == FRAME:
            raise SpecFieldError(path + ("name",), f"name {s.name!r} is already a body")
        for key in ("carrier", "geared_to"):
            v = getattr(s, key)
            if v != FRAME and v not in names:
                raise SpecFieldError(path + (key,), f"unknown body {v!r} (bodies: {', '.join(names)}, frame)")
        at = body_point(model, s.carrier, s.at, path + ("at",)) if s.carrier != FRAME or not isinstance(s.at, str) else tuple(model.frame_points.get(s.at, (np.nan, np.nan)))
        if not np.all(np.isfinite(at)):
            raise SpecFieldError(path + ("at",), f"the frame has no point {s.at!r}")
        try:
            out = add_counter_rotation(out, s.name, carrier=s.carrier, at=at, geared_to=s.geared_to,
                                       ratio=s.ratio, inertia=0.0, mass=s.mass)
        except ValueError as exc:
            raise SpecFieldError(path + ("ratio",), str(exc)) from None
        if s.radius is not None:  # drawing only: the mesh stays a couple (no pitch radii, no tooth forces)
            out = out.replace_body(replace(out.body(s.name), radius=s.radius))
        names.append(s.name)
    return out


def solve_inertias(model: Model, discs: list[str], t: np.ndarray, samples: int = 0, seed: int = 0,
                   states: R.States | None = None) -> tuple[np.ndarray, float, int]:
    """Least-squares disc inertias cancelling the angular momentum of the force-balanced
    ``model`` (discs present with zero inertia). Returns (inertias, relative residual, samples).
    ``states`` may come from the same model with other masses (the kinematics do not depend on
    them)."""
    st = states if states is not None else R.sample_states(model, t, samples, seed)
    Y = R.angular_regressor(st)
    names = R.param_names(model, angular=True)
    p = R.parameters(model, angular=True)
    cols = [names.index(f"J[{d}]") for d in discs]
    for c in cols:
        p[c] = 0.0
    H0 = Y @ p
    x, *_ = np.linalg.lstsq(Y[:, cols], -H0, rcond=None)
    n0 = float(np.linalg.norm(H0))
    res = float(np.linalg.norm(H0 + Y[:, cols] @ x)) / n0 if n0 > 0 else 0.0
    return x, res, st.count


def set_disc_inertias(model: Model, inertias: dict[str, float]) -> Model:
    for name, value in inertias.items():
        model = model.replace_body(replace(model.body(name), inertia=float(value)))
    return model


def moment_conditions(model: Model, discs: list[str], t: np.ndarray, tolerance: float, samples: int = 0,
                      seed: int = 0, states: R.States | None = None) -> LM.MomentConditions:
    """The angular-momentum conditions of ``model`` (discs included): the row space of Y_H about
    the origin, in RREF with the discs' inertias as first pivots."""
    st = states if states is not None else R.sample_states(model, t, samples, seed)
    Y = R.angular_regressor(st)
    names = R.param_names(model, angular=True)
    rs = R.row_space(Y, C.column_scale(model, angular=True), tolerance)
    first = [names.index(f"J[{d}]") for d in discs]
    order = first + [k for k in range(len(names)) if k not in first]
    matrix, _ = C.rref(rs.basis, order, C.pivot_tolerance(rs.gap))
    return LM.MomentConditions(names, matrix, discs)


def balance(ctx: BalanceContext) -> BalanceResult:
    """The stages; where the spec's gear ratios cannot cancel the moment (a disc would need a
    negative inertia, or the residual stays above :data:`MOMENT_TOLERANCE`), the sign combination
    that does is searched (:mod:`.gear_signs`) and named, every disc at once: in the error, or in
    the notes of a stage that then claims the force only."""
    method: MomentBalance = ctx.balancing
    try:
        result = _balance(ctx)
    except SpecFieldError as exc:
        if exc.path[-1:] != ("ratio",) or "negative inertia" not in exc.message:
            raise
        found = _working(ctx)
        if found is None:
            raise SpecFieldError(exc.path, exc.message.split(": reverse")[0] + "; no other signs of the ratios "
                                 "cancel the moment either (other carriers, gear targets or ratios may)") from None
        if method.gear_signs == "find":
            return _found(ctx, found)
        raise SpecFieldError(("balancing", "counter_rotations"), f"{exc.message.split(': reverse')[0]} with these "
                             f"ratios; the ratios {_named(method, found)} cancel the moment: set them "
                             "(or gear_signs: find)") from None
    if result.stages[-1].balances != "force+moment":
        found = _working(ctx)
        if found is not None and method.gear_signs == "find":
            return _found(ctx, found)
        if found is not None:
            result.notes.insert(0, f"The gear ratios {_named(method, found)} cancel the moment (these do not): set them.")
    return result


def _with_ratios(ctx: BalanceContext, ratios) -> BalanceContext:
    method: MomentBalance = ctx.balancing
    discs = [s.model_copy(update={"ratio": r}) for s, r in zip(method.counter_rotations, ratios)]
    return replace(ctx, balancing=method.model_copy(update={"counter_rotations": discs}))


def _found(ctx: BalanceContext, ratios) -> BalanceResult:
    """The balance with the gear signs found (``gear_signs: find``), saying which they are."""
    method: MomentBalance = ctx.balancing
    result = _balance(_with_ratios(ctx, ratios))
    given = ", ".join(f"{s.ratio:+g}" for s in method.counter_rotations)
    result.notes.insert(0, f"Gear signs found (gear_signs: find): {_named(method, ratios)}; the spec's ({given}) "
                        "could not cancel the moment.")
    return result


def _named(method: MomentBalance, ratios) -> str:
    return GS.named([s.name for s in method.counter_rotations], ratios)


def _working(ctx: BalanceContext):
    """The sign combination of the spec's ratios with which the moment is cancelled, or None."""
    method: MomentBalance = ctx.balancing

    def cancels(ratios) -> bool:
        try:
            out = _balance(_with_ratios(ctx, ratios))
        except SpecFieldError:
            return False
        return out.stages[-1].balances == "force+moment"

    return GS.working_ratios([float(s.ratio) for s in method.counter_rotations], cancels)


def _balance(ctx: BalanceContext) -> BalanceResult:
    method: MomentBalance = ctx.balancing
    model, t = ctx.model, ctx.t
    root = ("balancing",)
    discs = [s.name for s in method.counter_rotations]
    with_discs = add_discs(model, method.counter_rotations, root + ("counter_rotations",))
    states = R.sample_states(with_discs, t, method.samples, method.seed)  # conditions of both momenta
    cond = C.find(with_discs, t, method.rank_tolerance, states=states)
    p0 = R.parameters(with_discs)
    if not method.counterweights:
        bad = [(eq, r) for eq, r in zip(cond.equations(), cond.residuals(p0)) if abs(r) > 1e-9 * C.scale_of(with_discs)]
        if bad:
            raise SpecFieldError(root + ("counterweights",), "the mechanism is not force balanced ("
                                 + "; ".join(f"{eq} is off by {r:.4g}" for eq, r in bad)
                                 + "): give counterweights")
    mc = moment_conditions(with_discs, discs, t, method.rank_tolerance, states=states)
    regions = regions_from_spec(with_discs, method.counterweights, root + ("counterweights",))
    unmet: list[tuple[str, float]] = []
    try:
        sol = LM.solve(with_discs, cond, regions, method.polygon_sides, moment=mc)
    except LM.Infeasible as exc:
        # the parts cannot cancel the moment for every motion: least-mass force balance, then
        # the least-squares discs (the stage claims the force only)
        unmet = [c for c in exc.conditions if c[0] in mc.equations()] or exc.conditions
        try:
            sol = LM.solve(with_discs, cond, regions, method.polygon_sides) if regions else LM.Solution([], 0.0, method.polygon_sides, 0.0, [])
        except LM.Infeasible as exc_force:
            raise SpecFieldError(root + ("counterweights",), str(exc_force)) from None
    balanced = with_discs
    # a counterweight made as a part has the part's own inertia, not the programme's spread one:
    # the discs' inertias below are solved with it
    parts = made(with_discs, method.counterweights, sol.counterweights, root + ("counterweights",))
    for cw in sol.counterweights:
        if cw.mass > 0:
            inertia = inertia_of(parts[cw.region.name], cw.inertia) if cw.region.name in parts else cw.inertia
            balanced = add_counterweight(balanced, cw.region.body, cw.region.name, cw.mass, cw.position, inertia)
    # the discs' inertias by least squares on the counterweighted model, over states sampled anew
    # (another seed): the residual says how exactly the angular momentum is cancelled beyond the
    # states the conditions came from
    inertias, residual, samples = solve_inertias(balanced, discs, t, method.samples, method.seed + 1)
    for k, (name, J) in enumerate(zip(discs, inertias)):
        if J < -1e-9 * max(1e-12, float(np.max(np.abs(inertias)))):
            raise SpecFieldError(
                root + ("counter_rotations", k, "ratio"),
                f"disc {name!r} would need a negative inertia ({J:.4g} kg m^2): reverse the sign of its ratio "
                "(it must turn against the angular momentum it cancels)",
            )
    inertias = np.maximum(inertias, 0.0)
    full = set_disc_inertias(balanced, dict(zip(discs, inertias)))
    cw_model = model
    for b in model.bodies:
        cw_model = cw_model.replace_body(balanced.body(b.name))
    for s in method.counter_rotations:
        if s.mass > 0 and s.carrier != FRAME:
            at = body_point(model, s.carrier, s.at, ())
            cw_model = add_counterweight(cw_model, s.carrier, f"{s.name} (mass)", s.mass, at)
    cancelled = residual <= MOMENT_TOLERANCE
    params = [Parameter("force_conditions", cond.count, "", "counted from the momentum at reachable states", "independent force-balance conditions"),
              Parameter("moment_conditions", len(mc.matrix), "", "counted from the angular momentum at reachable states",
                        "independent conditions on the angular momentum (discs' inertias included)")]
    for cw in sol.counterweights:
        d = f"{cw.region.name} on {cw.region.body}, {cw.region.describe()}"
        params += [
            Parameter(f"{cw.region.name}.mass", cw.mass, "kg", "least added mass (linprog)", d),
            Parameter(f"{cw.region.name}.x", cw.position[0], "m", "least added mass (linprog)", f"{cw.region.name}: x in {cw.region.body}'s frame"),
            Parameter(f"{cw.region.name}.y", cw.position[1], "m", "least added mass (linprog)", f"{cw.region.name}: y in {cw.region.body}'s frame"),
            Parameter(f"{cw.region.name}.inertia", inertia_of(parts[cw.region.name], cw.inertia), "kg m^2",
                      f"the {parts[cw.region.name].shape}'s own", f"{cw.region.name}: centroidal inertia of its part")
            if cw.region.name in parts and parts[cw.region.name].outline else
            Parameter(f"{cw.region.name}.inertia", cw.inertia, "kg m^2", "least added mass (linprog)",
                      f"{cw.region.name}: centroidal inertia (a mass spread over its region)"),
        ]
    params.append(Parameter("counterweight_mass", sol.total_mass, "kg", "least added mass (linprog)", "total mass of the counterweights"))
    for name, J, s in zip(discs, inertias, method.counter_rotations):
        params.append(Parameter(f"{name}.inertia", float(J), "kg m^2", "least squares on the angular momentum",
                                f"disc on {s.carrier}, geared to {s.geared_to} with ratio {s.ratio:g}"))
    params.append(Parameter("moment_residual", residual, "", "least squares on the angular momentum",
                            "|H| left by the discs / |H| of the counterweighted mechanism, over the samples"))
    if unmet:
        notes_unmet = [
            "No counterweights in the allowed regions with these counter-rotations can cancel the shaking "
            "moment for every motion; unmet angular-momentum condition(s): "
            + "; ".join(f"{eq} (left at {r:.4g})" for eq, r in unmet[:4]) + ("; ..." if len(unmet) > 4 else "")
            + ". The counterweights are those of least mass for the force alone and the discs' inertias the "
            "least-squares fit."
        ]
    else:
        notes_unmet = []
    notes = notes_unmet + [
        f"{cond.count} independent force-balance conditions and {len(mc.matrix)} on the angular momentum "
        f"(found numerically from {cond.samples} states the mechanism can reach; the force count includes each disc's own: its centre of mass on its axis). "
        + (f"Counterweights of least added mass ({sol.total_mass:.6g} kg) meeting both, with the discs' "
           "inertias, in one linear programme; a counterweight's inertia is that of its mass spread over its region."
           if not unmet else f"Counterweights of least added mass for the force: {sol.total_mass:.6g} kg."),
        f"Counter-rotation inertias re-solved by least squares over {samples} states the mechanism can reach: relative residual "
        f"{numbers.ratio(residual)}" + (" (the moment is cancelled for every motion)." if cancelled else
                             f", above {numbers.tol(MOMENT_TOLERANCE)}: the stage claims only the force."),
    ] + LM.tie_note(sol)
    details = {
        "force_balance": cond.to_json(R.parameters(model.add(tuple(b for b in with_discs.bodies if b.name in discs)))),
        "moment_balance": {
            "conditions": mc.equations(),
            "counterweights": [{"name": c.region.name, "body": c.region.body, "region": c.region.describe(),
                                "mass": c.mass, "position": list(c.position),
                                "inertia": inertia_of(parts[c.region.name], c.inertia) if c.region.name in parts else c.inertia}
                               for c in sol.counterweights],
            "discs": [{"name": n, "carrier": s.carrier, "geared_to": s.geared_to, "ratio": s.ratio, "mass": s.mass,
                       "inertia": float(J)} for n, J, s in zip(discs, inertias, method.counter_rotations)],
            "residual": residual, "samples": samples, "tolerance": MOMENT_TOLERANCE,
            "added_inertia": float(np.sum(inertias)), "total_mass": sol.total_mass,
            "polygon_sides": sol.polygon_sides, "disc_accuracy": sol.disc_accuracy,
            "unmet": [{"equation": eq, "residual": r} for eq, r in unmet],
        },
    }
    stages = [
        Stage("unbalanced", "unbalanced", model, "the mechanism as given"),
        Stage("counterweights", "counterweights", cw_model, "force balanced by counterweights", balances="force",
              parts=tuple(parts.values())),
        Stage("counter_rotations", "counterweights + counter-rotations", full,
              "counter-rotating discs with the inertias solved from the angular momentum",
              balances="force+moment" if cancelled else "force", parts=tuple(parts.values())),
    ]
    return BalanceResult(params, stages, notes, details=details)


def counter_rotation_notation(discs: list, root: str) -> dict:
    """Symbols of counter-rotating discs named after each disc: U_<disc>, m_<disc>, r_<disc>
    (and I_<disc> when the spec gives the inertia)."""
    from ..notation import ours

    table = {}
    for k, d in enumerate(discs):
        p, n = f"{root}[{k}]", d.name
        table.update({
            f"{p}.carrier": ours(f"`{n}`", f"body holding the axis of `{n}`"),
            f"{p}.at": ours(f"`{n}`", f"axis of `{n}` on its carrier"),
            f"{p}.geared_to": ours(f"`{n}`", f"the body `{n}` is geared to"),
            f"{p}.ratio": ours(f"U_{{{n}}}", f"ratio of `{n}`: (ω_{{disc}} − ω_{{carrier}}) / (ω_{{geared}} − ω_{{carrier}})"),
            f"{p}.mass": ours(f"m_{{{n}}}", f"mass of `{n}`"),
            f"{p}.radius": ours(f"r_{{{n}}}", f"radius of `{n}` (drawing)"),
            f"{p}.inertia": ours(f"I_{{{n}}}", f"centroidal inertia of `{n}`"),
        })
    return table


def notation(method: MomentBalance) -> dict:
    """Symbols of this method's inputs, named after the spec's counterweights and discs."""
    from .force_balance import counterweight_notation

    from ..notation import setting

    return {**counterweight_notation(method.counterweights),
            **counter_rotation_notation(method.counter_rotations, "balancing.counter_rotations"),
            "balancing.gear_signs": setting("gear signs", "the discs' gear signs as given, or found by the method")}
