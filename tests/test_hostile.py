"""Issue 14: hostile input and failures. One test per example of the issue: no hang, no
traceback, nothing written outside the site, nothing lost. Issue 7, item 3: the site can be
served (modes follow the umask)."""

from __future__ import annotations

import json
import os
import shutil
import signal
import stat
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

from balpipe import build as build_mod
from balpipe.cli import main
from balpipe.loader import SpecErrors, load, load_text
from _edits import replaced
from _terminal import StderrLines, balpipe_command

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
SCOTT = (SPECS / "scott_russell.yaml").read_text()
OFFSET = (SPECS / "offset_slider_crank.yaml").read_text()
FIVE = (SPECS / "paper004_five_bar.yaml").read_text()
FAST = "  samples: 501"  # replaced by fewer samples to keep these builds quick


def quick(text: str) -> str:
    """Fewer samples where the spec sets 501 (a speed-up only; specs on the default keep it)."""
    return replaced(text, FAST, "  samples: 41") if FAST in text else text


def balpipe(*args, cwd=None, timeout=300, **kw):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, timeout=timeout, **kw)


def no_traceback(r) -> None:
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout, r.stderr


def _load_error(tmp_path: Path, content: bytes | str, name: str = "s.yaml") -> str:
    p = tmp_path / name
    p.write_bytes(content if isinstance(content, bytes) else content.encode())
    with pytest.raises(SpecErrors) as e:
        load(p)
    return str(e.value)


# --- loader: aliases, encodings, control characters -------------------------------------------

BOMB = "".join(
    f"{k}: &{k} [" + ", ".join([f"*{p}"] * 9 if p else ['"lol"'] * 9) + "]\n"
    for k, p in zip("abcdefgh", [None, *"abcdefg"])
)


def test_alias_bomb_is_refused_fast_and_located(tmp_path, monkeypatch):
    """Fast by a condition, not a clock: refused from the node graph, before the document (a
    billion strings) is ever constructed."""
    import balpipe.loader as loader_mod

    def never(*args, **kwargs):
        raise AssertionError("the alias bomb was constructed")

    monkeypatch.setattr(loader_mod._Loader, "construct_document", never)
    with pytest.raises(SpecErrors, match="alias"):
        load_text(BOMB, "bomb.yaml")
    monkeypatch.undo()
    p = tmp_path / "bomb.yaml"
    p.write_text(BOMB)
    r = balpipe("check", p)
    assert r.returncode == 2
    no_traceback(r)
    assert "bomb.yaml:" in r.stderr and "alias" in r.stderr and "limit" in r.stderr


@pytest.mark.parametrize("text, values, refused", [
    ("a: 1\n", None, False), ("a: [1, 2, {b: c}]\nd: [[], {}]\n", None, False),  # small trees
    ("a: " + "[" * 63 + "1" + "]" * 63 + "\n", None, True),  # 64 collections, a scalar in the deepest: 65 levels
    ("a: " + "[" * 62 + "1" + "]" * 62 + "\n", None, False),  # 63 and a scalar: 64 levels, the limit
    ("a: " + "[" * 63 + "]" * 63 + "\n", None, False),  # 64 empty collections: 64 levels
    ("[" + ", ".join(["1"] * 10) + "]\n", 11, False),  # 11 values, the (lowered) limit
    ("[" + ", ".join(["1"] * 11) + "]\n", 11, True),  # 12 values
    ("a: &x [1, 2]\nb: *x\n", None, False), ("a: &x {b: 1}\nc: {<<: *x, d: 2}\n", None, False),
    (BOMB, None, True), ("name: &a [*a]\n", None, True),
])
def test_the_alias_walk_is_left_out_only_where_it_finds_nothing(text, values, refused, monkeypatch):
    """The walk of the node graph (aliases, sizes, depths) runs unless the event stream shows it
    cannot refuse the document (no alias, within the values' and the levels' limits): every
    document it refuses is walked (``values``: the values' limit lowered)."""
    import yaml

    import balpipe.loader as loader_mod

    if values is not None:
        monkeypatch.setattr(loader_mod, "MAX_VALUES", values)
    stream = loader_mod._check_nesting(text, "s.yaml")
    node = yaml.compose(text, Loader=loader_mod._Loader)
    try:
        loader_mod._check_aliases(node, "s.yaml")
        walk_refuses = False
    except SpecErrors:
        walk_refuses = True
    assert walk_refuses == refused
    walked = loader_mod._needs_alias_check(*stream)
    assert walked == ("*" in text or stream[0] > loader_mod.MAX_VALUES or stream[1] >= loader_mod.MAX_DEPTH)
    assert walked or not refused


