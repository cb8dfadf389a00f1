"""What every balancing method returns: computed parameters and the stages to analyse."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from ..model import Model


@dataclass(frozen=True)
class Parameter:
    """A computed design parameter. ``source`` names the paper equation it comes from."""

    name: str
    value: float
    unit: str
    source: str
    description: str = ""


@dataclass(frozen=True)
class Stage:
    """One balancing stage: a complete model of the mechanism in that state.

    ``balances`` says what the stage is designed to cancel ("" for none, "force",
    "force+moment"), so the report can check the claim against the analysis.
    """

    name: str
    label: str
    model: Model
    description: str = ""
    balances: str = ""
    reference: str | None = None  # the stage its ratios refer to (default: the first stage)
    group: str = ""  # stages of one motion (a spec with several motions groups them, e.g. per trajectory)
    tolerance: float | None = None  # the claims' tolerance set by the spec (default: balpipe.claim_precision)
    rounding: tuple = ()  # balpipe.claim_precision.Rounding of the numbers entered by hand


@dataclass(frozen=True)
class BalanceResult:
    parameters: list[Parameter]
    stages: list[Stage]
    notes: list[str] = field(default_factory=list)
    # optional hooks: figures(study) -> [(title, svg or html, caption)] drawn on the page;
    # derived(stage_results) -> [Parameter] computed from the analysed stages (before references)
    figures: Callable[[Any], Any] | None = None
    derived: Callable[[Any], list[Parameter]] | None = None
    details: dict = field(default_factory=dict)  # method-specific blocks for results.json (e.g. force_balance)
