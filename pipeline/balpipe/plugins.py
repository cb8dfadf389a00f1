"""Mechanism families as plugins: what a family contributes (its templates and balancing methods)
and how balpipe finds the families.

A family is a package with a module-level ``FAMILY`` (:class:`Family`). balpipe finds families in
two ways (the way MkDocs finds its plugins, with a package scan for runs from the source tree):

* the entry-point group ``balpipe.families`` of every installed distribution, whose entries point
  at a ``Family`` object (``name = "package.module:FAMILY"``): how a user's own family plugs in
  without an edit of balpipe;
* the subpackages of :mod:`balpipe.families`, for runs from a source tree without installed
  metadata (``PYTHONPATH=pipeline``).

Families come out sorted by :attr:`Family.order`, then name; templates and methods keep their
order within a family. That order is the order of the spec's unions (:mod:`balpipe.spec`), so it
fixes the JSON Schema and the text of a "which template?" error.

A family's spec sections, computing code, figures and notation tables may all be :class:`Ref`
objects, ``"package.module:name"`` imported on first use: ``balpipe check`` of a spec then loads
the sections of its own template and methods only (:func:`balpipe.spec.validate`) and no
method's code but the one it runs; the whole schema (``balpipe schema``, :class:`balpipe.spec.Spec`
validated directly) resolves every section.
"""

from __future__ import annotations

import pkgutil
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import import_module
from importlib.metadata import entry_points
from pathlib import Path
from typing import Any, Callable, cast

from pydantic import BaseModel

from . import FAMILY_GROUP
from .balancing.base import BalanceResult
from .balancing.context import BalanceContext
from .model import Model
from .spec_parts import Strict

GROUP = FAMILY_GROUP
IN_TREE = "balpipe.families"


@dataclass(frozen=True)
class Ref:
    """A module-level object named ``"package.module:name"``, imported when first used: calling
    a ``Ref`` calls the object (a template's ``build``, a method's ``balance``, figures); a table
    is read through :func:`resolved`."""

    target: str

    def resolve(self) -> Any:
        """The named object (its module imported now, once)."""
        return _load(self.target)

    def __call__(self, *args: Any, **kwargs: Any) -> Any:
        return _load(self.target)(*args, **kwargs)


@lru_cache(maxsize=None)
def _load(target: str) -> Any:
    module, _, name = target.partition(":")
    if not name:
        raise ValueError(f"a Ref names 'package.module:name', not {target!r}")
    return getattr(import_module(module), name)


def resolved(obj: Any) -> Any:
    """``obj``, or the object a :class:`Ref` names."""
    return obj.resolve() if isinstance(obj, Ref) else obj


def section_class(spec: type[Strict] | Ref) -> type[Strict]:
    """A template's or method's spec section: the class, or the class its :class:`Ref` names."""
    cls = resolved(spec)
    if not (isinstance(cls, type) and issubclass(cls, BaseModel)):
        raise TypeError(f"a spec section is a pydantic model class (balpipe.spec_parts.Strict), not {cls!r}")
    return cast("type[Strict]", cls)


@dataclass(frozen=True)
class Template:
    """A mechanism template: ``spec`` is its pydantic section (a ``template`` literal names it),
    a class or a :class:`Ref` to one (:attr:`section` is the class),
    ``build(mechanism_spec, laws, t) -> Model``; ``laws`` maps drive names to laws. ``build``,
    ``figures`` and ``notation`` may be :class:`Ref` objects.
    ``figures(study)`` optionally yields extra report figures as (title, svg, caption).
    ``check_cost`` and ``build_cost`` (as :attr:`Method.check_cost`, :attr:`Method.build_cost`):
    hints for the order in which ``balpipe check`` and ``balpipe build`` start their specs
    (:mod:`balpipe.site_files.check_cost`), never a limit."""

    name: str
    spec: type[Strict] | Ref
    build: Callable[..., Model]
    label: str
    figures: Callable[..., Any] | None = None
    notation: Any = None  # the papers' symbols of the inputs: a table or table(mechanism_spec) (balpipe.notation)
    check_cost: float = 0.0  # seconds that ``balpipe check`` of a spec of this template takes beyond a plain one's
    build_cost: float = 0.0  # seconds that ``balpipe build --no-sim`` of such a spec takes beyond its text's estimate

    @property
    def section(self) -> type[Strict]:
        """The spec section's class (``spec``, its module imported now if it is a :class:`Ref`)."""
        return section_class(self.spec)


