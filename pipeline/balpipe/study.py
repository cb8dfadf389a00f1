"""One spec, end to end in memory: model -> balancing stages -> analysis of every stage ->
checks and references. No files are written here (see :mod:`balpipe.build`)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields
from typing import Any

import numpy as np

from .diagnose import actuation, assembly, dead_centres, loop_closure
from .display import numbers
from .mechanics import realisable
from . import registry
from .balancing.base import BalanceResult, Stage
from .balancing.context import Memo, compute
from .mechanics.claim_precision import claim_tolerances
from .runtime.allocator import keep_freed_memory
from .engine import Analysis, AnalysisError, analyse, condition_peak
from .engine.load_reference import LoadReference, load_reference
from .mechanics.sampling import gravity_vector  # noqa: F401  (balpipe.study.gravity_vector, as before)
from .spec import Spec
from .spec_parts import SpecFieldError


@dataclass
class StageResult:
    stage: Stage
    analysis: Analysis
    added_mass: float
    added_inertia: float
    validation: Any = None  # balpipe.validate.StageValidation, when simulated
    torque: Any = None  # balpipe.validate.torque.TorqueDriven, when simulated
    _metrics: StageMetrics | None = field(default=None, repr=False)  # set once by run()

    @property
    def metrics(self) -> StageMetrics:
        """The stage's peaks, ratios, claim and costs, computed once by :func:`run`: what
        ``results.json``, the pages and ``balpipe diff`` read."""
        if self._metrics is None:
            raise RuntimeError(f"stage {self.stage.name!r}: its metrics are computed by balpipe.study.run")
        return self._metrics

    @property
    def max_effort(self) -> float:
        if not self.analysis.efforts:
            return 0.0
        return float(max(np.max(np.abs(e)) for e in self.analysis.efforts.values()))


@dataclass
class Study:
    spec: Spec
    balance: BalanceResult
    stages: list[StageResult]
    references: list[dict]
    checks: dict
    problems: list[str] = field(default_factory=list)
    reactionless: Any = None
    warnings: list[dict] = field(default_factory=list)  # dead centres and singularities (balpipe.diagnose.dead_centres)
    # checks that could not resolve their own error: nothing shown false; exit 0 unless --strict
    unconfirmed: list[str] = field(default_factory=list)

    @property
    def unbalanced(self) -> StageResult:
        return self.stages[0]

    @property
    def ok(self) -> bool:
        return not self.problems

    @property
    def reference(self) -> LoadReference:
        """The denominators of every relative figure (see :mod:`balpipe.load_reference`)."""
        return ratio_reference(self.unbalanced)

    def extra_figures(self) -> list[tuple[str, str, str]]:
        """Figures that only the mechanism's template or the method knows how to draw (title,
        svg, caption): the method's (:attr:`plugins.Method.figures`: the paper's figures of its
        method), then the template's (:attr:`plugins.Template.figures`), then those of the
        balancing result."""
        out = []
        method = registry.METHODS.get(self.spec.balancing.method)
        for hook in (method.figures if method is not None else None,
                     registry.TEMPLATES[self.spec.mechanism.template].figures):
            if hook is not None:
                out += list(hook(self))
        if self.balance.figures is not None:
            out += list(self.balance.figures(self))
        return out

    def reference_stage(self, sr: StageResult) -> StageResult:
        """The stage whose peaks ``sr``'s ratios refer to (see :func:`reference_of`)."""
        return reference_of(self.stages, sr)


def reference_of(stages: list[StageResult], sr: StageResult) -> StageResult:
    """The stage whose peaks ``sr``'s ratios refer to: ``Stage.reference`` or the first stage."""
    if sr.stage.reference is not None:
        for s in stages:
            if s.stage.name == sr.stage.reference:
                return s
    return stages[0]


NEAR_SINGULAR = 1e3  # condition number above which the page warns of lost accuracy


def run_stage_analyses(spec: Spec, result: BalanceResult) -> list[StageResult]:
    t = registry.time_grid(spec)
    base = result.stages[0].model
    out = []
    for stage in result.stages:
        try:
            an = analyse(stage.model, t, gravity_vector(spec), tuple(spec.analysis.moment_point))
        except AnalysisError as exc:
            raise loop_closure.located(base, t, exc, stage.name) from None
        out.append(
            StageResult(
                stage, an,
                added_mass=difference(stage.model.total_mass(), base.total_mass()),
                added_inertia=difference(total_inertia(stage.model), total_inertia(base)),
            )
        )
    return out


