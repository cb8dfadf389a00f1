"""The ``stages`` method: hand-written balancing stages for any template. Each stage adds parts
to the model of the stage before it, changes them (a part of the same name on the same body
replaces the earlier one) or removes them; the first stage is always the mechanism as given."""

from __future__ import annotations

from dataclasses import replace


from ..mechanics.claim_precision import Rounding, half_unit
from ..model import Attachment, Model
from ..spec_parts import SpecFieldError
from ..engine import analyse
from .base import Aim, BalanceResult, Goal, Stage
from .context import BalanceContext
from .force_balance import body_point
from .load_measures import goal_label, measure, term_notation
from .made_parts import inertia_of, part_for, part_notation
from ..mechanics.part_shapes import MadePart
from .moment_balance import add_discs, set_disc_inertias
from .specs import PartSpec, Stages


def made_part(model: Model, part: PartSpec, path: tuple) -> MadePart | None:
    """The part that ``part``'s ``part:`` section makes of it (None without one)."""
    if part.part is None:
        return None
    pos = body_point(model, part.body, part.position, path + ("position",))
    axis = body_point(model, part.body, part.part.axis, path + ("part", "axis"))
    return part_for(model, part.body, part.name, part.part, part.mass, pos, axis, path + ("part",))


def attach(model: Model, part: PartSpec, path: tuple, made: MadePart | None = None) -> Model:
    """``model`` with ``part`` on its body (of the inertia of ``made``, its part, when given); a
    part of the same name there is replaced."""
    try:
        body = model.body(part.body)
    except KeyError:
        raise SpecFieldError(path + ("body",), f"unknown body {part.body!r} (bodies: {', '.join(b.name for b in model.bodies)})") from None
    pos = body_point(model, part.body, part.position, path + ("position",))
    inertia = inertia_of(made, part.inertia) if made is not None else part.inertia
    new = Attachment(part.name, part.mass, pos, inertia, part.kind, part.radius)
    kept = tuple(a for a in body.attachments if a.name != part.name)
    return model.replace_body(replace(body, attachments=kept + (new,)))


def detach(model: Model, ref: str, path: tuple) -> Model:
    body_name, _, name = ref.partition(".")
    try:
        body = model.body(body_name)
    except KeyError:
        raise SpecFieldError(path, f"unknown body {body_name!r} (write body.part)") from None
    if not any(a.name == name for a in body.attachments):
        raise SpecFieldError(path, f"{body_name!r} carries no part {name!r} (parts: {', '.join(a.name for a in body.attachments) or 'none'})")
    return model.replace_body(replace(body, attachments=tuple(a for a in body.attachments if a.name != name)))


def part_rounding(part: PartSpec) -> Rounding:
    """Half-units of the numbers of a part as entered (a named point is exact)."""
    x, y = (0.0, 0.0) if isinstance(part.position, str) else (half_unit(part.position[0]), half_unit(part.position[1]))
    dm, dI = half_unit(part.mass), half_unit(part.inertia)
    text = ", ".join(f"{part.name}.{k} = {v:.12g} {u}" for k, v, u, h in (
        ("mass", part.mass, "kg", dm), ("inertia", part.inertia, "kg m^2", dI)) if h)
    if x or y:
        text += (", " if text else "") + f"{part.name}.position = ({part.position[0]:.12g}, {part.position[1]:.12g}) m"
    return Rounding(part.body, part.name, dm, x, y, dI, text)


