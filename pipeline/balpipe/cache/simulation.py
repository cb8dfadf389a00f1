"""The pymunk simulations cached by content: a stage whose model, motion,
reference loads and validation settings did not change is not simulated again, in this spec or
in another one of the same output folder (paper 000's idler-loop stages appear in three specs).

A simulation is a deterministic function of its inputs (the model with its drivers' laws, the
analysis it is measured against, the settings, the reference loads), balpipe's code and pymunk's
version (and numpy's): :func:`run` keys it by all of them (:func:`balpipe.cache.content.key`) and keeps its
result (the run's dataclass, pickled) in ``<out>/.cache/sims/<slug>/<sha256>.pickle``. A key is
looked up in the spec's own folder, then in the other specs' folders (copied into its own when
found there: :class:`balpipe.cache.content.Store`). While one process computes a
key, another that needs the same key waits for it (a lock file per key, ``.locks/``, removed after),
so that a cold build of several specs runs a shared simulation once. What :func:`run` cannot
key (a lambda in a model) is simulated, never cached.

The results served are byte for byte what the simulation returned (``timing``, the run time of
that simulation, included). ``balpipe build --force`` simulates everything again; ``--no-sim``
leaves the cache alone; ``--scheduler`` does not use it. The entries are pickles: like the whole
output folder, they are read only by the user who builds there (a symlink is never followed, a
damaged entry is computed again).
"""

from __future__ import annotations

from typing import Any, Callable, ClassVar

from . import content as content_cache

SIMS = "sims"


class Store(content_cache.PickleStore):
    """The simulation cache of one spec (:class:`balpipe.cache.content.PickleStore`, entries
    ``.pickle``, locks in ``sims/.locks/``); ``computed``: the simulations run, for tests and the
    benchmark."""

    KIND: ClassVar[str] = SIMS
    HEADER: ClassVar[bytes] = b"balpipe-sim-1 "


#: the libraries whose versions are part of every key (they produce the numbers)
LIBRARIES = ("pymunk", "numpy")


def environment() -> str:
    """What a simulation depends on besides balpipe's code and its inputs: the installed versions
    of :data:`LIBRARIES`."""
    return content_cache.library_versions(LIBRARIES)


#: the store of :func:`using`: a module global, so that forked simulation workers inherit it
ACTIVE = content_cache.Active(environment)
using = ACTIVE.using  # run the simulations of the block through a store (None: run them all, no cache)
used = ACTIVE.used  # the keys asked for in this process (a forked worker's: :func:`mark_used` in the parent)
mark_used = ACTIVE.mark_used


def run(fn: Callable[..., Any], *args: Any, **kwargs: Any) -> Any:
    """``fn(*args, **kwargs)``, a simulation, from the active store when it holds it, else run
    and stored. Without a store, or for inputs that cannot be keyed: run."""
    return ACTIVE.run(fn, args, kwargs)
