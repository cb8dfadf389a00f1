"""A spec in Python: ``load`` (a file or YAML text), ``Spec.with_values`` (fields changed
by their dotted paths, for parameter studies) and ``Spec.from_parts`` (a spec assembled
from sections built in Python). Every one of them validates through the loader that ``balpipe
check`` and ``balpipe build`` use (``balpipe.loader.load_text``: the schema, the units, the
limits, the motion's tables), so a spec accepted here is accepted there and a refused one is
refused with the same located problems (``balpipe.api.errors.SpecError``)."""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any, Mapping

import yaml

from .. import loader
from ..vary import with_values as _changed
from .errors import SpecError

#: the file name of a spec given as text (its tables are read relative to the working folder)
TEXT = "<text>"


class Spec:
    """One validated spec: its text and where it came from.

    Make one with ``balpipe.load``, ``with_values`` or ``from_parts``; run it with
    ``balpipe.run``. A Spec is immutable: every change makes a new one."""

    __slots__ = ("_loaded",)

    def __init__(self, loaded: loader.LoadedSpec):
        self._loaded = loaded

    @property
    def path(self) -> Path:
        """The spec's file (``<text>`` for a spec given as text); errors and ``results.json``'s
        ``source`` name it, and the motion's tables are read relative to its folder."""
        return self._loaded.path

    @property
    def source(self) -> str:
        """How messages and ``results.json`` name the spec: a relative path as given, any other
        made relative to the working folder or the git repository (never a machine path, as
        ``balpipe build`` publishes it); ``<text>`` for a spec given as text."""
        return self._loaded.name or str(self.path)

    @property
    def text(self) -> str:
        """The spec's YAML text, as the page shows it."""
        return self._loaded.text

    @property
    def name(self) -> str:
        """The spec's ``name``."""
        return self._loaded.spec.name

    @property
    def parsed(self):
        """The validated spec, a ``balpipe.spec.Spec`` (pydantic): every field with its
        default, in SI units. Read it; change a spec with ``with_values``."""
        return self._loaded.spec

    def data(self) -> dict:
        """The spec's YAML as plain data (a fresh copy: changing it changes no spec)."""
        return yaml.safe_load(self.text)

    def with_values(self, changes: Mapping[str, Any]) -> "Spec":
        """A copy of this spec with fields changed, validated as a file would be.

        Args:
            changes: dotted field path -> new value, written as in the YAML (a number in SI
                units or a string with its unit): ``{"mechanism.crank.mass": "1.5 kg",
                "mechanism.bodies.0.inertia": 0.002, "motion.duration": "0.4 s"}``. A list item
                is named by its index. The last key of a path may be a field the spec omits.

        Returns:
            The new ``Spec``; its text is the changed YAML (comments dropped), its path
                this spec's (its tables are read from the same folder).

        Raises:
            SpecError: a path that is not in the spec, or a value the schema refuses, located at
                the field in this spec's file where it exists (named ``source``)."""
        paths = [tuple(int(p) if p.isdigit() else p for p in str(key).split(".")) for key in changes]
        data = yaml.safe_load(self.text)
        try:
            new = _changed(data, paths, tuple(changes.values()))
        except KeyError as exc:
            bad = tuple(exc.args[0])
            where = ".".join(map(str, bad))
            raise SpecError([self._at(bad, f"unknown path: {where} is not in the spec")]) from None
        text = dump(new)
        try:
            spec, node = loader.load_text(text, self.source, self.path.parent)
        except loader.SpecErrors as exc:  # located at the field in this spec's own file
            raise SpecError([self._at(_path_of(e.path), e.message) for e in exc.errors]) from None
        return Spec(loader.LoadedSpec(self.path, text, spec, node, self._loaded.name))

    def _at(self, path: tuple, message: str) -> loader.SpecError:
        return loader.located(self.source, self._loaded.node, path, message)

    @classmethod
    def from_parts(cls, name: str, mechanism: Any, motion: Any, balancing: Any = None, *,
                   path: str | Path | None = None, **sections: Any) -> "Spec":
        """A spec assembled in Python, validated exactly as its YAML would be.

        Args:
            name: the study's title (the spec's ``name``).
            mechanism: the ``mechanism`` section: a pydantic section (the builders of
                ``balpipe.families.custom.builders`` make a custom mechanism body by body) or
                the same as plain data.
            motion: the ``motion`` section (data or its pydantic section).
            balancing: the ``balancing`` section (default: none).
            path: the file the spec is said to come from (errors name it; the motion's tables are
                read relative to its folder); default ``<text>``.
            sections: any other top-level field (``description``, ``analysis``, ``validation``,
                ``compare``, ``references``), as data or pydantic sections.

        Returns:
            The ``Spec``; its text is the YAML the sections make.

        Raises:
            SpecError: what the loader refuses, located in that YAML text."""
        data: dict[str, Any] = {"name": name, **{k: v for k, v in sections.items() if k == "description"},
                                "mechanism": mechanism, "motion": motion}
        if balancing is not None:
            data["balancing"] = balancing
        data.update({k: v for k, v in sections.items() if k != "description"})
        text = dump(_plain(data))
        return loads(text, path if path is not None else TEXT)

    def __repr__(self) -> str:
        return f"<balpipe.Spec {self.name!r} from {self.source}>"


