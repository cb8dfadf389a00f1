"""What every balancing method receives: one :class:`BalanceContext`, the same for the generic
methods and for every family's, so that a method is ``balance(ctx) -> BalanceResult`` and the
registry calls them all alike.

The context holds the spec and its two sections a method reads (the mechanism's and its own),
the unbalanced model, the time grid, the gravity vector and the moment point of the analysis,
whether the page's outputs are wanted, the mechanism on another motion section (for a method
that balances over several motions), and the memo through which the method's costly searches go
(:class:`Memo`: the build's content cache, or none). Nothing a method needs is ambient: a method
called twice with equal contexts computes the same result.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Protocol

import numpy as np

from ..model import Model


class Memo(Protocol):
    """``memo(fn, *args, **kwargs)`` is ``fn(*args, **kwargs)``, possibly served from a cache of
    earlier results for equal arguments (:class:`balpipe.cache.balance.Memo`); ``fn`` must be a
    pure function of plain data."""

    def __call__(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Any: ...


def compute(fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Any:
    """The memo without a cache: ``fn(*args, **kwargs)``, computed every time."""
    return fn(*args, **kwargs)


#: ``models(motion, samples, path) -> (unbalanced model, time grid)`` of the spec's mechanism
#: driven by another ``motion`` section (errors located at ``path``): :func:`balpipe.registry.motion_model`
OtherMotions = Callable[[Any, "int | None", tuple], "tuple[Model, np.ndarray]"]


@dataclass(frozen=True)
class BalanceContext:
    """The inputs of one balancing (see the module's docstring).

    ``spec``: the whole spec (motion, analysis settings, references; None for a model balanced
    outside a spec); ``mechanism``/``balancing``: its mechanism section and the method's section
    (the main design's, or a ``compare`` design's); ``model``: the unbalanced model; ``t``: the
    time grid (s); ``gravity``: (0, -g) or (0, 0) (m/s^2); ``moment_point``: the point of the
    shaking moment (m); ``page``: False in ``balpipe check`` of a spec without references, where a
    method may leave out what only the page shows (never a stage, never an error); ``models``:
    the mechanism on another motion (:data:`OtherMotions`), None when the caller has no spec;
    ``memo``: what the method's searches are computed through (:class:`Memo`)."""

    balancing: Any
    model: Model
    t: np.ndarray
    spec: Any = None
    mechanism: Any = None
    gravity: tuple[float, float] = (0.0, 0.0)
    moment_point: tuple[float, float] = (0.0, 0.0)
    page: bool = True
    models: OtherMotions | None = None
    memo: Memo = compute
