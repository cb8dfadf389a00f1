"""The structural contract of a mechanism family (:class:`balpipe.plugins.Family`): what every
template and method gives, that balpipe found the family, that its examples use every template
and method it has, and that an example's model is consistent (named bodies, joints between
known bodies, an initial pose for every body, at least one driver)."""

from __future__ import annotations

import typing
from pathlib import Path
from typing import Any, Union

from .. import plugins, registry
from ..loader import LoadedSpec, load, load_text
from ..model import FRAME, Model


class ConformanceError(AssertionError):
    """A family breaks its contract; the message names the family, template, method or example."""


def _require(ok: object, message: str) -> None:
    if not ok:
        raise ConformanceError(message)


def _literal(cls: type, field: str) -> tuple[Any, ...]:
    fields = getattr(cls, "model_fields", {})
    if field not in fields:
        return ()
    return typing.get_args(fields[field].annotation)


#: an example: a spec file's path, or a spec's YAML text
Example = Union[str, Path]


def is_text(example: Example) -> bool:
    """Whether ``example`` is a spec's text (a string of several lines) rather than a path."""
    return isinstance(example, str) and "\n" in example


def example_name(example: Example) -> str:
    """A short name for an example: its file's stem, or the ``name:`` line of a text."""
    if not is_text(example):
        return Path(example).stem
    for line in str(example).splitlines():
        if line.startswith("name:"):
            return line.split(":", 1)[1].strip().strip("'\"") or "text"
    return "text"


def load_example(example: Example) -> LoadedSpec:
    """The example validated as a spec (a text is read as if it were a file ``<example>.yaml``)."""
    if is_text(example):
        text = str(example)
        file = f"<example {example_name(example)}>"
        spec, node = load_text(text, file)
        return LoadedSpec(Path(file), text, spec, node)
    return load(example)


def check_discovered(family: plugins.Family) -> None:
    """balpipe finds the family (its entry point in the ``balpipe.families`` group, or a package
    under ``balpipe.families``) and the registry holds its own templates and methods."""
    names = [f.name for f in plugins.discover()]
    _require(family.name in names, f"family {family.name!r} is not found by balpipe.plugins.discover() (found: "
             f"{', '.join(names)}): install its package with an entry point in the group {plugins.GROUP!r}")
    for t in family.templates:
        _require(registry.TEMPLATES.get(t.name) is t, f"template {t.name!r} of family {family.name!r}: the registry "
                 "holds another object of that name (two families define it, or the family was imported twice)")
    for m in family.methods:
        _require(registry.METHODS.get(m.name) is m, f"method {m.name!r} of family {family.name!r}: the registry "
                 "holds another object of that name (two families define it, or the family was imported twice)")


def _check_part(kind: str, name: str, label: str, notation: object, spec: type, code: object) -> None:
    where = f"{kind} {name!r}"
    _require(label.strip(), f"{where}: empty label")
    _require(notation is not None, f"{where}: no notation (a table of the papers' symbols, may be empty)")
    _require(_literal(spec, kind) == (name,), f"{where}: its spec's field {kind!r} must be Literal[{name!r}]")
    _require(callable(code), f"{where}: its {'build' if kind == 'template' else 'balance'} is not callable")


def check_template(template: plugins.Template) -> None:
    """A template has a label, a notation table, a ``template`` literal naming it, a build."""
    _check_part("template", template.name, template.label, template.notation, template.section, template.build)


def check_method(method: plugins.Method) -> None:
    """A method has a label, a notation table, a ``method`` literal naming it, a balance, and
    applies to templates balpipe knows."""
    _check_part("method", method.name, method.label, method.notation, method.section, method.balance)
    unknown = set(method.templates) - set(registry.TEMPLATES)
    _require(method.templates and not unknown,
             f"method {method.name!r}: applies to no template, or to unknown ones {sorted(unknown)}")


def check_examples_cover(family: plugins.Family, examples: typing.Sequence[Example]) -> None:
    """The examples use every template and every method of the family (so that each is built,
    balanced and analysed by the checks)."""
    _require(examples, f"family {family.name!r} has no examples (Family.examples: spec files or texts)")
    templates: set[str] = set()
    methods: set[str | None] = set()
    for ex in examples:
        spec: Any = load_example(ex).spec  # its sections are the registry's unions, built at run time
        templates.add(spec.mechanism.template)
        methods.add(getattr(spec.balancing, "method", None))
    missing = [t.name for t in family.templates if t.name not in templates]
    missing += [m.name for m in family.methods if m.name not in methods]
    _require(not missing, f"family {family.name!r}: no example uses {', '.join(missing)}")


def check_model(model: Model, where: str, driven: bool = True) -> None:
    """Bodies with distinct names, joints between known bodies (or the frame), an initial pose
    for every body and (``driven``) at least one driver."""
    names = {b.name for b in model.bodies}
    _require(names and len(names) == len(model.bodies), f"{where}: no bodies, or two of one name")
    for j in model.joints:
        ends = {getattr(j, k) for k in ("a", "b", "guide", "slider", "carrier") if hasattr(j, k)}
        _require(len(ends) >= 2 and ends <= names | {FRAME}, f"{where}: joint {j.name!r} joins {sorted(ends)}")
    _require(set(model.initial) == names, f"{where}: initial poses for {sorted(model.initial)}, bodies {sorted(names)}")
    _require(model.drivers or not driven, f"{where}: no driver")


def check_example_model(family: plugins.Family, example: Example) -> None:
    """The example is valid, uses one of the family's templates, and that template builds a
    consistent model from it (:func:`check_model`; without drivers when the spec drives
    nothing and its method plans the motion: every stage's model is checked with its drivers by
    :func:`balpipe.testing.check_example_physics`)."""
    loaded = load_example(example)
    spec: Any = loaded.spec  # its sections are the registry's unions, built at run time
    template = spec.mechanism.template
    _require(template in {t.name for t in family.templates},
             f"example {example_name(example)!r} uses the template {template!r}, not one of family {family.name!r}")
    driven = bool(getattr(spec.motion, "drive", True))
    check_model(registry.unbalanced_model(spec), f"example {example_name(example)!r} ({template})", driven)
