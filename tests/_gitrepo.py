"""A throw-away git repository of specs, for the history and site tests."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
from pathlib import Path
from _edits import replaced

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
ENV = {**os.environ, "GIT_AUTHOR_NAME": "t", "GIT_AUTHOR_EMAIL": "t@example.org",
       "GIT_COMMITTER_NAME": "t", "GIT_COMMITTER_EMAIL": "t@example.org",
       "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}


def git(repo: Path, *args: str) -> str:
    return subprocess.run(["git", *args], cwd=repo, env=ENV, capture_output=True, text=True, check=True).stdout


class Repo:
    def __init__(self, path: Path):
        self.path = path
        path.mkdir(parents=True, exist_ok=True)
        git(path, "init", "-q", "-b", "main")
        self._n = 0

    def commit(self, message: str, files: dict[str, str] | None = None) -> str:
        """Write ``files`` (repo-relative path -> text), commit them with a fixed date one minute
        after the previous commit, and return the commit hash."""
        for rel, text in (files or {}).items():
            p = self.path / rel
            p.parent.mkdir(parents=True, exist_ok=True)
            p.write_text(text)
            git(self.path, "add", rel)
        self._n += 1
        date = f"2026-11-30T10:{self._n:02d}:00+00:00"
        env = {**ENV, "GIT_AUTHOR_DATE": date, "GIT_COMMITTER_DATE": date}
        subprocess.run(["git", "commit", "-qm", message], cwd=self.path, env=env, check=True)
        return git(self.path, "rev-parse", "HEAD").strip()

    def read(self, rel: str) -> str:
        return (self.path / rel).read_text()

    def copy_spec(self, name: str, rel: str | None = None) -> str:
        rel = rel or f"specs/{name}"
        (self.path / rel).parent.mkdir(parents=True, exist_ok=True)
        shutil.copy(SPECS / name, self.path / rel)
        return rel


def balpipe(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True, cwd=cwd)


def edit(text: str, old: str, new: str) -> str:
    return replaced(text, old, new)