@dataclass(frozen=True)
class Method:
    """A balancing method: ``spec`` is its pydantic section (a ``method`` literal names it),
    ``balance(ctx) -> BalanceResult`` with ``ctx`` a :class:`balpipe.balancing.context.BalanceContext`
    (the spec, its mechanism section and this method's, the unbalanced model, the time grid,
    gravity, moment point, ``page``, the mechanism on other motions and the memo of its searches),
    for ``templates`` (empty: every template, as the generic methods).
    ``figures(study)`` optionally yields the method's report figures as (title, svg or html,
    caption), drawn from the study's stages and ``study.balance.details``: the page composes the
    template's figures and the method's, so no figure code branches on a method's name.
    ``page_only`` names fields of ``spec`` that only add to the page (no error depends on them):
    ``balpipe check`` balances with them set to None. ``ctx.page`` is False in ``balpipe check``
    of a spec without references: a method may then leave out parameters, notes and details that
    no error depends on (designs only drawn).
    ``spec``, ``balance``, ``figures`` and ``notation`` may be :class:`Ref` objects (:attr:`section`
    is the spec's class): the section is imported when a spec names the method, the computing code
    when the method runs. ``check_cost``: the seconds (on one
    core, measured) that checking a spec with this method takes beyond a plain spec's few
    hundredths; ``balpipe check`` starts its costliest specs first (:mod:`balpipe.site_files.check_cost`),
    so that a long one does not start last and leave the other cores idle at the end.
    ``build_cost``: the same for ``balpipe build --no-sim``, beyond the estimate from the spec's
    text (:func:`balpipe.build.spec_cost`). ``imports``: the libraries the method's code imports
    when it runs (inside its functions, so that importing it stays light: ``"scipy.optimize"``,
    0.3 s); ``balpipe check`` of several specs imports them, and the method's code, before its
    workers fork when a spec names the method, so that each worker does not import them again.
    Only the time depends on it."""

    name: str
    spec: type[Strict] | Ref
    balance: Callable[[BalanceContext], BalanceResult]
    templates: tuple[str, ...]  # the templates it applies to; () for every template (the generic methods)
    label: str
    notation: Any = None  # the papers' symbols of the inputs: a table or table(method_spec) (balpipe.notation)
    figures: Callable[..., Any] | None = None
    page_only: tuple[str, ...] = ()
    check_cost: float = 0.0  # seconds that ``balpipe check`` of a spec with this method takes beyond a plain one's
    build_cost: float = 0.0  # seconds that ``balpipe build --no-sim`` of such a spec takes beyond its text's estimate
    imports: tuple[str, ...] = ()  # libraries its code imports when it runs (loaded before check's workers fork)

    @property
    def section(self) -> type[Strict]:
        """The spec section's class (``spec``, its module imported now if it is a :class:`Ref`)."""
        return section_class(self.spec)

    def load_code(self) -> None:
        """Import the method's code (its ``balance``'s module) and its :attr:`imports` now."""
        resolved(self.balance)
        for name in self.imports:
            import_module(name)


