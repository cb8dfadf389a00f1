"""Results cached by content in the output folder: what a build computed from
some inputs is kept under the SHA-256 of those inputs, so that a build whose inputs did not change
reads it instead of computing it again. Three caches use it: the figures (:mod:`balpipe.cache.figures`,
``<out>/.cache/figures/``), the pymunk simulations (:mod:`balpipe.cache.simulation`,
``<out>/.cache/sims/``) and the balancing's numerical searches (:mod:`balpipe.cache.balance`,
``<out>/.cache/balance/``).

Keys
    :func:`key` hashes a function's module and name, its arguments and a salt (balpipe's code
    hash, and what else the result depends on). Arguments are fed by :func:`feed`: numbers,
    strings, bytes, numpy arrays, lists, tuples, dicts (in their order), sets, enums, dataclasses
    (their fields, less those marked :data:`MEMO`), pydantic models (their JSON), and functions:
    a named function by its module and name (its code is balpipe's, which the salt covers), its
    defaults and the values its closure captured.
    Anything else (a lambda, an arbitrary object) is :class:`Unhashable`: such a result is
    computed, never cached.

Entries
    ``<out>/.cache/<kind>/<slug>/<sha256><suffix>``: a header line with the SHA-256 of the
    payload that follows (a truncated or damaged entry is computed again, never served),
    written atomically (:func:`balpipe.runtime.fsutil.write_file_atomic`); a symlink anywhere on the way
    is never followed. :meth:`Store.prune` removes the spec's entries that its build did not use;
    :func:`prune_specs` the folders of specs that have no page any more.

Results as objects
    :class:`PickleStore` keeps any picklable result (a pickle is exact: the same floats, arrays,
    dicts in their order); :class:`Active` is the store a build makes active for one kind, and
    :meth:`Active.run` computes a function's result through it, holding a lock per key (another
    process that needs the same key waits for it, then reads it).
"""

from __future__ import annotations

import contextlib
import dataclasses
import enum
import hashlib
import os
import pickle
import re
import stat
import struct
import types
from contextlib import contextmanager
from functools import lru_cache
from pathlib import Path
from typing import Any, Callable, ClassVar, Iterator

import numpy as np

from ..runtime.fsutil import TMP_MARK, remove_path, write_file_atomic

#: the caches' folder in the output folder; never part of the published site
CACHE_DIR = ".cache"
#: a dataclass field's metadata key marking a memo (``field(metadata={MEMO: True})``): what the
#: object computed and kept for itself (a law's solutions per time grid), not an input; left out
#: of keys, so that a key does not depend on what was evaluated before it was asked for
MEMO = "balpipe_memo"
#: a kind's folder of lock files (:meth:`PickleStore.lock`); :func:`prune_specs` leaves it alone
LOCKS = ".locks"


class Unhashable(TypeError):
    """An input that :func:`key` cannot serialise deterministically (a lambda, an arbitrary
    object): pass the plain data the result is computed from instead."""


def callable_name(fn: Any, closures: bool = False) -> str:
    """``module:qualname`` of a named function; a lambda (no unique name), or a function defined
    inside another when not ``closures``, is :class:`Unhashable`."""
    name = getattr(fn, "__qualname__", "") or ""
    module = getattr(fn, "__module__", "") or ""
    anonymous = "<" in name.replace("<locals>", "")  # <lambda>, <listcomp>, ...
    if not name or not module or anonymous or ("<locals>" in name and not closures):
        raise Unhashable(f"{fn!r}: only a named function can be part of a key")
    return f"{module}:{name}"


