"""Reaching a dask.distributed scheduler (``balpipe build --scheduler``, ``balpipe sweep
--scheduler``): a refused or unreachable address is told at once, not after the client's
connection retries (20 s for the build, 30 s by dask's default), and so is a service that is no
scheduler (dask's client would wait for its handshake for ever, or, when the service speaks
first, read its first bytes as a message length and try to allocate that much: exabytes).

Only ``tcp://host:port`` (or ``host:port``) is accepted: another protocol (``tls://`` needs
certificates that balpipe does not take, ``inproc://`` lives in one process) is refused with
that reason before any connection.

A dask scheduler greets every new connection with its handshake before it reads anything (its
listener writes first): an 8-byte little-endian length, then that many bytes holding the frame
count, each frame's length and a msgpack mapping with ``compression`` and ``pickle-protocol``.
The probe reads at most :data:`MAX_HANDSHAKE_BYTES` plus the length, all within the probe's
time, and checks that structure; anything else is no dask scheduler. The probe closes its
connection afterwards: the scheduler logs "closed before handshake completed" at INFO level,
nothing else."""

from __future__ import annotations

import socket
import struct
import time
from urllib.parse import urlsplit

PROBE_SECONDS = 5.0  # how long a silent host (a firewall dropping packets) is waited for, in all
MAX_HANDSHAKE_BYTES = 65_536  # a dask handshake is about 60 bytes


def address_problem(address: str) -> str | None:
    """What is wrong with ``address`` as a scheduler address (a usage error), or None."""
    u = urlsplit(address if "://" in address else "tcp://" + address)
    if u.scheme != "tcp":
        return (f"only tcp://host:port schedulers are supported, not {u.scheme}:// "
                "(tls needs certificates that balpipe does not take)")
    try:
        port = u.port
    except ValueError as exc:
        return str(exc)
    if not u.hostname or port is None:
        return "give the scheduler as tcp://host:port"
    return None


def unreachable(address: str, timeout: float = PROBE_SECONDS) -> str | None:
    """Why no dask scheduler answers at ``address`` (``tcp://host:port``, ``host:port``), or None
    when a TCP connection opens there and the other end greets it with a dask handshake (the
    client then makes the real one). At most ``timeout`` seconds and
    :data:`MAX_HANDSHAKE_BYTES` + 8 bytes are spent."""
    problem = address_problem(address)
    if problem is not None:
        return problem
    u = urlsplit(address if "://" in address else "tcp://" + address)
    deadline = time.monotonic() + timeout
    try:
        with socket.create_connection((u.hostname, u.port), timeout=timeout) as conn:
            try:
                head = _read(conn, 8, deadline)
            except socket.timeout:
                return f"a service listens there but sent no dask handshake within {timeout:g} s (no dask scheduler)"
            if not head:
                return "a service listens there but closed the connection at once (no dask scheduler)"
            if len(head) == 8:
                (n,) = struct.unpack("<Q", head)
                if 16 <= n <= MAX_HANDSHAKE_BYTES:
                    try:
                        body = _read(conn, n, deadline)
                    except socket.timeout:
                        body = b""
                    if _is_handshake(body, n):
                        return None
            return "a service listens there but what it sent is no dask handshake (no dask scheduler)"
    except socket.timeout:
        return f"no answer within {timeout:g} s"
    except OSError as exc:
        return exc.strerror or str(exc)


def _read(conn: socket.socket, n: int, deadline: float) -> bytes:
    """Up to ``n`` bytes, fewer if the peer closes; ``socket.timeout`` past ``deadline``."""
    data = b""
    while len(data) < n:
        left = deadline - time.monotonic()
        if left <= 0:
            raise socket.timeout()
        conn.settimeout(left)
        chunk = conn.recv(min(n - len(data), 65_536))
        if not chunk:
            break
        data += chunk
    return data


def _is_handshake(body: bytes, n: int) -> bool:
    """``body`` (``n`` bytes announced) is a dask frame set: a frame count, the frames' lengths
    adding up to the rest, and the handshake's keys in it."""
    if len(body) != n or n < 16:
        return False
    (frames,) = struct.unpack("<Q", body[:8])
    if not 1 <= frames <= 16 or 8 + 8 * frames > n:
        return False
    lengths = struct.unpack(f"<{frames}Q", body[8:8 + 8 * frames])
    return sum(lengths) == n - 8 - 8 * frames and b"pickle-protocol" in body and b"compression" in body
