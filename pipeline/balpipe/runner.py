"""The one path from a loaded spec to its results: study (balancing and analysis), checks,
simulation. ``check``, ``build``, ``diff``, ``history`` and the Python API (:mod:`balpipe.api`) all
go through it, so a spec that one of them rejects is rejected by the others with the same located
errors. Each call runs on one BLAS thread whatever the import order
(:func:`balpipe.runtime.threads.blas_threads`)."""

from __future__ import annotations

from contextlib import contextmanager

from . import study as study_mod
from .balancing.context import Memo, compute
from .limits import check_finite, check_simulation
from .loader import LoadedSpec, SpecError, SpecErrors
from .runtime.threads import blas_threads
from .spec_parts import SpecFieldError


def analyse(loaded: LoadedSpec, simulate: bool = True, page: bool = True, memo: Memo = compute):
    """Balance and analyse one loaded spec (no simulation, nothing written): the study, or
    :class:`SpecErrors` for every problem of the spec, located. The results must be finite and,
    with ``simulate``, within the simulation's limits. Without ``page`` (``balpipe check``), what
    only the page shows is left out: the same errors, less work. ``memo``: what the balancing's
    searches go through (the build's cache)."""
    try:
        with _quiet_numpy(), blas_threads():
            st = study_mod.run(loaded.spec, page, memo)
            check_finite(st)
            if simulate:
                check_simulation(st)
        return st
    except SpecFieldError as exc:
        raise loaded.error(exc) from None
    except ArithmeticError as exc:  # overflow, division by zero from extreme input
        raise SpecErrors([SpecError(str(loaded.path), None, None, "",
                                    f"the computation failed on this spec's numbers ({type(exc).__name__}: {exc}); "
                                    "check the magnitudes of masses, lengths and the duration")]) from None


def simulate(loaded: LoadedSpec, st, workers: int = 1) -> bool:
    """The pymunk validation of every stage of ``st`` when the spec enables it; True when it ran.
    ``workers`` > 1: the stages' simulations in that many processes (the same results)."""
    if not loaded.spec.validation.enabled:
        return False
    from .validation_stage import simulate_study  # pymunk only when a simulation runs

    try:
        with blas_threads():
            simulate_study(st, workers=workers)
    except SpecFieldError as exc:
        raise loaded.error(exc) from None
    return True


def run(loaded: LoadedSpec, simulate_it: bool = True):
    """:func:`analyse`, then :func:`simulate` when ``simulate_it``: the study with its validation."""
    st = analyse(loaded, simulate=simulate_it)
    if simulate_it:
        simulate(loaded, st)
    return st


@contextmanager
def _quiet_numpy():
    import numpy as np

    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        yield
