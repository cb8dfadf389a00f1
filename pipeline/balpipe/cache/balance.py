"""The balancing's numerical searches cached by content: a spec rebuilt after
a change that no search reads (a comment, the description, another design) does not search again.

What is cached is a pure function of plain data, called through :func:`run`, never a whole
balancing result (its stages hold models whose motion laws are closures): a partial balancing's
Pareto fronts (:func:`balpipe.balancing.partial.fronts.fronts`, from the load maps, the budget and
the fronts' settings: about 90 % of its time), and the 4-RRR's searches (the counter-masses of a
drawn topology, :func:`balpipe.families.rrr4.topologies.solve_counter_masses`; the condition
finder's check, :func:`balpipe.families.rrr4.finder.check`; a design's peak shaking force,
:func:`balpipe.families.rrr4.counter_masses.peak_inertial_force`), and paper 003's phi
optimisation (:func:`balpipe.families.serial_arm.com_planning.phi_search`). The key
(:func:`balpipe.cache.content.key`) is the function's name and arguments, balpipe's code hash
and the versions of the libraries that compute the numbers (numpy, scipy, Clarabel); the
result is kept as a pickle in ``<out>/.cache/balance/<slug>/<sha256>.pickle``, looked up in the
spec's folder, then in the other specs' of the same output folder, with the checksum, atomic
writes, refusal of symlinks, pruning and per-key locks of :class:`balpipe.cache.content.PickleStore`.

A served result is the object that was computed, unpickled: the same bits. ``balpipe build``
uses the cache (with ``--no-sim`` too: the balancing is the same); ``--force`` computes every
search again and rewrites its entry; ``--scheduler``, ``balpipe check``, ``sweep`` and ``diff``
do not use it. The store is no ambient global: the build hands a :class:`Memo` over it to the
study, which gives it to the balancing in its context (:class:`balpipe.balancing.context.BalanceContext`);
a method computes its searches as ``ctx.memo(fn, *args)``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, ClassVar

from . import content as content_cache

BALANCE = "balance"
#: the libraries whose versions are part of every key (they produce the numbers)
LIBRARIES = ("numpy", "scipy", "clarabel")


class Store(content_cache.PickleStore):
    """The balancing cache of one spec (:class:`balpipe.cache.content.PickleStore`, entries
    ``.pickle``, locks in ``balance/.locks/``); ``computed``: the searches run."""

    KIND: ClassVar[str] = BALANCE
    HEADER: ClassVar[bytes] = b"balpipe-balance-1 "


def environment() -> str:
    """The installed versions of :data:`LIBRARIES` (from their metadata: Clarabel is not imported
    for a spec that does not solve a cone programme)."""
    return content_cache.library_versions(LIBRARIES)


@dataclass(frozen=True)
class Memo:
    """``memo(fn, *args, **kwargs)``: ``fn(*args, **kwargs)``, a balancing search, from ``store``
    when it holds it, else computed and stored (:func:`balpipe.cache.content.run_through`, with
    :func:`environment` in the key). Without a store, or for inputs that cannot be keyed:
    computed."""

    store: Store | None = None

    def __call__(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Any:
        return content_cache.run_through(self.store, environment, fn, args, kwargs)