@dataclass(frozen=True)
class Citation:
    """A paper cited as far as the sources say: what its stored text prints, or a public record
    whose abstract is the stored text's word for word (``source`` names it); a field that no such
    source gives stays empty and :meth:`text` says so, instead of a guess."""

    title: str
    authors: str = ""
    venue: str = ""
    year: str = ""
    doi: str = ""
    source: str = ""  # where a field not printed in the stored paper comes from

    def text(self) -> str:
        """'V. Arakelian, "Title", Venue, 2025. DOI 10.x/y', missing fields named as missing."""
        parts = [self.authors] if self.authors else []
        parts.append(f"“{self.title}”")
        if self.venue:
            parts.append(self.venue)
        if self.year:
            parts.append(self.year)
        out = ", ".join(parts) + "."
        if self.doi:
            out += f" DOI {self.doi}."
        if self.source:
            out += f" (Title from {self.source}; its authors, venue and year are not in the part of that record we could read.)"
        elif not (self.authors and self.venue and self.year):
            out += (" (Title as the spec describes the paper: its stored text has no title block, authors,"
                    " venue or year.)")
        return out


@dataclass(frozen=True)
class Paper:
    """A paper whose worked examples a family reproduces: ``id`` is the number a spec names it by
    (``paper: "NNN: title"``); ``citation`` (None: the spec's own title is cited, and said to
    be); ``figures``: the figure numbers its pages reproduce (a number covers its panels: "6"
    by "6a"), which a test holds the pages to; ``own_figures(study)`` optionally yields the
    paper's panels that no method's or template's hook draws as the paper numbers them
    (title, svg or html, caption), shown on the page of every spec that names the paper, after
    the balancing's figures. ``own_figures`` may be a :class:`Ref`."""

    id: str
    citation: Citation | None = None
    figures: tuple[str, ...] = ()
    own_figures: Callable[..., Any] | None = None


@dataclass(frozen=True)
class Family:
    """One mechanism family: its templates and paper methods, in the order they appear in the
    spec's unions, and the papers it reproduces (:class:`Paper`: citation, figures; each paper
    declared by one family). ``package`` is the family's import package (the build's code hash
    takes the code of the package that the family's entry point names, read without importing
    it). ``examples``: specs that use the family, shipped with its package (paths, e.g.
    :func:`packaged_examples`, or YAML texts); :func:`balpipe.testing.check_family` builds them,
    so that a family is checked without balpipe's own ``specs/``."""

    name: str
    order: int
    templates: tuple[Template, ...] = ()
    methods: tuple[Method, ...] = ()
    papers: tuple[Paper, ...] = ()
    package: str = field(default="")
    examples: tuple[str | Path, ...] = ()


def packaged_examples(package_file: str) -> tuple[Path, ...]:
    """The ``*.yaml`` specs in the ``examples`` folder beside ``package_file`` (a family
    package's ``__init__.py``: ``packaged_examples(__file__)``), sorted by name."""
    return tuple(sorted((Path(package_file).resolve().parent / "examples").glob("*.yaml")))


def _check(obj: Any, where: str) -> Family:
    if not isinstance(obj, Family):
        raise TypeError(f"{where} is not a balpipe.plugins.Family (got {type(obj).__name__})")
    return obj


def _from_entry_points() -> dict[str, Family]:
    found: dict[str, Family] = {}
    for ep in entry_points(group=GROUP):
        fam = _check(ep.load(), f"entry point {ep.name!r} ({ep.value})")
        found.setdefault(fam.name, fam)
    return found


def _from_package_scan() -> dict[str, Family]:
    found: dict[str, Family] = {}
    pkg = import_module(IN_TREE)
    for info in sorted(pkgutil.iter_modules(pkg.__path__, IN_TREE + "."), key=lambda m: m.name):
        fam = _check(getattr(import_module(info.name), "FAMILY", None), info.name)
        found.setdefault(fam.name, fam)
    return found


@lru_cache(maxsize=1)
def discover() -> tuple[Family, ...]:
    """Every family, from entry points first, then the in-tree package scan (an entry point of
    the same name wins), sorted by order and name. Cached: call :func:`discover.cache_clear`
    after installing a family in the running process."""
    found = _from_entry_points()
    for name, fam in _from_package_scan().items():
        found.setdefault(name, fam)
    return tuple(sorted(found.values(), key=lambda f: (f.order, f.name)))