def feed(h, x: Any) -> None:
    """Feed ``x`` into the hash ``h``, every value tagged with its type so that no two different
    inputs give the same bytes (1 and 1.0 and '1' and [1] differ; dicts in their order).

    The bytes, by the first kind that ``x`` is: None ``N``; a bool ``T``/``F``; a numpy array or
    scalar ``A`` dtype shape length, then its bytes (C order); an enum ``E`` class ``.`` name; an
    int ``I`` digits; a float ``R`` hex; a str ``S`` length UTF-8; bytes ``B`` length bytes; a
    list ``L``, a tuple ``U``, length then each item; a dict ``M`` length then each key and value;
    a set ``Z`` length and its items' sorted SHA-256s; a dataclass ``C`` class, field count, then
    ``name=`` value for each field not marked :data:`MEMO`; a function ``f`` name, defaults, closure
    values; a pydantic model ``P`` class and its JSON. The kind depends on the type alone, so it is
    found once per type (:func:`_feeder`) and kept (some 110000 values a build of specs/)."""
    f = _FEEDERS.get(type(x))
    if f is None:
        f = _FEEDERS[type(x)] = _feeder(type(x))
    f(h, x)


def _feed_none(h, x: Any) -> None:
    h.update(b"N")


def _feed_bool(h, x: Any) -> None:
    h.update(b"T" if x else b"F")


def _feed_array(h, x: Any) -> None:
    a = np.asarray(x)
    if a.dtype.hasobject:
        raise Unhashable(f"a numpy array of objects ({a.dtype}) cannot be hashed")
    data = np.ascontiguousarray(a).tobytes()
    h.update(b"A" + a.dtype.str.encode() + repr(a.shape).encode() + struct.pack("<Q", len(data)))
    h.update(data)


def _feed_enum(h, x: Any) -> None:
    h.update(b"E" + type(x).__qualname__.encode() + b"." + x.name.encode() + b"\0")


def _feed_int(h, x: Any) -> None:
    h.update(b"I" + str(int(x)).encode() + b"\0")


def _feed_float(h, x: Any) -> None:
    h.update(b"R" + float(x).hex().encode() + b"\0")


def _feed_str(h, x: Any) -> None:
    b = x.encode("utf-8", "surrogatepass")
    h.update(b"S" + struct.pack("<Q", len(b)) + b)


def _feed_bytes(h, x: Any) -> None:
    h.update(b"B" + struct.pack("<Q", len(x)) + x)


def _feed_items(h, x: Any) -> None:
    h.update((b"L" if isinstance(x, list) else b"U") + struct.pack("<Q", len(x)))
    for v in x:
        feed(h, v)


def _feed_dict(h, x: Any) -> None:
    h.update(b"M" + struct.pack("<Q", len(x)))
    for k, v in x.items():
        feed(h, k)
        feed(h, v)


def _feed_set(h, x: Any) -> None:
    parts = sorted(hashlib.sha256(digest_of(v)).digest() for v in x)
    h.update(b"Z" + struct.pack("<Q", len(parts)) + b"".join(parts))


def _feed_function(h, x: Any) -> None:
    # a motion law's profile (motion.quintic) or a closure of one (its captured values)
    h.update(b"f" + callable_name(x, closures=True).encode() + b"\0")
    feed(h, x.__defaults__)
    feed(h, x.__kwdefaults__)
    feed(h, tuple(c.cell_contents for c in (x.__closure__ or ())))


def _feed_pydantic(h, x: Any) -> None:  # a pydantic model of a spec
    cls = type(x)
    h.update(b"P" + f"{cls.__module__}.{cls.__qualname__}".encode() + b"\0")
    feed(h, x.model_dump_json())


def _dataclass_feeder(cls: type) -> Callable[[Any, Any], None]:
    """The feeder of a dataclass: its class and its fields less the memos, named once."""
    names = [f.name for f in dataclasses.fields(cls) if not f.metadata.get(MEMO)]
    head = b"C" + f"{cls.__module__}.{cls.__qualname__}".encode() + b"\0" + struct.pack("<Q", len(names))
    labels = [(name, name.encode() + b"=") for name in names]

    def fields(h, x: Any) -> None:
        h.update(head)
        for name, label in labels:
            h.update(label)
            feed(h, getattr(x, name))

    return fields


