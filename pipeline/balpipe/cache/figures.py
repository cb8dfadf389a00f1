"""Figures cached by content: a changed spec whose figures did not change redraws none of
them.

A figure is drawn by a module-level function of plain data (numbers, strings, numpy arrays,
lists, tuples, dicts, dataclasses such as :class:`balpipe.model.Body`), called through
:func:`svg`. When a :class:`Store` is active (:func:`using`, set by ``balpipe build`` for one
spec), the SVG is looked up under the SHA-256 of everything that determines it: the function's
module and name, its arguments serialised deterministically (:func:`key`), the store's salt
(balpipe's code hash), matplotlib's version and its rcParams. The function receives exactly the
arguments that were hashed, so an entry can only be served for the inputs it was drawn from.

Entries live in ``<out>/.cache/figures/<slug>/<sha256>.svg``, each a header line with the
SHA-256 of the SVG that follows (a truncated or damaged entry is redrawn, never served),
written atomically (:func:`balpipe.runtime.fsutil.write_file_atomic`); a symlink anywhere on the way
(the cache folders or the entry) is never followed: the figure is drawn and nothing is read or
written there. A key missing from the spec's folder is looked up in the other specs' folders
(two specs drawing the same figure draw it once; :class:`balpipe.cache.content.Store`).
After a spec's page is built, :meth:`Store.prune` removes the entries of that
spec that its build did not use. Without an active store (``--scheduler``, ``balpipe diff``, a
test) :func:`svg` just draws.
"""

from __future__ import annotations

import hashlib
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, ClassVar, Iterator

from . import content as content_cache
from .content import CACHE_DIR, Unhashable  # noqa: F401  (the figure cache's names)

FIGURES = "figures"
_HEADER = "balpipe-figure-1 "

_ACTIVE: ContextVar["Store | None"] = ContextVar("balpipe_figure_store", default=None)


def environment() -> str:
    """What the SVG depends on besides balpipe's code and the figure's inputs: matplotlib's
    version and its settings (rcParams as they are now: a ``matplotlibrc`` of the user's changes
    them; :mod:`balpipe.draw.figures` sets its own when imported, which its code hash covers)."""
    import matplotlib

    rc = repr(sorted((k, repr(v)) for k, v in matplotlib.rcParams.items()))
    return _digest(matplotlib.__version__, rc)


@lru_cache(maxsize=8)
def _digest(version: str, rc: str) -> str:
    return hashlib.sha256(f"{version}\0{rc}".encode()).hexdigest()


def key(fn: Callable[..., str], args: tuple, kwargs: dict, salt: str) -> str:
    """The SHA-256 (hex) of a figure (:func:`balpipe.cache.content.key`): ``fn``'s module and
    name, ``args`` and ``kwargs``, ``salt`` and the :func:`environment`. ``fn`` must be a
    module-level function: :class:`Unhashable` otherwise, as for an argument that is not plain
    data."""
    return content_cache.key(fn, args, kwargs, f"{salt}\0{environment()}")


def _pack(svg: str) -> str:
    return content_cache.pack(_HEADER.encode(), svg.encode("utf-8")).decode("utf-8")


class Store(content_cache.Store):
    """The figure cache of one spec (:class:`balpipe.cache.content.Store`, entries ``.svg``);
    ``drawn``: the figures drawn, for tests and the benchmark."""

    KIND: ClassVar[str] = FIGURES
    SUFFIX: ClassVar[str] = ".svg"
    HEADER: ClassVar[bytes] = _HEADER.encode()

    def __init__(self, out: Path, slug: str, salt: str, reuse: bool = True, used: set[str] | None = None,
                 fresh_since: float | None = None) -> None:
        super().__init__(out, slug, salt, reuse, set(used or ()), fresh_since=fresh_since)

    @property
    def drawn(self) -> int:
        return self.computed

    def get(self, k: str) -> str | None:
        """The cached SVG of key ``k``, or None (missing, damaged, or behind a symlink)."""
        data = self.get_bytes(k)
        try:
            return data.decode("utf-8") if data is not None else None
        except UnicodeDecodeError:
            return None

    def put(self, k: str, svg: str) -> None:
        self.put_bytes(k, svg.encode("utf-8"))


@contextmanager
def using(store: Store | None) -> Iterator[Store | None]:
    """Draw the figures of the block through ``store`` (None: draw them all, no cache)."""
    token = _ACTIVE.set(store)
    try:
        yield store
    finally:
        _ACTIVE.reset(token)


def active() -> Store | None:
    """The store of :func:`using`, if any."""
    return _ACTIVE.get()


def svg(fn: Callable[..., str], *args: Any, **kwargs: Any) -> str:
    """``fn(*args, **kwargs)``, the SVG of a figure, from the active store when it holds it
    (byte for byte what ``fn`` returned then), else drawn and stored. Without a store: drawn."""
    store = _ACTIVE.get()
    if store is None:
        return fn(*args, **kwargs)
    return store.serve(key(fn, args, kwargs, store.salt), lambda: fn(*args, **kwargs))
