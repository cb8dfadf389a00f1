"""balpipe's layers: a module imports only from its own layer or the layers below it,
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

# Lowest first. Each entry is a top-level module (``balpipe.units``) or a folder (``balpipe.engine``, its
# modules and sub-folders with it): the layer of a module is the one entry naming it or its
# nearest folder. The bare package is its ``__init__`` only; a module that is in no entry fails.
LAYERS: tuple[tuple[str, ...], ...] = (
    # L0 core data and maths: the vocabulary, the planar mechanics below the engine, where work runs, the caches,
    # how numbers read (display)
    ("balpipe", "balpipe.units", "balpipe.model", "balpipe.motion", "balpipe.notation",
     "balpipe.mechanics", "balpipe.runtime", "balpipe.cache", "balpipe.display"),
    # L1 computation: the engine and the pymunk validation
    ("balpipe.engine", "balpipe.validate"),
    # L2 contracts and drawing: spec parts, the motion laws and their spec sections, the balancing methods, drawing,
    # families' registry, kinematic diagnosis located in the spec
    ("balpipe.spec_parts", "balpipe.vary", "balpipe.plugins", "balpipe.registry",
     "balpipe.laws", "balpipe.balancing", "balpipe.draw", "balpipe.diagnose"),
    # L3 families (plugins)
    ("balpipe.families",),
    # L3' the schema
    ("balpipe.spec", "balpipe.sweep_spec", "balpipe.loader", "balpipe.limits"),
    # L4 pipeline, and the families' conformance checks that run it (balpipe.testing)
    ("balpipe.study", "balpipe.validation_stage", "balpipe.runner", "balpipe.testing"),
    # L5 presentation
    ("balpipe.report",),
    # L6 commands, and the Python API (the build's functions, for a caller in Python)
    ("balpipe.build", "balpipe.diff", "balpipe.history", "balpipe.sweep", "balpipe.site_files", "balpipe.api"),
    # L7 command line
    ("balpipe.cli", "balpipe.__main__"),
)

#: the top level holds the vocabulary and the pipeline's spine; everything else lives in a folder
MAX_LOOSE_MODULES = 20


def layer_of(module: str, src: Path = SRC) -> int:
    """The layer of ``module``: the entry equal to it, else the entry of its nearest folder
    (``balpipe.engine.compile`` -> ``balpipe.engine``). The package itself (``balpipe``) names its
    ``__init__`` only, never a module below it; a top-level module is never matched by prefix."""
    found = [k for k, entries in enumerate(LAYERS) if module in entries]
    name = module
    while not found and name.count(".") > 1:
        name = name.rsplit(".", 1)[0]
        found = [k for k, entries in enumerate(LAYERS) if name in entries]
    if not found:
        raise AssertionError(f"{module} is in no layer: add it (or its folder) to tests/test_layers.py LAYERS")
    if len(found) > 1:
        raise AssertionError(f"{module} is listed in layers {found}")
    return found[0]


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


#: The one upward import allowed: the package's ``__init__`` (L0) re-exports the public API
#: (``balpipe.load``, ``balpipe.run``, ...) from ``balpipe.api`` lazily, in its module
#: ``__getattr__`` (an import there runs on first use of a name, after every layer has loaded).
#: The same import anywhere else in ``__init__``, or of any other module there, is refused.
FACADE = ("balpipe", "__getattr__", "balpipe.api")


def imports(src: Path) -> dict[str, set[tuple[str, bool, int]]]:
    """module -> {(imported balpipe module, deferred?, line)}, every import statement of the file
    (inside functions too), less the lazy re-export of :data:`FACADE`."""
    mods = modules(src)
    edges: dict[str, set[tuple[str, bool, int]]] = defaultdict(set)
    for m, p in mods.items():
        pkg = m if p.name == "__init__.py" else m.rsplit(".", 1)[0]

        def target(name: str) -> str | None:
            while name not in mods and "." in name:
                name = name.rsplit(".", 1)[0]
            return name if name in mods and name.startswith("balpipe") else None

        def visit(node: ast.AST, deferred: bool, function: str) -> None:
            for ch in ast.iter_child_nodes(node):
                d = deferred or isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef, ast.Lambda))
                fn = ch.name if isinstance(ch, (ast.FunctionDef, ast.AsyncFunctionDef)) and node is tree else function
                found: list[str | None] = []
                if isinstance(ch, ast.Import):
                    found = [target(a.name) for a in ch.names]
                elif isinstance(ch, ast.ImportFrom):
                    mod = source_of(ch, pkg)
                    found = [target(f"{mod}.{a.name}") for a in ch.names]
                for t in found:
                    if t and t != m and (m, function, t) != FACADE:
                        edges[m].add((t, d, ch.lineno))
                visit(ch, d, fn)

        tree = _tree(p.read_text(encoding="utf-8"))
        visit(tree, False, "")
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


def test_every_entry_is_listed_once_and_exists():
    entries = [e for layer in LAYERS for e in layer]
    assert len(entries) == len(set(entries))
    mods = modules(SRC)
    assert [e for e in entries if e not in mods] == []


def test_a_folder_is_one_layer_and_a_loose_module_is_listed_by_name():
    """Every entry that is a folder holds only its own modules; no entry is a module inside a
    listed folder (that would make a folder span two layers)."""
    mods = modules(SRC)
    folders = {e for layer in LAYERS for e in layer if e != "balpipe" and (SRC / Path(*e.split("."))).is_dir()}
    nested = [e for layer in LAYERS for e in layer for f in folders if e != f and e.startswith(f + ".")]
    assert nested == []
    loose = [m for m, p in mods.items() if p.parent == SRC / "balpipe" and p.name != "__init__.py"]
    assert len(loose) + 1 <= MAX_LOOSE_MODULES, sorted(loose)  # + the package's __init__


def test_a_planted_unlisted_module_fails(tree_copy: Path):
    """A new top-level module that no entry names is in no layer: the bare package does not
    swallow it, and neither does a folder for a top-level file."""
    (tree_copy / "balpipe" / "stray.py").write_text("X = 1\n")
    with pytest.raises(AssertionError, match="balpipe.stray is in no layer"):
        for m in modules(tree_copy):
            layer_of(m, tree_copy)


def test_a_planted_upward_import_from_a_folder_fails(tree_copy: Path):
    """A module of a low folder (mechanics, L0) importing the pipeline (L4) is refused."""
    meshes = tree_copy / "balpipe" / "mechanics" / "meshes.py"
    meshes.write_text(meshes.read_text(encoding="utf-8") + "\n\ndef _planted():\n    from ..study import Study\n")
    assert any(b.startswith("balpipe.mechanics.meshes:") and "balpipe.study (deferred)" in b for b in upward(tree_copy))


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


def test_the_api_is_re_exported_lazily_only(tree_copy: Path):
    """The package's ``__getattr__`` may import balpipe.api (:data:`FACADE`); the same import at
    the top of ``__init__``, or ``__getattr__`` importing the build, is an upward import."""
    assert not any(b.startswith("balpipe:") for b in upward(SRC))
    init = tree_copy / "balpipe" / "__init__.py"
    text = init.read_text(encoding="utf-8")
    assert "        from . import api\n" in text
    init.write_text(text.replace("        from . import api\n", "        from . import api, build  # noqa\n")
                    + "\nfrom . import api as _eager  # noqa\n")
    found = upward(tree_copy)
    top = layer_of("balpipe.api")
    assert any(b.startswith("balpipe:") and b.endswith(f"imports balpipe.build (deferred): layer 0 < {top}") for b in found)
    assert any(b.startswith("balpipe:") and b.endswith(f"imports balpipe.api: layer 0 < {top}") for b in found)


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
    meshes = tree_copy / "balpipe" / "mechanics" / "meshes.py"
    meshes.write_text(meshes.read_text(encoding="utf-8") + "\n\ndef _planted():\n    from .. import notation\n")
    notation = tree_copy / "balpipe" / "notation.py"
    notation.write_text(notation.read_text(encoding="utf-8") + "\nfrom .mechanics import meshes  # noqa\n")
    assert ["balpipe.mechanics.meshes", "balpipe.notation"] in cycles(tree_copy)


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
    """String constants (docstrings aside) and identifiers equal to one of ``words`` (a family's,
    a template's or a method's name; a paper's id), in modules outside ``balpipe.families``."""
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


def _paper_ids() -> set[str]:
    """The ids of the papers the families declare (``Family.papers``): "000" to "004" in this tree."""
    from balpipe import plugins

    ids = {p.id for f in plugins.discover() for p in f.papers}
    assert ids >= {"000", "001", "002", "003", "004"}  # the test below has something to find
    return ids


def test_no_core_module_names_a_paper():
    """A paper's data (citation, figures, its own panels) live on the family that reproduces it:
    no module outside ``balpipe.families`` names a paper id as a string constant."""
    assert names_of_families(SRC, _paper_ids()) == []


def test_a_planted_paper_id_in_the_core_fails(tree_copy: Path):
    page = tree_copy / "balpipe" / "report" / "page.py"
    page.write_text(page.read_text(encoding="utf-8") + '\n\ndef _planted(spec):\n    return spec.paper == "004"\n')
    assert any(b.startswith("balpipe.report.page:") and b.endswith("names '004'")
               for b in names_of_families(tree_copy, _paper_ids()))


def _docs_layers() -> dict[int, str]:
    """The layer list of docs/development.md: its text from each ``L<k>`` line to the next."""
    import re

    text = (SRC.parent / "docs" / "development.md").read_text(encoding="utf-8")
    block = text[text.index("  L0  "): text.index("templates/ ")]
    parts = re.split(r"^  (L\d'?) +", block, flags=re.M)[1:]
    order = [f"L{k}" for k in range(4)] + ["L3'"] + [f"L{k}" for k in range(4, 8)]
    return {order.index(parts[i]): parts[i + 1] for i in range(0, len(parts), 2)}


def test_the_docs_list_every_entry_in_its_layer():
    """docs/development.md names every entry of LAYERS in that entry's layer (a folder as
    ``name/``), so the documented architecture is the tested one."""
    import re

    docs = _docs_layers()
    assert len(docs) == len(LAYERS)
    missing = []
    for k, entries in enumerate(LAYERS):
        for e in entries:
            if e == "balpipe":
                continue
            short = e.split(".", 1)[1]
            folder = (SRC / Path(*e.split("."))).is_dir()
            pattern = rf"(?<![\w/]){re.escape(short)}/" if folder else rf"(?<![\w/.]){re.escape(short)}(?![\w/])"
            if not re.search(pattern, docs[k]):
                missing.append(f"L{k}: {e}")
    assert missing == []


def test_the_tests_mirror_the_package_folders():
    """Each folder of tests/ (fixtures aside) is named after a folder of the package, so a test
    of ``balpipe.engine`` is found in ``tests/engine/``; the tests of the whole (specs, docs,
    the command line's contracts, the layers) stay at the top."""
    tests = SRC.parent / "tests"
    pkg_folders = {p.name for p in (SRC / "balpipe").iterdir() if (p / "__init__.py").exists()}
    folders = {p.name for p in tests.iterdir() if p.is_dir() and p.name not in ("fixtures", "__pycache__")}
    assert folders - pkg_folders == set()
    assert all(any(f.glob("test_*.py")) for f in (tests / n for n in folders))