def _unhashable(h, x: Any) -> None:
    raise Unhashable(f"an input of type {type(x).__qualname__} cannot be hashed; pass plain data")


def _feeder(cls: type) -> Callable[[Any, Any], None]:
    """How :func:`feed` writes a value of type ``cls``: the first kind of its list that ``cls`` is."""
    if cls is type(None):
        return _feed_none
    if cls is bool:
        return _feed_bool
    for kinds, fn in (((np.ndarray, np.generic), _feed_array), (enum.Enum, _feed_enum), (int, _feed_int),
                      (float, _feed_float), (str, _feed_str), (bytes, _feed_bytes), ((list, tuple), _feed_items),
                      (dict, _feed_dict), ((set, frozenset), _feed_set)):
        if issubclass(cls, kinds):
            return fn
    if dataclasses.is_dataclass(cls) and not issubclass(cls, type):
        return _dataclass_feeder(cls)
    if issubclass(cls, types.FunctionType):
        return _feed_function
    if hasattr(cls, "model_fields") and hasattr(cls, "model_dump_json"):
        return _feed_pydantic
    return _unhashable


_FEEDERS: dict[type, Callable[[Any, Any], None]] = {}


def digest_of(x: Any) -> bytes:
    h = hashlib.sha256()
    feed(h, x)
    return h.digest()


def key(fn: Callable[..., Any], args: tuple, kwargs: dict, salt: str) -> str:
    """The SHA-256 (hex) of ``fn(*args, **kwargs)``: ``fn``'s module and name (a module-level
    function: :class:`Unhashable` otherwise), ``args`` and ``kwargs`` (:func:`feed`) and
    ``salt``."""
    h = hashlib.sha256()
    h.update(f"{callable_name(fn)}\0{salt}\0".encode())
    feed(h, tuple(args))
    feed(h, dict(sorted(kwargs.items())))
    return h.hexdigest()


def pack(header: bytes, payload: bytes) -> bytes:
    """An entry: ``header``, the payload's SHA-256, a newline, the payload."""
    return header + hashlib.sha256(payload).hexdigest().encode() + b"\n" + payload


def unpack(header: bytes, data: bytes) -> bytes | None:
    """The payload of an entry whose header and checksum hold, else None."""
    head, sep, body = data.partition(b"\n")
    if not sep or not head.startswith(header):
        return None
    if hashlib.sha256(body).hexdigest().encode() != head[len(header):]:
        return None
    return body


def safe_folder(out: Path, parts: tuple[str, ...], create: bool) -> Path | None:
    """``out / parts...``, created when ``create``; None when it is missing or when anything on
    the way from ``out`` is a symlink or not a folder (refused, never followed)."""
    p = out
    for part in parts:
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


def read_entry(path: Path) -> bytes | None:
    """The bytes of the file ``path``, never through a symlink; None when it cannot be read."""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NOFOLLOW", 0))
    except OSError:
        return None
    return _read_all(fd)


def read_entry_in(folder: Path, name: str) -> bytes | None:
    """The bytes of the file ``name`` in ``folder``, neither of them through a symlink; None when
    it cannot be read. Where the system has no ``dir_fd`` opens, :func:`safe_folder`'s checks of
    ``folder`` and :func:`read_entry`."""
    nofollow = getattr(os, "O_NOFOLLOW", 0)
    if os.open not in os.supports_dir_fd or not nofollow or not hasattr(os, "O_DIRECTORY"):  # pragma: no cover - not Linux
        if folder.is_symlink() or not folder.is_dir():
            return None
        return read_entry(folder / name)
    try:
        dir_fd = os.open(folder, os.O_RDONLY | os.O_DIRECTORY | nofollow)
    except OSError:
        return None
    try:
        fd = os.open(name, os.O_RDONLY | nofollow, dir_fd=dir_fd)
    except OSError:
        return None
    finally:
        os.close(dir_fd)
    return _read_all(fd)


