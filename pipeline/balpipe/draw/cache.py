"""Figures cached by content (issue 23, "Fast": a changed spec whose figures did not change
redraws none of them).

A figure is drawn by a module-level function of plain data (numbers, strings, numpy arrays,
lists, tuples, dicts, dataclasses such as :class:`balpipe.model.Body`), called through
:func:`svg`. When a :class:`Store` is active (:func:`using`, set by ``balpipe build`` for one
spec), the SVG is looked up under the SHA-256 of everything that determines it: the function's
module and name, its arguments serialised deterministically (:func:`key`), the store's salt
(balpipe's code hash), matplotlib's version and its rcParams. The function receives exactly the
arguments that were hashed, so an entry can only be served for the inputs it was drawn from.

Entries live in ``<out>/.cache/figures/<slug>/<sha256>.svg``, each a header line with the
SHA-256 of the SVG that follows (a truncated or damaged entry is redrawn, never served),
written atomically (:func:`balpipe.fsutil.write_file_atomic`); a symlink anywhere on the way
(the cache folders or the entry) is never followed: the figure is drawn and nothing is read or
written there. After a spec's page is built, :meth:`Store.prune` removes the entries of that
spec that its build did not use. Without an active store (``--scheduler``, ``balpipe diff``, a
test) :func:`svg` just draws.
"""

from __future__ import annotations

import dataclasses
import enum
import hashlib
import os
import re
import struct
from contextlib import contextmanager
from contextvars import ContextVar
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, Iterator

import numpy as np

from ..fsutil import TMP_MARK, remove_path, write_file_atomic

#: the cache's folder in the output folder; never part of the published site
CACHE_DIR = ".cache"
FIGURES = "figures"
_HEADER = "balpipe-figure-1 "
_ENTRY = re.compile(r"[0-9a-f]{64}\.svg")
_ACTIVE: ContextVar["Store | None"] = ContextVar("balpipe_figure_store", default=None)


class Unhashable(TypeError):
    """A figure's argument that :func:`key` cannot serialise deterministically (a function, an
    arbitrary object): pass the plain data the figure is drawn from instead."""


def _feed(h, x: Any) -> None:
    """Feed ``x`` into the hash ``h``, every value tagged with its type so that no two different
    inputs give the same bytes (1 and 1.0 and '1' and [1] differ; dicts in their order, which is
    the order a figure draws them in)."""
    if x is None:
        h.update(b"N")
    elif x is True or x is False:
        h.update(b"T" if x else b"F")
    elif isinstance(x, np.ndarray) or isinstance(x, np.generic):
        a = np.asarray(x)
        if a.dtype.hasobject:
            raise Unhashable(f"a numpy array of objects ({a.dtype}) cannot be hashed")
        data = np.ascontiguousarray(a).tobytes()
        h.update(b"A" + a.dtype.str.encode() + repr(a.shape).encode() + struct.pack("<Q", len(data)))
        h.update(data)
    elif isinstance(x, enum.Enum):
        h.update(b"E" + type(x).__qualname__.encode() + b"." + x.name.encode() + b"\0")
    elif isinstance(x, int):
        h.update(b"I" + str(int(x)).encode() + b"\0")
    elif isinstance(x, float):
        h.update(b"R" + float(x).hex().encode() + b"\0")
    elif isinstance(x, str):
        b = x.encode("utf-8", "surrogatepass")
        h.update(b"S" + struct.pack("<Q", len(b)) + b)
    elif isinstance(x, bytes):
        h.update(b"B" + struct.pack("<Q", len(x)) + x)
    elif isinstance(x, (list, tuple)):
        h.update((b"L" if isinstance(x, list) else b"U") + struct.pack("<Q", len(x)))
        for v in x:
            _feed(h, v)
    elif isinstance(x, dict):
        h.update(b"M" + struct.pack("<Q", len(x)))
        for k, v in x.items():
            _feed(h, k)
            _feed(h, v)
    elif isinstance(x, (set, frozenset)):
        parts = sorted(hashlib.sha256(_digest_of(v)).digest() for v in x)
        h.update(b"Z" + struct.pack("<Q", len(parts)) + b"".join(parts))
    elif dataclasses.is_dataclass(x) and not isinstance(x, type):
        cls = type(x)
        h.update(b"C" + f"{cls.__module__}.{cls.__qualname__}".encode() + b"\0")
        fields = dataclasses.fields(x)
        h.update(struct.pack("<Q", len(fields)))
        for f in fields:
            h.update(f.name.encode() + b"=")
            _feed(h, getattr(x, f.name))
    else:
        raise Unhashable(f"a figure's input of type {type(x).__qualname__} cannot be hashed; pass plain data")


