"""The docs site (mkdocs.yml): ``mkdocs build --strict`` passes (a broken link or a docstring the
API reference cannot read fails it), the API reference lists every public name, the gallery links
every example's page, and the example script in docs/ runs."""

from __future__ import annotations

import csv
import inspect
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import balpipe

ROOT = Path(__file__).resolve().parents[1]


def _mkdocs_missing() -> str | None:
    import importlib.util

    missing = [m for m in ("mkdocs", "material", "mkdocstrings", "mkdocstrings_handlers.python")
               if importlib.util.find_spec(m.split(".")[0]) is None
               or (m.count(".") and importlib.util.find_spec(m) is None)]
    return f"the docs packages are not installed ({', '.join(missing)}): pip install '.[docs]'" if missing else None


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    why = _mkdocs_missing()
    if why:
        pytest.skip(why)
    out = tmp_path_factory.mktemp("docs") / "site"
    env = {**os.environ, "NO_MKDOCS_2_WARNING": "1"}
    r = subprocess.run([sys.executable, "-m", "mkdocs", "build", "--strict", "-d", str(out)], cwd=ROOT, env=env,
                       capture_output=True, text=True, timeout=600)
    assert r.returncode == 0, r.stderr[-4000:]
    assert "WARNING" not in r.stderr, r.stderr[-4000:]
    return out


def test_the_site_builds_strict_with_every_docs_page(site):
    for page in (ROOT / "docs").glob("*.md"):
        assert (site / page.stem / "index.html").is_file() or page.stem == "index", page.name
    assert (site / "index.html").is_file() and (site / "gallery" / "index.html").is_file()


def _anchors(html: str) -> set[str]:
    return set(re.findall(r'id="(balpipe\.[\w.]+)"', html))


def test_the_api_reference_lists_every_public_name(site):
    from balpipe.families.custom import builders

    ids = _anchors((site / "reference" / "index.html").read_text(encoding="utf-8"))
    for name in balpipe.__all__:
        if name == "__version__":
            continue
        obj = getattr(balpipe, name)
        assert {f"balpipe.api.{name}", f"{obj.__module__}.{obj.__qualname__}"} & ids, name
        if inspect.isclass(obj):  # and every public member of the API's classes
            for member in (m for m in vars(obj) if not m.startswith("_")):
                assert f"{obj.__module__}.{obj.__qualname__}.{member}" in ids or \
                    not callable(getattr(obj, member)) and not isinstance(vars(obj)[member], property), f"{name}.{member}"
    public = [n for n, f in vars(builders).items() if inspect.isfunction(f) and f.__module__ == builders.__name__
              and not n.startswith("_")]
    assert public and [n for n in public if f"balpipe.families.custom.builders.{n}" not in ids] == []


def test_the_gallery_links_every_example_page(site):
    from balpipe.site_files.spec_files import slug_for

    html = (site / "gallery" / "index.html").read_text(encoding="utf-8")
    linked = re.findall(r'<a class="study" href="\.\./\.\./([^"/]+)/index\.html">', html)
    specs = sorted((ROOT / "specs").glob("*.yaml"))
    assert linked == [slug_for(Path("specs") / p.name) for p in specs]  # the build's page folders, in order


def test_the_parameter_study_example_runs(tmp_path):
    """docs/examples/parameter_study.py (shown whole in docs/getting-started.md): its table and
    plot; the physics it shows holds (counterweights linear in the coupler's mass, the force
    cancelled)."""
    r = subprocess.run([sys.executable, str(ROOT / "docs" / "examples" / "parameter_study.py"), str(tmp_path)],
                       capture_output=True, text=True, timeout=600, cwd=tmp_path)
    assert r.returncode == 0, r.stderr
    assert len(r.stdout.strip().splitlines()) == 5
    assert (tmp_path / "parameter_study.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    rows = list(csv.DictReader(open(tmp_path / "parameter_study.csv")))
    m = np.array([float(r["coupler_mass_kg"]) for r in rows])
    added = np.array([float(r["added_mass_kg"]) for r in rows])
    assert np.allclose(np.diff(added) / np.diff(m), (added[-1] - added[0]) / (m[-1] - m[0]), rtol=1e-6)
    for row in rows:
        assert float(row["balanced_force_N"]) <= 1e-9 * float(row["unbalanced_force_N"])
    assert "--8<-- \"docs/examples/parameter_study.py\"" in (ROOT / "docs" / "getting-started.md").read_text()


def test_the_generated_pages_are_the_ones_the_docs_may_link():
    import importlib.util

    from test_docs import GENERATED

    spec = importlib.util.spec_from_file_location("docs_hook", ROOT / "docs" / "hooks" / "site.py")
    hook = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(hook)
    assert set(hook.GENERATED) == GENERATED
    assert not any((ROOT / "docs" / name).exists() for name in GENERATED)  # made at build time only
