"""``balpipe diff REV:PATH``: a revision is verified as a commit before git reads the file, so
one that starts with ``-`` is a located error and never reaches git as an option; and a diff page
of absolute paths names the specs without the machine's paths."""

from __future__ import annotations

import shutil
import subprocess
import sys
from pathlib import Path

from _edits import replaced
from _gitrepo import Repo

ROOT = Path(__file__).resolve().parents[2]


def balpipe(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


def repo_with_spec(tmp_path: Path) -> Path:
    repo = Repo(tmp_path / "repo")
    repo.commit("one", {"specs/sc.yaml": (ROOT / "specs" / "offset_slider_crank.yaml").read_text()})
    return repo.path


def test_a_revision_starting_with_a_dash_is_refused_not_run_as_an_option(tmp_path):
    repo = repo_with_spec(tmp_path)
    planted = tmp_path / "planted.txt"
    for rev in (f"--output={planted}", "-p", "--", "-"):
        r = balpipe("diff", "--no-sim", "--", f"{rev}:specs/sc.yaml", "specs/sc.yaml", cwd=repo)
        assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
        assert "not a git revision" in r.stderr and "cannot start with '-'" in r.stderr, r.stderr
        assert not planted.exists()


def test_a_revision_that_is_no_commit_is_a_clear_error(tmp_path):
    repo = repo_with_spec(tmp_path)
    for rev in ("NOPE", "HEAD~5", "HEAD^{tree}"):
        r = balpipe("diff", f"{rev}:specs/sc.yaml", "specs/sc.yaml", "--no-sim", cwd=repo)
        assert r.returncode == 2 and "Traceback" not in r.stderr and "is not a commit" in r.stderr, r.stderr
    r = balpipe("diff", "HEAD:specs/sc.yaml", "specs/sc.yaml", "--no-sim", cwd=repo)
    assert r.returncode == 0, r.stderr


def test_a_diff_page_of_absolute_paths_names_no_path_of_the_machine(tmp_path):
    old, new = tmp_path / "a" / "old.yaml", tmp_path / "a" / "new.yaml"
    old.parent.mkdir()
    shutil.copy(ROOT / "specs" / "scott_russell.yaml", old)
    new.write_text(replaced(old.read_text(), "crank_counterweight: -0.1 m", "crank_counterweight: -0.12 m"))
    out = tmp_path / "d.html"
    for fmt in ("html", "json", "markdown"):
        r = balpipe("diff", old, new, "--no-sim", "-f", fmt, "-o", out, cwd="/")
        assert r.returncode == 0, r.stderr
        text = out.read_text()
        assert str(tmp_path) not in text and "old.yaml" in text


def test_a_history_of_absolute_paths_publishes_no_path_of_the_machine(tmp_path):
    repo = repo_with_spec(tmp_path)
    out = tmp_path / "out"
    r = balpipe("history", repo / "specs", "-o", out, "--no-sim", "--cache", tmp_path / "cache", cwd="/")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    files = [f for f in out.rglob("*") if f.is_file() and ".cache" not in f.parts]
    assert any(f.name == "history.json" for f in files)
    for f in files:
        assert str(tmp_path).encode() not in f.read_bytes(), f
    assert '"source": "specs/sc.yaml"' in (out / "sc" / "history.json").read_text()
