"""Ctrl-C and SIGTERM at any moment of any verb and any ``-j``: exit 130 or 143, no traceback and
no "Exception ignored". Each moment is reached by a condition, not by a clock: the child process
sets SIGINT's handler itself (whatever disposition the test runner inherited), hooks a function
of balpipe that runs at that moment, and sends the signal to its main process from there."""

from __future__ import annotations

import signal
import subprocess
import sys
from pathlib import Path

import pytest

from _gitrepo import Repo

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"

CHILD = """
import importlib, os, signal, sys
signal.signal(signal.SIGINT, signal.default_int_handler)  # set here: never inherited
MAIN = os.getpid()
hook, signame, when = sys.argv[1:4]
parts = hook.split(".")
def module(k):
    try:
        return importlib.import_module(".".join(parts[:k]))
    except ImportError:
        return None
k = max(k for k in range(1, len(parts)) if module(k) is not None)
mod = module(k)
for name in parts[k:-1]:
    mod = getattr(mod, name)
attr = parts[-1]
real = getattr(mod, attr)
def hooked(*a, **k):
    if when == "before":
        os.kill(MAIN, getattr(signal, signame))
    try:
        return real(*a, **k)
    finally:
        if when == "after":
            os.kill(MAIN, getattr(signal, signame))
setattr(mod, attr, hooked)
sys.argv = ["balpipe", *sys.argv[4:]]
from balpipe.cli import entry
entry()
"""


def child(hook: str, signame: str, when: str, *args, cwd: Path | None = None) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-c", CHILD, hook, signame, when, *map(str, args)],
                          capture_output=True, text=True, cwd=cwd, timeout=900,
                          preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))


def assert_stopped(r: subprocess.CompletedProcess, signame: str) -> None:
    want = 130 if signame == "SIGINT" else 143
    assert r.returncode == want, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
    assert ("interrupted" if signame == "SIGINT" else "terminated") in r.stderr


def two_specs(tmp_path: Path) -> Path:
    d = tmp_path / "specs"
    d.mkdir()
    for name in ("scott_russell.yaml", "offset_slider_crank.yaml"):
        (d / name).write_text((SPECS / name).read_text().replace("  samples: 501", "  samples: 41"))
    return d


@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
def test_a_signal_as_the_pool_shuts_down_at_the_end_of_a_parallel_build(tmp_path, signame):
    """The generator clean-up race: the build's pool shut down after its last result. It used to
    be shut down by the garbage collector, where a Ctrl-C was printed as "Exception ignored" and
    lost (exit 0)."""
    d = two_specs(tmp_path)
    r = child("concurrent.futures.ProcessPoolExecutor.shutdown", signame, "after",
              "build", d, "-o", tmp_path / "out", "--no-sim", "-j", "2")
    assert_stopped(r, signame)
    assert not (tmp_path / "out" / "index.html").exists()  # the index is not written by a stopped build


MOMENTS = [  # (hook, verb's arguments): a function that runs in the main process at that moment
    ("balpipe.cli.Parser.parse_args", ["check", "{specs}"]),
    ("balpipe.site_files.spec_files.find_specs", ["build", "{specs}", "-o", "{out}", "--no-sim", "-j", "1"]),
    ("balpipe.loader.load", ["build", "{specs}", "-o", "{out}", "--no-sim", "-j", "1"]),
    ("balpipe.runtime.pool.in_order", ["build", "{specs}", "-o", "{out}", "--no-sim", "-j", "2"]),
    ("balpipe.report.site.write_site", ["build", "{specs}", "-o", "{out}", "--no-sim", "-j", "2"]),
    ("balpipe.runtime.pool.in_order", ["check", "{specs}", "-j", "2"]),
    ("balpipe.loader.schema", ["schema"]),
    ("balpipe.loader.load", ["diff", "{specs}/scott_russell.yaml", "{specs}/offset_slider_crank.yaml", "--no-sim"]),
    ("balpipe.loader.load_text", ["sweep", "{specs}/scott_russell.yaml", "--vary", "mechanism.slider.mass=0.2,0.7",
                                  "-o", "{out}", "-j", "1", "-q"]),
    ("balpipe.history.spec_commits", ["history", "specs", "-o", "{out}", "--no-sim", "--cache", "{tmp}/cache"]),
    ("balpipe.cli.main", ["check", "{specs}/scott_russell.yaml"]),  # after main: the window before the exit
]


@pytest.mark.parametrize("signame", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("hook, args", MOMENTS, ids=[f"{h.rsplit('.', 1)[1]}-{a[0]}" for h, a in MOMENTS])
def test_a_signal_at_any_moment_of_any_verb_is_a_clean_stop(tmp_path, hook, args, signame):
    repo = Repo(tmp_path / "repo")
    d = two_specs(repo.path)
    repo.commit("specs", {f"specs/{f.name}": f.read_text() for f in d.iterdir()})
    fill = {"specs": d, "out": tmp_path / "out", "tmp": tmp_path}
    when = "after" if hook in ("balpipe.cli.main", "balpipe.loader.schema") else "before"
    r = child(hook, signame, when, *[a.format(**fill) for a in args], cwd=repo.path)
    if hook == "balpipe.cli.main":  # the work is done: exit 0, or the signal's code; never a traceback
        assert r.returncode in (0, 130 if signame == "SIGINT" else 143), r.stderr
        assert "Traceback" not in r.stderr and "Exception ignored" not in r.stderr, r.stderr
        return
    assert_stopped(r, signame)