def difference(after: float, before: float) -> float:
    """``after - before``, exactly 0 where it is below 1e-12 of the larger total: a stage that
    adds nothing (its parts re-summed in another order, a link's inertia written back) leaves
    the cancellation error of two float sums (2.8e-11 kg m² on the V-twin), not an addition."""
    d = after - before
    return 0.0 if abs(d) <= 1e-12 * max(abs(after), abs(before)) else d


def total_inertia(model) -> float:
    """Sum of the declared centroidal inertias of links, attachments and gears (no parallel-axis
    terms): what a balancing stage adds as rotating inertia (counter-rotations, inertia
    counterweights)."""
    return sum(b.inertia + sum(a.inertia for a in b.attachments) for b in model.bodies)


def ratio_reference(unbalanced: StageResult) -> LoadReference:
    """The unbalanced stage's inertial peaks, floored by 1 % of its gross inertial loads."""
    return load_reference(unbalanced.stage.model, unbalanced.analysis)


@dataclass(frozen=True)
class StageMetrics:
    """Peaks, ratios, claim and costs of one stage, computed once by :func:`run` (see
    :func:`stage_metrics`) and read by ``results.json``, the pages and ``balpipe diff``. The
    field names are the keys of a stage's row in ``results.json`` (:meth:`to_json`);
    ``reference_loads`` (the denominators of the ratios) is not one of them."""

    name: str
    label: str
    description: str
    balances: str
    paper_claims: str
    headline: bool
    max_shaking_force: float
    max_shaking_moment: float
    max_inertial_force: float
    max_inertial_moment: float
    force_ratio: float
    moment_ratio: float
    force_balanced: bool
    moment_balanced: bool
    force_tolerance: float
    moment_tolerance: float
    tolerance_source: str
    max_actuator_effort: float
    added_mass: float
    added_inertia: float
    reactions_vs_momentum_force: float
    reactions_vs_momentum_moment: float
    realisable: bool
    not_realisable: str
    not_realisable_parts: str
    reference: str
    reference_loads: LoadReference = field(repr=False, compare=False)

    def to_json(self) -> dict[str, Any]:
        """The stage's row of ``results.json`` (``stages[]``)."""
        return {f.name: getattr(self, f.name) for f in fields(self) if f.name != "reference_loads"}

    def number(self, key: str) -> float | None:
        """The row's field ``key`` as a float, None when it is not a number (a reference's
        ``stage.metric``)."""
        value = self.to_json().get(key)
        return float(value) if isinstance(value, (int, float)) else None


def stage_metrics(sr: StageResult, unbalanced: StageResult, tol: float, overrides: dict | None = None,
                  ref: LoadReference | None = None) -> StageMetrics:
    """Peaks, ratios and balance of one stage. Ratios and the balance criterion use the inertial
    part of the loads (the shaking loads less the moving links' weight and its moment, which a
    force-balanced mechanism keeps constant); without gravity that is the loads themselves.
    They divide by :func:`ratio_reference` (the unbalanced peaks, or their floor). The claims
    are judged at the stage's own tolerances (:func:`balpipe.mechanics.claim_precision.claim_tolerances`:
    ``tol`` for computed designs, the precision of the entered numbers for designs typed by
    hand, or ``overrides[stage]``). ``ref``: :func:`ratio_reference` of ``unbalanced`` when the
    caller has it (computed here otherwise)."""
    ref = ref if ref is not None else ratio_reference(unbalanced)
    claim = claim_tolerances(sr.stage, sr.stage.model, sr.analysis, ref, tol, overrides)
    F0, M0 = ref.force, ref.moment
    F, M = sr.analysis.max_inertial_force, sr.analysis.max_inertial_moment
    df, dm = sr.analysis.route_difference()
    unmade = realisable.unmade(sr.stage.parts)
    not_realisable = realisable.verdict(sr.stage.model)
    if unmade:  # a counterweight's part that does not fit (or has no shape): the design cannot be made
        not_realisable = f"{not_realisable}; a part cannot be made" if not_realisable else "not realisable: a part cannot be made"
    return StageMetrics(
        name=sr.stage.name,
        label=sr.stage.label,
        description=sr.stage.description,
        balances=sr.stage.balances,
        paper_claims=sr.stage.paper_claims,
        headline=sr.stage.headline,
        max_shaking_force=sr.analysis.max_force,
        max_shaking_moment=sr.analysis.max_moment,
        max_inertial_force=F,
        max_inertial_moment=M,
        force_ratio=F / F0 if F0 > 0 else 0.0,
        moment_ratio=M / M0 if M0 > 0 else 0.0,
        force_balanced=F <= claim["force"] * F0,
        moment_balanced=M <= claim["moment"] * M0,
        force_tolerance=claim["force"],
        moment_tolerance=claim["moment"],
        tolerance_source=claim["source"],
        max_actuator_effort=sr.max_effort,
        added_mass=sr.added_mass,
        added_inertia=sr.added_inertia,
        reactions_vs_momentum_force=df / F0 if F0 > 0 else df,
        reactions_vs_momentum_moment=dm / M0 if M0 > 0 else dm,
        realisable=not not_realisable,
        not_realisable=not_realisable,
        not_realisable_parts="; ".join(filter(None, [realisable.details(sr.stage.model), *unmade])),
        reference=unbalanced.stage.name,
        reference_loads=ref,
    )


