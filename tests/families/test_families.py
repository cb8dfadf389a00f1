"""Mechanism families as plugins: balpipe's own families pass the public conformance checks
(:mod:`balpipe.testing`, on the examples their packages ship), the spec's unions follow the
discovery order, a family from a package of its own (tests/fixtures/plugin, found through its
entry point only) builds a spec and passes the same checks in its own suite, and ``import
balpipe.spec`` stays light. A family installed beside balpipe changes none of these tests:
they enumerate balpipe's own families (the package ``balpipe.families``), not every one found."""

from __future__ import annotations

import importlib

import json
import os
import subprocess
import sys
import typing
from pathlib import Path

import pytest

from balpipe import plugins, registry, spec
from balpipe.testing import family_cases

ROOT = Path(__file__).resolve().parents[2]
PLUGIN = ROOT / "tests" / "fixtures" / "plugin"
PENDULUM = PLUGIN / "balpipe_pendulum" / "examples" / "pendulum.yaml"
#: every family found (balpipe's and any installed beside it): the spec's unions are built from these
DISCOVERED = plugins.discover()
#: balpipe's own families, whatever else is installed
FAMILIES = tuple(f for f in DISCOVERED if f.package.startswith(plugins.IN_TREE + "."))
TEMPLATES = [t for f in DISCOVERED for t in f.templates]
#: the fixture family found without the tests putting it on the path (installed, or on PYTHONPATH)
PENDULUM_INSTALLED = any(f.name == "pendulum" for f in DISCOVERED)
METHODS = [m for f in DISCOVERED for m in f.methods]


def _union(annotated) -> tuple:
    return typing.get_args(typing.get_args(annotated)[0])


def test_the_shipped_families_are_found_in_order():
    assert [f.name for f in FAMILIES] == ["slider_crank", "custom", "five_bar", "rrr4", "rpr3", "serial_arm"]
    assert all(f.package == f"balpipe.families.{f.name}" for f in FAMILIES)


def test_entry_points_and_package_scan_agree():
    """Installed metadata and the source tree name the same in-tree families (a run from either
    finds all of balpipe's own; another package's entry points may add more)."""
    own = {n for n, f in plugins._from_entry_points().items() if f.package.startswith(plugins.IN_TREE + ".")}
    assert own == set(plugins._from_package_scan()) == {f.name for f in FAMILIES}


def test_union_order_is_the_discovery_order():
    assert _union(spec.Mechanism) == tuple(t.section for t in TEMPLATES)
    generic = tuple(m.section for m in registry.GENERIC)
    assert _union(spec.Balancing) == (spec.NoBalancing,) + tuple(m.section for m in METHODS) + generic
    assert list(registry.TEMPLATES) == [t.name for t in TEMPLATES]


@pytest.mark.parametrize("check", [c for f in FAMILIES for c in family_cases(f)])
def test_family_conformance(check):
    """balpipe.testing's checks of every in-tree family: found and complete, its examples
    (shipped in its package) covering every template and method, each example's model
    consistent and its stages' physics sound (claims met, reactions equal momentum rates,
    masses x k scale the loads by k)."""
    check()


def test_every_family_ships_examples_that_are_worked_examples():
    """Each in-tree family's examples are files of its package, copies of worked examples in
    specs/ byte for byte (the site shows the same specs the checks run)."""
    for f in FAMILIES:
        assert f.examples, f.name
        for ex in f.examples:
            path = Path(ex)
            # in the family's package as installed (the source tree, or site-packages after pip install .)
            package = Path(importlib.import_module(f"balpipe.families.{f.name}").__file__).parent
            assert path.parent.parent == package and path.parent.name == "examples"
            assert path.read_bytes() == (ROOT / "specs" / path.name).read_bytes(), path


def test_family_lists_are_by_their_own_names():
    """Templates and methods found, with distinct names (the registry's tables are by name)."""
    assert len({t.name for t in TEMPLATES}) == len(TEMPLATES)
    assert len({m.name for m in METHODS}) == len(METHODS)


def test_a_family_must_be_a_family():
    with pytest.raises(TypeError, match="not a balpipe.plugins.Family"):
        plugins._check(object(), "entry point 'x'")


def _run(args: list[str], tmp_path: Path, **env: str) -> subprocess.CompletedProcess:
    full = dict(os.environ, **env)
    return subprocess.run([sys.executable, *args], capture_output=True, text=True, cwd=tmp_path, env=full, timeout=600)


