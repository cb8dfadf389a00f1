"""The spec: one YAML file describing a mechanism, its motion, the balancing method and the
analysis. ``balpipe schema`` prints its JSON Schema.

The mechanism and balancing sections are unions of the templates and methods the registry
discovered (:mod:`balpipe.plugins`, :mod:`balpipe.registry`): each is a pydantic model with a
``template`` (``method``) literal that discriminates the union. The unions are resolved when a
validator or the schema is built, not when this module is imported: :class:`Spec` validated
directly (and its JSON Schema) imports every family's sections, :func:`validate` only those of the
template and methods a spec names (``balpipe check`` of one spec: one family's).
"""

from __future__ import annotations

import functools
from typing import Annotated, Any, Callable, Literal, Optional, Union, cast

from pydantic import Field, GetCoreSchemaHandler, create_model, field_validator
from pydantic_core import CoreSchema

from . import registry
from .display.units import display_units
from .laws.motion_spec import Motion
from .spec_parts import Strict
from .units import Length, count, number, quantity


class NoBalancing(Strict):
    """Analyse the mechanism as given."""

    method: Literal["none"] = Field(description="balancing method")


class Deferred:
    """A field's type (in ``Annotated[Any, Deferred(...)]``) made by ``resolve()`` when pydantic
    builds a validator or a schema that holds it, not when a model naming it is defined: its
    modules are imported then."""

    def __init__(self, resolve: Callable[[], Any]) -> None:
        self.resolve = resolve

    def type(self) -> Any:
        """The field's type (its modules imported now)."""
        return self.resolve()

    def __get_pydantic_core_schema__(self, source: Any, handler: GetCoreSchemaHandler) -> CoreSchema:
        return handler.generate_schema(self.type())


class Sections(Deferred):
    """A discriminated union of spec sections (:class:`Deferred`): ``key`` is the discriminating
    field (``template``, ``method``), ``sections()`` the member classes in union order."""

    def __init__(self, key: str, sections: Callable[[], tuple[type, ...]], description: str) -> None:
        super().__init__(self.union)
        self.key = key
        self.sections = sections
        self.description = description

    def union(self) -> Any:
        """The union as a type: ``Annotated[Union[...], Field(discriminator=key, description=...)]``."""
        return Annotated[Union[self.sections()], Field(discriminator=self.key, description=self.description)]


def _loads() -> Any:
    from .laws.load_spec import LoadSpec

    return list[LoadSpec]  # type: ignore[valid-type]


def _frame() -> Any:
    from .laws.frame_spec import FrameSpec

    return Optional[FrameSpec]


def _sweep() -> Any:
    from .sweep_spec import SweepSpec

    return Optional[SweepSpec]


#: the spec's optional sections whose modules are imported when a spec has them (or the whole
#: schema is built): a spec without them is validated by :func:`validate` without them
OPTIONAL = {"loads": Deferred(_loads), "frame": Deferred(_frame), "sweep": Deferred(_sweep)}


_MECHANISM = "the mechanism: a template with its parameters"
_BALANCING = "the balancing method and its design choices"
#: every template's section (the registry's union order)
MECHANISMS = Sections("template", registry.template_specs, _MECHANISM)
#: "none" and every method's section
BALANCINGS = Sections("method", lambda: (NoBalancing, *registry.method_specs()), _BALANCING)


def __getattr__(name: str) -> Any:
    """``Mechanism`` and ``Balancing``: the whole unions as types (every family's sections imported)."""
    if name == "Mechanism":
        return MECHANISMS.union()
    if name == "Balancing":
        return BALANCINGS.union()
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


class Design(Strict):
    """Another balancing design of the same mechanism, analysed beside the main one."""

    name: str = Field(min_length=1, pattern=r"^[A-Za-z0-9_\-]+$", description="short name, prefixes its stages (name:stage)")
    label: str = Field("", description="label in figures and tables (default: the name)")
    balancing: Annotated[Any, BALANCINGS]

    def __eq__(self, other: object) -> bool:
        return _same(self, other, Design)

    def __reduce__(self) -> tuple:
        return restore, (Design, self.__getstate__())


class AnalysisSettings(Strict):
    """How the motion is sampled and the loads are expressed."""

    samples: count(ge=3, le=200_000) = Field(501, description="number of time samples over the motion")
    gravity: bool = Field(False, description="gravity along -y; most papers work in a horizontal plane")
    g: quantity("acceleration", gt=0) = Field(9.80665, description="gravitational acceleration")
    moment_point: tuple[Length, Length] = Field((0.0, 0.0), description="point about which shaking moments are taken")
    balance_tolerance: number(gt=0, lt=1) = Field(
        1e-9,
        description="a stage counts as balanced when its peak is below this fraction of the reference load (the unbalanced peak, floored by 1 % of the gross inertial load)",
    )
    claim_tolerance: dict[str, number(gt=0, lt=1)] = Field(
        {}, description="the tolerance of a stage's claims by stage name (default: balance_tolerance for computed "
        "designs; for stages typed by hand, balance_tolerance plus what the rounding of their numbers allows)")


