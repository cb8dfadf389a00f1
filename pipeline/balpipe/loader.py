"""Load a spec file: YAML -> :class:`~balpipe.spec.Spec`, with every error located.

Errors become :class:`SpecError` values that name the file, the line and column, the field path
and what is wrong, e.g. ``specs/a.yaml:12:11: mechanism.crank.mass: must be >= 0``. The YAML is
composed once into a node tree that keeps the position of every key and value, so schema errors
(pydantic) and semantic errors raised later (:class:`~balpipe.spec_parts.SpecFieldError`) point
at the same place.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from .spec import Spec
from .spec_parts import SpecFieldError

try:  # the C loader is 5-10x faster; fall back to the pure-Python one
    from yaml import CSafeLoader as _Loader
except ImportError:  # pragma: no cover
    from yaml import SafeLoader as _Loader  # type: ignore[assignment]


@dataclass(frozen=True)
class SpecError:
    """One located problem in a spec file."""

    file: str
    line: int | None
    column: int | None
    path: str
    message: str

    def __str__(self) -> str:
        where = self.file
        if self.line is not None:
            where += f":{self.line}:{self.column}"
        return f"{where}: {self.path + ': ' if self.path else ''}{self.message}"


class SpecErrors(Exception):
    """All the problems found in one spec file."""

    def __init__(self, errors: list[SpecError]):
        super().__init__("\n".join(map(str, errors)))
        self.errors = errors


@dataclass
class LoadedSpec:
    path: Path
    text: str
    spec: Spec
    node: yaml.Node

    def error(self, exc: SpecFieldError) -> SpecErrors:
        """Locate a semantic error raised while building or balancing this spec."""
        return SpecErrors([_located(str(self.path), self.node, exc.path, exc.message)])


def _format_path(path: tuple) -> str:
    out = ""
    for p in path:
        out += f"[{p}]" if isinstance(p, int) else (f".{p}" if out else str(p))
    return out


def _find(node: yaml.Node | None, path: tuple) -> tuple[yaml.Node | None, bool]:
    """The deepest node along ``path``; the flag says whether the whole path was found."""
    cur = node
    for key in path:
        if isinstance(cur, yaml.MappingNode):
            nxt = None
            for k, v in cur.value:
                if k.value == str(key):
                    nxt = v
                    break
            if nxt is None:
                return cur, False
            cur = nxt
        elif isinstance(cur, yaml.SequenceNode) and isinstance(key, int) and 0 <= key < len(cur.value):
            cur = cur.value[key]
        else:
            return cur, False
    return cur, True


def _key_node(node: yaml.Node | None, path: tuple) -> yaml.Node | None:
    """For an unknown key the error is at the key itself, not at its value."""
    parent, ok = _find(node, path[:-1])
    if ok and isinstance(parent, yaml.MappingNode):
        for k, _ in parent.value:
            if k.value == str(path[-1]):
                return k
    return None


def _located(file: str, root: yaml.Node | None, path: tuple, message: str, at_key: bool = False) -> SpecError:
    target = _key_node(root, path) if at_key else None
    if target is None:
        target, _ = _find(root, path)
    if target is None:
        return SpecError(file, None, None, _format_path(path), message)
    mark = target.start_mark
    return SpecError(file, mark.line + 1, mark.column + 1, _format_path(path), message)


_DISCRIMINATORS = ("template", "method", "type")


def _clean_loc(loc: tuple, data: Any) -> tuple:
    """Drop the parts of pydantic's error location that are not in the document: the tags of
    discriminated unions (e.g. 'slider_crank') and validator names ('function-after[...]')."""
    out: list = []
    cur = data
    for part in loc:
        if isinstance(part, str) and ("[" in part or part.startswith("function-")):
            continue
        if isinstance(cur, dict) and part not in cur and any(cur.get(d) == part for d in _DISCRIMINATORS):
            continue
        out.append(part)
        if isinstance(cur, dict):
            cur = cur.get(part)
        elif isinstance(cur, list) and isinstance(part, int) and 0 <= part < len(cur):
            cur = cur[part]
        else:
            cur = None
    return tuple(out)


def _message(err: dict) -> str:
    msg = err["msg"]
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    kind = err["type"]
    if kind == "extra_forbidden":
        return "unknown key (not part of the spec schema; check the spelling)"
    if kind == "missing":
        return "required field is missing"
    ctx = err.get("ctx", {})
    if kind == "union_tag_invalid":
        return f"unknown value {ctx.get('tag')!r}; expected one of: {ctx.get('expected_tags', '')}"
    if kind in ("greater_than", "greater_than_equal", "less_than", "less_than_equal"):
        op = {"greater_than": ">", "greater_than_equal": ">=", "less_than": "<", "less_than_equal": "<="}[kind]
        bound = next(iter(ctx.values()), "")
        return f"must be {op} {bound} (got {err.get('input')!r})"
    if kind == "union_tag_not_found":
        return f"missing the key {err.get('ctx', {}).get('discriminator', '')} that says which kind this is"
    return msg


def _check_duplicates(node: yaml.Node, file: str, path: tuple = ()) -> list[SpecError]:
    errors = []
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for k, v in node.value:
            if k.value in seen:
                m = k.start_mark
                errors.append(SpecError(file, m.line + 1, m.column + 1, _format_path(path + (k.value,)), "duplicate key"))
            seen.add(k.value)
            errors += _check_duplicates(v, file, path + (k.value,))
    elif isinstance(node, yaml.SequenceNode):
        for i, v in enumerate(node.value):
            errors += _check_duplicates(v, file, path + (i,))
    return errors


def load_text(text: str, file: str) -> tuple[Spec, yaml.Node]:
    try:
        node = yaml.compose(text, Loader=_Loader)
        data = yaml.load(text, Loader=_Loader)
    except yaml.YAMLError as exc:
        mark = getattr(exc, "problem_mark", None)
        problem = getattr(exc, "problem", None) or str(exc)
        context = getattr(exc, "context", None)
        msg = f"malformed YAML: {problem}" + (f" ({context})" if context else "")
        line, col = (mark.line + 1, mark.column + 1) if mark else (None, None)
        raise SpecErrors([SpecError(file, line, col, "", msg)]) from None
    if node is None or not isinstance(data, dict):
        raise SpecErrors([SpecError(file, 1, 1, "", "the spec must be a YAML mapping (name:, mechanism:, motion:, ...)")])
    dup = _check_duplicates(node, file)
    if dup:
        raise SpecErrors(dup)
    try:
        spec = Spec.model_validate(data)
    except ValidationError as exc:
        errors = []
        for err in exc.errors():
            loc = _clean_loc(err["loc"], data)
            if err["type"] in ("union_tag_invalid", "union_tag_not_found"):
                loc = loc + (err.get("ctx", {}).get("discriminator", "").strip("'"),)
            errors.append(_located(file, node, loc, _message(err), at_key=err["type"] == "extra_forbidden"))
        # one line per place: a union may report the same field several times
        unique = list(dict.fromkeys(errors))
        raise SpecErrors(sorted(unique, key=lambda e: (e.line or 0, e.column or 0))) from None
    return spec, node


def load(path: str | Path) -> LoadedSpec:
    """Read and validate one spec file; raises :class:`SpecErrors`."""
    p = Path(path)
    try:
        text = p.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as exc:
        raise SpecErrors([SpecError(str(p), None, None, "", f"cannot read the file: {exc}")]) from None
    spec, node = load_text(text, str(p))
    return LoadedSpec(p, text, spec, node)


def schema() -> dict[str, Any]:
    """The JSON Schema of a spec (``balpipe schema``)."""
    s = Spec.model_json_schema(by_alias=True)
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    s["title"] = "balpipe spec"
    return s
