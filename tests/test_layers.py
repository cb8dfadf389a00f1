"""balpipe's layers (issue 19): a module imports only from its own layer or the layers below it,
deferred (in-function) imports included, and the import graph has no cycle. Families are
plugins: nothing outside ``balpipe.families`` imports one."""

from __future__ import annotations

import ast
import functools
import shutil
from collections import defaultdict
from pathlib import Path

import pytest

SRC = Path(__file__).resolve().parents[1] / "pipeline"

# lowest first; a module belongs to the layer of its longest matching prefix
LAYERS: tuple[tuple[str, ...], ...] = (
    # L0 core data and maths
    ("balpipe", "balpipe.units", "balpipe.model", "balpipe.motion", "balpipe.meshes", "balpipe.joint_laws",
     "balpipe.realisable", "balpipe.notation", "balpipe.sampling", "balpipe.fsutil", "balpipe.drivers", "balpipe.laws",
     "balpipe.motion_outputs", "balpipe.claim_precision", "balpipe.sweep_limit", "balpipe.pool"),
    # L1 computation (and the kinematic diagnosis on top of the engine: dyads, dead centres)
    ("balpipe.engine", "balpipe.validate", "balpipe.dyads", "balpipe.dead_centres"),
    # L2 contracts and drawing (laws.drives, laws.motion_spec: the motion's spec sections; actuators, loop closure and
    # the assembly branch: checks that locate their errors in the spec)
    ("balpipe.spec_parts", "balpipe.vary", "balpipe.balancing", "balpipe.draw", "balpipe.plugins", "balpipe.registry",
     "balpipe.laws.drives", "balpipe.laws.motion_spec", "balpipe.actuation", "balpipe.loop_closure", "balpipe.assembly"),
    # L3 families (plugins)
    ("balpipe.families",),
    # L3' the schema
    ("balpipe.spec", "balpipe.sweep_spec", "balpipe.loader", "balpipe.limits"),
    # L4 pipeline
    ("balpipe.study", "balpipe.validation_stage", "balpipe.runner"),
    # L5 presentation
    ("balpipe.report",),
    # L6 commands
    ("balpipe.build", "balpipe.diff", "balpipe.history", "balpipe.sweep", "balpipe.site_earlier", "balpipe.spec_files",
     "balpipe.check_cost"),
    # L7 command line
    ("balpipe.cli", "balpipe.__main__"),
)


def layer_of(module: str) -> int:
    best, found = -1, None
    for k, prefixes in enumerate(LAYERS):
        for p in prefixes:
            if (module == p or module.startswith(p + ".")) and len(p) > best:
                best, found = len(p), k
    if found is None:
        raise AssertionError(f"{module} is in no layer: add it to tests/test_layers.py LAYERS")
    return found


def modules(src: Path) -> dict[str, Path]:
    out = {}
    for p in sorted((src / "balpipe").rglob("*.py")):
        name = ".".join(p.relative_to(src).with_suffix("").parts)
        out[name.removesuffix(".__init__")] = p
    return out


def source_of(node: ast.ImportFrom, pkg: str) -> str:
    """The absolute name of the module a ``from ... import`` reads, in the package ``pkg``."""
    if not node.level:
        return node.module or ""
    parts = pkg.split(".")
    base = ".".join(parts[: len(parts) - (node.level - 1)])
    return f"{base}.{node.module}" if node.module else base


def imports(src: Path) -> dict[str, set[tuple[str, bool, int]]]:
    """module -> {(imported balpipe module, deferred?, line)}, every import statement of the file
    (inside functions too)."""
    mods = modules(src)
    edges: dict[str, set[tuple[str, bool, int]]] = defaultdict(set)
    for m, p in mods.items():
        pkg = m if p.name == "__init__.py" else m.rsplit(".", 1)[0]

        def target(name: str) -> str | None:
            while name not in mods and "." in name:
                name = name.rsplit(".", 1)[0]
            return name if name in mods and name.startswith("balpipe") else None

        def visit(node: ast.AST, deferred: bool) -> None:
            for ch in ast.iter_child_nodes(node):
                d = deferred or isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                found: list[str | None] = []
                if isinstance(ch, ast.Import):
                    found = [target(a.name) for a in ch.names]
                elif isinstance(ch, ast.ImportFrom):
                    mod = source_of(ch, pkg)
                    found = [target(f"{mod}.{a.name}") for a in ch.names]
                for t in found:
                    if t and t != m:
                        edges[m].add((t, d, ch.lineno))
                visit(ch, d)

        visit(_tree(p.read_text(encoding="utf-8")), False)
    return edges