def test_no_worked_example_needs_the_alias_walk():
    import balpipe.loader as loader_mod

    for spec in Path(__file__).resolve().parents[1].joinpath("specs").glob("*.yaml"):
        assert not loader_mod._needs_alias_check(*loader_mod._check_nesting(spec.read_text(encoding="utf-8"), "x"))


def test_recursive_alias_is_a_located_error_and_the_build_goes_on(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "rec.yaml").write_text("name: &a [*a]\n")
    (d / "good.yaml").write_text(quick(SCOTT))
    r = balpipe("build", d, "-o", tmp_path / "out", "--no-sim")
    no_traceback(r)
    assert r.returncode == 2
    assert "rec.yaml:1:" in r.stderr and "recursive alias" in r.stderr
    assert (tmp_path / "out" / "index.html").exists() and (tmp_path / "out" / "good" / "index.html").exists()


@pytest.mark.parametrize("content,where,words", [
    ("name: x\n".encode("utf-16"), "1:1", "UTF-16"),
    (b"name: x\ndescription: caf\xff\n", "2:17", "not UTF-8"),
    (b"name: x\ndescription: a\x00b\n", "2:15", "U+0000 (NUL)"),
    (b"name: x\ndescription: a\x1bb\n", "2:15", "U+001B (ESC)"),
    (b'name: "a\\x1b[31m"\n', "1:7", "U+001B (ESC)"),
    (b'name: "a\\0"\n', "1:7", "U+0000 (NUL)"),
])
def test_encodings_and_control_characters_are_located(tmp_path, content, where, words):
    msg = _load_error(tmp_path, content)
    assert f"s.yaml:{where}:" in msg and words in msg


def test_deep_nesting_is_refused_without_crashing(tmp_path):
    p = tmp_path / "deep.yaml"
    p.write_text("name: " + "[" * 200000 + "]" * 200000 + "\n")
    r = balpipe("check", p)
    no_traceback(r)
    assert r.returncode == 2 and "nested deeper than" in r.stderr


def test_file_size_limit(tmp_path):
    msg = _load_error(tmp_path, "name: x\n" + "# padding\n" * 200_000)
    assert "file too large" in msg and "limit" in msg


# --- numbers: limits and overflow -------------------------------------------------------------

@pytest.mark.parametrize("old,new,words", [
    ("duration: 0.5 s", "duration: 1.0e+300 s", "motion.duration: time out of range"),
    ("length: 0.2 m, mass: 1.2 kg", "length: 1.0e+300 m, mass: 1.2 kg", "mechanism.crank.length: length out of range"),
    ("  coupler_counterweight: -0.15 m", "  coupler_counterweight: -0.15 m\nvalidation:\n  dt: 1.0e-300",
     "validation.dt: a time step of 1e-300 s takes"),
    ("  coupler_counterweight: -0.15 m", "  coupler_counterweight: -0.15 m\nreferences:\n  - {name: mcp1, published: .nan}",
     "references[0].published: number must be a finite number"),
])
def test_extreme_numbers_are_refused_up_front(tmp_path, old, new, words):
    msg = _load_error(tmp_path, replaced(OFFSET, old, new))
    assert words in msg


def _assert_checks(p: Path, text: str) -> None:
    """``balpipe check`` accepts ``text`` written to ``p``: exit 0, no traceback."""
    p.write_text(text)
    r = balpipe("check", p)
    no_traceback(r)
    assert r.returncode == 0, r.stderr


def test_huge_duration_within_limits_builds(tmp_path):
    _assert_checks(tmp_path / "slow.yaml", replaced(quick(OFFSET), "duration: 0.5 s", "duration: 90000 s"))


def test_five_bar_with_massless_distal_links_checks(tmp_path):
    _assert_checks(tmp_path / "fb.yaml",
                   replaced(quick(FIVE), "distal:   {length: 0.30 m, mass: 1.0 kg", "distal:   {length: 0.30 m, mass: 0 kg"))


