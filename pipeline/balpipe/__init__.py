"""balpipe: declarative dynamic balancing of planar mechanisms.

The Python API (docs/api.md)::

    import balpipe
    study = balpipe.run(balpipe.load("specs/offset_slider_crank.yaml"))
    study.results()          # the dict written as results.json
    study.timeseries()       # the columns of timeseries.csv
    study.write("out/osc")   # the page

The API's names (:data:`__all__`) are loaded on first use (the module ``__getattr__`` below), so
``import balpipe`` loads neither numpy nor pydantic and ``balpipe --help`` stays fast.
"""

import os as _os

# One BLAS thread unless the user sets otherwise (before numpy loads it): balpipe's linear algebra
# is many small matrices (the regressor's sampler takes a batched SVD of 300 72 x 75 Jacobians),
# where OpenBLAS's threads cost far more than they give: 0.4 s of CPU on one thread, 12.7 s and
# 56 s of wall time on a loaded 2-core machine with its default threads (benchmarks/README.md).
# A BLAS library loaded before balpipe (numpy imported first) never reads these: the engine's
# calls limit its threads where they run (balpipe.runtime.threads).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

__version__ = "0.1.0"

#: the entry-point group of mechanism families (:mod:`balpipe.plugins`)
FAMILY_GROUP = "balpipe.families"

#: the largest sweep balpipe runs unless told otherwise: the spec's ``sweep.max_designs``
#: (:mod:`balpipe.sweep_spec`) and ``balpipe sweep --max-designs``, here so that ``balpipe --help``
#: states it without loading pydantic or numpy
MAX_DESIGNS = 100_000

#: the stable API (docs/api.md): :mod:`balpipe.api`'s names, loaded on first use
__all__ = ["Spec", "SpecError", "Stage", "Study", "load", "loads", "run", "__version__"]


def __getattr__(name: str):
    """``balpipe.load`` and the other names of :data:`__all__`, from :mod:`balpipe.api` on first
    use (the API sits above the build in balpipe's layers; importing it loads numpy and pydantic)."""
    if name in __all__:
        from . import api

        value = getattr(api, name)
        globals()[name] = value
        return value
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
