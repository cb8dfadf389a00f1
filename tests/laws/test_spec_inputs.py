"""Files a spec names (its CSV tables, in ``motion``, in a further ``motions`` entry and as a
path's timing) are read only when they are regular files inside the spec's folder once links are
resolved, at most the size limit (enforced while reading), and a refused or bad file is a located
error that quotes nothing of the file: no traceback, no hang on a FIFO, no memory exhausted by a
device, no line of an outside file on the published site."""

from __future__ import annotations

import os
import resource
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.cli import main
from balpipe.runtime import inputs
from balpipe.runtime.inputs import InputFileError, read_input, read_input_text
from test_motion_specs import FOUR_BAR, TWO_R_TIP, _csv

SECRET = "API_TOKEN=s3cr3t-value-0123456789"


def spec(folder: Path, file: str, name: str = "s.yaml", duration: str = "2 s") -> Path:
    p = folder / name
    p.write_text(FOUR_BAR + f"motion:\n  duration: {duration}\n  drive:\n"
                 f"    crank: {{law: table, file: {file!r}, ends: periodic}}\n")
    return p


def secret_file(path: Path) -> Path:
    """A file with commas (a CSV row to a reader) whose every line carries the secret."""
    path.write_text("".join(f"{SECRET}, {k}\n" for k in range(30)))
    return path


def limited(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess:
    """``balpipe args`` in a child whose address space is capped at 1.5 GB, so that a reader that
    reads a device to its end fails quickly (MemoryError) instead of loading the machine; the
    time-out only guards against a hang (a FIFO), it measures nothing."""
    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (1_500_000_000, 1_500_000_000))
    return subprocess.run([sys.executable, "-m", "balpipe", *args], capture_output=True, text=True, cwd=cwd,
                          preexec_fn=cap, timeout=600)


def located(r: subprocess.CompletedProcess, spec_path: Path, words: str) -> str:
    assert r.returncode == 2, (r.returncode, r.stderr)
    assert "Traceback" not in r.stderr + r.stdout, r.stderr
    line = next((ln for ln in r.stderr.splitlines() if words in ln), None)
    assert line is not None, r.stderr
    where = line.split(": ", 1)[0]
    assert where.startswith(str(spec_path)) and where.count(":") == 2, line
    assert "motion.drive.crank.file" in line or ".file" in line, line
    return line


@pytest.mark.parametrize("how", ["parent", "absolute", "link"])
def test_a_table_outside_the_spec_folder_is_refused_and_not_quoted(tmp_path, how):
    folder = tmp_path / "specs"
    folder.mkdir()
    outside = secret_file(tmp_path / "outside.csv")
    name = {"parent": "../outside.csv", "absolute": str(outside), "link": "crank.csv"}[how]
    if how == "link":
        (folder / "crank.csv").symlink_to(outside)
    p = spec(folder, name)
    r = limited("check", str(p))
    line = located(r, p, "absolute path" if how == "absolute" else "outside the spec's folder")
    assert SECRET not in r.stderr and "API_TOKEN" not in r.stderr
    assert str(tmp_path) not in line.split(": ", 1)[1] or how == "absolute"


def test_a_link_inside_the_folder_to_a_file_inside_is_read(tmp_path):
    (tmp_path / "data").mkdir()
    (tmp_path / "data" / "crank.csv").write_text(_csv())
    (tmp_path / "crank.csv").symlink_to(tmp_path / "data" / "crank.csv")
    assert main(["check", str(spec(tmp_path, "crank.csv"))]) == 0


def test_a_device_table_is_refused_before_a_byte_is_read(tmp_path):
    """``/dev/zero`` never ends and has st_size 0: named directly or through a link it is
    refused at once (the child's memory is capped: reading it would fail there, not hang)."""
    (tmp_path / "zero.csv").symlink_to("/dev/zero")
    for name in ("zero.csv", "/dev/zero", "/dev/urandom"):
        p = spec(tmp_path, name)
        r = limited("check", str(p))
        located(r, p, "absolute path" if name.startswith("/") else "outside the spec's folder")
        assert "MemoryError" not in r.stderr


def test_a_device_inside_the_folder_is_refused_as_a_device(tmp_path, monkeypatch):
    """A device node inside the folder (as root could make one): refused by its mode, whether
    stat sees it first or only fstat on the open descriptor does."""
    f = tmp_path / "dev.csv"
    f.write_text(_csv())
    real_stat, real_fstat = os.stat, os.fstat

    def as_device(result):
        fields = list(result)
        fields[0] = stat.S_IFCHR | 0o666
        return os.stat_result(fields)

    monkeypatch.setattr(inputs.os, "stat", lambda p, *a, **k: as_device(real_stat(p, *a, **k)))
    with pytest.raises(InputFileError, match="is a device, not a regular file"):
        read_input(tmp_path, "dev.csv", 1000)
    monkeypatch.setattr(inputs.os, "stat", real_stat)
    monkeypatch.setattr(inputs.os, "fstat", lambda fd: as_device(real_fstat(fd)))
    with pytest.raises(InputFileError, match="is a device, not a regular file"):
        read_input(tmp_path, "dev.csv", 1000)


