"""Which templates and balancing methods exist, which go together, and how a spec becomes the
unbalanced model and its balancing stages."""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Any, Callable

import numpy as np

from . import units
from .families.serial_arm import com_planning, decoupling
from .families.five_bar import gear_balancing as fb_balancing
from .families.rpr3 import idler_loop as rpr3_idler, scott_russell as rpr3_scott_russell
from .families.rrr4 import counter_masses as rrr4_balancing
from .balancing import force_balance as generic_force
from .balancing import moment_balance as generic_moment
from .families.slider_crank import counterweights as sc_balancing
from .balancing import stages as generic_stages
from .balancing.base import BalanceResult, Stage
from .families.custom import template as custom
from .families.five_bar import template as five_bar
from .families.rpr3 import template as rpr3
from .families.rrr4 import template as rrr4
from .families.serial_arm import template as serial_arm
from .families.slider_crank import template as slider_crank
from .model import Law, Model
from .motion import law_for
from .spec_parts import SpecFieldError


@dataclass(frozen=True)
class Template:
    """``build(mechanism_spec, laws, t) -> Model``; ``laws`` maps drive names to laws.
    ``figures(study)`` optionally yields extra report figures as (title, svg, caption)."""

    build: Callable[..., Model]
    label: str
    figures: Callable[..., Any] | None = None
    notation: Any = None  # the papers' symbols of the inputs: a table or table(mechanism_spec) (balpipe.notation)


@dataclass(frozen=True)
class Method:
    """``balance(mechanism_spec, method_spec, model) -> BalanceResult`` for ``templates``."""

    balance: Callable[..., BalanceResult]
    templates: tuple[str, ...]
    label: str
    uses_spec: bool = False  # balance(..., spec): the method also reads the motion and analysis settings
    generic: bool = False  # applies to every template; balance() also receives the time grid t
    notation: Any = None  # the papers' symbols of the inputs: a table or table(method_spec) (balpipe.notation)


TEMPLATES: dict[str, Template] = {
    "slider_crank": Template(slider_crank.build, "slider-crank"),
    "custom": Template(custom.build, "custom mechanism"),
    "five_bar": Template(five_bar.build, "five-bar (5R), fixed-sequence with gear-coupled inputs", five_bar.figures),
    "rrr4": Template(rrr4.build, "planar n-RRR parallel manipulator (4-RRR of paper 001, legs removable)", rrr4.figures),
    "rpr3": Template(rpr3.build, "3-RPR parallel manipulator", rpr3.figures),
    "serial_arm": Template(serial_arm.build, "serial nR arm"),
}
METHODS: dict[str, Method] = {
    "slider_crank_counterweights": Method(
        sc_balancing.balance, ("slider_crank",), "counterweights (+ eq. 20 inertia for Scott-Russell)"
    ),
    "five_bar_gear_balancing": Method(
        fb_balancing.balance, ("five_bar",), "counterweights + counter-rotating gears 5, 6, 7 (eqs. 9-21)"
    ),
    "rrr4_counter_masses": Method(
        rrr4_balancing.balance, ("rrr4",), "counter-masses: leg by leg (eqs. 8-11), from eq. 17 (Fig. 4a) and eqs. 19/21 (Fig. 6)"
    ),
    "rpr3_idler_loop": Method(
        rpr3_idler.balance, ("rpr3",), "idler loop E-F-P, counterweights (eqs. 5a-d), chained counter-rotations (eqs. 9a-d)"
    ),
    "rpr3_scott_russell": Method(
        rpr3_scott_russell.balance, ("rpr3",),
        "Scott-Russell legs, counterweights (eqs. 30a-d), eq. 30e, one counter-rotation per leg (eq. 30f)",
    ),
    "gear_decoupling": Method(
        decoupling.balance, ("serial_arm",), "decoupling by gears 1'-2' and mass redistribution, counter-rotating gear 3 (paper 002)"
    ),
    "com_motion_planning": Method(
        com_planning.balance, ("serial_arm",), "centre-of-mass motion planning, phi optimised (paper 003)", uses_spec=True
    ),
}
# methods for every template (they read only the model)
METHODS.update({
    "force_balance": Method(
        generic_force.balance, (), "force-balance conditions from the momentum + least-mass counterweights", generic=True
    ),
    "moment_balance": Method(
        generic_moment.balance, (), "least-mass counterweights + counter-rotations from the angular momentum", generic=True
    ),
    "stages": Method(generic_stages.balance, (), "stages written by hand, each adding parts", generic=True),
})

