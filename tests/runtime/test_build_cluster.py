"""``balpipe build --scheduler``: the specs computed on a dask.distributed cluster give the same
site, byte for byte, as a build in one process; a cluster that cannot be used is a usage error."""

from __future__ import annotations

import os
import shutil
import struct
import subprocess
import sys
import time
from pathlib import Path

import pytest

from balpipe.build import Options, SchedulerError, build

ROOT = Path(__file__).resolve().parents[2]
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


@pytest.fixture
def no_client(monkeypatch):
    """dask's Client replaced by one that records being made: "told at once" is a condition (the
    client and its 20-30 s of connection retries are never started), not a wall-clock bound."""
    distributed = pytest.importorskip("distributed")
    made: list[tuple] = []

    def client(*args, **kwargs):
        made.append(args)
        raise AssertionError("the dask client was started")

    monkeypatch.setattr(distributed, "Client", client)
    return made


def test_scheduler_usage_errors_exit_2_without_a_traceback(tmp_path, capsys, no_client):
    from balpipe.cli import main

    spec = str(ROOT / "specs" / SPECS[0])
    assert main(["build", spec, "-o", str(tmp_path / "a"), "--scheduler", "tcp://127.0.0.1:9", "-j", "2"]) == 2
    assert "exclude each other" in capsys.readouterr().err
    assert main(["build", spec, "-o", str(tmp_path / "b"), "--no-sim", "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the dask scheduler at tcp://127.0.0.1:9: Connection refused" in err and "Traceback" not in err
    assert no_client == []  # told by the probe, not after the client's retries
    r = balpipe("build", "--help")
    assert "--scheduler" in r.stdout


def test_sweep_on_an_unreachable_scheduler_is_a_usage_error_told_at_once(tmp_path, capsys, no_client):
    from balpipe.cli import main

    assert main(["sweep", str(ROOT / "tests" / "fixtures" / "sweep_block.yaml"), "-o", str(tmp_path / "sw"),
                 "--scheduler", "tcp://127.0.0.1:9"]) == 2
    err = capsys.readouterr().err
    assert "cannot reach the dask scheduler at tcp://127.0.0.1:9: Connection refused" in err and "Traceback" not in err
    assert no_client == [] and not (tmp_path / "sw").exists()


_PAYLOAD = b"\x83\xabcompression\xc0\xa6python\x93\x03\x0b\x07\xafpickle-protocol\x05"
#: what a dask scheduler (distributed 2026.8) sends first on a new connection: the frames' total
#: length, the frame count, each frame's length, the msgpack handshake
DASK_HANDSHAKE = (struct.pack("<Q", 16 + len(_PAYLOAD)) + struct.pack("<QQ", 1, len(_PAYLOAD)) + _PAYLOAD)


def _speaker(first: bytes, then_wait: bool = False):
    """A service that speaks first: sends ``first`` to each connection (then keeps it open when
    ``then_wait``, until the test closes the server)."""
    import socket
    import threading

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    stop = threading.Event()

    def answer() -> None:
        while not stop.is_set():
            try:
                conn, _ = srv.accept()
            except OSError:
                return
            try:
                conn.sendall(first)
                if then_wait:
                    stop.wait()
            except OSError:
                pass
            finally:
                conn.close()

    threading.Thread(target=answer, daemon=True).start()
    return srv, srv.getsockname()[1], stop


@pytest.mark.parametrize("first", [b"\xff" * 64, b"SSH-2.0-OpenSSH_9.2\r\n", struct.pack("<Q", 58) + b"\0" * 58,
                                   struct.pack("<Q", 2 ** 61)], ids=["huge-length", "banner", "not-dask", "length-only"])
def test_a_service_that_speaks_first_is_no_scheduler_and_nothing_huge_is_read(first):
    from balpipe.runtime.cluster import unreachable

    srv, port, stop = _speaker(first, then_wait=True)
    try:
        why = unreachable(f"tcp://127.0.0.1:{port}", timeout=1.0)
    finally:
        stop.set()
        srv.close()
    assert why is not None and "no dask" in why


def test_a_build_and_a_sweep_on_a_service_that_speaks_first_are_usage_errors(tmp_path):
    """Once the probe let such a service through and dask's client read its first bytes as a
    length: a 2.82 EiB allocation and a traceback. The child's memory is capped, so a regression
    fails quickly instead of loading the machine."""
    import resource

    pytest.importorskip("distributed")
    srv, port, stop = _speaker(b"\xff" * 64)
    env = dict(os.environ, PYTHONPATH=str(ROOT / "pipeline"))

    def cap() -> None:
        resource.setrlimit(resource.RLIMIT_AS, (3_000_000_000, 3_000_000_000))
    try:
        for args in (["build", str(ROOT / "specs" / SPECS[0]), "-o", str(tmp_path / "a"), "--no-sim"],
                     ["sweep", str(ROOT / "tests" / "fixtures" / "sweep_block.yaml"), "-o", str(tmp_path / "sw")]):
            r = subprocess.run([sys.executable, "-m", "balpipe", *args, "--scheduler", f"tcp://127.0.0.1:{port}"],
                               capture_output=True, text=True, env=env, timeout=300, preexec_fn=cap)
            assert r.returncode == 2 and "Traceback" not in r.stderr and "MemoryError" not in r.stderr, r.stderr
            assert "no dask handshake" in r.stderr
    finally:
        stop.set()
        srv.close()


@pytest.mark.parametrize("address", ["tls://127.0.0.1:8786", "inproc://x", "ucx://h:1", "tcp://host", "tcp://:80"])
def test_a_scheduler_address_of_another_protocol_is_refused_before_any_work(tmp_path, capsys, address, no_client):
    from balpipe.cli import main

    for args in (["build", str(ROOT / "specs" / SPECS[0]), "-o", str(tmp_path / "a"), "--no-sim"],
                 ["sweep", str(ROOT / "tests" / "fixtures" / "sweep_block.yaml"), "-o", str(tmp_path / "sw")]):
        assert main([*args, "--scheduler", address]) == 2
        err = capsys.readouterr().err
        assert f"--scheduler {address}:" in err and "Traceback" not in err, err
        assert "only tcp://" in err or "tcp://host:port" in err
    assert no_client == [] and not (tmp_path / "a").exists() and not (tmp_path / "sw").exists()


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

    srv, port = serve(DASK_HANDSHAKE)
    assert unreachable(f"tcp://127.0.0.1:{port}", timeout=2.0) is None
    srv.close()
    srv, port = serve(b"")  # listens, never accepts nor writes
    assert "sent no dask handshake within 0.5 s" in unreachable(f"127.0.0.1:{port}", timeout=0.5)
    srv.close()
    srv, port = serve(None)
    assert "closed the connection at once" in unreachable(f"tcp://127.0.0.1:{port}", timeout=2.0)
    srv.close()
    assert unreachable(f"tcp://127.0.0.1:{port}") == "Connection refused"
    assert "only tcp://" in unreachable("inproc://x") and "only tcp://" in unreachable("tls://127.0.0.1:9")
    assert "out of range" in unreachable("tcp://127.0.0.1:99999")


def test_a_build_on_a_service_that_is_no_scheduler_is_a_usage_error_not_a_hang(tmp_path, capsys, no_client):
    """dask's client waits for ever for the handshake of a service that accepts and says nothing;
    balpipe says what listens there after the probe's time, and never starts the client."""
    import socket

    from balpipe.cli import main

    srv = socket.socket()
    srv.bind(("127.0.0.1", 0))
    srv.listen()
    port = srv.getsockname()[1]
    try:
        code = main(["build", str(ROOT / "specs" / SPECS[0]), "-o", str(tmp_path / "a"), "--no-sim",
                     "--scheduler", f"tcp://127.0.0.1:{port}"])
    finally:
        srv.close()
    err = capsys.readouterr().err
    assert code == 2 and "Traceback" not in err, err
    assert f"cannot reach the dask scheduler at tcp://127.0.0.1:{port}: a service listens there" in err
    assert no_client == []
