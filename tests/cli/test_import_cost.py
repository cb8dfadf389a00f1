"""``balpipe --help`` and ``balpipe check`` of a spec load only what they need (issue 23 item 4):
no scipy, matplotlib, pymunk, jinja2, cvxpy, Clarabel or dask. Each runs in a fresh interpreter, so what
another test imported cannot hide an import."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("scipy", "matplotlib", "pymunk", "jinja2", "cvxpy", "clarabel", "distributed", "dask")

PROBE = """
import json, sys
from balpipe.cli import main
try:
    main(json.loads(sys.argv[1]))
except SystemExit:
    pass
print(json.dumps(sorted(m for m in {heavy!r} if m in sys.modules)), file=sys.stderr)
"""


def loaded_by(args: list[str]) -> list[str]:
    r = subprocess.run([sys.executable, "-c", PROBE.format(heavy=HEAVY), json.dumps(args)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    return json.loads(r.stderr.strip().splitlines()[-1])


@pytest.mark.parametrize("args", [["--help"], ["build", "--help"], ["check", "specs/scott_russell.yaml"],
                                  ["check", "specs/offset_slider_crank.yaml", "specs/paper002_decoupling.yaml"]])
def test_a_command_loads_no_heavy_library_it_does_not_use(args):
    assert loaded_by(args) == []


@pytest.mark.parametrize("args", [["--help"], ["check", "--help"], ["sweep", "--help"], ["--version"]])
def test_help_loads_neither_numpy_nor_pydantic(args):
    """The help states the sweep's limit (balpipe.MAX_DESIGNS) without the spec schema."""
    probe = PROBE.format(heavy=HEAVY + ("numpy", "pydantic"))
    r = subprocess.run([sys.executable, "-c", probe, json.dumps(args)], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert json.loads(r.stderr.strip().splitlines()[-1]) == []


@pytest.mark.parametrize("args", [["check", "specs/scott_russell.yaml"],
                                  ["check", "specs/offset_slider_crank.yaml", "specs/paper002_decoupling.yaml"]])
def test_check_loads_neither_numpy_ma_nor_numpy_random(args):
    """``np.unique`` imports numpy.ma (~90 ms) and the dead-centre search numpy.random: the
    engine spreads its continuation's samples without it (:func:`balpipe.mechanics.sampling.spread_indices`)
    and check leaves the page's diagnostics out. The sweep's planner only for a spec with a
    ``sweep:`` block."""
    probe = PROBE.format(heavy=HEAVY + ("numpy.ma", "numpy.random", "balpipe.sweep"))
    r = subprocess.run([sys.executable, "-c", probe, json.dumps(args)], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert json.loads(r.stderr.strip().splitlines()[-1]) == []


CODE_PROBE = """
import json, sys
{action}
from balpipe import registry
from balpipe.plugins import Ref
code = {{f.target.split(":")[0] for item in (*registry.TEMPLATES.values(), *registry.METHODS.values())
         for f in (getattr(item, k, None) for k in ("build", "balance", "figures", "notation")) if isinstance(f, Ref)}}
heavy = {heavy!r}
print(json.dumps({{"code": sorted(m for m in code if m in sys.modules),
                   "heavy": sorted(m for m in sys.modules if m.split(".")[0] in heavy or m.startswith(
                       ("balpipe.engine", "balpipe.draw", "balpipe.report", "balpipe.study")))}}), file=sys.stderr)
"""


def code_loaded(action: str) -> dict:
    """The methods' and templates' code modules (named by their :class:`balpipe.plugins.Ref`) and
    the heavy libraries and computing layers loaded after ``action``, in a fresh interpreter."""
    r = subprocess.run([sys.executable, "-c", CODE_PROBE.format(action=action, heavy=HEAVY)], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    return json.loads(r.stderr.strip().splitlines()[-1])


@pytest.mark.parametrize("module", ["balpipe.spec", "balpipe.loader"])
def test_the_schema_loads_no_methods_code(module):
    """The spec's unions need the methods' sections, not their code (issue 23 item 4): importing
    the schema loads no method's or figure's module, no engine, and no heavy library."""
    assert code_loaded(f"import {module}") == {"code": [], "heavy": []}


@pytest.mark.parametrize("spec, code", [
    ("specs/scott_russell.yaml", ["balpipe.families.slider_crank.counterweights", "balpipe.families.slider_crank.template"]),
    ("specs/paper002_decoupling.yaml", ["balpipe.families.serial_arm.decoupling", "balpipe.families.serial_arm.template"]),
    ("specs/paper004_five_bar.yaml", ["balpipe.families.five_bar.gear_balancing", "balpipe.families.five_bar.template"]),
])
def test_check_loads_the_code_of_its_specs_method_only(spec, code):
    """``balpipe check`` of a spec imports its own method's code and its own template's and no
    other's (registry entries are :class:`balpipe.plugins.Ref` objects, resolved on first use),
    nor any figure module."""
    found = code_loaded(f"from balpipe.cli import main\ntry:\n    main(['check', {spec!r}])\nexcept SystemExit:\n    pass")
    assert found["code"] == code
    assert [m for m in found["heavy"] if not m.startswith(("balpipe.engine", "balpipe.study"))] == []


SECTIONS_PROBE = """
import json, sys
from balpipe.cli import main
try:
    main(json.loads(sys.argv[1]))
except SystemExit:
    pass
print(json.dumps(sorted(m for m in sys.modules if m.startswith(("balpipe.families.", "balpipe.balancing.")))),
      file=sys.stderr)
"""


@pytest.mark.parametrize("spec, family, generic", [
    ("specs/offset_slider_crank.yaml", "slider_crank", []),
    ("specs/paper002_decoupling.yaml", "serial_arm", []),
    ("specs/custom_four_bar_balancing.yaml", "custom", ["balpipe.balancing.specs"]),
    ("specs/partial_offset_slider_crank.yaml", "slider_crank",  # its method's code reads the generic sections
     ["balpipe.balancing.partial.spec", "balpipe.balancing.specs"]),
])
def test_check_of_one_spec_loads_its_own_family_only(spec, family, generic):
    """``balpipe check`` of one spec validates it with its own template's and methods' sections
    (:func:`balpipe.spec.validate`): no module of another family is imported (every family's
    package is: its ``FAMILY`` names the rest by :class:`balpipe.plugins.Ref`), and of the generic
    methods' sections only those the spec names."""
    r = subprocess.run([sys.executable, "-c", SECTIONS_PROBE, json.dumps(["check", spec])], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    loaded = json.loads(r.stderr.strip().splitlines()[-1])
    families = {m.split(".")[2] for m in loaded if m.startswith("balpipe.families.") and m.count(".") >= 3}
    assert families == {family}, loaded
    sections = [m for m in loaded if m in ("balpipe.balancing.specs", "balpipe.balancing.partial.spec")]
    assert sections == generic, loaded


@pytest.mark.parametrize("spec, optional", [
    ("specs/offset_slider_crank.yaml", []),
    ("specs/custom_four_bar_loaded.yaml", ["balpipe.laws.load_spec"]),
    ("specs/custom_v_twin_6000rpm.yaml", ["balpipe.laws.frame_spec"]),
])
def test_check_of_one_spec_loads_the_optional_sections_it_has(spec, optional):
    """The loads', frame's and sweep's section modules are imported for a spec that has them."""
    probe = SECTIONS_PROBE.replace('("balpipe.families.", "balpipe.balancing.")', '("balpipe.laws.", "balpipe.sweep")')
    r = subprocess.run([sys.executable, "-c", probe, json.dumps(["check", spec])], cwd=ROOT,
                       capture_output=True, text=True, timeout=120)
    loaded = json.loads(r.stderr.strip().splitlines()[-1])
    assert [m for m in loaded if m in ("balpipe.laws.load_spec", "balpipe.laws.frame_spec", "balpipe.sweep_spec")] \
        == optional, loaded


def test_check_with_workers_loads_the_methods_libraries_before_they_fork():
    """``balpipe check`` of several specs in worker processes imports, in the parent before they
    fork, the code of the methods the specs name and the libraries it declares
    (:attr:`balpipe.plugins.Method.imports`), so that no worker imports them again; a method that
    declares none loads none (the other tests above)."""
    probe = PROBE.format(heavy=("scipy.optimize", "balpipe.balancing.force_balance", "balpipe.families.rpr3.idler_loop"))
    args = ["check", "-j", "2", "specs/custom_four_bar_loaded.yaml", "specs/offset_slider_crank.yaml"]
    r = subprocess.run([sys.executable, "-c", probe, json.dumps(args)], cwd=ROOT, capture_output=True, text=True,
                       timeout=120)
    assert json.loads(r.stderr.strip().splitlines()[-1]) == ["balpipe.balancing.force_balance", "scipy.optimize"]
