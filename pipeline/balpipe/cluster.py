"""Reaching a dask.distributed scheduler (``balpipe build --scheduler``, ``balpipe sweep
--scheduler``): a refused or unreachable address is told at once, not after the client's
connection retries (20 s for the build, 30 s by dask's default)."""

from __future__ import annotations

import socket
from urllib.parse import urlsplit

PROBE_SECONDS = 5.0  # how long a silent host (a firewall dropping packets) is waited for


def unreachable(address: str, timeout: float = PROBE_SECONDS) -> str | None:
    """Why nothing answers at the scheduler ``address`` (``tcp://host:port``, ``host:port``), or
    None when a TCP connection opens there (the client then makes the real one). Other
    protocols (``tls://``, ``inproc://``, ``ucx://``) are left to the client: None."""
    u = urlsplit(address if "://" in address else "tcp://" + address)
    try:
        port = u.port
    except ValueError as exc:
        return str(exc)
    if u.scheme != "tcp" or not u.hostname or port is None:
        return None
    try:
        with socket.create_connection((u.hostname, port), timeout=timeout):
            return None
    except socket.timeout:
        return f"no answer within {timeout:g} s"
    except OSError as exc:
        return exc.strerror or str(exc)
