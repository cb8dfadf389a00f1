"""Design sweeps over numeric spec fields: ``balpipe sweep SPEC --vary PATH=RANGE``.

A sweep varies fields of one spec (dotted paths, e.g. ``mechanism.crank.mass``), builds every
design's model and balancing, and analyses the chosen stage (default: the last stage of the
spec's method). Designs whose model has the base spec's geometry (only masses, inertias,
counterweights differ) take the fast path: one engine analysis of the base design and a matrix
product per design (:mod:`balpipe.balancing.mass_sweep`); the others a full engine analysis. Designs are
evaluated locally on a process pool, or on a dask.distributed cluster.

Ranges (units as in the spec; the first value's unit applies to a second without one):

* ``LO:HI:N``   N evenly spaced values (grid), e.g. ``mechanism.crank.mass=0.5 kg:2 kg:7``;
* ``a,b,c``     the listed values (grid);
* ``LO:HI``     bounds for ``--sample random`` or ``--sample lhs`` (``-n`` designs, ``--seed``).

Every vary is checked before any work: the path must name a field of the spec's schema, its
values must validate (unit of the right kind, bounds), and the number of designs must stay below
the limit (``--max-designs``, default :data:`MAX_DESIGNS`). A design that fails (invalid spec,
no balancing solution, cannot assemble, negative counterweight) is a row with its error.
"""

from __future__ import annotations

from ..sweep_spec import MAX_DESIGNS  # noqa: F401  (one limit for --max-designs and sweep.max_designs)
from ..vary import SweepError, Vary, get_attr_path, parse_vary, set_path, with_values  # noqa: F401  (public here too)
from .evaluate import (  # noqa: F401  (balpipe.sweep.build_design etc., as before)
    _GEOMETRIES, MAX_GEOMETRIES, _error_text, _pick_stage, _settings, _validate, build_design, canonical,
    evaluate_chunk,
)
from .output import (  # noqa: F401  (balpipe.sweep.csv_text etc., as before)
    METRICS, UNITS_OF, SweepResult, csv_text, design_spec_text, mark_pareto, pareto, write,
)
from .plan import Plan, designs_of, plan  # noqa: F401  (balpipe.sweep.plan, as before)
from .run import (  # noqa: F401  (balpipe.sweep.run etc., as before)
    MAX_CORNERS, POOL_WORTH, _chunks, _corner_anchors, _front_confirmed, progress_printer, run,
)
