"""The optional ``sweep:`` block of a spec: what ``balpipe sweep SPEC`` varies when no ``--vary``
is given. ``balpipe build`` ignores the block; the sweep's own command-line
flags override it (``--vary`` replaces the whole ``vary`` mapping).

.. code-block:: yaml

    sweep:
      vary:                                   # dotted field path: range, as --vary PATH=RANGE
        mechanism.crank.mass: 0.5 kg:2 kg:7   # LO:HI:N, a grid of N values
        mechanism.slider.mass: [0.2 kg, 0.7 kg]   # listed values (or the string "0.2,0.7")
      sample: grid                            # grid | random | lhs (LO:HI bounds)
      designs: 50                             # random and lhs: number of designs
      seed: 0
      max_designs: 1000                       # refuse larger sweeps
      stage: counterweights                   # the stage whose loads are reported

Every range is checked here for its syntax (a located spec error); that each path names a
numeric field and that the values have units of its kind is checked by :func:`balpipe.sweep.plan`
against the spec itself, before any work, with the same location.
"""

from __future__ import annotations

import math
from typing import Annotated, Any, Literal

from pydantic import AfterValidator, BeforeValidator, Field, WithJsonSchema, model_validator

from .spec_parts import Strict
from . import MAX_DESIGNS
from .units import count
from .vary import SweepError, parse_vary


def _range_text(value: Any) -> str:
    """A range as the command line writes it: a string as is, a list as ``a,b,c``. A bare
    number is refused: YAML reads ``1:2:3`` as the sexagesimal integer 3723."""
    if isinstance(value, str):
        return value
    if isinstance(value, list):
        if not value:
            raise ValueError("expected at least one value")
        parts = []
        for x in value:
            if isinstance(x, bool) or not isinstance(x, (int, float, str)):
                raise ValueError(f"expected numbers or numbers with a unit in the list, got {x!r}")
            if isinstance(x, float) and not math.isfinite(x):
                raise ValueError(f"expected finite numbers in the list, got {x!r}")
            if isinstance(x, str) and "," in x:
                raise ValueError(f"one value per list item, got {x!r}")
            parts.append(repr(x) if isinstance(x, float) else str(x))
        return ",".join(parts)
    raise ValueError(
        f"expected a range string 'LO:HI:N', 'LO:HI' or 'a,b,c' (quoted: YAML reads 1:2:3 as a number) or a list "
        f"of values, got {value!r}"
    )


def _range_syntax(text: str) -> str:
    try:
        parse_vary("x=" + text, origin="", syntax_only=True)
    except SweepError as exc:
        raise ValueError(str(exc).removeprefix(": ").removeprefix("x=" + text + ": ")) from None
    return text


VaryRange = Annotated[
    str, BeforeValidator(_range_text), AfterValidator(_range_syntax),
    WithJsonSchema({"anyOf": [{"type": "string", "description": "LO:HI:N, LO:HI or a,b,c, units as in the field"},
                              {"type": "array", "items": {"type": ["number", "string"]}, "minItems": 1}]}),
]


class SweepSpec(Strict):
    """A design sweep of this spec, run by ``balpipe sweep SPEC`` (ignored by ``balpipe build``)."""

    vary: dict[str, VaryRange] = Field(
        min_length=1,
        description="field path (dotted, e.g. mechanism.crank.mass) -> range: 'LO:HI:N' (grid), a list of values, "
        "or 'LO:HI' (bounds for random and lhs); units as in the field",
    )
    sample: Literal["grid", "random", "lhs"] = Field("grid", description="design of experiments")
    designs: count(ge=0, le=10_000_000) = Field(0, description="number of designs for random and lhs")
    seed: count(ge=0) = Field(0, description="seed of random and lhs")
    max_designs: count(ge=1) = Field(MAX_DESIGNS, description="refuse sweeps with more designs")
    stage: str | None = Field(None, min_length=1, description="the stage whose loads are reported (default: the method's last)")

    @model_validator(mode="after")
    def _designs_for_samples(self) -> "SweepSpec":
        if self.sample != "grid" and self.designs < 1:
            raise ValueError(f"sample: {self.sample} needs designs: N (at least 1)")
        return self