def test_check_goes_on_past_a_crashing_spec_and_matches_build(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "a_bomb.yaml").write_text(BOMB)
    (d / "b_unknown_ref.yaml").write_text(
        quick(OFFSET) + "references:\n  - {name: no_such_parameter, published: 1.0}\n")
    for name in ("scott_russell.yaml", "offset_slider_crank.yaml"):
        (d / name).write_text(quick((SPECS / name).read_text()))
    r = balpipe("check", d)
    no_traceback(r)
    assert r.returncode == 2
    assert "scott_russell.yaml: ok" in r.stdout and "offset_slider_crank.yaml: ok" in r.stdout
    assert "b_unknown_ref.yaml:" in r.stderr and "nothing computes 'no_such_parameter'" in r.stderr
    assert "2 valid, 2 invalid" in r.stderr


def _four_bar_beyond_its_limit() -> str:
    """A non-Grashof four-bar (0.3 + 1.0 > 0.5 + 0.4) whose crank is driven half a turn: it
    reaches a limit position on the way, which only the analysis finds."""
    import math

    A, D, r1, r2 = (0.3, 0.0), (1.0, 0.0), 0.5, 0.4
    dx, dy = D[0] - A[0], D[1] - A[1]
    d = math.hypot(dx, dy)
    a = (r1**2 - r2**2 + d * d) / (2 * d)
    h = math.sqrt(r1 * r1 - a * a)
    B = (A[0] + a * dx / d - h * dy / d, A[1] + a * dy / d + h * dx / d)
    phi, psi = math.atan2(B[1] - A[1], B[0] - A[0]), math.atan2(B[1] - D[1], B[0] - D[0])
    return f"""name: four-bar driven beyond its limit position
mechanism:
  template: custom
  frame_points: {{O: [0, 0], D: [1, 0]}}
  bodies:
    - {{name: crank, mass: 1, com: [0.15, 0], inertia: 0.01, points: {{O: [0, 0], A: [0.3, 0]}}, pose: [0, 0, 0]}}
    - {{name: coupler, mass: 1, com: [0.25, 0], inertia: 0.02, points: {{A: [0, 0], B: [0.5, 0]}}, pose: [{A[0]}, {A[1]}, {phi}]}}
    - {{name: rocker, mass: 1, com: [0.2, 0], inertia: 0.015, points: {{D: [0, 0], B: [0.4, 0]}}, pose: [1, 0, {psi}]}}
  joints:
    - {{type: revolute, name: O, a: frame, b: crank, point_a: O, point_b: O}}
    - {{type: revolute, name: A, a: crank, b: coupler, point_a: A, point_b: A}}
    - {{type: revolute, name: B, a: coupler, b: rocker, point_a: B, point_b: B}}
    - {{type: revolute, name: D, a: frame, b: rocker, point_a: D, point_b: D}}
  drivers:
    - {{name: crank, joint: O}}
motion:
  duration: 1 s
  drive:
    crank: {{from: 0 deg, to: 180 deg}}
analysis:
  samples: 101
validation:
  enabled: false
"""


def test_check_refuses_a_motion_that_build_refuses(tmp_path):
    """A motion through a configuration the engine cannot pass: check says so, as build does."""
    p = tmp_path / "through.yaml"
    p.write_text(_four_bar_beyond_its_limit())
    rc = balpipe("check", p)
    rb = balpipe("build", p, "-o", tmp_path / "out", "--no-sim")
    no_traceback(rc), no_traceback(rb)
    assert rb.returncode == 2 and "cannot be closed" in rb.stderr
    assert rc.returncode == 2 and "through.yaml:" in rc.stderr and "cannot be closed" in rc.stderr


# --- names are data ---------------------------------------------------------------------------

NAMES_SPEC = """
name: "<script>alert('x')</script> & $\\\\frac{"
mechanism:
  template: custom
  frame_points: {"$\\\\frac{O$": [0, 0]}
  bodies:
    - {name: "arm <b>", mass: 1.0, com: [0.1, 0], inertia: 0.01, points: {"$P$": [0, 0]}, pose: [0, 0, 0]}
  joints:
    - {type: revolute, name: "pivot $x", a: frame, b: "arm <b>", point_a: "$\\\\frac{O$", point_b: "$P$"}
  drivers:
    - {name: "$\\\\frac{drive$", joint: "pivot $x"}
motion:
  duration: 0.5 s
  drive:
    "$\\\\frac{drive$": {from: 0 deg, to: 90 deg}
analysis:
  samples: 41
validation:
  enabled: false
"""


