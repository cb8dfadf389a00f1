"""balpipe: declarative dynamic balancing of planar mechanisms."""

import os as _os

# One BLAS thread unless the user sets otherwise (before numpy loads it): balpipe's linear algebra
# is many small matrices (the regressor's sampler takes a batched SVD of 300 72 x 75 Jacobians),
# where OpenBLAS's threads cost far more than they give: 0.4 s of CPU on one thread, 12.7 s and
# 56 s of wall time on a loaded 2-core machine with its default threads (benchmarks/README.md).
for _var in ("OPENBLAS_NUM_THREADS", "OMP_NUM_THREADS", "MKL_NUM_THREADS"):
    _os.environ.setdefault(_var, "1")

__version__ = "0.1.0"

#: the entry-point group of mechanism families (:mod:`balpipe.plugins`)
FAMILY_GROUP = "balpipe.families"

#: the largest sweep balpipe runs unless told otherwise: the spec's ``sweep.max_designs``
#: (:mod:`balpipe.sweep_spec`) and ``balpipe sweep --max-designs``, here so that ``balpipe --help``
#: states it without loading pydantic or numpy
MAX_DESIGNS = 100_000
