"""Which templates and balancing methods exist, which go together, and how a spec becomes the
unbalanced model and its balancing stages."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable

import numpy as np

from . import units
from .balancing import five_bar as fb_balancing
from .balancing import slider_crank as sc_balancing
from .balancing.base import BalanceResult, Stage
from .mechanisms import custom, five_bar, slider_crank
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


@dataclass(frozen=True)
class Method:
    """``balance(mechanism_spec, method_spec, model) -> BalanceResult`` for ``templates``."""

    balance: Callable[..., BalanceResult]
    templates: tuple[str, ...]
    label: str


TEMPLATES: dict[str, Template] = {
    "slider_crank": Template(slider_crank.build, "slider-crank"),
    "custom": Template(custom.build, "custom mechanism"),
    "five_bar": Template(five_bar.build, "five-bar (5R), fixed-sequence with gear-coupled inputs", five_bar.figures),
}
METHODS: dict[str, Method] = {
    "slider_crank_counterweights": Method(
        sc_balancing.balance, ("slider_crank",), "counterweights (+ eq. 20 inertia for Scott-Russell)"
    ),
    "five_bar_gear_balancing": Method(
        fb_balancing.balance, ("five_bar",), "counterweights + counter-rotating gears 5, 6, 7 (eqs. 9-21)"
    ),
}


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


def balance(spec: Any) -> BalanceResult:
    """The unbalanced model and the method's stages, with every semantic check of the spec."""
    name = spec.balancing.method
    model = unbalanced_model(spec)
    if name == "none":
        return BalanceResult([], [Stage("unbalanced", "unbalanced", model, "the mechanism as given")])
    method = METHODS[name]
    if spec.mechanism.template not in method.templates:
        raise SpecFieldError(
            ("balancing", "method"),
            f"method {name!r} applies to {', '.join(method.templates)}, not to {spec.mechanism.template!r}",
        )
    return method.balance(spec.mechanism, spec.balancing, model)