def _digest_of(x: Any) -> bytes:
    h = hashlib.sha256()
    _feed(h, x)
    return h.digest()


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
    """The SHA-256 (hex) of a figure: ``fn``'s module and name, ``args`` and ``kwargs``
    (:func:`_feed`), ``salt`` and the :func:`environment`. ``fn`` must be a module-level
    function (a closure's captured data would be missing from the key): :class:`Unhashable`
    otherwise, as for an argument that is not plain data."""
    name = getattr(fn, "__qualname__", "")
    module = getattr(fn, "__module__", "") or ""
    if not name or "<" in name or not module:
        raise Unhashable(f"{fn!r}: a cached figure is drawn by a module-level function")
    h = hashlib.sha256()
    h.update(f"{module}:{name}\0{salt}\0{environment()}\0".encode())
    _feed(h, tuple(args))
    _feed(h, dict(sorted(kwargs.items())))
    return h.hexdigest()


def _pack(svg: str) -> str:
    return _HEADER + hashlib.sha256(svg.encode("utf-8")).hexdigest() + "\n" + svg


def _unpack(text: str) -> str | None:
    """The SVG of an entry whose checksum holds, else None."""
    head, sep, body = text.partition("\n")
    if not sep or not head.startswith(_HEADER):
        return None
    if hashlib.sha256(body.encode("utf-8")).hexdigest() != head[len(_HEADER):]:
        return None
    return body


@dataclasses.dataclass
class Store:
    """The figure cache of one spec: ``out`` the output folder, ``slug`` the spec's page name,
    ``salt`` balpipe's code hash; ``reuse`` False (``--force``): every figure is drawn and its
    entry rewritten. ``used``: the keys this build asked for (:meth:`prune` keeps those);
    ``hits``, ``drawn``: counts, for tests and the benchmark."""

    out: Path
    slug: str
    salt: str
    reuse: bool = True
    used: set[str] = dataclasses.field(default_factory=set)
    hits: int = 0
    drawn: int = 0

    @property
    def folder(self) -> Path:
        return self.out / CACHE_DIR / FIGURES / self.slug

    def _safe_folder(self, create: bool) -> Path | None:
        """The spec's cache folder, created when ``create``; None when it is missing or when
        anything on the way from ``out`` is a symlink or not a folder (refused, never followed)."""
        p = self.out
        for part in (CACHE_DIR, FIGURES, self.slug):
            p = p / part
            if p.is_symlink():
                return None
            if not p.exists():
                if not create:
                    return None
                try:
                    os.mkdir(p, 0o777)
                except FileExistsError:
                    pass
                except OSError:
                    return None
                if p.is_symlink():
                    return None
            if not p.is_dir():
                return None
        return p

    def get(self, k: str) -> str | None:
        """The cached SVG of key ``k``, or None (missing, damaged, or behind a symlink)."""
        folder = self._safe_folder(create=False)
        if folder is None:
            return None
        try:
            fd = os.open(folder / f"{k}.svg", os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
        except OSError:
            return None
        try:
            with os.fdopen(fd, "rb") as f:
                text = f.read().decode("utf-8")
        except (OSError, UnicodeDecodeError):
            return None
        return _unpack(text)

    def put(self, k: str, svg: str) -> None:
        """Store ``svg`` under ``k`` (atomically; a symlink at the entry is replaced, not
        followed). A cache that cannot be written is left alone: the page does not need it."""
        folder = self._safe_folder(create=True)
        if folder is None:
            return
        try:
            write_file_atomic(folder / f"{k}.svg", _pack(svg))
        except OSError:
            pass

    def prune(self) -> None:
        """Remove this spec's entries that this build did not use (and temporaries that an
        interrupted write left)."""
        folder = self._safe_folder(create=False)
        if folder is None:
            return
        keep = {f"{k}.svg" for k in self.used}
        try:
            entries = list(folder.iterdir())
        except OSError:
            return
        for e in entries:
            if e.name not in keep and (_ENTRY.fullmatch(e.name) or TMP_MARK in e.name):
                try:
                    remove_path(e)
                except OSError:
                    pass


def prune_specs(out: Path, pages: set[str]) -> None:
    """Remove the cache folders of specs that have no page folder in ``out`` any more (a spec
    deleted or renamed), keeping those of ``pages`` (this build's specs)."""
    root = out / CACHE_DIR / FIGURES
    if any(p.is_symlink() for p in (out / CACHE_DIR, root)) or not root.is_dir():
        return
    try:
        entries = list(root.iterdir())
    except OSError:
        return
    for e in entries:
        page = out / e.name
        if e.name not in pages and not (page.is_dir() and not page.is_symlink()):
            try:
                remove_path(e)
            except OSError:
                pass


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
    k = key(fn, args, kwargs, store.salt)
    store.used.add(k)
    if store.reuse:
        hit = store.get(k)
        if hit is not None:
            store.hits += 1
            return hit
    out = fn(*args, **kwargs)
    store.drawn += 1
    store.put(k, out)
    return out