def _lookup(name: str, balance: BalanceResult, metrics: list[StageMetrics]) -> float | None:
    for p in balance.parameters:
        if p.name == name:
            return p.value
    if "." in name:
        stage, key = name.split(".", 1)
        for m in metrics:
            if m.name == stage and m.number(key) is not None:
                return m.number(key)
    return None


def compare_references(spec: Spec, balance: BalanceResult, metrics: list[StageMetrics]) -> list[dict]:
    """Published vs computed: 'agrees' within the reference's relative tolerance (and the
    rounding of the printed digits), 'differs' otherwise, 'unknown' if nothing computes it."""
    out = []
    for k, ref in enumerate(spec.references):
        computed = _lookup(ref.name, balance, metrics)
        if computed is None:
            raise SpecFieldError(
                ("references", k, "name"),
                f"nothing computes {ref.name!r}; parameters: {', '.join(p.name for p in balance.parameters)}, "
                "or stage.metric such as unbalanced.max_shaking_force",
            )
        rel = abs(computed - ref.published) / abs(ref.published) if ref.published else abs(computed)
        rounding = 0.5 * 10 ** (-_decimals(ref.published)) / abs(ref.published) if ref.published else 0.0
        agrees = rel <= max(ref.tolerance, rounding)
        out.append({
            "name": ref.name,
            "published": ref.published,
            "computed": computed,
            "unit": ref.unit,
            "relative_difference": rel,
            "status": "agrees" if agrees else "differs",
            "expected": ref.expect,
            "kind": reference_kind("agrees" if agrees else "differs", ref.expect),
            "note": ref.note,
        })
    return out


#: how a published number compares (``references[].kind`` in results.json), from its status and
#: what the spec expects of it (``references[].expect``): reproduced; reproduced within the
#: tolerance the spec states under assumptions the paper does not state (``assumption``); a
#: misprint the note explains (``misprint``); known not to reproduce (``differ``: the note says
#: why); unexpectedly not reproduced
REFERENCE_KINDS = ("reproduced", "assumption", "misprint", "not_reproduced", "unexpected")


def reference_kind(status: str, expect: str) -> str:
    """The :data:`REFERENCE_KINDS` entry of a published number: its ``status`` ('agrees' or
    'differs') and the spec's ``expect``."""
    if status == "agrees":
        return "assumption" if expect == "assumption" else "reproduced"
    return {"misprint": "misprint", "differ": "not_reproduced"}.get(expect, "unexpected")


def _decimals(x: float) -> int:
    s = repr(float(x))
    if "e" in s:
        return max(0, -int(s.split("e")[1]))
    frac = s.split(".")[1] if "." in s else ""
    return 0 if frac == "0" else len(frac)


def near_singular_note(stages: list[StageResult], balance: BalanceResult, problems: list[str]) -> float:
    """The largest condition number of the constraint Jacobian over the stages' motions (SVDs of
    the samples where it can be, :func:`.engine.condition_peak`, computed here when the engine's
    path has not computed them all); above
    :data:`NEAR_SINGULAR`, a note of the accuracy lost there, also appended to the balance
    ``problems`` (in place). Only the page shows them: ``balpipe check`` skips this."""
    peaks = [condition_peak(s.analysis) for s in stages]
    i = max(range(len(stages)), key=lambda i: peaks[i][1])  # the first stage of the largest
    k, cond = peaks[i]
    if cond > NEAR_SINGULAR:
        where = (f"the motion passes near a singular configuration (condition number of the constraint "
                 f"Jacobian {cond:.3g} at t = {stages[i].analysis.t[k]:.4g} s): accelerations there lose about "
                 f"{min(1.0, cond ** 2 * 1e-16):.1g} of their relative accuracy")
        balance.notes.append(where[0].upper() + where[1:] + ".")
        problems[:] = [p + f"; {where}" if "should cancel" in p else p for p in problems]
    return cond


