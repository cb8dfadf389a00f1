"""OS errors (a full disk, a read-only or unwritable folder, a file where a folder is expected) are
messages naming the path and the remedy, exit 1 or 2, no traceback; the other specs are still
built and the earlier site is left as it was. Simulated by making balpipe's own writers raise
(root ignores permission bits, so a chmod would prove nothing here)."""

from __future__ import annotations

import errno
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.cli import main
from balpipe.runtime import fsutil
from _gitrepo import Repo

ROOT = Path(__file__).resolve().parents[2]
NAMES = ("scott_russell.yaml", "offset_slider_crank.yaml")


def specs(tmp_path: Path, extra: str = "") -> Path:
    d = tmp_path / "specs"
    d.mkdir(exist_ok=True)
    for name in NAMES:
        text = (ROOT / "specs" / name).read_text().replace("  samples: 501", "  samples: 41")
        (d / name).write_text(text.replace("\nname: ", f"\nname: {extra}", 1) if extra else text)
    return d


def site(out: Path) -> dict[str, bytes]:
    return {f.relative_to(out).as_posix(): f.read_bytes() for f in sorted(out.rglob("*"))
            if f.is_file() and ".cache" not in f.parts}


def failing_writes(monkeypatch, code: int, when) -> None:
    """balpipe's file writer raises ``code`` for the paths ``when(path)`` selects."""
    real = fsutil.write_new

    def write_new(path, content):
        if when(Path(path)):
            raise OSError(code, os.strerror(code), str(path))
        return real(path, content)

    monkeypatch.setattr(fsutil, "write_new", write_new)


def in_page(slug: str):
    return lambda p: p.parent.name.startswith(f".{slug}") and fsutil.TMP_MARK in p.parent.name


@pytest.mark.parametrize("code, remedy", [(errno.ENOSPC, "free space"), (errno.EROFS, "read-only"),
                                          (errno.EACCES, "make it writable")])
def test_a_page_that_cannot_be_written_fails_alone_and_the_earlier_page_stays(tmp_path, monkeypatch, capsys,
                                                                            code, remedy):
    d, out = specs(tmp_path), tmp_path / "out"
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 0
    before = site(out)
    specs(tmp_path, extra="changed ")  # both specs change: both are rebuilt
    capsys.readouterr()
    failing_writes(monkeypatch, code, in_page("scott_russell"))
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    line = next(ln for ln in err.splitlines() if "its page scott_russell/ was not written" in ln)
    assert os.strerror(code) in line and remedy in line and "earlier page" in line
    after = site(out)
    old_page = {k: v for k, v in before.items() if k.startswith("scott_russell/")}
    assert {k: v for k, v in after.items() if k.startswith("scott_russell/")} == old_page  # untouched
    assert after["offset_slider_crank/index.html"] != before["offset_slider_crank/index.html"]  # the other built
    assert b"changed " in after["offset_slider_crank/index.html"]
    assert not [p for p in out.iterdir() if fsutil.TMP_MARK in p.name]


def test_a_full_disk_at_the_index_leaves_the_previous_index(tmp_path, monkeypatch, capsys):
    d, out = specs(tmp_path), tmp_path / "out"
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 0
    index = (out / "index.html").read_bytes()
    specs(tmp_path, extra="changed ")
    capsys.readouterr()
    failing_writes(monkeypatch, errno.ENOSPC, lambda p: p.parent == out and "index.html" in p.name)
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and "the site's index was not written" in err and "free space" in err, err
    assert (out / "index.html").read_bytes() == index
    assert not [p for p in out.iterdir() if fsutil.TMP_MARK in p.name]


def test_an_earlier_page_copy_that_cannot_be_removed_is_told_not_left_silently(tmp_path, monkeypatch, capsys):
    """A page folder that is read-only (its entries cannot be removed) once left a hidden copy of
    the old page in the published output without a word."""
    d, out = specs(tmp_path), tmp_path / "out"
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 0
    specs(tmp_path, extra="changed ")
    real = shutil.rmtree

    def rmtree(path, ignore_errors=False, **kw):
        if ".old" in Path(path).name:  # as in a read-only folder: nothing of it can be removed
            if ignore_errors:
                return None
            raise PermissionError(errno.EACCES, os.strerror(errno.EACCES), str(Path(path) / "index.html"))
        return real(path, ignore_errors=ignore_errors, **kw)

    monkeypatch.setattr(fsutil.shutil, "rmtree", rmtree)
    capsys.readouterr()
    assert main(["build", str(d), "-o", str(out), "--no-sim", "-j", "1"]) == 1
    err = capsys.readouterr().err
    assert "Traceback" not in err
    lines = [ln for ln in err.splitlines() if "could not be removed" in ln]
    assert len(lines) == 2 and all("remove it by hand" in ln and "Permission denied" in ln for ln in lines), err
    assert b"changed " in (out / "scott_russell" / "index.html").read_bytes()  # the new page is in place


@pytest.mark.skipif(os.geteuid() == 0, reason="root removes entries of read-only folders")
def test_a_read_only_earlier_page_is_made_writable_and_removed(tmp_path):
    folder = tmp_path / "old"
    (folder / "sub").mkdir(parents=True)
    (folder / "sub" / "f").write_text("x")
    os.chmod(folder / "sub", 0o500)
    os.chmod(folder, 0o500)
    fsutil.remove_tree(folder)
    assert not folder.exists()


def balpipe(*args, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=600)


def test_a_file_where_a_folder_is_expected_is_a_clear_error_in_every_verb(tmp_path):
    d = specs(tmp_path)
    blocker = tmp_path / "blocker"
    blocker.write_text("a file")
    cases = [
        ("build", d, "-o", blocker / "site", "--no-sim"),
        ("sweep", d / NAMES[0], "--vary", "mechanism.slider.mass=0.2,0.7", "-o", blocker, "-j", "1", "-q"),
        ("diff", d / NAMES[0], d / NAMES[0], "--no-sim", "-o", blocker / "d.txt"),
        ("schema", "-o", blocker / "s.json"),
    ]
    repo = Repo(tmp_path / "repo")
    repo.commit("one", {"specs/sr.yaml": (d / NAMES[0]).read_text()})
    cases += [("history", repo.path / "specs", "-o", blocker / "out", "--no-sim", "--cache", tmp_path / "c"),
              ("history", repo.path / "specs", "-o", tmp_path / "h", "--no-sim", "--cache", blocker / "c")]
    for args in cases:
        r = balpipe(*args)
        assert r.returncode == 2 and "Traceback" not in r.stderr, (args, r.stderr)
        assert "blocker" in r.stderr, (args, r.stderr)
    assert blocker.read_text() == "a file"


def test_a_cache_folder_that_is_a_file_does_not_stop_the_build(tmp_path):
    d, out = specs(tmp_path), tmp_path / "out"
    out.mkdir()
    (out / ".cache").write_text("not a folder")
    r = balpipe("build", d, "-o", out, "--no-sim", "-j", "1")
    assert r.returncode == 0 and "Traceback" not in r.stderr, r.stderr
    assert (out / "scott_russell" / "index.html").is_file()
