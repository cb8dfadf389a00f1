"""Mechanism families as plugins (issue 19): every discovered family's templates and methods
are complete and consistent, the spec's unions follow the discovery order, a family from a
package of its own (tests/fixtures/plugin, found through its entry point only) builds a spec,
and ``import balpipe.spec`` stays light."""

from __future__ import annotations

import json
import os
import subprocess
import sys
import typing
from pathlib import Path

import pytest

from balpipe import plugins, registry, spec
from balpipe.loader import load
from balpipe.model import FRAME

ROOT = Path(__file__).resolve().parents[1]
PLUGIN = ROOT / "tests" / "fixtures" / "plugin"
FAMILIES = plugins.discover()
TEMPLATES = [t for f in FAMILIES for t in f.templates]
METHODS = [m for f in FAMILIES for m in f.methods]


def _literal(cls: type, field: str) -> tuple:
    return typing.get_args(cls.model_fields[field].annotation)


def _union(annotated) -> tuple:
    return typing.get_args(typing.get_args(annotated)[0])


def _example(template: str) -> Path:
    for p in sorted((ROOT / "specs").glob("*.yaml")):
        if f"template: {template}\n" in p.read_text(encoding="utf-8"):
            return p
    raise AssertionError(f"no spec in specs/ uses the template {template!r}")


def test_the_shipped_families_are_found_in_order():
    assert [f.name for f in FAMILIES] == ["slider_crank", "custom", "five_bar", "rrr4", "rpr3", "serial_arm"]
    assert all(f.package == f"balpipe.families.{f.name}" for f in FAMILIES)


def test_entry_points_and_package_scan_agree():
    """Installed metadata and the source tree name the same families (a run from either finds all)."""
    assert set(plugins._from_entry_points()) == set(plugins._from_package_scan()) == {f.name for f in FAMILIES}


def test_union_order_is_the_discovery_order():
    assert _union(spec.Mechanism) == tuple(t.spec for t in TEMPLATES)
    generic = tuple(m.spec for m in registry.GENERIC)
    assert _union(spec.Balancing) == (spec.NoBalancing,) + tuple(m.spec for m in METHODS) + generic
    assert list(registry.TEMPLATES) == [t.name for t in TEMPLATES]


@pytest.mark.parametrize("template", TEMPLATES, ids=[t.name for t in TEMPLATES])
def test_template_is_complete(template):
    assert template.label.strip()
    assert template.notation is not None
    assert _literal(template.spec, "template") == (template.name,)
    assert callable(template.build)
    assert registry.TEMPLATES[template.name] is template


@pytest.mark.parametrize("template", TEMPLATES, ids=[t.name for t in TEMPLATES])
def test_template_builds_a_consistent_model_from_an_example_spec(template):
    loaded = load(_example(template.name))
    model = registry.unbalanced_model(loaded.spec)
    names = {b.name for b in model.bodies}
    assert names and len(names) == len(model.bodies)
    for j in model.joints:
        ends = {getattr(j, k) for k in ("a", "b", "guide", "slider", "carrier") if hasattr(j, k)}
        assert len(ends) >= 2 and ends <= names | {FRAME}, j
    assert set(model.initial) == names
    assert model.drivers


@pytest.mark.parametrize("method", METHODS, ids=[m.name for m in METHODS])
def test_method_is_complete(method):
    assert method.label.strip()
    assert method.notation is not None
    assert _literal(method.spec, "method") == (method.name,)
    assert method.templates and set(method.templates) <= set(registry.TEMPLATES)
    assert registry.METHODS[method.name] is method


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
    r = _run(["-m", "balpipe", "build", str(PLUGIN / "pendulum.yaml"), "-o", str(out), "--no-sim", "-j", "1"],
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
    # without it on the path, the same spec names the template as unknown (exit 2, no traceback)
    r = _run(["-m", "balpipe", "check", str(PLUGIN / "pendulum.yaml")], tmp_path)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "pendulum" in r.stdout + r.stderr


def test_import_spec_loads_no_heavy_library():
    code = ("import sys, balpipe.spec; "
            "print(sorted(m for m in ('scipy', 'matplotlib', 'pymunk') if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip() == "[]"


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
    comparing ``balancing.method`` with a name (issue 19)."""
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
