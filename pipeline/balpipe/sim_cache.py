"""The pymunk simulations cached by content (issue 23, "Fast"): a stage whose model, motion,
reference loads and validation settings did not change is not simulated again, in this spec or
in another one of the same output folder (paper 000's idler-loop stages appear in three specs).

A simulation is a deterministic function of its inputs (the model with its drivers' laws, the
analysis it is measured against, the settings, the reference loads), balpipe's code and pymunk's
version (and numpy's): :func:`run` keys it by all of them (:func:`balpipe.content_cache.key`) and keeps its
result (the run's dataclass, pickled) in ``<out>/.cache/sims/<slug>/<sha256>.pickle``. A key is
looked up in the spec's own folder, then in the other specs' folders (copied into its own when
found there: :class:`balpipe.content_cache.Store`). While one process computes a
key, another that needs the same key waits for it (a lock file per key prefix, ``.locks/``),
so that a cold build of several specs runs a shared simulation once. What :func:`run` cannot
key (a lambda in a model) is simulated, never cached.

The results served are byte for byte what the simulation returned (``timing``, the run time of
that simulation, included). ``balpipe build --force`` simulates everything again; ``--no-sim``
leaves the cache alone; ``--scheduler`` does not use it. The entries are pickles: like the whole
output folder, they are read only by the user who builds there (a symlink is never followed, a
damaged entry is computed again).
"""

from __future__ import annotations

import os
import pickle
from contextlib import contextmanager
from pathlib import Path
from typing import Any, Callable, ClassVar, Iterator

from . import content_cache
from .content_cache import CACHE_DIR, Unhashable

SIMS = "sims"
LOCKS = ".locks"


class Store(content_cache.Store):
    """The simulation cache of one spec (:class:`balpipe.content_cache.Store`, entries
    ``.pickle``); ``computed``: the simulations run, for tests and the benchmark."""

    KIND: ClassVar[str] = SIMS
    SUFFIX: ClassVar[str] = ".pickle"
    HEADER: ClassVar[bytes] = b"balpipe-sim-1 "

    def get(self, k: str) -> Any | None:
        """The result of key ``k`` (:meth:`balpipe.content_cache.Store.get_bytes`: this spec's
        entry or another spec's), or None."""
        data = self.get_bytes(k)
        if data is None:
            return None
        try:
            return pickle.loads(data)
        except Exception:  # an entry of an older layout: computed again
            return None

    def put(self, k: str, value: Any) -> None:
        try:
            data = pickle.dumps(value, protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:  # a result that cannot be pickled is simply not kept
            return
        self.put_bytes(k, data)

    @contextmanager
    def lock(self, k: str) -> Iterator[None]:
        """Held while key ``k`` is looked up and, if missing, computed: another process that
        needs it waits, then finds it. One lock file per first two hex digits of the key (at
        most 256 files); without a lockable folder, no lock (each process computes)."""
        import fcntl

        folder = content_cache.safe_folder(self.out, (CACHE_DIR, SIMS, LOCKS), create=True)
        fd = None
        if folder is not None:
            try:
                fd = os.open(folder / k[:2], os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:
                if fd is not None:
                    os.close(fd)
                fd = None
        try:
            yield
        finally:
            if fd is not None:
                fcntl.flock(fd, fcntl.LOCK_UN)
                os.close(fd)


#: the store of :func:`using`: a module global, so that forked simulation workers inherit it
_STORE: Store | None = None


@contextmanager
def using(store: Store | None) -> Iterator[Store | None]:
    """Run the simulations of the block through ``store`` (None: run them all, no cache)."""
    global _STORE
    previous, _STORE = _STORE, store
    try:
        yield store
    finally:
        _STORE = previous


def used() -> set[str]:
    """The keys the active store was asked for in this process (a forked worker's go back to
    the parent with its results: :func:`mark_used`)."""
    return set(_STORE.used) if _STORE is not None else set()


def mark_used(keys: set[str]) -> None:
    if _STORE is not None:
        _STORE.used |= keys


def run(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)``, a simulation, from the active store when it holds it, else run
    and stored. Without a store, or for inputs that cannot be keyed: run."""
    store = _STORE
    if store is None:
        return fn(*args, **kwargs)
    import numpy
    import pymunk

    try:
        k = content_cache.key(fn, args, kwargs, f"{store.salt}\0pymunk {pymunk.version}\0numpy {numpy.__version__}")
    except Unhashable:
        return fn(*args, **kwargs)
    with store.lock(k):
        return store.serve(k, lambda: fn(*args, **kwargs))
