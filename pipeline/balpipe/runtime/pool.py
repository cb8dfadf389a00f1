"""Processes for the commands that run specs in parallel (``build``, ``check``): how many cores
this process may use, the default number of processes, and :func:`in_order`, which runs a
function over items in a process pool and hands back the results in the items' order (so the
output does not depend on the number of processes)."""

from __future__ import annotations

import os
import signal
from contextlib import contextmanager
from typing import Any, Callable, Generator, Iterator


def worker_init() -> None:
    """Workers leave Ctrl-C to the main process (no traceback from each worker); SIGTERM ends
    them silently (its default action). A worker forked while Ctrl-C was held
    (:func:`sigint_held`) lets it through again once it ignores it."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    if hasattr(signal, "pthread_sigmask"):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})


@contextmanager
def sigint_held() -> Iterator[None]:
    """Ctrl-C held back while workers are forked, delivered when the block ends: a worker is
    never interrupted before :func:`worker_init` tells it to ignore Ctrl-C, and the main process
    still gets a Ctrl-C pressed meanwhile (ignoring it instead, as the pools once did, lost it)."""
    if not hasattr(signal, "pthread_sigmask"):  # pragma: no cover - Windows
        previous = signal.signal(signal.SIGINT, signal.SIG_IGN)
        try:
            yield
        finally:
            signal.signal(signal.SIGINT, previous)
        return
    mask = signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
    try:
        yield
    finally:
        signal.pthread_sigmask(signal.SIG_SETMASK, mask)


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
             cost: Callable[[Any], float] | None = None) -> Generator[Any, None, None]:
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
    start = sorted(range(len(items)), key=lambda i: -cost(items[i])) if cost is not None else range(len(items))
    with _pool(min(jobs, len(items)), _context()) as pool:
        with sigint_held():  # the workers are forked here; a Ctrl-C meanwhile arrives as it ends
            submitted = {i: pool.submit(fn, items[i], *args) for i in start}
        for i in range(len(items)):
            yield submitted[i].result()


@contextmanager
def finished(results: Generator[Any, None, None]) -> Iterator[Generator[Any, None, None]]:
    """Use the generator ``results`` (:func:`in_order`'s) in the block, then run it to its end
    here, where its pool shuts down, and close it in any case. A caller that takes exactly as
    many results as items leaves the generator suspended after its last ``yield``: its pool would
    then shut down when the garbage collector closes it, where a Ctrl-C is printed as "Exception
    ignored" and lost (the command exits 0). Here it propagates like any other."""
    try:
        yield results
        if iter(results) is results:  # an iterator (a list, as a test's stand-in pool gives, has nothing to run)
            for _ in results:
                pass
    finally:
        close = getattr(results, "close", None)
        if close is not None:
            close()


@contextmanager
def _pool(workers: int, context: Any) -> Iterator[Any]:
    """A process pool of ``workers`` started by ``context``, its workers set up by
    :func:`worker_init` (submit inside :func:`sigint_held`: they are forked then); on any
    exception in the block (Ctrl-C included) they are stopped at once (:func:`stop_now`), else
    shut down once their work is done. multiprocessing is imported only when there is a pool."""
    from concurrent.futures import ProcessPoolExecutor

    pool = ProcessPoolExecutor(max_workers=workers, mp_context=context, initializer=worker_init)
    try:
        yield pool
    except BaseException:
        stop_now(pool)
        raise
    pool.shutdown()


def _context() -> Any:
    """The pools' start method: fork on Linux, where the workers inherit the modules and schemas
    already loaded (Python 3.14 makes forkserver the default there, which would load them again
    in every worker); the platform's default elsewhere (macOS and Windows spawn)."""
    import multiprocessing
    import sys

    return multiprocessing.get_context("fork" if sys.platform == "linux" else None)


def stop_now(pool: Any) -> None:
    """Stop a process pool's workers at once (Ctrl-C, SIGTERM, a failure elsewhere), not when
    their work ends, and wait for them to be gone."""
    for proc in list(getattr(pool, "_processes", {}).values()):
        proc.terminate()
    pool.shutdown(wait=True, cancel_futures=True)


#: processes one spec's independent work may use (:func:`spare`): set by the build for the cores
#: that fewer specs than cores leave over (:func:`spare_workers`), 1 otherwise
_SPARE = 1
#: the state shared with forked workers (:func:`forked`): inherited, not pickled
_SHARED: Any = None


@contextmanager
def spare_workers(n: int) -> Iterator[None]:
    """Within this block, :func:`spare` is ``n`` (the build: a spec's share of the cores)."""
    global _SPARE
    previous, _SPARE = _SPARE, max(1, int(n))
    try:
        yield
    finally:
        _SPARE = previous


def spare() -> int:
    """How many processes one spec's independent work may use here (1: one after another)."""
    return _SPARE


def forked(tasks: list[tuple[Callable, tuple]], workers: int, shared: Any) -> list:
    """``fn(*args, shared)`` for every ``(fn, args)`` of ``tasks``, results in that order; in
    ``workers`` forked processes when more than one, from one pool (a worker that finishes its
    task takes the next), ``shared`` inherited by the fork rather than pickled (``fn``, ``args``
    and the results pickle; the parent's objects frozen out of the garbage collector meanwhile,
    so that a child's collection copies none of their pages: 0.2 s of CPU per child on a
    partial balancing's process). Serves a partial balancing's fronts and a spec's simulations
    (:func:`balpipe.validation_stage._parallel`). Deterministic tasks give the same results whatever
    ``workers``. On any exception (Ctrl-C included) the workers are stopped at once, not when
    their task ends."""
    if workers <= 1 or len(tasks) <= 1:
        return [fn(*a, shared) for fn, a in tasks]
    import gc
    import multiprocessing

    global _SHARED
    _SHARED = shared
    gc.freeze()  # the parent's objects out of the children's collections: no copy of their pages
    try:
        with _pool(min(workers, len(tasks)), multiprocessing.get_context("fork")) as pool:
            with sigint_held():  # the workers are forked here
                futures = [pool.submit(_call_shared, fn, a) for fn, a in tasks]
            return [f.result() for f in futures]
    finally:
        _SHARED = None
        gc.unfreeze()


def _call_shared(fn: Callable, args: tuple) -> Any:
    return fn(*args, _SHARED)