def _read_all(fd: int) -> bytes | None:
    """The bytes of the open file ``fd`` (closed after), None when it cannot be read."""
    try:
        with os.fdopen(fd, "rb") as f:
            return f.read()
    except OSError:
        return None


@dataclasses.dataclass
class Store:
    """The cache of one kind (:attr:`KIND`, a folder of ``<out>/.cache``) for one spec: ``out`` the
    output folder, ``slug`` the spec's page name, ``salt`` balpipe's code hash; ``reuse`` False
    (``--force``): everything is computed and its entry rewritten. ``used``: the keys this build
    asked for (:meth:`prune` keeps those); ``hits``: entries served; ``computed``: results
    computed (and stored). A subclass gives :meth:`get` and :meth:`put` (its values as bytes)."""

    KIND: ClassVar[str] = ""
    SUFFIX: ClassVar[str] = ""
    HEADER: ClassVar[bytes] = b""

    out: Path
    slug: str
    salt: str
    reuse: bool = True
    used: set[str] = dataclasses.field(default_factory=set)
    hits: int = 0
    computed: int = 0
    #: with ``reuse`` False: entries written at or after this time (``time.time()``, the start of a
    #: ``--force`` build) are served all the same: computed by this build (for another spec of the
    #: same output folder, or by another of its processes), not trusted from an earlier one
    fresh_since: float | None = None

    @property
    def folder(self) -> Path:
        return self.out / CACHE_DIR / self.KIND / self.slug

    def _folder(self, create: bool) -> Path | None:
        return safe_folder(self.out, (CACHE_DIR, self.KIND, self.slug), create)

    def get(self, k: str) -> Any | None:
        raise NotImplementedError

    def put(self, k: str, value: Any) -> None:
        raise NotImplementedError

    def serve(self, k: str, compute: Callable[[], Any]) -> Any:
        """The value of key ``k``: the stored one when there is one (and ``reuse``), else
        ``compute()``, stored. ``k`` is kept by :meth:`prune` either way."""
        self.used.add(k)
        if self.reuse or (self.fresh_since is not None and self._fresh(k)):
            hit = self.get(k)
            if hit is not None:
                self.hits += 1
                return hit
        out = compute()
        self.computed += 1
        self.put(k, out)
        return out

    def get_bytes(self, k: str) -> bytes | None:
        """The payload of key ``k``: from this spec's folder, else from another spec's of the
        same output folder (then copied into this one, so that the other spec's changes never
        take it away: the same stage or figure in two specs is computed once); None when no
        entry holds (missing, damaged, or behind a symlink)."""
        data = self._read(self.slug, k)
        if data is None:
            data = self._elsewhere(k)
            if data is not None:
                self.put_bytes(k, data)
        return data

    def _fresh(self, k: str) -> bool:
        """Key ``k`` has an entry (a regular file, never a symlink) written at or after
        :attr:`fresh_since`, in this spec's folder or another's; an older entry of this spec's is
        then removed, so that :meth:`get` reads the fresh one."""
        root = safe_folder(self.out, (CACHE_DIR, self.KIND), create=False)
        if root is None or self.fresh_since is None:
            return False
        try:
            slugs = [self.slug] + sorted(p.name for p in root.iterdir() if p.name != self.slug and not p.name.startswith("."))
        except OSError:
            return False
        for slug in slugs:
            try:
                st = os.lstat(root / slug / f"{k}{self.SUFFIX}")
            except OSError:
                continue
            if stat.S_ISREG(st.st_mode) and st.st_mtime >= self.fresh_since:
                if slug != self.slug:
                    try:
                        os.unlink(root / self.slug / f"{k}{self.SUFFIX}")
                    except OSError:
                        pass
                return True
        return False

    def _read(self, slug: str, k: str, root: Path | None = None) -> bytes | None:
        """The payload of key ``k`` in spec ``slug``'s folder of ``root`` (the kind's folder,
        checked by :func:`safe_folder` when not given), neither followed through a symlink."""
        root = root or safe_folder(self.out, (CACHE_DIR, self.KIND), create=False)
        data = read_entry_in(root / slug, f"{k}{self.SUFFIX}") if root is not None else None
        return unpack(self.HEADER, data) if data is not None else None

    def _elsewhere(self, k: str) -> bytes | None:
        """The payload of key ``k`` in another spec's folder (the first by name that holds it).
        The kind's folder is checked once (:func:`safe_folder`), each spec's folder as it is
        listed (a folder, not a symlink) and opened (``O_NOFOLLOW``): two system calls a folder
        instead of ten (a build of specs/ asked 5,800 folders, 60,000 ``stat`` calls, 0.2 s of CPU)."""
        root = safe_folder(self.out, (CACHE_DIR, self.KIND), create=False)
        if root is None:
            return None
        try:
            with os.scandir(root) as listing:
                slugs = sorted(e.name for e in listing if e.name != self.slug and not e.name.startswith(".")
                               and e.is_dir(follow_symlinks=False))
        except OSError:
            return None
        for slug in slugs:
            data = self._read(slug, k, root)
            if data is not None:
                return data
        return None

    def put_bytes(self, k: str, payload: bytes) -> None:
        """Store ``payload`` under ``k`` (atomically; a symlink at the entry is replaced, not
        followed). A cache that cannot be written is left alone: the page does not need it."""
        folder = self._folder(create=True)
        if folder is None:
            return
        try:
            write_file_atomic(folder / f"{k}{self.SUFFIX}", pack(self.HEADER, payload))
        except OSError:
            pass

    def prune(self) -> None:
        """Remove this spec's entries that this build did not use (and temporaries that an
        interrupted write left)."""
        folder = self._folder(create=False)
        if folder is None:
            return
        keep = {f"{k}{self.SUFFIX}" for k in self.used}
        entry = re.compile(r"[0-9a-f]{64}" + re.escape(self.SUFFIX))
        try:
            entries = list(folder.iterdir())
        except OSError:
            return
        for e in entries:
            if e.name not in keep and (entry.fullmatch(e.name) or TMP_MARK in e.name):
                try:
                    remove_path(e)
                except OSError:
                    pass


