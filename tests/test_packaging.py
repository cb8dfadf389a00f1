"""A normal (non-editable) install carries every subpackage and template: `pip install .` on a
fresh machine must give the same balpipe as the source tree."""

from __future__ import annotations

import tomllib
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def test_every_subpackage_and_template_is_installed():
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    listed = set(config["tool"]["setuptools"]["packages"])
    src = ROOT / "pipeline"
    found = {".".join(p.parent.relative_to(src).parts) for p in src.rglob("__init__.py")}
    assert found <= listed, f"not installed by `pip install .`: {sorted(found - listed)}"
    assert "balpipe.templates" in listed
    patterns = config["tool"]["setuptools"]["package-data"]["balpipe.templates"]
    suffixes = {p.removeprefix("*") for p in patterns}
    shipped = {p.suffix for p in (ROOT / "templates").iterdir() if p.is_file() and p.name != "__init__.py"}
    assert shipped <= suffixes, f"template files not installed: {sorted(shipped - suffixes)}"


def test_runtime_imports_are_declared_dependencies():
    """scipy is imported by the balancing methods; a fresh machine has only what is declared."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    declared = " ".join(config["project"]["dependencies"]).lower()
    imported = set()
    for path in (ROOT / "pipeline").rglob("*.py"):
        for line in path.read_text(encoding="utf-8").splitlines():
            words = line.split()
            if len(words) >= 2 and words[0] in ("import", "from") and line == line.lstrip():
                imported.add(words[1].split(".")[0])
    third_party = {"numpy", "scipy", "pydantic", "yaml", "jinja2", "matplotlib", "pymunk"}
    names = {"yaml": "pyyaml"}
    for mod in sorted(imported & third_party):
        assert names.get(mod, mod) in declared, f"{mod} is imported at module level but not a dependency"


def test_every_family_examples_folder_is_package_data():
    """The example specs a family ships (balpipe.plugins.Family.examples, run by balpipe.testing)
    are installed with it."""
    config = tomllib.loads((ROOT / "pyproject.toml").read_text(encoding="utf-8"))
    data = config["tool"]["setuptools"]["package-data"]
    folders = sorted((ROOT / "pipeline" / "balpipe" / "families").glob("*/examples"))
    assert folders
    for folder in folders:
        package = f"balpipe.families.{folder.parent.name}"
        assert "examples/*.yaml" in data.get(package, []), f"{package}: examples/*.yaml not installed"
