"""What the tests of the caches by content share (``balpipe.cache.simulation``, ``balpipe.cache.balance``):
damaged entries, and two processes that need one entry at the same time."""

from __future__ import annotations

import multiprocessing
import time
from pathlib import Path
from types import ModuleType

from balpipe.cache import content as content_cache

DAMAGES = ("truncated", "flipped", "no header")


def entry_damaged(good: bytes, damage: str) -> bytes:
    """The entry ``good`` cut in half, with its last byte flipped, or without its header line."""
    head, body = good.split(b"\n", 1)
    return {"truncated": good[: len(good) // 2], "flipped": head + b"\n" + body[:-1] + bytes([body[-1] ^ 1]),
            "no header": body}[damage]


def _slow_square(x: float, log: str) -> float:
    with open(log, "a") as f:
        f.write("ran\n")
    time.sleep(1.0)
    return x * x


def through(cache: ModuleType, store, fn, *args):
    """``fn(*args)`` computed through ``store`` of ``cache``: a memo over it (the balancing's
    searches, :class:`balpipe.cache.balance.Memo`) or the store made active (the simulations')."""
    if hasattr(cache, "Memo"):
        return cache.Memo(store)(fn, *args)
    with cache.using(store):
        return cache.run(fn, *args)


def _in_child(cache: ModuleType, out: str, log: str, q) -> None:
    q.put(through(cache, cache.Store(Path(out), "spec", "salt"), _slow_square, 3.0, log))


def computed_once_by_two_processes(cache: ModuleType, out: Path, log: Path) -> None:
    """Two forked processes ask ``cache`` (a module with ``Store`` and ``Memo``, or ``using`` and ``run``) for one
    slow result at once: both get it, it is computed once (the second waits for the first's entry)."""
    out.mkdir()  # the output folder, as a build has it
    ctx = multiprocessing.get_context("fork")
    q = ctx.Queue()
    procs = [ctx.Process(target=_in_child, args=(cache, str(out), str(log), q)) for _ in range(2)]
    for p in procs:
        p.start()
    for p in procs:
        p.join(30)
    assert [q.get(timeout=5), q.get(timeout=5)] == [9.0, 9.0]
    assert log.read_text() == "ran\n"
    assert (out / content_cache.CACHE_DIR / cache.Store.KIND / content_cache.LOCKS).is_dir()


def record_puts(monkeypatch, store: type) -> list[str]:
    """The keys whose results ``store`` (a :class:`balpipe.cache.content.Store` class) computes
    and stores in this process from now on (what it did not serve from its entries)."""
    keys: list[str] = []
    real = store.put

    def put(self, k, value):
        keys.append(k)
        return real(self, k, value)

    monkeypatch.setattr(store, "put", put)
    return keys


def write_spec(folder: Path, text: str, name: str) -> Path:
    folder.mkdir(exist_ok=True)
    (folder / f"{name}.yaml").write_text(text)
    return folder


def build_ok(specs: Path, out: Path, simulate: bool, **kw) -> list:
    """``balpipe build specs -o out`` in this process (``kw``: more :class:`balpipe.build.Options`),
    every spec ok."""
    from balpipe.build import Options, build

    outcomes = build([str(specs)], Options(out, simulate=simulate, **kw), jobs=1)
    assert all(o.status == "ok" for o in outcomes), [o.message for o in outcomes]
    return outcomes


def entries(out: Path, kind: str, slug: str) -> dict[str, bytes]:
    """The entries of the ``kind`` cache of spec ``slug``: name -> bytes."""
    folder = out / content_cache.CACHE_DIR / kind / slug
    return {p.name: p.read_bytes() for p in sorted(folder.iterdir())} if folder.is_dir() else {}


def page(out: Path, slug: str) -> tuple[bytes, bytes]:
    """What the caches feed: the spec's page and results.json."""
    return (out / slug / "index.html").read_bytes(), (out / slug / "results.json").read_bytes()