def test_an_out_of_tree_family_builds_a_spec(tmp_path: Path):
    """The pendulum family is a package outside balpipe with an entry point of its own: with it on
    the path, balpipe finds it, the schema names it, and its spec builds and balances."""
    env = {"PYTHONPATH": os.pathsep.join([str(PLUGIN), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    out = tmp_path / "site"
    r = _run(["-m", "balpipe", "build", str(PENDULUM), "-o", str(out), "--no-sim", "-j", "1"],
             tmp_path, **env)
    assert r.returncode == 0, r.stdout + r.stderr
    res = json.loads((out / "pendulum" / "results.json").read_text(encoding="utf-8"))
    peaks = {s["name"]: s["max_shaking_force"] for s in res["stages"]}
    assert peaks["unbalanced"] > 1.0 and peaks["counterweight"] <= 1e-9 * peaks["unbalanced"]
    mc = {p["name"]: p["value"] for p in res["parameters"]}["mc"]
    assert mc == pytest.approx(1.2 * 0.1 / 0.05)
    r = _run(["-m", "balpipe", "schema"], tmp_path, **env)
    mech = json.loads(r.stdout)["properties"]["mechanism"]
    assert mech["oneOf"][-1] == {"$ref": "#/$defs/PendulumMechanism"} and "slider_crank" in mech["discriminator"]["mapping"]
    if PENDULUM_INSTALLED:  # installed beside balpipe: there is no run without it
        return
    # without it on the path, the same spec names the template as unknown (exit 2, no traceback)
    r = _run(["-m", "balpipe", "check", str(PENDULUM)], tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "pendulum" in r.stdout + r.stderr


def test_an_out_of_tree_family_passes_the_conformance_checks_in_its_own_suite(tmp_path: Path):
    """The pendulum family's own suite (tests/fixtures/plugin/conformance_suite.py) runs
    ``from balpipe.testing import check_family`` and one test per ``family_cases`` check with
    pytest, the family on the path as if installed: every check runs and passes."""
    env = {"PYTHONPATH": os.pathsep.join([str(PLUGIN), os.environ.get("PYTHONPATH", "")]).rstrip(os.pathsep)}
    r = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:xdist", "conformance_suite.py"],
                       capture_output=True, text=True, cwd=PLUGIN, env=dict(os.environ, **env), timeout=600)
    assert r.returncode == 0, r.stdout + r.stderr
    assert "9 passed" in r.stdout, r.stdout  # 8 checks (2 examples) and check_family itself


def test_import_spec_loads_no_heavy_library():
    code = ("import sys, balpipe.spec; "
            "print(sorted(m for m in ('scipy', 'matplotlib', 'pymunk') if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


@pytest.mark.skipif(PENDULUM_INSTALLED, reason="the fixture family is installed: no run is without it")
def test_an_out_of_tree_family_is_part_of_the_code_hash(tmp_path: Path):
    """A build cached before the family was installed (or changed) is rebuilt: its code is hashed."""
    code = "from balpipe import build; print(build.code_hash())"
    plain = _run(["-c", code], tmp_path).stdout
    env = {"PYTHONPATH": str(PLUGIN)}
    with_family = _run(["-c", code], tmp_path, **env).stdout
    assert plain.strip() and with_family.strip() and plain != with_family
    assert _run(["-c", code], tmp_path, **env).stdout == with_family


def method_name_tests(source: str) -> list[int]:
    """Lines of ``source`` that compare ``<...>.balancing.method`` (or a bare ``balancing.method``)
    with a literal name or a literal collection of names (==, !=, in, not in, either side)."""
    import ast

    def names_method(node: ast.AST) -> bool:
        return (isinstance(node, ast.Attribute) and node.attr == "method"
                and ((isinstance(node.value, ast.Attribute) and node.value.attr == "balancing")
                     or (isinstance(node.value, ast.Name) and node.value.id == "balancing")))

    def literal(node: ast.AST) -> bool:
        if isinstance(node, ast.Constant):
            return isinstance(node.value, str)
        return isinstance(node, (ast.Tuple, ast.List, ast.Set)) and all(literal(e) for e in node.elts)

    out = []
    for node in ast.walk(ast.parse(source)):
        if isinstance(node, ast.Compare):
            sides = [node.left, *node.comparators]
            if any(names_method(s) for s in sides) and any(literal(s) for s in sides):
                out.append(node.lineno)
    return out


def test_no_family_module_branches_on_a_method_name():
    """A family's figures are its method's or its template's (plugins.Method.figures,
    Template.figures), composed by the page: no module under families/ asks which method ran by
    comparing ``balancing.method`` with a name."""
    found = [f"{p.relative_to(ROOT)}:{line}" for p in sorted((ROOT / "pipeline" / "balpipe" / "families").rglob("*.py"))
             for line in method_name_tests(p.read_text(encoding="utf-8"))]
    assert not found, f"compare balancing.method with a name: {found}"
    # the check finds what it looks for
    assert method_name_tests('if study.spec.balancing.method != "rrr4_counter_masses":\n    pass\n') == [1]
    assert method_name_tests('x = "a" == spec.balancing.method\ny = balancing.method in ("a", "b")\n') == [1, 2]
    assert method_name_tests('m = registry.METHODS[spec.balancing.method]\nok = spec.method == "x"\n') == []


def test_rrr4_figures_are_its_methods():
    """Paper 001's figures belong to its method rrr4_counter_masses (they draw that method's
    stages and details); the template has none of its own."""
    assert registry.TEMPLATES["rrr4"].figures is None
    assert registry.METHODS["rrr4_counter_masses"].figures is not None