def test_names_are_shown_literally_in_pages_and_figures(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "names.yaml").write_text(NAMES_SPEC)
    r = balpipe("build", d, "-o", tmp_path / "out")
    no_traceback(r)
    assert r.returncode == 0, r.stderr
    page = (tmp_path / "out" / "names" / "index.html").read_text()
    index = (tmp_path / "out" / "index.html").read_text()
    for html in (page, index):
        assert "<script>alert" not in html
        assert "&lt;script&gt;alert(" in html
    assert "frac{drive" in page  # the driver's name, literally, in the effort figure


def test_a_250_character_file_name_builds(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    name = "x" * 246 + ".yaml"
    (d / name).write_text(quick(SCOTT))
    r = balpipe("build", d, "-o", tmp_path / "out", "--no-sim")
    no_traceback(r)
    assert r.returncode == 0, r.stderr
    folders = [p for p in (tmp_path / "out").iterdir() if p.is_dir() and p.name != ".cache"]
    assert len(folders) == 1 and len(folders[0].name) <= build_mod.MAX_SLUG
    assert any((tmp_path / "out" / ".cache" / "figures" / folders[0].name).iterdir())  # its figures cached


@pytest.mark.parametrize("a,b", [("x.yaml", "x.yml"), ("a b.yaml", "a-b.yaml")])
def test_slug_clashes_are_named(tmp_path, a, b):
    d = tmp_path / "specs"
    d.mkdir()
    (d / a).write_text(quick(SCOTT))
    (d / b).write_text(quick(SCOTT))
    r = balpipe("build", d, "-o", tmp_path / "out", "--no-sim")
    no_traceback(r)
    assert r.returncode == 2
    for x, y in ((a, b), (b, a)):
        line = next(ln for ln in r.stderr.splitlines() if ln.startswith(f"specs/{x}"))  # published names
        assert f"specs/{y}" in line and "rename" in line
    rc = balpipe("check", d)
    assert rc.returncode == 2 and "would be the same" in rc.stderr


# --- the output folder is the only place written ----------------------------------------------

def test_unreadable_spec_folder_is_reported(tmp_path, monkeypatch, capsys):
    d = tmp_path / "specs"
    (d / "locked").mkdir(parents=True)
    (d / "good.yaml").write_text(quick(SCOTT))
    real = os.scandir

    def scandir(path="."):
        if Path(path).name == "locked":
            raise PermissionError(13, "Permission denied", str(path))
        return real(path)

    monkeypatch.setattr(os, "scandir", scandir)
    rc = main(["check", str(d)])
    err = capsys.readouterr().err
    assert rc == 2 and "locked: cannot read the folder: Permission denied" in err


@pytest.mark.skipif(os.geteuid() == 0, reason="root reads any folder")
def test_unreadable_spec_folder_is_reported_for_real(tmp_path):
    d = tmp_path / "specs"
    (d / "locked").mkdir(parents=True)
    (d / "good.yaml").write_text(quick(SCOTT))
    os.chmod(d / "locked", 0)
    try:
        r = balpipe("check", d)
    finally:
        os.chmod(d / "locked", 0o755)
    assert r.returncode == 2 and "cannot read the folder" in r.stderr


def test_output_path_that_is_a_file(tmp_path):
    (tmp_path / "out").write_text("keep me")
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    r = balpipe("build", tmp_path / "s.yaml", "-o", tmp_path / "out", "--no-sim")
    no_traceback(r)
    assert r.returncode == 2 and "is a file, not a folder" in r.stderr
    assert (tmp_path / "out").read_text() == "keep me"


def _old_site(out: Path) -> dict[str, str]:
    out.mkdir(parents=True, exist_ok=True)
    (out / "index.html").write_text("old index")
    (out / "page").mkdir(exist_ok=True)
    (out / "page" / "index.html").write_text("old page")
    return {"index.html": "old index", "page/index.html": "old page"}


def _unchanged(out: Path, old: dict[str, str]) -> None:
    for k, v in old.items():
        assert (out / k).read_text() == v
    # no temporaries left behind (the figure cache's folder is no temporary; one in it would be)
    locks = {out / ".cache" / kind / ".locks" for kind in ("sims", "balance")}  # sim_cache.py's, balance_cache.py's
    left = [p for p in out.rglob(".*") if p.name != ".balpipe.lock" and p != out / ".cache" and p not in locks]
    assert not left, left


def test_read_only_output_folder_leaves_the_site_alone(tmp_path, monkeypatch, capsys):
    out = tmp_path / "out"
    old = _old_site(out)
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    real = os.open

    def ro_open(path, flags, *a, **k):  # what a read-only folder answers (root bypasses modes)
        if Path(path).parent == out and flags & os.O_CREAT:
            raise PermissionError(13, "Permission denied", str(path))
        return real(path, flags, *a, **k)

    monkeypatch.setattr(os, "open", ro_open)
    rc = main(["build", str(tmp_path / "s.yaml"), "-o", str(out), "--no-sim"])
    err = capsys.readouterr().err
    assert rc == 2 and "cannot write to the output folder" in err and "Permission denied" in err
    _unchanged(out, old)


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into read-only folders")
def test_read_only_output_folder_for_real(tmp_path):
    out = tmp_path / "out"
    old = _old_site(out)
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    os.chmod(out, 0o555)
    try:
        r = balpipe("build", tmp_path / "s.yaml", "-o", out, "--no-sim")
    finally:
        os.chmod(out, 0o755)
    no_traceback(r)
    assert r.returncode == 2 and "cannot write to the output folder" in r.stderr
    _unchanged(out, old)


def test_schema_to_a_missing_folder(tmp_path):
    r = balpipe("schema", "-o", tmp_path / "no" / "such" / "dir" / "x.json")
    no_traceback(r)
    assert r.returncode == 2 and "cannot write" in r.stderr and "No such file or directory" in r.stderr


def test_planted_symlinks_are_not_followed(tmp_path):
    outside = tmp_path / "outside.html"
    outside.write_text("precious")
    outside_dir = tmp_path / "outside_dir"
    outside_dir.mkdir()
    (outside_dir / "keep.txt").write_text("precious")
    out = tmp_path / "out"
    out.mkdir()
    (out / "index.html").symlink_to(outside)
    (out / "balpipe.schema.json").symlink_to(outside)
    (out / "s").symlink_to(outside_dir, target_is_directory=True)
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    r = balpipe("build", tmp_path / "s.yaml", "-o", out, "--no-sim")
    no_traceback(r)
    assert r.returncode == 0, r.stderr
    assert outside.read_text() == "precious"
    assert sorted(p.name for p in outside_dir.iterdir()) == ["keep.txt"]
    assert not (out / "index.html").is_symlink() and "s/index.html" in (out / "index.html").read_text()
    assert not (out / "s").is_symlink() and (out / "s" / "results.json").exists()


def _umask_run(mask: int, *args):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          preexec_fn=lambda: os.umask(mask), timeout=300)