class ValidationSpec(Strict):
    """Settings of the pymunk validation of every stage."""

    enabled: bool = Field(True, description="simulate every stage in pymunk")
    dt: quantity("time", gt=0) | None = Field(None, description="time step in s (default chosen per mechanism); at least duration / 1e6 (a limit: one million steps)")
    stage_dt: dict[str, quantity("time", gt=0)] = Field(
        {}, description="the time step of the stages named here (s), where one needs another step than the others "
        "(a motion with features of a few milliseconds); the other stages keep dt or the default")
    iterations: count(ge=1, le=10_000) | None = Field(None, description="solver iterations per step")
    tolerance: number(gt=0, le=0.01) = Field(0.01, description="pass when residuals are below this fraction of the reference loads: the unbalanced peaks, floored by 1 % of the gross inertial load (at most 1 %)")
    reactionless: bool | None = Field(None, description="free-floating frame demonstration of every stage (default: in paper specs, the stages claiming to cancel force and moment and their reference stage)")
    max_refinement: number(ge=1, le=64) = Field(8, description="the validator's own budget: a run that cannot resolve its error at the first step is rerun at finer steps, down to the first divided by this; still unresolved, it is 'unconfirmed' with the setting that would resolve it (1: no refinement)")


class Reference(Strict):
    """A published value to compare with a computed one."""

    name: str = Field(
        description="a computed parameter's name (e.g. mcp1), or stage.metric for a stage result "
        "(e.g. unbalanced.max_shaking_force)"
    )
    published: number() = Field(description="the value printed in the paper, in SI units")
    unit: str = Field("", description="unit of the value, for display")
    tolerance: number(ge=0) = Field(0.005, description="relative tolerance for 'agrees'")
    note: str = Field("", description="what the paper says, misprints, how to read it")
    expect: Literal["agree", "differ", "misprint", "assumption"] = Field(
        "agree", description="'differ' when the published value is known not to reproduce (the note says why); "
        "'misprint' when the printed value is a misprint the note explains (counted apart, never lowering the "
        "verdict); 'assumption' when it reproduces within the stated tolerance only under assumptions the paper "
        "does not state (the note states them)"
    )


class ReportSettings(Strict):
    """How the study's pages show it (results.json and the CSV files stay SI)."""

    units: str | dict[str, str] | None = Field(
        None, description="the units every number on the pages uses: 'SI' (default) or 'engineering' (mm, kg, kN, "
        "kN m, rpm, deg, kW), or a mapping {quantity: unit} over SI (or over 'preset'): length m/mm/cm, mass kg/g, "
        "force N/kN, moment N m/kN m/N mm, speed rad/s/rpm, angle rad/deg, power W/kW")

    @field_validator("units")
    @classmethod
    def _known_units(cls, v: str | dict[str, str] | None) -> str | dict[str, str] | None:
        display_units(v)  # a ValueError names the quantity or unit
        return v


class Spec(Strict):
    """A balancing study: mechanism, motion, method, analysis and references."""

    name: str = Field(min_length=1, description="title of the study")
    description: str = Field("", description="what the spec reproduces and which values are assumed")
    paper: str | None = Field(None, description="the paper the spec reproduces, if any")
    mechanism: Annotated[Any, MECHANISMS]
    motion: Motion
    balancing: Annotated[Any, BALANCINGS] = Field(NoBalancing(method="none"))
    analysis: AnalysisSettings = Field(AnalysisSettings())
    validation: ValidationSpec = Field(ValidationSpec())
    loads: Annotated[Any, OPTIONAL["loads"]] = Field(
        [], description="springs, dampers, force laws, gas pressures, torsional springs, applied forces and torques, "
        "joint friction: counted in the efforts, reactions and frame loads, never in the shaking loads")
    frame: Annotated[Any, OPTIONAL["frame"]] = Field(
        None, description="the frame as a rigid body on elastic mounts: its vibration and the forces on the floor per stage")
    references: list[Reference] = Field([], description="published values to compare with")
    compare: list[Design] = Field(
        [], description="other balancing designs of the same mechanism, analysed and tabulated beside the main one"
    )
    report: ReportSettings = Field(ReportSettings(), description="how the pages show the study: their units")
    sweep: Annotated[Any, OPTIONAL["sweep"]] = Field(
        None, description="a design sweep run by 'balpipe sweep SPEC' (flags override it); 'balpipe build' ignores it"
    )

    def __eq__(self, other: object) -> bool:
        return _same(self, other, Spec)

    def __reduce__(self) -> tuple:
        return restore, (Spec, self.__getstate__())


