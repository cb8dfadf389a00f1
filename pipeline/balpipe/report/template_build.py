"""The report's Jinja templates compiled once, when balpipe is built, instead of in every process.

Jinja compiles a template to Python the first time a process renders it: the page's template
and its includes cost 0.13-0.15 s of CPU in every process of a build (each worker of
``build -j N`` renders pages), the index's 0.03 s more. ``setup.py`` calls :func:`compile_into`
on the built package's copy of ``balpipe/templates``: the modules land in its folder
``compiled`` (:data:`COMPILED`) with a manifest, the SHA-256 of every template's text and the
version of Jinja that compiled them, and pip byte-compiles them with the rest of the package.
:func:`loader` serves them where the manifest matches the installed templates and Jinja; anywhere
else (an editable install, an edited template, another Jinja) the templates are compiled from
their text as before. The pages are the same bytes either way
(tests/report/test_compiled_templates.py).

This module imports nothing of balpipe: ``setup.py`` loads it by its path, before balpipe's
dependencies are installed. The environment's options and its filters' names are here, and
:func:`balpipe.report.render.environment` is made from them. When compiling, every filter and
the finalizer raise if called, so that Jinja's optimizer folds no expression with balpipe's
functions into the compiled code (they are all evaluated when a page is rendered, as the
template's own code evaluates them: balpipe's filters are pure functions of their arguments).
"""

from __future__ import annotations

import hashlib
import json
from pathlib import Path
from typing import Any

import jinja2

#: the filters of the pages' environment (:func:`balpipe.report.render.environment`), each with
#: whether it takes the template's context (``jinja2.pass_context``), which the compiled code encodes
FILTERS = {
    "num": False, "ratio": False, "tol": False, "num_at": False, "qty": True, "qload": True, "unit_of": True,
    "clarity": False, "load": False, "unit": False, "printable": False,
}
#: the template files of ``balpipe/templates`` (the package data that pyproject.toml installs there)
PATTERNS = ("*.html", "*.js", "*.css", "*.txt")
#: the folder of the compiled modules, in the templates' folder
COMPILED = "compiled"
#: the compiled folder's manifest: {"jinja2": version, "templates": {name: SHA-256 of its text}}
MANIFEST = "manifest.json"


def options() -> dict[str, Any]:
    """The options of every environment of the report's templates, but the loader, the
    finalizer and the filters."""
    return {
        "autoescape": jinja2.select_autoescape(["html"]),
        "undefined": jinja2.StrictUndefined,
        "keep_trailing_newline": True,
    }


def template_names(folder: Path) -> list[str]:
    """The templates of ``folder`` (:data:`PATTERNS`, not its subfolders), sorted."""
    return sorted({p.name for pattern in PATTERNS for p in Path(folder).glob(pattern) if p.is_file()})


def digests(folder: Path, names: list[str]) -> dict[str, str]:
    """{name: SHA-256 of the file's bytes} of the templates ``names`` of ``folder``."""
    return {n: hashlib.sha256((Path(folder) / n).read_bytes()).hexdigest() for n in names}


def compile_into(source: Path, target: Path) -> list[str]:
    """Compile every template of folder ``source`` into Python modules in folder ``target``
    (Jinja's ``compile_templates``: one ``tmpl_<sha1 of the name>.py`` each) and write its
    :data:`MANIFEST`. Returns the templates' names. A template that does not compile raises."""
    env = jinja2.Environment(loader=jinja2.FileSystemLoader(str(source)), finalize=_at_render, **options())
    for name, with_context in FILTERS.items():
        env.filters[name] = _at_render_with_context if with_context else _at_render
    names = template_names(source)
    target = Path(target)
    target.mkdir(parents=True, exist_ok=True)
    env.compile_templates(str(target), zip=None, filter_func=lambda n: n in names, ignore_errors=False)
    manifest = {"jinja2": jinja2.__version__, "templates": digests(source, names)}
    (target / MANIFEST).write_text(json.dumps(manifest, indent=1, sort_keys=True) + "\n", encoding="utf-8")
    return names


def loader(folder: Path) -> jinja2.BaseLoader:
    """The loader of the templates of ``folder``: its compiled modules first (:func:`compile_into`),
    where ``folder/compiled`` has them for exactly these templates' texts and this Jinja; the
    templates' texts otherwise, and for a template the modules do not have."""
    text = jinja2.FileSystemLoader(str(folder))
    compiled = Path(folder) / COMPILED
    try:
        manifest = json.loads((compiled / MANIFEST).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return text
    if not isinstance(manifest, dict) or manifest.get("jinja2") != jinja2.__version__:
        return text
    names = template_names(Path(folder))
    if manifest.get("templates") != digests(Path(folder), names):
        return text
    return jinja2.ChoiceLoader([jinja2.ModuleLoader(str(compiled)), text])


def _at_render(*args: Any, **kwargs: Any) -> Any:
    raise RuntimeError("balpipe's template functions run when a page is rendered, not when it is compiled")


@jinja2.pass_context
def _at_render_with_context(*args: Any, **kwargs: Any) -> Any:
    raise RuntimeError("balpipe's template functions run when a page is rendered, not when it is compiled")
