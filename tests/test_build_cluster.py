"""``balpipe build --scheduler``: the specs computed on a dask.distributed cluster give the same
site, byte for byte, as a build in one process; a cluster that cannot be used is a usage error."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

from balpipe.build import Options, SchedulerError, build

ROOT = Path(__file__).resolve().parents[1]
SPECS = ["scott_russell.yaml", "offset_slider_crank.yaml"]


def tree(folder: Path) -> dict[str, bytes]:
    """The site's files, the figure cache (``.cache/``, not part of the site) left out."""
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*"))
            if p.is_file() and p.relative_to(folder).parts[0] != ".cache"}


def specs_with_a_broken_one(tmp_path: Path) -> Path:
    """Two paper specs and one whose coupler cannot reach the guide: an error found by the
    analysis, so on the workers, not when the spec is read."""
    folder = tmp_path / "specs"
    folder.mkdir()
    for name in SPECS:
        shutil.copy(ROOT / "specs" / name, folder / name)
    text = (ROOT / "specs" / "offset_slider_crank.yaml").read_text()
    (folder / "short_coupler.yaml").write_text(text.replace("coupler: {length: 0.3 m", "coupler: {length: 0.12 m"))
    return folder


def test_a_two_worker_cluster_builds_the_same_site_as_one_process(tmp_path):
    distributed = pytest.importorskip("distributed")
    specs = specs_with_a_broken_one(tmp_path)
    local, remote = tmp_path / "local", tmp_path / "remote"
    here = build([str(specs)], Options(local, simulate=False), jobs=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        there = build([str(specs)], Options(remote, simulate=False), scheduler=cl.scheduler_address)
    assert [(o.source, o.status, o.message) for o in there] == [(o.source, o.status, o.message) for o in here]
    assert [o.status for o in here] == ["ok", "ok", "error"]  # offset, scott_russell, short_coupler
    assert "short_coupler.yaml" in here[2].message and "coupler" in here[2].message
    assert tree(remote) == tree(local)
    # the workers cannot reach this folder's figure cache: they draw every figure, none is cached
    assert (local / ".cache" / "figures" / "scott_russell").is_dir() and not (remote / ".cache").exists()
    # a second build on the cluster computes nothing: every page is unchanged
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        again = build([str(specs)], Options(remote, simulate=False), scheduler=cl.scheduler_address)
    assert [o.skipped for o in again] == [True, True, False]
    assert tree(remote) == tree(local)


def test_workers_with_another_balpipe_are_refused(monkeypatch, tmp_path):
    distributed = pytest.importorskip("distributed")
    import balpipe.build as build_mod

    monkeypatch.setattr(build_mod, "code_hash", lambda: "not the workers' code")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        with pytest.raises(SchedulerError, match="run another balpipe"):
            build([str(ROOT / "specs" / SPECS[0])], Options(tmp_path / "site", simulate=False),
                  scheduler=cl.scheduler_address)
    assert not (tmp_path / "site" / "scott_russell").exists()


def balpipe(*args: str) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(ROOT / "pipeline"))
    return subprocess.run([sys.executable, "-m", "balpipe", *args], capture_output=True, text=True, env=env,
                          timeout=120)


def test_scheduler_usage_errors_exit_2_without_a_traceback(tmp_path):
    pytest.importorskip("distributed")
    spec = str(ROOT / "specs" / SPECS[0])
    r = balpipe("build", spec, "-o", str(tmp_path / "a"), "--scheduler", "tcp://127.0.0.1:9", "-j", "2")
    assert r.returncode == 2 and "exclude each other" in r.stderr and "Traceback" not in r.stderr
    start = time.perf_counter()
    r = balpipe("build", spec, "-o", str(tmp_path / "b"), "--no-sim", "--scheduler", "tcp://127.0.0.1:9")
    assert r.returncode == 2, r.stderr
    assert "cannot reach the dask scheduler at tcp://127.0.0.1:9: Connection refused" in r.stderr
    assert "Traceback" not in r.stderr and time.perf_counter() - start < 15.0  # told at once, not after 20 s of retries
    r = balpipe("build", "--help")
    assert "--scheduler" in r.stdout


def test_sweep_on_an_unreachable_scheduler_is_a_usage_error_told_at_once(tmp_path):
    pytest.importorskip("distributed")
    start = time.perf_counter()
    r = balpipe("sweep", str(ROOT / "tests" / "fixtures" / "sweep_block.yaml"), "-o", str(tmp_path / "sw"),
                "--scheduler", "tcp://127.0.0.1:9")
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert "cannot reach the dask scheduler at tcp://127.0.0.1:9: Connection refused" in r.stderr
    assert time.perf_counter() - start < 15.0 and not (tmp_path / "sw").exists()


def test_the_probe_tells_a_scheduler_from_a_silent_service_and_leaves_other_protocols_to_dask():
    """A dask scheduler greets a new connection first: a service that greets passes the probe, one
    that accepts and says nothing (where dask's client would wait for ever) or closes at once
    does not, nor a refused port."""
    import socket
    import threading

    from balpipe.runtime.cluster import unreachable

    def serve(greet: bytes | None) -> tuple[socket.socket, int]:
        srv = socket.socket()
        srv.bind(("127.0.0.1", 0))
        srv.listen()

        def answer() -> None:
            conn, _ = srv.accept()
            if greet is None:
                conn.close()  # closes at once
            else:
                conn.sendall(greet)
                time.sleep(1.0)
                conn.close()

        if greet != b"":
            threading.Thread(target=answer, daemon=True).start()
        return srv, srv.getsockname()[1]

    srv, port = serve(b"\x01handshake")
    assert unreachable(f"tcp://127.0.0.1:{port}", timeout=2.0) is None
    srv.close()
    srv, port = serve(b"")  # listens, never accepts nor writes
    assert "sent no dask handshake within 0.5 s" in unreachable(f"127.0.0.1:{port}", timeout=0.5)
    srv.close()
    srv, port = serve(None)
    assert "closed the connection at once" in unreachable(f"tcp://127.0.0.1:{port}", timeout=2.0)
    srv.close()
    assert unreachable(f"tcp://127.0.0.1:{port}") == "Connection refused"
    assert unreachable("inproc://x") is None and unreachable("tls://127.0.0.1:9") is None
    assert "out of range" in unreachable("tcp://127.0.0.1:99999")


def test_a_build_on_a_service_that_is_no_scheduler_is_a_usage_error_not_a_hang(tmp_path):
    """dask's client waits for ever for the handshake of a service that accepts and says nothing;
    balpipe says what listens there in the probe's 5 s."""
    import socket

    pytest.importorskip("distributed")
    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    port = srv.getsockname()[1]
    start = time.perf_counter()
    try:
        r = balpipe("build", str(ROOT / "specs" / SPECS[0]), "-o", str(tmp_path / "a"), "--no-sim",
                    "--scheduler", f"tcp://127.0.0.1:{port}")
    finally:
        srv.close()
    assert r.returncode == 2 and "Traceback" not in r.stderr, r.stderr
    assert f"cannot reach the dask scheduler at tcp://127.0.0.1:{port}: a service listens there" in r.stderr
    assert time.perf_counter() - start < 30.0