@pytest.mark.parametrize("mask", [0o022, 0o027])
def test_site_modes_follow_the_umask(tmp_path, mask):
    """Issue 7, item 3: every folder and file of the site gets the modes the umask gives (a web
    server running as another user can read it with umask 022); no 0700 temporary folders."""
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    out = tmp_path / "out"
    r = _umask_run(mask, "build", tmp_path / "s.yaml", "-o", out, "--no-sim")
    assert r.returncode == 0, r.stderr
    r = _umask_run(mask, "build", tmp_path / "s.yaml", "-o", out, "--no-sim", "--force")  # replaced pages too
    assert r.returncode == 0, r.stderr
    paths = [out, *out.rglob("*")]
    assert len(paths) >= 6
    for p in paths:
        mode = stat.S_IMODE(p.stat().st_mode)
        want = (0o777 if p.is_dir() else 0o666) & ~mask
        assert mode == want, (p, oct(mode), oct(want))


def test_a_failing_spec_keeps_the_earlier_good_page(tmp_path):
    spec = tmp_path / "s.yaml"
    out = tmp_path / "out"
    spec.write_text(quick(SCOTT))
    assert balpipe("build", spec, "-o", out, "--no-sim").returncode == 0
    good = (out / "s" / "index.html").read_text()
    # as built with a wrong counterweight: the counterweights stage no longer cancels the force
    spec.write_text(replaced(quick(SCOTT), "  moment_unknown:", "  crank_counterweight_mass: 1 kg\n  moment_unknown:"))
    r = balpipe("build", spec, "-o", out, "--no-sim")
    no_traceback(r)
    assert r.returncode == 1
    assert (out / "s" / "index.html").read_text() == good
    failed = json.loads((out / "s" / "failed" / "results.json").read_text())
    assert failed["status"] == "failed"
    index = (out / "index.html").read_text()
    assert "s/index.html" in index and "s/failed/index.html" in index and "page from an earlier build" in index
    spec.write_text(quick(SCOTT))  # fixed: the good build replaces both
    assert balpipe("build", spec, "-o", out, "--no-sim").returncode == 0
    assert not (out / "s" / "failed").exists()