def run(spec: Spec, page: bool = True, memo: Memo = compute) -> Study:
    """Balance and analyse every stage; collect checks and problems (no simulation). Without
    ``page``, what only the page shows is not computed (:func:`.registry.balance`), nor the
    condition numbers, near-singular notes and dead-centre warnings (``checks`` then has
    ``max_condition_number`` None), nor the parameters of the method's ``derived`` hook unless
    the spec has references (which may name them): none of them makes a spec invalid. ``memo``:
    what the balancing's searches go through (:class:`balpipe.cache.balance.Memo` in a build).
    The C allocator keeps freed memory from here on (:func:`balpipe.runtime.allocator.keep_freed_memory`,
    which the engine's first analysis would set): a balancing's searches allocate arrays of the same
    sizes thousands of times (paper 003's ramps: 70,000 pages faulted in again, 0.15 s, without it)."""
    keep_freed_memory()
    model = registry.unbalanced_model(spec)
    if model.sources:  # a spec that gives its own poses (custom): the assembly must confirm them
        assembly.check(model, float(registry.time_grid(spec)[0]))
    try:
        balance = registry.balance_designs(spec, page, memo, model)  # the model built once
    except AnalysisError as exc:  # a balancing method analysed a motion that cannot be followed
        raise loop_closure.located(model, registry.time_grid(spec), exc) from None
    stages = run_stage_analyses(spec, balance)
    tol = spec.analysis.balance_tolerance
    overrides = spec.analysis.claim_tolerance
    names = [s.stage.name for s in stages]
    for where, by_stage in ((("analysis", "claim_tolerance"), overrides),
                            (("validation", "stage_dt"), spec.validation.stage_dt)):
        for name in by_stage:
            if name not in names:
                raise SpecFieldError((*where, name), f"no stage {name!r} (stages: {', '.join(names)})")
    loads_of: dict[int, LoadReference] = {}  # each reference stage's loads, computed once for all its stages

    def reference_loads(r: StageResult) -> LoadReference:
        if id(r) not in loads_of:
            loads_of[id(r)] = ratio_reference(r)
        return loads_of[id(r)]

    for s in stages:
        r = reference_of(stages, s)
        s._metrics = stage_metrics(s, r, tol, overrides, reference_loads(r))
    metrics = [s.metrics for s in stages]
    if balance.derived is not None and (page or spec.references):  # the page's, and what a reference may name
        balance.parameters.extend(balance.derived(stages))
    problems = list(dict.fromkeys(p for s in stages for p in realisable.unmade(s.stage.parts)))  # parts not made
    rvm = max(max(m.reactions_vs_momentum_force, m.reactions_vs_momentum_moment) for m in metrics)
    if not rvm <= 1e-9 or not math.isfinite(rvm):
        problems.append(f"reactions and momentum disagree by {rvm:.3g} of the reference load (limit 1e-9)")
    for m in metrics:
        row = m.to_json()
        for what in ("force", "moment"):
            if what in m.balances and not row[f"{what}_balanced"]:
                problems.append(f"stage {m.name!r} should cancel the shaking {what} but keeps {row[f'{what}_ratio']:.3g} "
                                f"of it (tolerance {row[f'{what}_tolerance']:.3g}: {m.tolerance_source})")
        claimed = [w for w in ("force", "moment") if w in m.balances]
        if claimed and m.tolerance_source != "analysis.balance_tolerance":
            balance.notes.append(f"Stage {m.label!r}: its claim is judged at the tolerance " + ", ".join(
                f"{numbers.tol(row[f'{w}_tolerance'])} of the reference {w} (achieved {numbers.ratio(row[f'{w}_ratio'], None)})" for w in claimed)
                + f", set by the {m.tolerance_source}" + ("" if m.tolerance_source == "spec" else
                " (each rounded at its last digit, the worst case carried through the loads)") + ".")
    max_condition = near_singular_note(stages, balance, problems) if page else None
    redundant = max(s.analysis.redundant_actuators for s in stages)
    if redundant:
        n = len(stages[0].stage.model.drivers)
        balance.notes.append(
            f"Redundant actuation: {n} actuators drive {n - redundant} degrees of freedom. The efforts are "
            "the minimum-norm ones (the pseudo-inverse solution: of all efforts that produce the motion, "
            "the least sum of squares, no internal preload), and the joint reactions follow from the same "
            "multipliers. The shaking force and moment do not depend on how the actuators share the load."
        )
    warnings = (dead_centres.unique([w for s in stages for w in dead_centres.find(s.stage.model, s.analysis, s.stage.name)])
                if page else [])
    virtual = actuation.virtual_note(stages[0].stage.model)
    if virtual:
        balance.notes.append(virtual)
    refs = compare_references(spec, balance, metrics)
    checks = {"reactions_vs_momentum": rvm, "balance_tolerance": tol, "max_condition_number": max_condition,
              "reference": reference_loads(stages[0]).to_json()}
    return Study(spec, balance, stages, refs, checks, problems, warnings=warnings)
