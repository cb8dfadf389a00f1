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
"""

from __future__ import annotations

import pkgutil
from dataclasses import dataclass, field
from functools import lru_cache
from importlib import import_module
from importlib.metadata import entry_points
from typing import Any, Callable

from . import FAMILY_GROUP
from .balancing.base import BalanceResult
from .model import Model
from .spec_parts import Strict

GROUP = FAMILY_GROUP
IN_TREE = "balpipe.families"


@dataclass(frozen=True)
class Template:
    """A mechanism template: ``spec`` is its pydantic section (a ``template`` literal names it),
    ``build(mechanism_spec, laws, t) -> Model``; ``laws`` maps drive names to laws.
    ``figures(study)`` optionally yields extra report figures as (title, svg, caption)."""

    name: str
    spec: type[Strict]
    build: Callable[..., Model]
    label: str
    figures: Callable[..., Any] | None = None
    notation: Any = None  # the papers' symbols of the inputs: a table or table(mechanism_spec) (balpipe.notation)


@dataclass(frozen=True)
class Method:
    """A balancing method: ``spec`` is its pydantic section (a ``method`` literal names it),
    ``balance(mechanism_spec, method_spec, model) -> BalanceResult`` for ``templates``.
    ``figures(study)`` optionally yields the method's report figures as (title, svg or html,
    caption), drawn from the study's stages and ``study.balance.details``: the page composes the
    template's figures and the method's, so no figure code branches on a method's name.
    ``page_only`` names fields of ``spec`` that only add to the page (no error depends on them):
    ``balpipe check`` balances with them set to None. With ``page_aware``, ``balance`` also
    receives ``page=``: False in ``balpipe check`` of a spec without references, where it may
    leave out parameters, notes and details that no error depends on (designs only drawn)."""

    name: str
    spec: type[Strict]
    balance: Callable[..., BalanceResult]
    templates: tuple[str, ...]
    label: str
    uses_spec: bool = False  # balance(..., spec): the method also reads the motion and analysis settings
    generic: bool = False  # applies to every template; balance() also receives the time grid t
    # balance(..., models=f) also receives f(motion, samples, path) -> (unbalanced model, time grid)
    # of the mechanism on another motion section (errors located at path); generic methods only
    other_motions: bool = False
    notation: Any = None  # the papers' symbols of the inputs: a table or table(method_spec) (balpipe.notation)
    figures: Callable[..., Any] | None = None
    page_only: tuple[str, ...] = ()
    page_aware: bool = False  # balance(..., page=bool): whether the page's outputs are wanted


@dataclass(frozen=True)
class Family:
    """One mechanism family: its templates and paper methods, in the order they appear in the
    spec's unions. ``package`` is the family's import package (the build's code hash takes the
    code of the package that the family's entry point names, read without importing it)."""

    name: str
    order: int
    templates: tuple[Template, ...] = ()
    methods: tuple[Method, ...] = ()
    paper: str | None = None
    package: str = field(default="")


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
