"""The largest sweep balpipe runs unless told otherwise: one number for the spec's
``sweep.max_designs`` (:mod:`balpipe.sweep_spec`) and ``balpipe sweep --max-designs``, in a module
that imports nothing, so that ``balpipe --help`` states it without loading pydantic or numpy."""

MAX_DESIGNS = 100_000
