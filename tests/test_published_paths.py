"""Nothing of the machine in a published file: a build from absolute paths publishes the same
site as one from relative paths (spec names relative to the working folder, the repository or
the folder named on the command line), and a spec folder holding hostile inputs (a link to a
secret, a device as a table) builds its good spec and publishes neither the secret nor a path."""

from __future__ import annotations

import os
import resource
import subprocess
import sys
from pathlib import Path

from balpipe.site_files.spec_files import published_names
from test_motion_specs import FOUR_BAR, _csv

ROOT = Path(__file__).resolve().parents[1]
SECRET = "API_TOKEN=s3cr3t-value-0123456789"


def run(*args, cwd: Path) -> subprocess.CompletedProcess:
    def cap() -> None:  # a reader of /dev/zero fails quickly here instead of loading the machine
        resource.setrlimit(resource.RLIMIT_AS, (1_500_000_000, 1_500_000_000))
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True,
                          cwd=cwd, preexec_fn=cap, timeout=900)


def site_bytes(out: Path) -> dict[str, bytes]:
    return {f.relative_to(out).as_posix(): f.read_bytes() for f in sorted(out.rglob("*"))
            if f.is_file() and ".cache" not in f.parts and f.name != ".balpipe.lock"}


def machine_paths(tmp_path: Path) -> list[bytes]:
    """Byte strings that betray the machine: the test's folders, as given and resolved."""
    return sorted({str(p).encode() for p in (tmp_path, tmp_path.resolve())})


def table_spec(file: str) -> str:
    return (FOUR_BAR.replace("analysis: {samples: 201}", "analysis: {samples: 41}")
            + f"motion:\n  duration: 2 s\n  drive:\n    crank: {{law: table, file: {file}, ends: periodic}}\n")


def test_a_build_from_absolute_paths_publishes_no_path_of_the_machine(tmp_path):
    folder = tmp_path / "work" / "specs"
    folder.mkdir(parents=True)
    (folder / "crank.csv").write_text(_csv())
    (folder / "good.yaml").write_text(table_spec("crank.csv"))
    (folder / "bad.yaml").write_text("name: [x\n")
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    r = run("build", folder, "-o", tmp_path / "abs", "--no-sim", "-j", "1", cwd=elsewhere)
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    published = site_bytes(tmp_path / "abs")
    assert "good/results.json" in published and "index.html" in published
    for name, data in published.items():
        for bad in machine_paths(tmp_path):
            assert bad not in data, (name, bad)
    assert b"\"source\": \"specs/good.yaml\"" in published["good/results.json"] and b"specs/bad.yaml:2:" in published["index.html"]
    # the same site as a build from the relative path, byte for byte
    r = run("build", "specs", "-o", tmp_path / "rel", "--no-sim", "-j", "1", cwd=tmp_path / "work")
    assert r.returncode == 2, r.stderr
    assert site_bytes(tmp_path / "rel") == published


def test_published_names_keep_relative_paths_and_never_give_an_absolute_one(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "a").mkdir()
    spec = tmp_path / "a" / "x.yaml"
    assert published_names(["a"], [Path("a/x.yaml")]) == {Path("a/x.yaml"): "a/x.yaml"}
    assert published_names([str(tmp_path / "a")], [spec]) == {spec: "a/x.yaml"}
    monkeypatch.chdir("/")  # the working folder "/" is no base: the named folder's is
    assert published_names([str(tmp_path / "a")], [spec]) == {spec: "a/x.yaml"}
    assert published_names([str(spec)], [spec]) == {spec: "x.yaml"}
    (tmp_path / ".git").mkdir()
    assert published_names([str(spec)], [spec]) == {spec: "a/x.yaml"}  # relative to the repository


def test_a_folder_with_a_secret_link_and_a_device_table_builds_the_good_spec_only(tmp_path):
    """The acceptance case: a link to a secret file, a /dev/zero table and a good spec. The good
    one is built, the bad ones are located errors (exit 2), and the output folder holds no byte
    of the secret nor any path of the machine."""
    secret = tmp_path / "secret.env"
    secret.write_text("".join(f"{SECRET}, {k}\n" for k in range(30)))
    folder = tmp_path / "specs"
    folder.mkdir()
    (folder / "leak.csv").symlink_to(secret)
    (folder / "zero.csv").symlink_to("/dev/zero")
    (folder / "crank.csv").write_text(_csv())
    (folder / "good.yaml").write_text(table_spec("crank.csv"))
    (folder / "leak.yaml").write_text(table_spec("leak.csv"))
    (folder / "abs.yaml").write_text(table_spec(str(secret)))
    (folder / "zero.yaml").write_text(table_spec("zero.csv"))
    (folder / "dev.yaml").write_text(table_spec("/dev/zero"))
    out = tmp_path / "site"
    r = run("build", folder.resolve(), "-o", out.resolve(), "--no-sim", "-j", "2", cwd=ROOT)
    assert r.returncode == 2 and "Traceback" not in r.stderr and "MemoryError" not in r.stderr, r.stderr
    for name in ("leak", "abs", "zero", "dev"):
        line = next(ln for ln in r.stderr.splitlines() if f"specs/{name}.yaml:" in ln and ".file:" in ln)
        assert line.split(":")[1].isdigit() and "motion.drive.crank.file" in line
    assert (out / "good" / "index.html").is_file() and not (out / "leak").exists()
    published = site_bytes(out)
    assert len(published) > 3
    for name, data in published.items():
        assert b"s3cr3t" not in data and b"API_TOKEN" not in data, name
        for bad in machine_paths(tmp_path):
            assert bad not in data, (name, bad)
    assert os.path.getsize(out / "good" / "timeseries.csv") > 0


def test_a_sweep_of_an_absolute_path_publishes_no_path_of_the_machine(tmp_path):
    folder = tmp_path / "specs"
    folder.mkdir()
    (folder / "sr.yaml").write_text((ROOT / "specs" / "scott_russell.yaml").read_text())
    out = tmp_path / "sweep"
    r = run("sweep", folder / "sr.yaml", "--vary", "mechanism.slider.mass=0.2,0.7", "-o", out, "-j", "1", "-q",
            cwd=ROOT)
    assert r.returncode == 0, r.stderr
    published = site_bytes(out)
    assert "index.html" in published and any(k.startswith("designs/") for k in published)
    for name, data in published.items():
        for bad in machine_paths(tmp_path):
            assert bad not in data, (name, bad)
    assert b"sr.yaml" in published["index.html"]
