"""Load a spec file: YAML -> :class:`~balpipe.spec.Spec`, with every error located.

Errors become :class:`SpecError` values that name the file, the line and column, the field path
and what is wrong, e.g. ``specs/a.yaml:12:11: mechanism.crank.mass: must be >= 0``. The YAML is
composed once into a node tree that keeps the position of every key and value, so schema errors
(pydantic) and semantic errors raised later (:class:`~balpipe.spec_parts.SpecFieldError`) point
at the same place.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml
from pydantic import ValidationError

from .laws.drives import read_tables
from .runtime.inputs import InputFileError, read_regular
from .limits import check_limits
from .spec import Spec, validate
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
    name: str | None = None  # how messages name the file (a published name), else str(path)

    def error(self, exc: SpecFieldError) -> SpecErrors:
        """Locate a semantic error raised while building or balancing this spec."""
        return SpecErrors([located(self.name or str(self.path), self.node, exc.path, exc.message)])


def format_path(path: tuple) -> str:
    out = ""
    for p in path:
        if not isinstance(p, int):
            p = str(p)
            if not p or not p.isprintable() or p != p.strip():  # keys are data: show them quoted
                p = repr(p)
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
    if not path:
        return None
    parent, ok = _find(node, path[:-1])
    if ok and isinstance(parent, yaml.MappingNode):
        for k, _ in parent.value:
            if k.value == str(path[-1]):
                return k
    return None


def located(file: str, root: yaml.Node | None, path: tuple, message: str, at_key: bool = False) -> SpecError:
    target = _key_node(root, path) if at_key else None
    if target is None:
        target, _ = _find(root, path)
    if target is None:
        return SpecError(file, None, None, format_path(path), message)
    mark = target.start_mark
    return SpecError(file, mark.line + 1, mark.column + 1, format_path(path), message)


_DISCRIMINATORS = ("template", "method", "type")


def clean_loc(loc: tuple, data: Any) -> tuple:
    """Drop the parts of pydantic's error location that are not in the document: the tags of
    discriminated unions (a template's or method's name) and validator names ('function-after[...]')."""
    out: list = []
    cur = data
    for k, part in enumerate(loc):
        in_document = isinstance(cur, dict) and part in cur
        if isinstance(part, str) and ("[" in part or part.startswith("function-")) and not in_document:
            continue
        tag = isinstance(cur, dict) and any(cur.get(d) == part for d in _DISCRIMINATORS)
        # a tag that is also a key of the mapping (method: stages, with its stages: list) is the
        # tag when the next part of the location is a key of the same mapping
        if tag and (part not in cur or (k + 1 < len(loc) and loc[k + 1] in cur)):
            continue
        out.append(part)
        if isinstance(cur, dict):
            cur = cur.get(part)
        elif isinstance(cur, list) and isinstance(part, int) and 0 <= part < len(cur):
            cur = cur[part]
        else:
            cur = None
    return tuple(out)


def error_message(err: dict) -> str:
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
    got = _describe(err.get("input"))
    expected = {
        "string_type": "text (a string)", "dict_type": "a mapping (key: value)", "model_type": "a mapping (key: value)",
        "list_type": "a list", "tuple_type": "a list", "bool_type": "true or false", "bool_parsing": "true or false",
        "int_type": "a whole number", "int_parsing": "a whole number", "float_type": "a number",
        "float_parsing": "a number", "finite_number": "a finite number",
    }.get(kind)
    if expected:
        return f"expected {expected}, got {got}"
    if kind == "literal_error":
        return f"expected {ctx.get('expected', 'one of the listed values')}, got {got}"
    if kind in ("too_short", "too_long"):
        return f"{'too few' if kind == 'too_short' else 'too many'} items: {msg.split(', ', 1)[-1]}"
    if kind == "string_too_short":
        return "must not be empty"
    if msg.startswith("Input should be "):
        return f"expected {msg[len('Input should be '):]}, got {got}"
    return msg


def _describe(value: Any) -> str:
    """A short description of a value for an error message."""
    if value is None:
        return "nothing (null)"
    if isinstance(value, bool):
        return f"a boolean ({str(value).lower()})"
    if isinstance(value, dict):
        return "a mapping"
    if isinstance(value, (list, tuple)):
        return f"a list of {len(value)}"
    text = repr(value)
    return text if len(text) <= 60 else text[:57] + "..."


def _check_duplicates(node: yaml.Node, file: str, path: tuple = (), done: set | None = None) -> list[SpecError]:
    """Keys written twice in one mapping, on the composed document (before the constructor
    flattens merge keys): a key that overrides one merged in with ``<<: *anchor`` is not a
    duplicate. A node reached through several aliases is checked once."""
    done = set() if done is None else done
    if id(node) in done:
        return []
    done.add(id(node))
    errors = []
    if isinstance(node, yaml.MappingNode):
        seen = set()
        for k, v in node.value:
            if k.value in seen and k.tag != "tag:yaml.org,2002:merge":
                m = k.start_mark
                errors.append(SpecError(file, m.line + 1, m.column + 1, format_path(path + (k.value,)), "duplicate key"))
            seen.add(k.value)
            errors += _check_duplicates(v, file, path + (k.value,), done)
    elif isinstance(node, yaml.SequenceNode):
        for i, v in enumerate(node.value):
            errors += _check_duplicates(v, file, path + (i,), done)
    return errors


#: Limits of a spec file, checked before any work (docs/limits.md).
MAX_FILE_BYTES = 1_000_000
MAX_DEPTH = 64
MAX_VALUES = 200_000  # values after alias expansion (an alias bomb multiplies them)

_CONTROL = re.compile(r"[\x00-\x08\x0b\x0c\x0e-\x1f\x7f-\x84\x86-\x9f\ufffe\uffff]")
_CONTROL_NAMES = {0: "NUL", 7: "BEL", 8: "BS", 0x1B: "ESC", 0x7F: "DEL"}


def _control_message(ch: str) -> str:
    name = _CONTROL_NAMES.get(ord(ch))
    return f"control character U+{ord(ch):04X}{f' ({name})' if name else ''} is not allowed in a spec"


def _check_text(text: str, file: str) -> None:
    """Control characters (raw in the file) with their line and column."""
    errors = []
    for m in _CONTROL.finditer(text):
        line = text.count("\n", 0, m.start()) + 1
        col = m.start() - (text.rfind("\n", 0, m.start()) + 1) + 1
        errors.append(SpecError(file, line, col, "", _control_message(m.group())))
        if len(errors) >= 5:
            break
    if errors:
        raise SpecErrors(errors)


def _yaml_error(exc: yaml.YAMLError, file: str) -> SpecErrors:
    mark = getattr(exc, "problem_mark", None)
    problem = getattr(exc, "problem", None) or str(exc)
    context = getattr(exc, "context", None)
    msg = f"malformed YAML: {problem}" + (f" ({context})" if context else "")
    line, col = (mark.line + 1, mark.column + 1) if mark else (None, None)
    return SpecErrors([SpecError(file, line, col, "", msg)])


def _check_nesting(text: str, file: str) -> tuple[int, int, bool]:
    """Nesting depth from the event stream (iterative: a deeply nested document would otherwise
    overflow the C composer's stack) before any tree is built. Returns what the stream holds:
    (values: scalars and collections, the deepest nesting of collections, whether it has an
    alias), which tells :func:`_needs_alias_check`."""
    depth = deepest = values = 0
    aliased = False
    events = yaml.parse(text, Loader=_Loader)
    while True:
        try:
            ev = next(events)
        except StopIteration:
            return values, deepest, aliased
        except yaml.YAMLError as exc:
            # PyYAML >= 6.0.4 has a nesting limit of its own, which a document far deeper than
            # ours reaches first: the same refusal, in the same words on every PyYAML
            if "nesting depth" in str(getattr(exc, "problem", "") or ""):
                m = exc.problem_mark
                raise SpecErrors([SpecError(file, m.line + 1 if m else None, m.column + 1 if m else None, "",
                                            f"nested deeper than {MAX_DEPTH} levels (limit)")]) from None
            raise
        if isinstance(ev, (yaml.MappingStartEvent, yaml.SequenceStartEvent)):
            depth += 1
            values += 1
            deepest = max(deepest, depth)
            if depth > MAX_DEPTH:
                m = ev.start_mark
                raise SpecErrors([SpecError(file, m.line + 1, m.column + 1, "",
                                            f"nested deeper than {MAX_DEPTH} levels (limit)")])
        elif isinstance(ev, (yaml.MappingEndEvent, yaml.SequenceEndEvent)):
            depth -= 1
        elif isinstance(ev, yaml.ScalarEvent):
            values += 1
        elif isinstance(ev, yaml.AliasEvent):
            aliased = True


def _needs_alias_check(values: int, deepest: int, aliased: bool) -> bool:
    """Whether :func:`_check_aliases` can refuse a document whose event stream holds ``values``
    scalars and collections, nested ``deepest`` collections deep, ``aliased`` or not: without an
    alias its nodes are a tree, one per event, so no value expands to more than ``values``
    values nor nests deeper than ``deepest`` + 1 levels (a scalar in the deepest collection):
    within the limits, the walk of the node graph would find nothing (0.45 ms a spec)."""
    return aliased or values > MAX_VALUES or deepest + 1 > MAX_DEPTH


def _children(node: yaml.Node) -> list[yaml.Node]:
    if isinstance(node, yaml.MappingNode):
        return [x for kv in node.value for x in kv]
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    return []


def _check_aliases(root: yaml.Node, file: str) -> None:
    """Refuse recursive aliases and alias bombs: the size of the document with every alias
    expanded is computed on the shared node graph (linear time) and bounded by MAX_VALUES."""
    size: dict[int, int] = {}
    depth: dict[int, int] = {}
    on_path: set[int] = set()
    stack: list[tuple[yaml.Node, bool]] = [(root, False)]

    def fail(node: yaml.Node, msg: str) -> SpecErrors:
        m = node.start_mark
        return SpecErrors([SpecError(file, m.line + 1, m.column + 1, "", msg)])

    while stack:
        node, done = stack.pop()
        key = id(node)
        kids = _children(node)
        if done:
            on_path.discard(key)
            size[key] = 1 + sum(size[id(k)] for k in kids)
            depth[key] = 1 + max((depth[id(k)] for k in kids), default=0)
            if size[key] > MAX_VALUES:
                raise fail(node, f"aliases expand this value to more than {MAX_VALUES} values (limit; an alias bomb?)")
            if depth[key] > MAX_DEPTH:
                raise fail(node, f"aliases nest this value deeper than {MAX_DEPTH} levels (limit)")
            continue
        if key in size:
            continue
        on_path.add(key)
        stack.append((node, True))
        for k in kids:
            if id(k) in on_path:
                raise fail(k, "recursive alias: this value contains itself")
            if id(k) not in size:
                stack.append((k, False))


def _check_strings(node: yaml.Node, file: str, path: tuple = ()) -> list[SpecError]:
    """Control characters that reached a string through a YAML escape ("\\x1b", "\\0")."""
    errors: list[SpecError] = []
    stack = [(node, path)]
    seen: set[int] = set()
    while stack:
        n, p = stack.pop()
        if id(n) in seen:
            continue
        seen.add(id(n))
        if isinstance(n, yaml.ScalarNode):
            m = _CONTROL.search(n.value) if isinstance(n.value, str) else None
            if m:
                mk = n.start_mark
                errors.append(SpecError(file, mk.line + 1, mk.column + 1, format_path(p), _control_message(m.group())))
        elif isinstance(n, yaml.MappingNode):
            for k, v in n.value:
                stack.append((k, p))
                stack.append((v, p + (k.value if isinstance(k, yaml.ScalarNode) else "?",)))
        elif isinstance(n, yaml.SequenceNode):
            stack += [(v, p + (i,)) for i, v in enumerate(n.value)]
    return sorted(errors, key=lambda e: (e.line or 0, e.column or 0))[:5]


def load_text(text: str, file: str, folder: str | Path | None = None) -> tuple[Spec, yaml.Node]:
    """Validate the spec ``text``; messages name it ``file``. The files it names (tables) are
    read in ``folder`` (default: ``file``'s folder). Raises :class:`SpecErrors`."""
    if text.startswith("\ufeff"):
        text = text[1:]
    _check_text(text, file)
    try:
        stream = _check_nesting(text, file)
        loader = _Loader(text)
        try:
            node = loader.get_single_node()
            if node is not None and _needs_alias_check(*stream):
                _check_aliases(node, file)
            dup = _check_duplicates(node, file) if node is not None else []  # before merge keys are flattened
            data = loader.construct_document(node) if node is not None else None
        finally:
            loader.dispose()
    except yaml.YAMLError as exc:
        raise _yaml_error(exc, file) from None
    except RecursionError:
        raise SpecErrors([SpecError(file, None, None, "", f"nested too deeply (limit {MAX_DEPTH} levels)")]) from None
    if node is not None:
        bad = _check_strings(node, file)
        if bad:
            raise SpecErrors(bad)
    if node is None or not isinstance(data, dict):
        raise SpecErrors([SpecError(file, 1, 1, "", "the spec must be a YAML mapping (name:, mechanism:, motion:, ...)")])
    if dup:
        raise SpecErrors(dup)
    try:
        spec = validate(data)
    except ValidationError as exc:
        errors = []
        for err in exc.errors():
            loc = clean_loc(err["loc"], data)
            if err["type"] in ("union_tag_invalid", "union_tag_not_found"):
                loc = loc + (err.get("ctx", {}).get("discriminator", "").strip("'"),)
            errors.append(located(file, node, loc, error_message(err), at_key=err["type"] == "extra_forbidden"))
        # one line per place: a union may report the same field several times
        unique = list(dict.fromkeys(errors))
        raise SpecErrors(sorted(unique, key=lambda e: (e.line or 0, e.column or 0))) from None
    try:
        check_limits(spec)
        read_tables(spec, Path(file).parent if folder is None else Path(folder))
    except SpecFieldError as exc:
        raise SpecErrors([located(file, node, exc.path, exc.message)]) from None
    return spec, node


def decode(raw: bytes, file: str) -> str:
    """UTF-8 text of a spec file; other encodings are refused with the line and column of the
    first byte that is not UTF-8."""
    for bom, name in ((b"\xff\xfe\x00\x00", "UTF-32"), (b"\x00\x00\xfe\xff", "UTF-32"),
                      (b"\xff\xfe", "UTF-16"), (b"\xfe\xff", "UTF-16")):
        if raw.startswith(bom):
            raise SpecErrors([SpecError(file, 1, 1, "", f"the file is {name} (byte-order mark); save it as UTF-8")])
    try:
        return raw.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        start = raw.rfind(b"\n", 0, exc.start) + 1
        col = len(raw[start:exc.start].decode("utf-8", errors="replace")) + 1
        hint = " (UTF-16?)" if b"\x00" in raw[:64] else ""
        raise SpecErrors([SpecError(file, line, col, "",
                                    f"not UTF-8{hint}: byte 0x{raw[exc.start]:02x} cannot be decoded; save the file as UTF-8")]) from None


def load(path: str | Path, name: str | None = None) -> LoadedSpec:
    """Read and validate one spec file; raises :class:`SpecErrors`. Messages name the file
    ``name`` (a published name, :func:`balpipe.site_files.spec_files.published_names`), else
    ``path``."""
    p = Path(path)
    shown = name or str(p)
    try:  # a regular file only (a FIFO or /dev/zero named on the command line is refused), the limit enforced while reading
        raw = read_regular(p, MAX_FILE_BYTES, "the file")
    except InputFileError as exc:
        message = str(exc).replace("the file is larger than", "file too large: larger than")
        raise SpecErrors([SpecError(shown, None, None, "", message)]) from None
    text = decode(raw, shown)
    spec, node = load_text(text, shown, p.parent)
    return LoadedSpec(p, text, spec, node, name)


def prepare() -> None:
    """Build the whole spec's validator now (every family's sections, ~50 ms; pydantic defers it
    to the first spec validated): before a process pool forks, so that its workers inherit it
    instead of each building it or the narrower ones of :func:`balpipe.spec.validate`."""
    Spec.model_rebuild()


def schema() -> dict[str, Any]:
    """The JSON Schema of a spec (``balpipe schema``)."""
    s = _stable_def_names(Spec.model_json_schema(by_alias=True))
    s["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    s["title"] = "balpipe spec"
    return s


def _stable_def_names(node: Any) -> Any:
    """pydantic names a definition whose class name is not unique by its module path; a family's
    template module ``balpipe.families.X.template`` keeps the name it had as
    ``balpipe.mechanisms.X``, so the schema does not change when code moves."""
    if isinstance(node, dict):
        return {_stable_name(k): _stable_def_names(v) for k, v in node.items()}
    if isinstance(node, list):
        return [_stable_def_names(v) for v in node]
    return _stable_name(node) if isinstance(node, str) else node


def _stable_name(text: str) -> str:
    return re.sub(r"balpipe__families__([A-Za-z0-9_]+?)__template__", r"balpipe__mechanisms__\1__", text)
