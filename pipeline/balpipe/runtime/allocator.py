"""The C allocator's thresholds for the engine's arrays (glibc).

The engine allocates and frees arrays of a few megabytes many times per analysis: the positions,
the Jacobian's values and the solves of each chunk (:func:`balpipe.engine.fastpath.dynamics_by_chunks`).
glibc serves an allocation above its mmap threshold (128 kB at start, raised as large blocks are
freed) with fresh pages from the kernel, and hands freed memory at the top of its heap back to the
kernel beyond its trim threshold (twice the mmap threshold): the next chunk's arrays fault every
page in again, zeroed by the kernel. On the 10R chain at 10^4 samples those page faults were a
third of the analysis's CPU time (``benchmarks/README.md``). :func:`keep_freed_memory` sets both
thresholds once to values within the range glibc's own adjustment reaches (a 16 MB mmap
threshold, its maximum being 32 MB; a 32 MB trim threshold): arrays below 16 MB come from the heap
and freed memory up to 32 MB stays with the process for the next chunk. What an analysis computes
does not change, only where its arrays live; the process may keep up to 32 MB of freed memory.

Not done when the user set glibc's own settings (``MALLOC_MMAP_THRESHOLD_``,
``MALLOC_TRIM_THRESHOLD_``, ``GLIBC_TUNABLES``), nor where the C library has no ``mallopt`` (not
glibc), nor when ``BALPIPE_MALLOC=default``.
"""

from __future__ import annotations

import os
import sys

#: glibc's mallopt parameters (malloc.h)
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
#: arrays below this many bytes come from the heap
MMAP_THRESHOLD = 16 << 20
#: freed memory kept at the top of the heap, at most
TRIM_THRESHOLD = 32 << 20
#: the environment variables that say the user chose the allocator's settings
USER_SETTINGS = ("MALLOC_MMAP_THRESHOLD_", "MALLOC_TRIM_THRESHOLD_", "GLIBC_TUNABLES")

_state: dict[str, bool] = {}


def keep_freed_memory() -> bool:
    """Set glibc's mmap and trim thresholds (:data:`MMAP_THRESHOLD`, :data:`TRIM_THRESHOLD`) for
    the rest of the process, once; True when they are set (now or before), False when left as
    they are (not Linux, no ``mallopt``, the user's own settings, ``BALPIPE_MALLOC=default``)."""
    if "set" not in _state:
        _state["set"] = _set()
    return _state["set"]


def _set() -> bool:
    if not sys.platform.startswith("linux") or os.environ.get("BALPIPE_MALLOC") == "default":
        return False
    if any(name in os.environ for name in USER_SETTINGS):
        return False
    try:
        import ctypes  # numpy has loaded it already

        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes, mallopt.restype = (ctypes.c_int, ctypes.c_int), ctypes.c_int
    return bool(mallopt(M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1 and mallopt(M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1)