def _plain(value: Any) -> Any:
    """Pydantic sections as the data they were made from (the fields set, in SI units), tuples
    as lists: what ``yaml.safe_dump`` writes."""
    if hasattr(value, "model_dump"):
        return _plain(value.model_dump(mode="json", by_alias=True, exclude_unset=True))
    if isinstance(value, Mapping):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    return value


class _Dumper(yaml.SafeDumper):
    """YAML as a person writes a spec: a list of plain values ([x, y], a pose) on one line."""

    def represent_sequence(self, tag, sequence, flow_style=None):
        flat = all(not isinstance(v, (dict, list, tuple)) for v in sequence)
        return super().represent_sequence(tag, sequence, flow_style=flat if flow_style is None else flow_style)


def dump(data: Any) -> str:
    """The YAML text of spec ``data`` (keys in their order, lists of values on one line)."""
    return yaml.dump(data, Dumper=_Dumper, sort_keys=False, allow_unicode=True, width=100)


_PART = re.compile(r"\[(\d+)\]|\.?([^.\[]+)")


def _path_of(text: str) -> tuple:
    """A field path as the loader prints it (``a.b[0].c``) back to its keys."""
    return tuple(int(m.group(1)) if m.group(1) is not None else m.group(2) for m in _PART.finditer(text))


def loads(text: str, path: str | Path = TEXT) -> Spec:
    """A ``Spec`` from YAML ``text``; ``path`` names it in errors and is the folder its
    tables are read from. Raises ``SpecError``."""
    try:
        spec, node = loader.load_text(text, str(path))
    except loader.SpecErrors as exc:
        raise SpecError.of(exc) from None
    return Spec(loader.LoadedSpec(Path(path), text if not text.startswith("\ufeff") else text[1:], spec, node))


def load(path_or_text: str | Path) -> Spec:
    """Read and validate one spec.

    Args:
        path_or_text: a spec file (a ``pathlib.Path``, or a string without a line break),
            or the spec's YAML text (a string with at least one line break).

    Returns:
        The validated ``Spec``.

    Raises:
        SpecError: every problem of the spec, located (``file:line:column: field: message``), as
            ``balpipe check`` prints them."""
    from ..site_files.spec_files import published_names

    if isinstance(path_or_text, str) and "\n" in path_or_text:
        return loads(path_or_text)
    p = Path(path_or_text)
    try:
        return Spec(loader.load(p, name=published_names([str(p)], [p])[p]))
    except loader.SpecErrors as exc:
        raise SpecError.of(exc) from None