def balance(ctx: BalanceContext) -> BalanceResult:
    method: Stages = ctx.balancing
    model = ctx.model
    stages = [Stage("unbalanced", "unbalanced", model, "the mechanism as given")]
    current = model
    seen = {"unbalanced"}
    entered: dict[tuple[str, str | None], Rounding] = {}  # the precision of the parts on the model
    made: dict[tuple[str, str], MadePart] = {}  # the parts made so far, by body and name
    for k, step in enumerate(method.stages):
        path = ("balancing", "stages", k)
        if step.name in seen:
            raise SpecFieldError(path + ("name",), f"stage name {step.name!r} is used twice")
        seen.add(step.name)
        for i, ref in enumerate(step.remove):
            current = detach(current, ref, path + ("remove", i))
            entered.pop(tuple(ref.split(".", 1)), None)  # type: ignore[arg-type]
            made.pop(tuple(ref.split(".", 1)), None)  # type: ignore[arg-type]
        for i, part in enumerate(step.parts):
            if part.body not in {b.name for b in current.bodies}:
                current = attach(current, part, path + ("parts", i))  # the located error of an unknown body
            made_now = made_part(current, part, path + ("parts", i))
            current = attach(current, part, path + ("parts", i), made_now)
            entered[(part.body, part.name)] = part_rounding(part)
            made.pop((part.body, part.name), None)
            if made_now is not None:
                made[(part.body, part.name)] = made_now
        if step.counter_rotations:
            current = add_discs(current, step.counter_rotations, path + ("counter_rotations",))
            current = set_disc_inertias(current, {c.name: c.inertia for c in step.counter_rotations})
            for c in step.counter_rotations:
                entered[(c.name, None)] = Rounding(c.name, None, inertia=half_unit(c.inertia),
                                                   text=f"{c.name}.inertia = {c.inertia:.12g} kg m^2")
        stages.append(Stage(step.name, step.label or step.name, current, step.description, step.balances,
                            tolerance=step.tolerance, rounding=tuple(entered.values()), parts=tuple(made.values()),
                            aim=aim(ctx, model, current, step.aim, path + ("aim",)) if step.aim else None))
    return BalanceResult([], stages, [])


def aim(ctx: BalanceContext, unbalanced: Model, model: Model, terms: list, path: tuple) -> Aim:
    """What a hand-written stage aims at: each load term of its ``aim`` measured on the stage and
    on the unbalanced mechanism over the motion (:func:`~balpipe.balancing.load_measures.measure`),
    as partial balancing's objective terms are, so that the verdict judges the stage on them."""
    before = analyse(unbalanced, ctx.t, ctx.gravity, ctx.moment_point)
    after = analyse(model, ctx.t, ctx.gravity, ctx.moment_point)
    goals = []
    for i, term in enumerate(terms):
        value, unit = measure(after, model, term, path + (i,))
        reference, _ = measure(before, unbalanced, term, path + (i,))
        goals.append(Goal(goal_label(term), "objective", value, reference, unit, None, term.load))
    return Aim(tuple(goals))


def notation(method: Stages) -> dict:
    """Symbols of the hand-written stages' parts, named after each part: m_<part>, I_<part>..."""
    from ..notation import ours
    from .moment_balance import counter_rotation_notation

    table = {}
    for k, s in enumerate(method.stages):
        p = f"balancing.stages[{k}]"
        table[f"{p}.label"] = ours(f"`{s.name}`", f"label of stage `{s.name}`")
        table[f"{p}.balances"] = ours(f"`{s.name}`", f"what stage `{s.name}` claims to balance")
        table[f"{p}.remove"] = ours(f"`{s.name}`", f"parts stage `{s.name}` removes")
        for j, part in enumerate(s.parts):
            q, n = f"{p}.parts[{j}]", part.name
            table.update({
                f"{q}.body": ours(f"`{n}`", f"the body that carries `{n}` (stage `{s.name}`)"),
                f"{q}.mass": ours(f"m_{{{n}}}", f"mass of `{n}` on `{part.body}` (stage `{s.name}`)"),
                f"{q}.position": ours(f"r_{{{n}}}", f"centre of mass of `{n}`, in `{part.body}`'s frame"),
                f"{q}.inertia": ours(f"I_{{{n}}}", f"centroidal inertia of `{n}`"),
                f"{q}.kind": ours("kind", f"what `{n}` is"),
                f"{q}.radius": ours(f"r_{{{n},disc}}", f"radius of `{n}` drawn as a disc"),
                **part_notation(f"{q}.part", n),
            })
        table.update(counter_rotation_notation(s.counter_rotations, f"{p}.counter_rotations"))
        table.update(term_notation(f"{p}.aim", s.aim, f"aim of `{s.name}`,"))
    return table