def test_a_fifo_table_is_refused_without_waiting(tmp_path):
    os.mkfifo(tmp_path / "crank.csv")
    p = spec(tmp_path, "crank.csv")
    located(limited("check", str(p)), p, "FIFO")


def test_the_size_limit_is_enforced_while_reading(tmp_path, monkeypatch):
    """A file that grows past its stat size (or lies about it) is read to the limit plus one
    byte, never further."""
    (tmp_path / "big.csv").write_bytes(b"x" * 100_000)
    read = []
    real_read = os.read
    monkeypatch.setattr(inputs.os, "read", lambda fd, n: read.append(len(real_read(fd, n))) or b"x" * read[-1])
    with pytest.raises(InputFileError, match="larger than 1000 bytes"):
        read_input(tmp_path, "big.csv", 1000)
    assert sum(read) <= 1001
    assert read_input(tmp_path, "big.csv", 100_000) == b"x" * 100_000


def test_a_folder_or_missing_table_is_a_located_error(tmp_path):
    (tmp_path / "dir.csv").mkdir()
    for name, words in (("dir.csv", "is a folder"), ("gone.csv", "cannot read the table 'gone.csv'")):
        p = spec(tmp_path, name)
        located(limited("check", str(p)), p, words)


def test_a_byte_order_mark_does_not_rename_the_first_column(tmp_path):
    (tmp_path / "crank.csv").write_bytes(b"\xef\xbb\xbf" + _csv().encode())
    p = tmp_path / "s.yaml"
    p.write_text(FOUR_BAR + "motion:\n  duration: 2 s\n  drive:\n"
                 "    crank: {law: table, file: crank.csv, ends: periodic, time: t, value: crank}\n")
    assert main(["check", str(p)]) == 0
    assert read_input_text(tmp_path, "crank.csv", 10**6).startswith("t [s]")


def test_a_bad_row_is_located_without_quoting_the_file(tmp_path):
    (tmp_path / "crank.csv").write_text(_csv()[:200] + f"{SECRET}, 1\n" + "".join(_csv().splitlines(True)[10:]))
    p = spec(tmp_path, "crank.csv")
    line = located(limited("check", str(p)), p, "expected numbers")
    assert "crank.csv:" in line and "API_TOKEN" not in line and "s3cr3t" not in line


def test_not_utf8_is_located_without_quoting_the_file(tmp_path):
    (tmp_path / "crank.csv").write_bytes(_csv().encode()[:100] + b"\xff\xfe secret \n")
    p = spec(tmp_path, "crank.csv")
    line = located(limited("check", str(p)), p, "not UTF-8")
    assert "secret" not in line


OTHER_MOTION = """\
balancing:
  method: partial_balance
  counterweights:
    - {body: crank, name: cw_crank, segment: [[0, 0], [-0.08, 0]]}
  motions:
    - name: second
      samples: 51
      motion:
        duration: 2 s
        drive:
          crank: {law: table, file: '../outside.csv', ends: periodic}
  objective:
    - {load: shaking_force}
  budget: {mass: 1.5 kg}
"""

PATH_TIMING = TWO_R_TIP.replace("timing: {law: quintic}", "timing: {law: table, file: timing.csv}")


def test_a_further_motion_and_a_path_timing_read_only_inside_the_folder(tmp_path):
    folder = tmp_path / "specs"
    folder.mkdir()
    secret_file(tmp_path / "outside.csv")
    (folder / "crank.csv").write_text(_csv())
    p = folder / "m.yaml"
    p.write_text(FOUR_BAR + "motion:\n  duration: 2 s\n  drive:\n    crank: {law: table, file: crank.csv, ends: periodic}\n"
                 + OTHER_MOTION)
    r = limited("check", str(p))
    line = located(r, p, "outside the spec's folder")
    assert "balancing.motions[0].motion.drive.crank.file" in line and "API_TOKEN" not in r.stderr
    (folder / "timing.csv").symlink_to(tmp_path / "outside.csv")
    q = folder / "path.yaml"
    q.write_text(PATH_TIMING)
    r = limited("check", str(q))
    line = located(r, q, "outside the spec's folder")
    assert "motion.drive.tip.timing.file" in line and "API_TOKEN" not in r.stderr
