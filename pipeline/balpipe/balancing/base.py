"""What every balancing method returns: computed parameters and the stages to analyse."""

from __future__ import annotations

from dataclasses import dataclass, field

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


@dataclass(frozen=True)
class BalanceResult:
    parameters: list[Parameter]
    stages: list[Stage]
    notes: list[str] = field(default_factory=list)
    details: dict = field(default_factory=dict)  # method-specific blocks for results.json (e.g. force_balance)
