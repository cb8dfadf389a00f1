"""Reaching a dask.distributed scheduler (``balpipe build --scheduler``, ``balpipe sweep
--scheduler``): a refused or unreachable address is told at once, not after the client's
connection retries (20 s for the build, 30 s by dask's default), and so is a service that is no
scheduler (dask's client would wait for its handshake for ever).

A dask scheduler greets every new connection with its handshake before it reads anything (its
listener writes first), so a TCP connection that receives nothing within the probe's time has
no scheduler behind it. The probe closes its connection after the first bytes: the scheduler
logs "closed before handshake completed" at INFO level, nothing else."""

from __future__ import annotations

import socket
from urllib.parse import urlsplit

PROBE_SECONDS = 5.0  # how long a silent host (a firewall dropping packets) is waited for


def unreachable(address: str, timeout: float = PROBE_SECONDS) -> str | None:
    """Why no dask scheduler answers at ``address`` (``tcp://host:port``, ``host:port``), or None
    when a TCP connection opens there and the other end greets it (the client then makes the
    real one). Other protocols (``tls://``, ``inproc://``, ``ucx://``) are left to the client:
    None."""
    u = urlsplit(address if "://" in address else "tcp://" + address)
    try:
        port = u.port
    except ValueError as exc:
        return str(exc)
    if u.scheme != "tcp" or not u.hostname or port is None:
        return None
    try:
        with socket.create_connection((u.hostname, port), timeout=timeout) as conn:
            try:
                greeting = conn.recv(1)
            except socket.timeout:
                return f"a service listens there but sent no dask handshake within {timeout:g} s (no dask scheduler)"
            if not greeting:
                return "a service listens there but closed the connection at once (no dask scheduler)"
            return None
    except socket.timeout:
        return f"no answer within {timeout:g} s"
    except OSError as exc:
        return exc.strerror or str(exc)
