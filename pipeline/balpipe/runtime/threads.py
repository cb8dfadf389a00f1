"""One BLAS thread around balpipe's own heavy calls, whatever was imported first.

balpipe's linear algebra is many small matrices, where OpenBLAS's threads cost far more than
they give (benchmarks/README.md). ``import balpipe`` sets ``OPENBLAS_NUM_THREADS=1`` (and the OMP
and MKL variables) when they are unset, but a BLAS library reads them once, when it is loaded:
in a notebook that imported numpy before balpipe they come too late. :func:`blas_threads` limits
the BLAS pools of every library loaded at the time of the call (numpy's, scipy's) for the
duration of a block, through threadpoolctl, so the engine runs on the same number of threads in
either import order, and the caller's own setting is restored when the block ends."""

from __future__ import annotations

import os
from contextlib import contextmanager
from typing import Iterator

#: the variables that name a BLAS thread count, in the order they are read
VARIABLES = ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS")

#: the thread count every BLAS library of this process was loaded with, when the command line
#: knows it (:func:`environment_only`); None: unknown, :func:`blas_threads` limits the libraries
_loaded_with: dict[str, int] = {}


def wanted() -> int:
    """The BLAS threads balpipe runs on: the first of :data:`VARIABLES` set to a positive whole
    number (``import balpipe`` sets them to 1 where the user did not), else 1."""
    for name in VARIABLES:
        value = os.environ.get(name, "").strip()
        if value.isdigit() and int(value) > 0:
            return int(value)
    return 1


def environment_only() -> None:
    """Called by the command line (:func:`balpipe.cli.entry`) before anything loads a BLAS
    library: every one this process (and the workers it forks) loads reads the variables that
    ``import balpipe`` set, and nothing but balpipe's code runs here to change them, so
    :func:`blas_threads` has nothing to limit while :func:`wanted` is what they were loaded with
    (the scan of the loaded libraries costs 2 ms a spec in ``balpipe check``). Not done when numpy
    is loaded already."""
    import sys

    if "numpy" not in sys.modules and "scipy" not in sys.modules:
        _loaded_with["threads"] = wanted()


@contextmanager
def blas_threads(limit: int | None = None) -> Iterator[None]:
    """Within the block, every loaded BLAS library uses at most ``limit`` threads (default
    :func:`wanted`); nested blocks cost one library scan each (about a millisecond). Nothing to
    do when every library was loaded with that many (:func:`environment_only`)."""
    threads = wanted() if limit is None else limit
    if _loaded_with.get("threads") == threads:
        yield
        return
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=threads, user_api="blas"):
        yield