def restore(cls: type, state: dict) -> Any:
    """A pickled :class:`Spec` or :class:`Design` (which class validated it aside), as pickle
    restores a pydantic model: the instance made without validation, its state set."""
    obj = cls.__new__(cls)
    obj.__setstate__(state)
    return obj


def _same(a: Any, b: object, base: type) -> bool:
    """pydantic's equality, with a :class:`Spec` (:class:`Design`) validated by :func:`validate`'s
    narrower class equal to the same one validated by the whole schema."""
    if isinstance(b, base) and type(b) is not type(a):
        return a.__dict__ == b.__dict__ and (a.__pydantic_extra__ or {}) == (b.__pydantic_extra__ or {})
    return bool(super(base, a).__eq__(b))


def validate(data: Any) -> Spec:
    """``data`` (a spec's YAML, parsed) validated as a :class:`Spec`, with the same result and the
    same errors as ``Spec.model_validate(data)``. Until the whole schema is built (:class:`Spec`
    validated directly, its JSON Schema, :func:`balpipe.loader.prepare`), a spec that names a
    known template and known methods (its own and its compared designs') is validated by a Spec
    whose unions hold only those sections and that leaves out the :data:`OPTIONAL` sections it
    does not have (their defaults): only their families' section modules are imported and the
    validator is a fraction of the whole one. Any other spec (an unknown or missing name,
    errors to report) goes through the whole schema, whose messages list every choice. The
    narrower classes are named, pickled, hashed (:mod:`balpipe.cache.content`) and compared as
    :class:`Spec` and :class:`Design`."""
    names = None if Spec.__pydantic_complete__ else named_sections(data)
    cls = Spec if names is None else _narrowed(*names)
    return cls.model_validate(data)


def named_sections(data: Any) -> tuple[str, tuple[str, ...], tuple[str, ...]] | None:
    """(template, methods in the registry's order, the :data:`OPTIONAL` sections it does not
    have) of ``data``: the names in ``mechanism``, ``balancing`` and each design of ``compare``,
    when every one is a name the registry knows ("none" left out); None otherwise."""
    if not isinstance(data, dict) or not isinstance(data.get("mechanism"), dict):
        return None
    template = data["mechanism"].get("template")
    if not isinstance(template, str) or template not in registry.TEMPLATES:
        return None
    compare = data.get("compare", [])
    if not isinstance(compare, list) or not all(isinstance(d, dict) and "balancing" in d for d in compare):
        return None
    methods = set()
    for balancing in [data.get("balancing", {"method": "none"}), *(d["balancing"] for d in compare)]:
        method = balancing.get("method") if isinstance(balancing, dict) else None
        if not isinstance(method, str) or (method != "none" and method not in registry.METHODS):
            return None
        methods.add(method)
    absent = tuple(k for k in OPTIONAL if k not in data)
    return template, tuple(m for m in registry.METHODS if m in methods), absent


@functools.lru_cache(maxsize=None)
def _narrowed(template: str, methods: tuple[str, ...], absent: tuple[str, ...] = ()) -> type[Spec]:
    """:class:`Spec` with its unions narrowed to ``template``'s section and "none" and ``methods``',
    and the ``absent`` optional sections left at their defaults without a type (a spec without
    them never validates them) (:func:`validate`); one class per combination in a process."""
    mechanism = Sections("template", lambda: (registry.TEMPLATES[template].section,), _MECHANISM)
    balancing = Sections("method", lambda: (NoBalancing, *(registry.METHODS[m].section for m in methods)),
                         _BALANCING)
    design = create_model("Design", __base__=Design, __module__=__name__, balancing=(Annotated[Any, balancing], ...))
    fields = Spec.model_fields
    spec = create_model(
        "Spec", __base__=Spec, __module__=__name__,
        mechanism=(Annotated[Any, mechanism], ...),
        balancing=(Annotated[Any, balancing], Field(fields["balancing"].default)),
        compare=(list[design], Field(fields["compare"].default, description=fields["compare"].description)),  # type: ignore[valid-type]
        **{k: (Any, Field(fields[k].default, description=fields[k].description)) for k in absent},  # type: ignore[dict-item]
    )
    return cast("type[Spec]", spec)

