"""Which templates and balancing methods exist, which go together, and how a spec becomes the
unbalanced model and its balancing stages."""

from __future__ import annotations

import functools
from dataclasses import replace
from typing import Any

import numpy as np

from . import units
from .balancing.base import BalanceResult, Stage
from .balancing.context import BalanceContext, Memo, compute
from .model import Law, Model
from .laws.drives import drive_laws
from .motion import law_for
from .plugins import Method, Paper, Ref, Template, discover
from .mechanics.sampling import gravity_vector, time_grid
from .spec_parts import DriveSpec, SpecFieldError

__all__ = [
    "METHODS", "PAPERS", "TEMPLATES", "BalanceContext", "Method", "Paper", "Template", "balance",
    "balance_designs", "context", "method_specs", "scalar_laws", "template_specs", "time_grid", "unbalanced_model", "motion_model",
]

# methods for every template (they read only the model); "none" is the spec's own default. Their
# sections and code are imported when a spec uses them (the whole schema needs every section).
_CODE = "balpipe.balancing"
_LINPROG = ("scipy.optimize",)  # the least-mass programmes (balpipe.balancing.least_mass)
GENERIC: tuple[Method, ...] = (
    Method("force_balance", Ref(f"{_CODE}.specs:ForceBalance"), Ref(f"{_CODE}.force_balance:balance"), (),
           "force-balance conditions from the momentum + least-mass counterweights",
           notation=Ref(f"{_CODE}.force_balance:notation"), imports=_LINPROG),
    Method("moment_balance", Ref(f"{_CODE}.specs:MomentBalance"), Ref(f"{_CODE}.moment_balance:balance"), (),
           "least-mass counterweights + counter-rotations from the angular momentum",
           notation=Ref(f"{_CODE}.moment_balance:notation"), imports=_LINPROG),
    Method("stages", Ref(f"{_CODE}.specs:Stages"), Ref(f"{_CODE}.stages:balance"), (), "stages written by hand, each adding parts",
           notation=Ref(f"{_CODE}.stages:notation")),
    Method("partial_balance", Ref(f"{_CODE}.partial.spec:PartialBalance"), Ref(f"{_CODE}.partial.method:balance"), (),
           "optimal partial balancing (cone programme)",
           notation=Ref(f"{_CODE}.partial.method:notation"),
           page_only=("fronts",),  # the Pareto fronts: about 90 % of its time, drawn only on the page
           check_cost=0.5,  # the optimum's cone programme (Clarabel): 0.1-1 s beyond a plain spec
           build_cost=0.3,  # and the fronts: 0.3-1.2 s a spec
           imports=("clarabel", "scipy.sparse")),
)


def _tables() -> tuple[dict[str, Template], dict[str, Method], dict[str, Paper]]:
    """Templates, methods and papers of the discovered families in their order, then the generic
    methods; the papers by id."""
    templates: dict[str, Template] = {}
    methods: dict[str, Method] = {}
    papers: dict[str, Paper] = {}
    for family in discover():
        for kind, table, items in (("template", templates, family.templates), ("method", methods, family.methods)):
            for item in items:
                if item.name in table or (kind == "method" and item.name == "none"):
                    raise ValueError(f"family {family.name!r}: {kind} {item.name!r} is already defined")
                table[item.name] = item
        for paper in family.papers:
            if paper.id in papers:
                raise ValueError(f"family {family.name!r}: paper {paper.id!r} is already declared")
            papers[paper.id] = paper
    for item in GENERIC:
        if item.name in methods:
            raise ValueError(f"method {item.name!r} is already defined")
        methods[item.name] = item
    return templates, methods, papers


#: the templates and methods by name, the papers the families reproduce by id (:class:`balpipe.plugins.Paper`)
TEMPLATES, METHODS, PAPERS = _tables()


def template_specs() -> tuple[type, ...]:
    """The templates' spec sections, in union order (every family's section module imported)."""
    return tuple(t.section for t in TEMPLATES.values())


def method_specs() -> tuple[type, ...]:
    """The methods' spec sections, in union order (after the spec's own "none"; every section
    module imported)."""
    return tuple(m.section for m in METHODS.values())


def scalar_laws(motion: Any, dims: dict[str, str]) -> dict[str, Law]:
    """Laws of the scalar drives named in motion.drive, converted with their dimensions."""
    out = {}
    for name, drive in motion.drive.items():
        path = ("motion", "drive", name)
        if not isinstance(drive, DriveSpec):  # constant speed, cam, fourier, table, cycle, path
            out.update(drive_laws(name, drive, dims, motion))
            continue
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


def unbalanced_model(spec: Any) -> Model:
    mech = spec.mechanism
    template = TEMPLATES[mech.template]
    if hasattr(mech, "laws"):
        laws = mech.laws(spec.motion)
    else:
        laws = scalar_laws(spec.motion, mech.drives())
    t = time_grid(spec)
    model = template.build(mech, laws, t)
    if getattr(spec, "loads", None):
        from .laws.load_spec import model_loads  # the loads' section module only for a spec with loads

        model = replace(model, loads=model_loads(spec.loads, model, float(t[0])))
    return model