# the papers' symbols of each template's and method's inputs (balpipe.notation, the inputs table)
for _name, _table in (("slider_crank", slider_crank.NOTATION), ("custom", custom.notation),
                      ("five_bar", five_bar.NOTATION), ("rrr4", rrr4.NOTATION), ("rpr3", rpr3.NOTATION),
                      ("serial_arm", serial_arm.notation)):
    TEMPLATES[_name] = replace(TEMPLATES[_name], notation=_table)
for _name, _table in (("slider_crank_counterweights", sc_balancing.NOTATION),
                      ("five_bar_gear_balancing", fb_balancing.NOTATION),
                      ("rrr4_counter_masses", rrr4_balancing.NOTATION), ("rpr3_idler_loop", rpr3_idler.NOTATION),
                      ("rpr3_scott_russell", rpr3_scott_russell.NOTATION), ("gear_decoupling", decoupling.NOTATION),
                      ("com_motion_planning", com_planning.NOTATION), ("force_balance", generic_force.notation),
                      ("moment_balance", generic_moment.notation), ("stages", generic_stages.notation)):
    METHODS[_name] = replace(METHODS[_name], notation=_table)


def scalar_laws(motion: Any, dims: dict[str, str]) -> dict[str, Law]:
    """Laws of the scalar drives named in motion.drive, converted with their dimensions."""
    out = {}
    for name, drive in motion.drive.items():
        path = ("motion", "drive", name)
        if name not in dims:
            raise SpecFieldError(path, f"unknown drive {name!r}; this mechanism drives: {', '.join(dims)}")
        values = []
        for key, raw in (("from", drive.start), ("to", drive.end)):
            try:
                values.append(units.parse(raw, dims[name]))
            except ValueError as exc:
                raise SpecFieldError(path + (key,), str(exc)) from None
        for key in ("start_velocity", "end_velocity", "start_acceleration", "end_acceleration"):
            try:
                units.check_rate(getattr(drive, key), dims[name])
            except ValueError as exc:
                raise SpecFieldError(path + (key,), f"{exc} ({name})") from None
        out[name] = law_for(motion, values[0], values[1], drive)
    return out


def time_grid(spec: Any) -> np.ndarray:
    return np.linspace(0.0, spec.motion.duration, spec.analysis.samples)


def unbalanced_model(spec: Any) -> Model:
    mech = spec.mechanism
    template = TEMPLATES[mech.template]
    if hasattr(mech, "laws"):
        laws = mech.laws(spec.motion)
    else:
        laws = scalar_laws(spec.motion, mech.drives())
    return template.build(mech, laws, time_grid(spec))


def balance(spec: Any, balancing: Any = None) -> BalanceResult:
    """The unbalanced model and the method's stages, with every semantic check of the spec;
    ``balancing`` replaces ``spec.balancing`` (the designs of ``spec.compare``)."""
    balancing = balancing if balancing is not None else spec.balancing
    name = balancing.method
    model = unbalanced_model(spec)
    if name == "none":
        return BalanceResult([], [Stage("unbalanced", "unbalanced", model, "the mechanism as given")])
    method = METHODS[name]
    if method.generic:
        return method.balance(spec.mechanism, balancing, model, t=time_grid(spec))
    if spec.mechanism.template not in method.templates:
        raise SpecFieldError(
            ("balancing", "method"),
            f"method {name!r} applies to {', '.join(method.templates)}, not to {spec.mechanism.template!r}",
        )
    if method.uses_spec:
        return method.balance(spec.mechanism, balancing, model, spec)
    return method.balance(spec.mechanism, balancing, model)


def balance_designs(spec: Any) -> BalanceResult:
    """:func:`balance`, then the stages of every design in ``spec.compare`` after the main
    design's, named ``design:stage`` (their unbalanced stage, the same model, is dropped);
    parameters are prefixed the same way and details go to ``details["compare"][design]``."""
    main = balance(spec)
    designs = getattr(spec, "compare", None) or []
    if not designs:
        return main
    stages, params, notes = list(main.stages), list(main.parameters), list(main.notes)
    details = dict(main.details)
    details["compare"] = {}
    for k, d in enumerate(designs):
        try:
            res = balance(spec, d.balancing)
        except SpecFieldError as exc:
            path = exc.path
            if path[:1] == ("balancing",):
                path = ("compare", k) + path
            raise SpecFieldError(path, f"design {d.name!r}: {exc.message}") from None
        for s in res.stages[1:]:
            stages.append(replace(s, name=f"{d.name}:{s.name}", label=f"{d.label or d.name}: {s.label}"))
        params += [replace(p, name=f"{d.name}:{p.name}") for p in res.parameters]
        notes += [f"{d.label or d.name}: {n}" for n in res.notes]
        details["compare"][d.name] = res.details
    return replace(main, parameters=params, stages=stages, notes=notes, details=details)
