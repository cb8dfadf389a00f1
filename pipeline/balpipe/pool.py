"""Processes for the commands that run specs in parallel (``build``, ``check``): how many cores
this process may use, the default number of processes, and :func:`in_order`, which runs a
function over items in a process pool and hands back the results in the items' order (so the
output does not depend on the number of processes)."""

from __future__ import annotations

import os
import signal
from typing import Any, Callable, Iterable


def worker_init() -> None:
    """Workers leave Ctrl-C to the main process (no traceback from each worker); SIGTERM ends
    them silently (its default action)."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)


def usable_cores() -> int:
    """The cores this process may run on: ``os.process_cpu_count()`` (Python 3.13), else the
    scheduler's affinity mask, else ``os.cpu_count()``; at least 1."""
    count = getattr(os, "process_cpu_count", None)
    if count is not None:
        n = count()
    elif hasattr(os, "sched_getaffinity"):
        n = len(os.sched_getaffinity(0))
    else:  # pragma: no cover - macOS, Windows before 3.13
        n = os.cpu_count()
    return max(1, n or 1)


def default_jobs(items: int) -> int:
    """The default number of processes: one per usable core, at most one per item (spec)."""
    return max(1, min(usable_cores(), items))


def in_order(fn: Callable[..., Any], items: list, jobs: int, *args: Any,
             cost: Callable[[Any], float] | None = None) -> Iterable[Any]:
    """``fn(item, *args)`` for each item, yielded in the items' order: in ``jobs`` processes
    when ``jobs`` > 1 and there is more than one item (``fn`` and its arguments must pickle),
    else here, one after another. ``cost``: an estimate of each item's work; the pool starts the
    costliest first (longest processing time first: no core left with the one long item at the
    end), the results still come in the items' order. On any exception (KeyboardInterrupt
    included) while the results are read, the workers are stopped before it propagates."""
    if jobs <= 1 or len(items) <= 1:
        for item in items:
            yield fn(item, *args)
        return
    from concurrent.futures import ProcessPoolExecutor  # multiprocessing: only when there is a pool

    previous = signal.signal(signal.SIGINT, signal.SIG_IGN)  # forked workers start ignoring it
    pool = ProcessPoolExecutor(max_workers=min(jobs, len(items)), initializer=worker_init)
    start = sorted(range(len(items)), key=lambda i: -cost(items[i])) if cost is not None else range(len(items))
    try:
        submitted = {i: pool.submit(fn, items[i], *args) for i in start}
        futures = [submitted[i] for i in range(len(items))]
    finally:
        signal.signal(signal.SIGINT, previous)
    try:
        for f in futures:
            yield f.result()
    except BaseException:
        stop_now(pool)
        raise
    pool.shutdown()


def stop_now(pool: Any) -> None:
    """Stop a process pool's workers at once (Ctrl-C, SIGTERM, a failure elsewhere), not when
    their work ends, and wait for them to be gone."""
    for proc in list(getattr(pool, "_processes", {}).values()):
        proc.terminate()
    pool.shutdown(wait=True, cancel_futures=True)