def motion_model(spec: Any, motion: Any, samples: int | None, path: tuple) -> tuple[Model, np.ndarray]:
    """The unbalanced model and time grid of ``spec``'s mechanism driven by another ``motion``
    (a section of the spec's schema, at ``path``) on ``samples`` samples (default: the spec's);
    its errors are located at ``path``."""
    analysis = spec.analysis.model_copy(update={"samples": samples or spec.analysis.samples})
    other = spec.model_copy(update={"motion": motion, "analysis": analysis})
    try:
        return unbalanced_model(other), time_grid(other)
    except SpecFieldError as exc:
        if exc.path[:1] != ("motion",):
            raise
        raise SpecFieldError(path + exc.path[1:], exc.message) from None


def context(spec: Any, balancing: Any = None, page: bool = True, memo: Memo = compute,
            model: Model | None = None) -> BalanceContext:
    """The :class:`BalanceContext` of ``spec`` for its method section ``balancing`` (default:
    ``spec.balancing``; a design of ``spec.compare`` otherwise): its unbalanced ``model`` (built
    when not given), time grid, gravity and moment point; ``page`` True unless ``balpipe check``
    runs a spec without references (which may name any parameter); ``memo`` as given."""
    return BalanceContext(
        balancing=balancing if balancing is not None else spec.balancing,
        model=model if model is not None else unbalanced_model(spec),
        t=time_grid(spec), spec=spec, mechanism=spec.mechanism, gravity=gravity_vector(spec),
        moment_point=tuple(spec.analysis.moment_point), page=bool(page or spec.references),
        models=functools.partial(motion_model, spec), memo=memo)


def balance(spec: Any, balancing: Any = None, page: bool = True, memo: Memo = compute,
            model: Model | None = None) -> BalanceResult:
    """The unbalanced model and the method's stages, with every semantic check of the spec:
    ``METHODS[name].balance(ctx)`` with ctx its :func:`context`. ``balancing`` replaces
    ``spec.balancing`` (the designs of ``spec.compare``). Without ``page``, the method's
    :attr:`Method.page_only` fields are left out (``balpipe check``) and the context says so
    unless the spec has references. ``memo``: what the method's searches go through (the
    build's cache, :class:`balpipe.cache.balance.Memo`; default: computed). ``model``: the
    spec's :func:`unbalanced_model` when the caller has it (built here otherwise): the same
    frozen object then serves as the unbalanced stage's model."""
    balancing = balancing if balancing is not None else spec.balancing
    name = balancing.method
    model = model if model is not None else unbalanced_model(spec)
    if name == "none":
        return BalanceResult([], [Stage("unbalanced", "unbalanced", model, "the mechanism as given")])
    method = METHODS[name]
    if not page and method.page_only:
        balancing = balancing.model_copy(update=dict.fromkeys(method.page_only))
    if method.templates and spec.mechanism.template not in method.templates:
        raise SpecFieldError(
            ("balancing", "method"),
            f"method {name!r} applies to {', '.join(method.templates)}, not to {spec.mechanism.template!r}",
        )
    return method.balance(context(spec, balancing, page, memo, model))


def balance_designs(spec: Any, page: bool = True, memo: Memo = compute,
                    model: Model | None = None) -> BalanceResult:
    """:func:`balance`, then the stages of every design in ``spec.compare`` after the main
    design's, each with its :attr:`Stage.design` and named ``design:stage`` on the page and in
    results.json (their unbalanced stage, the same model, is dropped);
    parameters are prefixed the same way and details go to ``details["compare"][design]``;
    ``page``, ``memo`` and ``model`` as in :func:`balance`: the unbalanced model is built once
    for every design (each design's mechanism is the spec's)."""
    model = model if model is not None else unbalanced_model(spec)
    main = balance(spec, page=page, memo=memo, model=model)
    designs = getattr(spec, "compare", None) or []
    if not designs:
        return main
    stages, params, notes = list(main.stages), list(main.parameters), list(main.notes)
    details = dict(main.details)
    details["compare"] = {}
    for k, d in enumerate(designs):
        try:
            res = balance(spec, d.balancing, page, memo, model)
        except SpecFieldError as exc:
            path = exc.path
            if path[:1] == ("balancing",):
                path = ("compare", k) + path
            raise SpecFieldError(path, f"design {d.name!r}: {exc.message}") from None
        for s in res.stages[1:]:
            parts = tuple(replace(p, where=f"compare[{k}].{p.where}") for p in s.parts)  # located in the spec
            stages.append(replace(s, name=f"{d.name}:{s.name}", label=f"{d.label or d.name}: {s.label}", design=d.name,
                                  parts=parts))
        params += [replace(p, name=f"{d.name}:{p.name}") for p in res.parameters]
        notes += [f"{d.label or d.name}: {n}" for n in res.notes]
        details["compare"][d.name] = res.details
    return replace(main, parameters=params, stages=stages, notes=notes, details=details)