@dataclasses.dataclass
class PickleStore(Store):
    """A store whose values are Python objects, kept as pickles (``.pickle`` entries): a value
    read back is equal to the one stored, bit for bit (floats, numpy arrays, dicts in their
    order). A subclass names the :attr:`KIND` and the :attr:`HEADER`."""

    SUFFIX: ClassVar[str] = ".pickle"

    held: int = dataclasses.field(default=0, repr=False)  # locks this process holds (:meth:`lock`)

    def get(self, k: str) -> Any | None:
        """The value of key ``k`` (:meth:`Store.get_bytes`: this spec's entry or another
        spec's), or None."""
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
        except Exception:  # a value that cannot be pickled is simply not kept
            return
        self.put_bytes(k, data)

    @contextmanager
    def lock(self, k: str) -> Iterator[None]:
        """Held while key ``k`` is looked up and, if missing, computed: another process that
        needs it waits, then finds it. One lock file per key (``<kind>/.locks/<key>``), removed
        when the lock is released: a process never waits for another key (with one file per
        first two hex digits, a build of specs/ on two processes waited 0.69 s, every time, for
        a simulation of another spec whose key began the same). Removing it is safe because the
        lock only guards "compute if missing": whoever takes it after its owner, on the removed
        file or on a new one, finds the entry its owner stored. A computation that asks for
        another key while this process holds a lock takes none (two processes never wait on
        each other); without a lockable folder, no lock (each process computes)."""
        import fcntl

        folder = safe_folder(self.out, (CACHE_DIR, self.KIND, LOCKS), create=True) if not self.held else None
        fd = None
        if folder is not None:
            try:
                fd = os.open(folder / k, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
                fcntl.flock(fd, fcntl.LOCK_EX)
            except OSError:
                if fd is not None:
                    os.close(fd)
                fd = None
        self.held += 1
        try:
            yield
        finally:
            self.held -= 1
            if fd is not None and folder is not None:
                with contextlib.suppress(OSError):
                    os.unlink(folder / k)
                fcntl.flock(fd, fcntl.LOCK_UN)
                os.close(fd)


@lru_cache(maxsize=8)
def library_versions(names: tuple[str, ...]) -> str:
    """``"name version"`` of each installed distribution of ``names``, joined by NUL (``-`` for
    one not installed), read from their metadata: nothing is imported. What a cached kind's
    results depend on besides balpipe's code and a function's arguments (:class:`Active`)."""
    from importlib.metadata import PackageNotFoundError, version

    def installed(name: str) -> str:
        try:
            return version(name)
        except PackageNotFoundError:
            return "-"

    return "\0".join(f"{name} {installed(name)}" for name in names)


class Active:
    """The :class:`PickleStore` of one kind that the running build computes through (None:
    everything computed, no cache). One per kind, a module global, so that forked workers
    inherit it. ``environment()``: what the kind's results depend on besides balpipe's code and
    a function's arguments (the versions of the libraries that compute them), part of every key."""

    def __init__(self, environment: Callable[[], str]) -> None:
        self.store: PickleStore | None = None
        self.environment = environment

    @contextmanager
    def using(self, store: PickleStore | None) -> Iterator[PickleStore | None]:
        """Compute the block's results through ``store`` (None: compute them all, no cache)."""
        previous, self.store = self.store, store
        try:
            yield store
        finally:
            self.store = previous

    def used(self) -> set[str]:
        """The keys the active store was asked for in this process (a forked worker's go back to
        the parent with its results: :meth:`mark_used`)."""
        return set(self.store.used) if self.store is not None else set()

    def mark_used(self, keys: set[str]) -> None:
        if self.store is not None:
            self.store.used |= keys

    def run(self, fn: Callable[..., Any], args: tuple, kwargs: dict) -> Any:
        """``fn(*args, **kwargs)`` through the active store (:func:`run_through`)."""
        return run_through(self.store, self.environment, fn, args, kwargs)


def run_through(store: PickleStore | None, environment: Callable[[], str], fn: Callable[..., Any], args: tuple,
                kwargs: dict) -> Any:
    """``fn(*args, **kwargs)`` from ``store`` when it holds it (the object computed then,
    unpickled), else computed and stored; ``environment()`` is part of the key. Without a store,
    or for inputs that cannot be keyed (:class:`Unhashable`): computed."""
    if store is None:
        return fn(*args, **kwargs)
    try:
        k = key(fn, args, kwargs, f"{store.salt}\0{environment()}")
    except Unhashable:
        return fn(*args, **kwargs)
    with store.lock(k):
        return store.serve(k, lambda: fn(*args, **kwargs))


def prune_specs(out: Path, pages: set[str], kind: str) -> None:
    """Remove the ``kind`` cache folders of specs that have no page folder in ``out`` any more
    (a spec deleted or renamed), keeping those of ``pages`` (this build's specs)."""
    root = out / CACHE_DIR / kind
    if any(p.is_symlink() for p in (out / CACHE_DIR, root)) or not root.is_dir():
        return
    try:
        entries = list(root.iterdir())
    except OSError:
        return
    for e in entries:
        page = out / e.name
        if e.name.startswith("."):
            continue  # the cache's own files (the locks)
        if e.name not in pages and not (page.is_dir() and not page.is_symlink()):
            try:
                remove_path(e)
            except OSError:
                pass
