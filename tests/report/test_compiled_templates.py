"""Issue 43: the report's templates are compiled when balpipe is built (setup.py,
``balpipe.report.template_build``), not in every process: the pages are the same bytes as from
the templates' text; a compiled folder that does not match the templates' text or Jinja is not
used; an installed (not editable) balpipe uses its compiled templates."""

from __future__ import annotations

import importlib.util
import json
import shutil
from pathlib import Path

import jinja2
import pytest

from balpipe import build as build_module
from balpipe.report import render, template_build

ROOT = Path(__file__).resolve().parents[2]
SPECS = ("offset_slider_crank.yaml", "paper004_five_bar.yaml", "custom_v_twin_6000rpm.yaml")


@pytest.fixture
def compiled_copy(tmp_path) -> Path:
    """A copy of the source templates with their compiled folder, as setup.py makes it."""
    folder = tmp_path / "templates"
    shutil.copytree(ROOT / "templates", folder, ignore=shutil.ignore_patterns("__pycache__", "compiled"))
    names = template_build.compile_into(folder, folder / template_build.COMPILED)
    assert "spec.html" in names and "index.html" in names
    return folder


def _site(out: Path, folder: Path, loader, monkeypatch, specs) -> dict[str, bytes]:
    monkeypatch.setattr(template_build, "loader", loader)
    monkeypatch.setattr(render.resources, "files", lambda package: folder)
    render.environment.cache_clear()
    try:
        build_module.build([str(ROOT / "specs" / s) for s in specs],
                           build_module.Options(out=out, simulate=False, force=True), jobs=1)
    finally:
        render.environment.cache_clear()
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*.html"))}


def test_the_pages_from_the_compiled_templates_are_the_same_bytes(compiled_copy, tmp_path, monkeypatch):
    real_loader = template_build.loader
    assert isinstance(real_loader(compiled_copy), jinja2.ChoiceLoader)
    text = _site(tmp_path / "text", compiled_copy, lambda f: jinja2.FileSystemLoader(str(f)), monkeypatch, SPECS)
    served = []

    def compiled(folder):
        loader = real_loader(folder)
        served.append(loader)
        return loader

    fast = _site(tmp_path / "compiled", compiled_copy, compiled, monkeypatch, SPECS)
    assert served and all(isinstance(x, jinja2.ChoiceLoader) for x in served)
    assert len(text) >= len(SPECS) + 1 and text == fast


def test_a_compiled_folder_that_does_not_match_is_not_used(compiled_copy):
    env = lambda f: jinja2.Environment(loader=template_build.loader(f))  # noqa: E731
    assert isinstance(template_build.loader(compiled_copy), jinja2.ChoiceLoader)
    # a template edited after the build: its text, not the stale module
    (compiled_copy / "base.html").write_text("edited {{ 1 + 1 }}\n", encoding="utf-8")
    assert isinstance(template_build.loader(compiled_copy), jinja2.FileSystemLoader)
    assert env(compiled_copy).get_template("base.html").render() == "edited 2"
    # compiled by another Jinja
    names = template_build.compile_into(compiled_copy, compiled_copy / template_build.COMPILED)
    manifest = compiled_copy / template_build.COMPILED / template_build.MANIFEST
    data = json.loads(manifest.read_text(encoding="utf-8"))
    assert sorted(data["templates"]) == names
    assert isinstance(template_build.loader(compiled_copy), jinja2.ChoiceLoader)
    manifest.write_text(json.dumps({**data, "jinja2": "0.0"}), encoding="utf-8")
    assert isinstance(template_build.loader(compiled_copy), jinja2.FileSystemLoader)
    # no manifest, or an unreadable one
    manifest.write_text("{not json", encoding="utf-8")
    assert isinstance(template_build.loader(compiled_copy), jinja2.FileSystemLoader)
    manifest.unlink()
    assert isinstance(template_build.loader(compiled_copy), jinja2.FileSystemLoader)


def test_the_filters_named_for_the_build_are_the_pages_filters():
    env = render.environment()
    own = {name: f for name, f in env.filters.items() if name not in jinja2.Environment().filters}
    assert set(own) == set(template_build.FILTERS)
    for name, f in own.items():
        takes_context = getattr(f, "jinja_pass_arg", None) is not None
        assert takes_context == template_build.FILTERS[name], name


def test_an_installed_balpipe_uses_the_templates_compiled_when_it_was_built():
    folder = Path(str(render.resources.files("balpipe.templates")))
    if not (folder / template_build.COMPILED).is_dir():
        # an editable install (the templates are the source tree's): setup.py's step is skipped there
        assert folder == ROOT / "templates"
        pytest.skip("editable install: the templates are compiled from their text")
    render.environment.cache_clear()
    try:
        assert isinstance(render.environment().loader, jinja2.ChoiceLoader)
        # from its module in the compiled folder, not compiled from its text
        assert Path(render.environment().get_template("spec.html").filename).parent == folder / template_build.COMPILED
    finally:
        render.environment.cache_clear()


def test_setup_py_loads_the_compiler_without_balpipe():
    spec = importlib.util.spec_from_file_location("_setup_under_test", ROOT / "setup.py")
    text = (ROOT / "setup.py").read_text(encoding="utf-8")
    assert spec is not None and "BuildWithTemplates" in text
    source = (ROOT / "pipeline" / "balpipe" / "report" / "template_build.py").read_text(encoding="utf-8")
    imports = [line for line in source.splitlines() if line.startswith(("import ", "from "))]
    assert not [line for line in imports if "balpipe" in line or line.startswith("from .")], imports