def test_concurrent_builds_wait_for_the_lock(tmp_path):
    import fcntl

    out = tmp_path / "out"
    out.mkdir()
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    fd = os.open(out / ".balpipe.lock", os.O_RDWR | os.O_CREAT)
    fcntl.flock(fd, fcntl.LOCK_EX)
    p = subprocess.Popen([sys.executable, "-m", "balpipe", "build", tmp_path / "s.yaml", "-o", out, "--no-sim"],
                         stderr=subprocess.PIPE, text=True)
    first = p.stderr.readline()  # blocks until the build reports that it waits
    assert "waiting for another build" in first
    time.sleep(1)
    assert p.poll() is None and not (out / "index.html").exists()
    fcntl.flock(fd, fcntl.LOCK_UN)
    os.close(fd)
    _, err = p.communicate(timeout=300)
    assert p.returncode == 0 and (out / "index.html").exists(), err


@pytest.mark.parametrize("sig,code,jobs", [(signal.SIGINT, 130, 2), (signal.SIGTERM, 143, 2),
                                           (signal.SIGINT, 130, 1), (signal.SIGTERM, 143, 1)])
def test_interrupt_is_clean_at_any_jobs(tmp_path, sig, code, jobs):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "a_invalid.yaml").write_text("name: [\n")  # done at once: its worker waits idle for work
    # busy: simulated for about 20 s on an idle machine (the five-bar, 7 s since the validation got
    # faster, could finish before the signal)
    shutil.copy(SPECS / "paper000_rpr3_idler_loop.yaml", d / "paper000_rpr3_idler_loop.yaml")
    out = tmp_path / "out"
    old = _old_site(out)
    p = subprocess.Popen(balpipe_command("build", d, "-o", out, "-j", jobs),
                         stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, start_new_session=True)
    lines = StderrLines(p)
    # inside the work: the invalid spec is reported, the idler loop is being built (it takes longer)
    lines.wait_for("a_invalid.yaml: error")
    assert p.poll() is None
    os.killpg(p.pid, sig)  # as a terminal's Ctrl-C does: the whole process group
    p.wait(timeout=120)
    err = lines.text()
    assert p.returncode == code, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    lines = err.strip().splitlines()
    assert lines[-1].startswith("balpipe: ") and sum(ln.startswith("balpipe") for ln in lines) == 1, err
    _unchanged(out, old)


def test_simulation_steps_are_bounded_before_the_simulation_starts(tmp_path, monkeypatch, capsys):
    """The default step shrinks with the fastest body's speed (validate.default_settings): a
    motion so fast that the simulation would take more than a million steps is refused by
    check and build before any simulation, naming the limit."""
    from balpipe import validate

    monkeypatch.setattr(validate, "default_settings", lambda model, analysis: (1e-9, 100))
    (tmp_path / "s.yaml").write_text(quick(SCOTT))
    rc = main(["check", str(tmp_path / "s.yaml")])
    err = capsys.readouterr().err
    assert rc == 2 and "motion.duration" in err and "limit 1,000,000" in err
    rc = main(["build", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "out")])
    err = capsys.readouterr().err
    assert rc == 2 and "limit 1,000,000" in err
    assert main(["build", str(tmp_path / "s.yaml"), "-o", str(tmp_path / "out"), "--no-sim"]) == 0


def test_control_characters_in_file_names_never_reach_the_index(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    (d / "a\x1b[31m.yaml").write_text("name: [\n")
    r = balpipe("build", d, "-o", tmp_path / "out", "--no-sim")
    no_traceback(r)
    assert r.returncode == 2
    index = (tmp_path / "out" / "index.html").read_text()
    assert "\x1b" not in index and "a\\x1b[31m.yaml" in index
