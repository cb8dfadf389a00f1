"""A spec's expected ``balpipe check`` work, so that the check's process pool starts the costliest
specs first (:func:`balpipe.runtime.pool.in_order`'s ``cost``: longest processing time first). Without it
paper 003's spec, ten times the work of most, started 19th of 24 and ran alone at the end. The
same hints, ``build_cost``, order ``balpipe build --no-sim`` (:func:`balpipe.build.spec_cost`).

The estimate is :data:`PLAIN` plus the ``check_cost`` that the spec's template and balancing method
declare (:class:`balpipe.plugins.Template`, :class:`balpipe.plugins.Method`: seconds on one core,
measured). The parent process reads the two names from the YAML event stream (no tree is built,
no alias expanded, nothing validated): a file that cannot be read or parsed, or names that are
not known, cost :data:`PLAIN`, and the worker that checks the spec reports what is wrong with it.
Only the order in which the specs start depends on it, never what check says nor in which order.
"""

from __future__ import annotations

import stat
from pathlib import Path

import yaml

try:
    from yaml import CSafeLoader as _Parser  # libyaml: the events without Python's scanner
except ImportError:  # pragma: no cover - PyYAML without libyaml
    from yaml import SafeLoader as _Parser  # type: ignore[assignment]

#: seconds that a plain spec's check takes (load, balance, analyse): most specs of specs/
PLAIN = 0.05
#: the (section, key) pairs whose scalar values name the template and the method
_NAMES = (("mechanism", "template"), ("balancing", "method"))


def check_cost(path: Path) -> float:
    """The expected seconds of ``balpipe check`` of the spec at ``path`` (see the module)."""
    return PLAIN + declared_cost(path, "check_cost")


def check_hints(path: Path) -> tuple[float, str | None]:
    """(:func:`check_cost`, the ``balancing: {method: ...}`` it names or None) of the spec at
    ``path``, from one read of its names: ``balpipe check`` of several specs needs both before its
    workers fork (the methods' code is loaded there)."""
    names = _read_names(path)
    return PLAIN + _cost_of(names, "check_cost"), names.get(_NAMES[1])


def declared_cost(path: Path, hint: str) -> float:
    """The sum of the ``hint`` attribute (``check_cost`` or ``build_cost``) of the template and
    the method that the spec at ``path`` names; 0 where it cannot be read or names neither."""
    return _cost_of(_read_names(path), hint)


def _cost_of(names: dict[tuple[str, str], str], hint: str) -> float:
    """The sum of the ``hint`` attribute of the template and the method of ``names``
    (:func:`declared_names`' dictionary); 0 for names not known."""
    from .. import registry

    template = registry.TEMPLATES.get(names.get(_NAMES[0], ""))
    method = registry.METHODS.get(names.get(_NAMES[1], ""))
    return sum(getattr(item, hint) for item in (template, method) if item is not None)


def _read_names(path: Path) -> dict[tuple[str, str], str]:
    """:func:`declared_names` of the file at ``path``; empty where it cannot be read."""
    from ..loader import MAX_FILE_BYTES

    try:
        st = path.stat()
        if not stat.S_ISREG(st.st_mode) or st.st_size > MAX_FILE_BYTES:  # a pipe would block here
            return {}
        return declared_names(path.read_text(encoding="utf-8"))
    except (OSError, UnicodeDecodeError, yaml.YAMLError):
        return {}


def declared_names(text: str) -> dict[tuple[str, str], str]:
    """The scalar values of ``mechanism: {template: ...}`` and ``balancing: {method: ...}`` in a
    spec's text, by (section, key), read from its YAML events (a stack of the open collections:
    for a mapping, the key whose value is being read; None while a key is expected)."""
    found: dict[tuple[str, str], str] = {}
    stack: list[list] = []  # [is a mapping, its current key or None]
    for ev in yaml.parse(text, Loader=_Parser):
        if isinstance(ev, yaml.CollectionStartEvent):
            stack.append([isinstance(ev, yaml.MappingStartEvent), None])
        elif isinstance(ev, yaml.CollectionEndEvent):
            stack.pop()
            _value_done(stack)
        elif isinstance(ev, (yaml.ScalarEvent, yaml.AliasEvent)):
            if stack and stack[-1][0] and stack[-1][1] is None:  # a key of the innermost mapping
                stack[-1][1] = ev.value if isinstance(ev, yaml.ScalarEvent) else ""
                continue
            path = tuple(key if is_map else None for is_map, key in stack)
            if path in _NAMES and isinstance(ev, yaml.ScalarEvent):
                found[path] = ev.value  # type: ignore[index]
                if len(found) == len(_NAMES):
                    break
            _value_done(stack)
    return found


def _value_done(stack: list[list]) -> None:
    """After a value: the innermost collection, if a mapping, expects its next key."""
    if stack and stack[-1][0]:
        stack[-1][1] = None