@functools.lru_cache(maxsize=None)
def _tree(text: str) -> ast.Module:
    """The syntax tree of a module's text, parsed once per text in this process: every test reads
    the same files (a planted copy differs in one or two), and parsing them all is most of a
    test's time. The trees are only read."""
    return ast.parse(text)


def upward(src: Path) -> list[str]:
    bad = []
    for m, targets in sorted(imports(src).items()):
        for t, deferred, line in sorted(targets):
            if layer_of(t) > layer_of(m):
                bad.append(f"{m}:{line} imports {t}{' (deferred)' if deferred else ''}: layer {layer_of(m)} < {layer_of(t)}")
    return bad


def cycles(src: Path) -> list[list[str]]:
    """Strongly connected components of more than one module (Tarjan), deferred imports included."""
    adj = {m: sorted({t for t, _, _ in ts}) for m, ts in imports(src).items()}
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on: set[str] = set()
    out: list[list[str]] = []

    def go(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on.add(v)
        for w in adj.get(v, ()):
            if w not in index:
                go(w)
                low[v] = min(low[v], low[w])
            elif w in on:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                out.append(sorted(comp))

    for v in sorted(modules(src)):
        if v not in index:
            go(v)
    return out


def family_imports_outside_families(src: Path) -> list[str]:
    return [
        f"{m}:{line} imports {t}"
        for m, ts in sorted(imports(src).items()) if not m.startswith("balpipe.families")
        for t, _, line in sorted(ts) if t.startswith("balpipe.families")
    ]


def test_every_module_has_a_layer():
    for m in modules(SRC):
        layer_of(m)


def test_no_upward_import():
    assert upward(SRC) == []


def test_no_import_cycle():
    assert cycles(SRC) == []


def test_no_core_module_imports_a_family():
    assert family_imports_outside_families(SRC) == []


def test_families_import_nothing_above_the_drawing_layer():
    fam = layer_of("balpipe.families")
    bad = [
        f"{m}:{line} imports {t}" for m, ts in sorted(imports(SRC).items()) if m.startswith("balpipe.families.")
        for t, _, line in sorted(ts)
        if layer_of(t) >= fam and not t.startswith("balpipe.families." + m.split(".")[2])
    ]
    assert bad == []


@pytest.fixture()
def tree_copy(tmp_path: Path) -> Path:
    shutil.copytree(SRC / "balpipe", tmp_path / "balpipe")
    return tmp_path


def test_a_planted_cycle_fails(tree_copy: Path):
    """A deferred import of the command layer from the model closes a cycle and goes upward."""
    model = tree_copy / "balpipe" / "model.py"
    model.write_text(model.read_text(encoding="utf-8") + "\n\ndef _planted():\n    from .build import build\n")
    units = tree_copy / "balpipe" / "units.py"
    units.write_text(units.read_text(encoding="utf-8") + "\n\ndef _planted():\n    from . import model\n")
    assert any({"balpipe.model", "balpipe.units"} <= set(c) for c in cycles(tree_copy))
    assert any(b.startswith("balpipe.model:") and "balpipe.build (deferred)" in b for b in upward(tree_copy))


def test_a_planted_cycle_within_one_layer_fails(tree_copy: Path):
    """Two modules of one layer importing each other: no upward import, still a cycle."""
    meshes = tree_copy / "balpipe" / "meshes.py"
    meshes.write_text(meshes.read_text(encoding="utf-8") + "\n\ndef _planted():\n    from . import notation\n")
    notation = tree_copy / "balpipe" / "notation.py"
    notation.write_text(notation.read_text(encoding="utf-8") + "\nfrom . import meshes  # noqa\n")
    assert ["balpipe.meshes", "balpipe.notation"] in cycles(tree_copy)


def test_a_planted_family_import_in_the_core_fails(tree_copy: Path):
    study = tree_copy / "balpipe" / "study.py"
    study.write_text(study.read_text(encoding="utf-8") + "\nfrom .families.rrr4 import template  # noqa\n")
    assert any(b.startswith("balpipe.study:") for b in family_imports_outside_families(tree_copy))


def _unit(module: str, path: Path) -> str:
    """What may share private names: a package's modules, among themselves (``balpipe.engine.*``);
    a top-level module (``balpipe.history``) only with itself."""
    pkg = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    return module if pkg == "balpipe" else pkg


def private_names_across_packages(src: Path) -> list[str]:
    """Every use of a private name (one leading underscore) of a module of another package or of
    another top-level module: ``from balpipe.x import _y`` (deferred too) and ``x._y`` on a module
    bound by an import. Such a name is the other package's API and must be public (no leading
    underscore, a docstring)."""
    mods = modules(src)
    found = []
    for m, p in mods.items():
        pkg = m if p.name == "__init__.py" else m.rsplit(".", 1)[0]
        mine = _unit(m, p)
        tree = _tree(p.read_text(encoding="utf-8"))
        bound: dict[str, str] = {}

        def owner(name: str) -> str | None:
            while name not in mods and "." in name:
                name = name.rsplit(".", 1)[0]
            return name if name in mods else None

        def private(name: str) -> bool:
            return name.startswith("_") and not name.startswith("__")

        for n in ast.walk(tree):
            if isinstance(n, ast.ImportFrom):
                mod = source_of(n, pkg)
                if not mod.startswith("balpipe"):
                    continue
                for a in n.names:
                    if f"{mod}.{a.name}" in mods:  # a module: its private attributes are checked below
                        bound[a.asname or a.name] = f"{mod}.{a.name}"
                    elif private(a.name) and (o := owner(mod)) and _unit(o, mods[o]) != mine:
                        found.append(f"{m}:{n.lineno} imports {o}.{a.name}")
            elif isinstance(n, ast.Import):
                for a in n.names:
                    if a.asname and a.name in mods:
                        bound[a.asname] = a.name
        for n in ast.walk(tree):
            if (isinstance(n, ast.Attribute) and isinstance(n.value, ast.Name) and n.value.id in bound
                    and private(n.attr) and _unit(bound[n.value.id], mods[bound[n.value.id]]) != mine):
                found.append(f"{m}:{n.lineno} uses {bound[n.value.id]}.{n.attr}")
    return sorted(set(found))


def test_no_private_name_crosses_a_package():
    assert private_names_across_packages(SRC) == []


def test_a_planted_private_import_fails(tree_copy: Path):
    """A top-level module importing another package's private name fails, directly or deferred,
    or through the module's attribute; a package's own modules may share theirs."""
    history = tree_copy / "balpipe" / "history.py"
    history.write_text(history.read_text(encoding="utf-8")
                       + "\n\ndef _planted():\n    from .engine.compile import _perp\n    from . import units\n"
                         "    return units._NUM\n")
    found = private_names_across_packages(tree_copy)
    assert any(b.startswith("balpipe.history:") and b.endswith("imports balpipe.engine.compile._perp") for b in found)
    assert any(b.startswith("balpipe.history:") and b.endswith("uses balpipe.units._NUM") for b in found)
    assert not any("balpipe.engine.constraints:" in b for b in found)  # engine.constraints imports compile._perp


def _family_words() -> set[str]:
    from balpipe import plugins

    return {w for f in plugins.discover() for w in (f.name, *(t.name for t in f.templates), *(m.name for m in f.methods))}


def names_of_families(src: Path, words: set[str]) -> list[str]:
    """String constants (docstrings aside) and identifiers equal to a family's, a template's or a
    method's name, in modules outside ``balpipe.families``."""
    found = []
    for m, p in modules(src).items():
        if m.startswith("balpipe.families"):
            continue
        tree = _tree(p.read_text(encoding="utf-8"))
        docs = {id(n.body[0].value) for n in ast.walk(tree)
                if isinstance(n, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)) and n.body
                and isinstance(n.body[0], ast.Expr) and isinstance(n.body[0].value, ast.Constant)}
        for n in ast.walk(tree):
            text = (n.value if isinstance(n, ast.Constant) and isinstance(n.value, str) and id(n) not in docs
                    else n.id if isinstance(n, ast.Name) else n.attr if isinstance(n, ast.Attribute) else None)
            if text in words:
                found.append(f"{m}:{n.lineno} names {text!r}")
    return found


def test_no_core_module_names_a_family():
    assert names_of_families(SRC, _family_words()) == []


def test_a_planted_family_name_in_the_core_fails(tree_copy: Path):
    study = tree_copy / "balpipe" / "study.py"
    study.write_text(study.read_text(encoding="utf-8") + '\n\ndef _planted(spec):\n    return spec.mechanism.template == "rrr4"\n')
    assert any(b.startswith("balpipe.study:") for b in names_of_families(tree_copy, _family_words()))
