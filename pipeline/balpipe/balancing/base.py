"""What every balancing method returns: computed parameters and the stages to analyse."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any, Callable

from ..mechanics.part_shapes import MadePart
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
class Goal:
    """One load a stage was optimised for (``role`` 'objective') or held to (``role`` 'cap', at
    most ``at_most`` x ``reference``): its measure's ``value`` at the stage and at the
    ``reference`` (the unbalanced mechanism), in ``unit``."""

    label: str
    role: str
    value: float
    reference: float
    unit: str = ""
    at_most: float | None = None
    load: str = ""  # shaking_force, shaking_moment, effort, joint: which of the stage's loads it is

    def to_json(self) -> dict[str, Any]:
        return {"label": self.label, "role": self.role, "load": self.load, "value": self.value, "reference": self.reference,
                "ratio": self.value / self.reference if self.reference else None, "unit": self.unit,
                "at_most": self.at_most}


@dataclass(frozen=True)
class Aim:
    """What an optimised stage aimed at: its objective's terms and its caps
    (:mod:`balpipe.report.verdict` judges the stage on them, the shaking loads it did not optimise
    being side effects), and, for a design that adds nothing, why (``nothing_added``)."""

    goals: tuple[Goal, ...]
    nothing_added: str = ""

    def to_json(self) -> dict[str, Any]:
        return {"goals": [g.to_json() for g in self.goals], "nothing_added": self.nothing_added}


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
    tolerance: float | None = None  # the claims' tolerance set by the spec (default: balpipe.mechanics.claim_precision)
    rounding: tuple = ()  # balpipe.mechanics.claim_precision.Rounding of the numbers entered by hand
    # the stage's line style on the page, draw.figures.style(k) (default: its place in its group):
    # a method whose paper states its figures' line styles gives them, so that one style means
    # one stage on the whole page, the paper's figures included
    style: int | None = None
    # the stage whose numbers the paper publishes (paper 003: case 2 against case 1, while case 3
    # follows it): the verdict's headline for its motion (default: the motion's last stage),
    # balpipe.report.verdict.headline_stage
    headline: bool = False
    # the design of ``spec.compare`` the stage belongs to (its name; its stage is then named
    # "design:stage" on the page and in results.json), None for the main design's
    design: str | None = None
    # what an optimised stage minimised and was held to (partial_balance): the verdict's measure
    aim: Aim | None = None
    # what the stage's paper claims it balances where that is more than the design as given
    # guarantees ("force+moment" for the Scott-Russell legs' counter-rotations of paper 000, whose
    # printed inertias break eq. 30e): the verdict judges it ("the paper's claim fails"), while the
    # build and the simulation check only ``balances``
    paper_claims: str = ""
    # the stage's counterweights made as parts (a spec's ``part:`` sections), sized and checked
    parts: tuple[MadePart, ...] = ()


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


def styled(results: list) -> bool:
    """Whether the method gave the main design's stages of ``results`` their line styles
    (:attr:`Stage.style`): each has one, and they are 0 .. n-1 (a partial balancing that wraps a
    paper's method, whose own stages have none, keeps the order of its stages)."""
    styles = [r.stage.style for r in results if r.stage.design is None]
    return bool(styles) and None not in styles and sorted(styles) == list(range(len(styles)))


def in_style_order(results: list) -> list:
    """Stage results (anything with a ``.stage``) in the order of their line styles on the page:
    when :func:`styled`, the main design's stages by :attr:`Stage.style`, then those of the
    compared designs (:attr:`Stage.design`) in their order; else in their order. Item k of the
    list is drawn in ``draw.figures.style(k)`` in every figure of a page, the generic ones and
    the paper's."""
    if not styled(results):
        return list(results)
    main = sorted((r for r in results if r.stage.design is None), key=lambda r: r.stage.style)
    return main + [r for r in results if r.stage.design is not None]


def style_index(results: list[Any], r: Any) -> int:
    """The line style of stage result ``r`` on the page (``draw.figures.style(k)``): its place in
    :func:`in_style_order` of the stages of its group (its motion)."""
    group = [x for x in results if x.stage.group == r.stage.group]
    return next(i for i, x in enumerate(in_style_order(group)) if x is r)
