"""Did balancing work, and what did it cost? The ``verdict`` object of ``results.json``.

"Built and cross-checked" (the build's status, the validation) says nothing about whether a
stage balanced anything. This module reads a study's result rows (:class:`balpipe.study.StageMetrics` as results.json writes them:
peaks and ratios of the *inertial* loads to the stage's reference, the stage's claim) and says,
per stage and per spec, for the force and for the moment each: *cancelled* (at most the balance
tolerance of the reference), *reduced by x*, *unchanged* (within :data:`UNCHANGED`) or
*worse* (x % of the reference below ten times, × x the reference from there on: the site's one
ratio convention), against what the stage claims; and how many of the paper's published numbers
the build reproduces. A load that was already at round-off in the reference
(a Scotch yoke's shaking moment about its axis) and stays there reads *0 before and after*
(outcome ``zero``): nothing was cancelled, and nothing is lost.

One vocabulary, from one function (:func:`stage_words`), for the index, the page, ``balpipe
diff`` and results.json: what was claimed and holds ("force balanced as designed", "balanced as
claimed" for a paper's claim of complete balance), the loads a stage does not claim that grow as
costs ("moment × 12.6", never a lower level), a claim that fails ("the paper's claim fails: moment
× 6.74"), an optimised stage by its objective (:func:`aim_verdict`); machine-readable as
``verdict`` (:data:`KINDS`), ``words`` and ``costs``.

Levels, worst first: ``bad`` (a claim fails, a published number that should reproduce does not,
or the build failed), ``warn`` (a stage that claims nothing makes a load worse than its
reference, a part cannot be built, or a published number is known not to reproduce), ``neutral``
(nothing changed), ``good``. A published number the page explains (a misprint, or reproduced
within the stated tolerance under stated assumptions) is counted apart and never lowers the level
(:func:`references_verdict`). A spec's level is the worst of its main design's headline stages
(below), of its stages' claims and of its references: a spec whose |M| gets worse after a stage
that claims moment balance is never ``good``. A failing claim is said only where a claim of the
analysis fails: a build that failed a check while every claim holds (the pymunk simulation
contradicts the analysis) says so instead, and a check that could not resolve its own error
(``unconfirmed`` in results.json: nothing shown false) is named after the loads.

The headline numbers come from the spec's main design (not a design of ``compare``), one
row per motion (the stages sharing a reference stage); a compared design never stands in. Per
motion the headline is the stage whose numbers the paper publishes where the method declares one
(:attr:`balpipe.balancing.base.Stage.headline`; paper 003: case 2, not the case 3 after it), else
the motion's last stage: :func:`headline_stage`. Every stage keeps its own verdict.
With gravity on, the loads are the inertial part and the weight (total moving mass x g) is given
apart. Pure functions of the result rows: the index reads a results.json written earlier with
the same code.
"""

from __future__ import annotations

from typing import Any

from ..display import numbers
from ..study import REFERENCE_KINDS, reference_kind
from .costs import cost_factors, factor_text

#: a ratio within this of 1 reads "unchanged"
UNCHANGED = 0.01
LEVELS = ("good", "neutral", "warn", "bad")  # from best to worst
_ORDER = {"zero": 0, "cancelled": 0, "reduced": 1, "unchanged": 2, "worse": 3}
ZERO_TEXT = "0 before and after"


def worst(levels) -> str:
    """The worst of ``levels`` ('good' for none)."""
    return max(levels, key=LEVELS.index, default="good")


def percent(x: float) -> str:
    """0.6031 -> '60.3 %', 47.434 -> '4743 %' (three significant digits or whole percent, never
    scientific)."""
    v = 100 * x
    if abs(v) >= 100:
        return f"{v:.0f} %"  # 4743 %, never 4.74e+03
    return f"{numbers.num(v, 3)} %" if abs(v) >= 1 else f"{numbers.num(v, 2)} %"


def outcome(ratio: float | None, cancelled: bool, claimed: bool, was_zero: bool = False) -> dict:
    """What a stage did to one load, its ratio to the reference's peak: cancelled / reduced /
    unchanged / worse, with the words shown on the pages; ``was_zero``: the reference's own load
    is at round-off, so a stage that keeps it there cancelled nothing (``zero``)."""
    if ratio is None:
        return {"outcome": "unknown", "ratio": None, "claimed": claimed, "text": "—"}
    r = float(ratio)
    if cancelled and was_zero:
        kind, text = "zero", ZERO_TEXT
    elif cancelled:
        kind, text = "cancelled", "cancelled"
    elif abs(r - 1.0) <= UNCHANGED:
        kind, text = "unchanged", "unchanged"
    elif r < 1.0:
        kind, text = "reduced", f"reduced by {percent(1.0 - r)}"
    else:
        shown = numbers.ratio(r, None)  # the site's convention: percent below ten times, a factor from there on
        kind, text = "worse", f"worse: {shown} {'the' if shown.startswith('×') else 'of the'} reference"
    return {"outcome": kind, "ratio": r, "claimed": claimed, "text": text}


def claims_of(stage: dict) -> list[str]:
    """The loads a stage claims to balance, from its ``balances`` ('force', 'force+moment', '')."""
    b = stage.get("balances") or ""
    return [p for p in ("force", "moment") if p in b]


#: a cap is kept when its ratio is at most its bound by this relative margin (the solver's tolerance)
CAP_MARGIN = 1e-6
SHAKING = {"force": "shaking_force", "moment": "shaking_moment"}


def aim_verdict(aim: dict, loads: dict, realisable: bool) -> tuple[str, str, dict]:
    """(level, words, details) of an optimised stage, judged on what it aimed at (its row's
    ``aim``: :class:`balpipe.balancing.base.Aim`): each objective term reduced / unchanged / worse
    in the words of :func:`outcome`, each cap kept or broken, and the shaking force and moment it
    did not optimise as side effects. A stage that adds nothing says why."""
    goals = aim.get("goals") or []
    objective = [{**g, **outcome(g.get("ratio"), False, False)} for g in goals if g["role"] == "objective"]
    caps = [{**g, "kept": g.get("ratio") is not None and g["at_most"] is not None
             and g["ratio"] <= g["at_most"] * (1 + CAP_MARGIN)} for g in goals if g["role"] == "cap"]
    aimed_at = {g.get("load") for g in goals if g["role"] == "objective"}
    side = [p for p in ("force", "moment") if SHAKING[p] not in aimed_at]
    kinds = {o["outcome"] for o in objective}
    if any(not c["kept"] for c in caps):
        level = "bad"
    elif "worse" in kinds or not realisable:
        level = "warn"
    elif not kinds or kinds <= {"unchanged", "zero"}:
        level = "neutral"
    else:
        level = "good"
    parts = [f"{o['label']} {o['text']} (objective)" for o in objective]
    parts += [f"{c['label']} {numbers.num(c['ratio'], 3)} x the unbalanced, cap {c['at_most']:g} x "
              f"{'kept' if c['kept'] else 'broken'}" for c in caps]
    if side:
        parts.append(", ".join(f"{p} {loads[p]['text']}" for p in side) + (" (side effects)" if len(side) > 1 else " (side effect)"))
    words = "; ".join(parts)
    if aim.get("nothing_added"):
        words = f"adds nothing: {aim['nothing_added']}; {words}"
    return level, words, {"objective": objective, "caps": caps, "side_effects": side,
                          "nothing_added": aim.get("nothing_added") or ""}


#: the machine-readable verdict of a stage or spec (``verdict`` in results.json): every claim
#: holds; a claim fails; an optimised stage judged by its objective; no claim, no aim (the loads'
#: changes only); the claims hold in the analysis but a simulation check could not confirm them
KINDS = ("holds", "fails", "objective", "unclaimed", "unconfirmed")


def _row(stage: Any) -> dict:
    """A stage's results.json row: a :class:`balpipe.study.StageMetrics` or its row already."""
    return stage.to_json() if hasattr(stage, "to_json") else stage


def paper_claims_of(stage: dict) -> list[str]:
    """The loads the stage's paper claims it balances beyond what its design as given
    guarantees (``paper_claims``: the Scott-Russell legs' counter-rotations as printed)."""
    own = claims_of(stage)
    return [p for p in claims_of({"balances": stage.get("paper_claims")}) if p not in own]


def _shortfall(load: str, o: dict) -> str:
    """A claimed load that is not cancelled: 'moment × 6.74' (grown), or what is left of it."""
    r = o["ratio"]
    if r is None:
        return f"{load} unknown"
    return f"{load} {factor_text(r)}" if r >= 1.0 else f"{load} not cancelled ({percent(r)} of the reference left)"


def _cost(load: str, o: dict) -> str:
    """A load the stage does not claim that grows: 'moment × 12.6'."""
    return f"{load} {factor_text(o['ratio'])}"


def stage_words(stage: Any, paper: bool = False, reference: dict | None = None) -> dict:
    """The verdict of one stage in engineering words: the one function the index, the page,
    ``balpipe diff`` and results.json read. ``stage``: a :class:`balpipe.study.StageMetrics` or
    its results.json row; ``paper``: the spec reproduces a paper (a claim of complete balance is
    then the paper's: "balanced as claimed"); ``reference``: the row of the stage it is measured
    against (a load at round-off there reads ``zero``).

    Returns ``verdict`` (one of :data:`KINDS`), ``words``, ``costs`` (the loads the stage does
    not claim that grow, 'moment × 12.6'), ``level``, the per-load outcomes and the claims:

    * every claim holds: "force balanced as designed" (a force balance: the moment's growth is
      a cost, not a failure), "balanced as designed" (force and moment), "balanced as claimed"
      (force and moment, claimed by the spec's paper); "... on paper only" when a part cannot be
      built;
    * a claim fails: "the paper's claim fails: moment × 6.74" (the spec's paper, or a claim the
      paper makes beyond the design as given), else "the design's claim fails: ...";
    * an optimised stage: judged by its objective and caps (:func:`aim_verdict`);
    * no claim and no aim: "loads reduced", "no change" or "loads worse"."""
    row = _row(stage)
    ref = _row(reference) if reference is not None else None
    design = claims_of(row)
    beyond = paper_claims_of(row)
    claims = [p for p in ("force", "moment") if p in design or p in beyond]
    loads = {p: outcome(row.get(f"{p}_ratio"), bool(row.get(f"{p}_balanced")), p in claims,
                        bool(ref and ref.get(f"{p}_balanced")))
             for p in ("force", "moment")}
    realisable = row.get("realisable", True) is not False
    costs = [_cost(p, loads[p]) for p in ("force", "moment") if p not in claims and loads[p]["outcome"] == "worse"]
    out: dict[str, Any] = {"claims": claims, "paper_claims": beyond, "realisable": realisable,
                           "force": loads["force"], "moment": loads["moment"], "costs": costs}
    if row.get("aim") and not claims:
        level, text, aim = aim_verdict(row["aim"], loads, realisable)
        if not realisable:
            text += f"; {row.get('not_realisable') or 'not realisable'} (on paper only)"
        kinds = {o["outcome"] for o in aim["objective"]}
        if any(not c["kept"] for c in aim["caps"]):
            words = "a cap broken"
        elif aim["nothing_added"] and level == "neutral":
            words = "adds nothing"
        elif "worse" in kinds:
            words = "objective worse"
        elif level == "neutral":
            words = "objective unchanged"
        else:
            words = "objective reduced"
        out["costs"] = [_cost(p, loads[p]) for p in aim["side_effects"] if loads[p]["outcome"] == "worse"]
        return {**out, "verdict": "objective", "words": words, "level": level, "text": text, "holds": None,
                "aim": aim}
    fails = [p for p in claims if loads[p]["outcome"] not in ("cancelled", "zero")]
    gains = [f"{p} {loads[p]['text']}" for p in ("force", "moment")
             if p not in claims and loads[p]["outcome"] in ("reduced", "cancelled")]
    if fails:
        whose = "the paper's claim" if paper or any(p in beyond for p in fails) else "the design's claim"
        kind, level = "fails", "bad"
        words = f"{whose} fails: " + ", ".join(_shortfall(p, loads[p]) for p in fails)
        kept = [p for p in claims if p not in fails]
        details = [f"{p} {loads[p]['text']} as claimed" for p in kept] + gains
    elif claims:
        kind = "holds"
        complete = claims == ["force", "moment"]
        words = ("balanced" if complete else f"{claims[0]} balanced") + (" as claimed" if paper and complete else " as designed")
        level = "good"
        details = gains
        if not realisable:
            words += " on paper only"
            level = "warn"
    else:
        kind = "unclaimed"
        kinds = {loads[p]["outcome"] for p in loads}
        if "worse" in kinds:  # nothing claimed: a load made worse is no chosen cost
            words, level = "loads worse" if kinds <= {"worse", "unchanged", "zero"} else "a load worse", "warn"
        elif kinds & {"reduced", "cancelled"}:
            words, level = "loads reduced", "good"
        else:
            words, level = "no change", "neutral"
        details = [f"{p} {loads[p]['text']}" for p in ("force", "moment")]
        costs = out["costs"] = []  # the loads' own words say it
        if not realisable:
            level = worst([level, "warn"])
    text = words
    if details:
        text += ": " + ", ".join(details) if kind == "unclaimed" else "; " + ", ".join(details)
    if costs:
        text += f"; cost{'s' if len(costs) > 1 else ''}: " + ", ".join(costs)
    if not realisable:
        text += f"; {row.get('not_realisable') or 'not realisable'}" + ("" if words.endswith("on paper only")
                                                                         else " (balanced on paper only)")
    return {**out, "verdict": kind, "words": words, "level": level, "text": text,
            "holds": (not fails) if claims else None}


def stage_verdict(stage: dict, weight: float | None = None, reference: dict | None = None,
                  paper: bool = False) -> dict:
    """The verdict of one stage (:func:`stage_words`) with its weight (N, gravity on) apart."""
    return {**stage_words(stage, paper, reference), "weight": weight}


def main_design(results: dict) -> set[str]:
    """The names of the stages of the spec's main design, from the ``comparison`` rows of a
    results.json (their ``design`` is "main"); every stage when it has none."""
    rows = (results.get("comparison") or {}).get("rows")
    if not rows:
        return {s["name"] for s in results.get("stages") or []}
    return {r["stage"] for r in rows if r.get("design") == "main"}


def motions(stages: list[dict], main: set[str]) -> list[tuple[dict, list[dict]]]:
    """The main design's stages (those named in ``main``) per motion: (reference stage, the stages
    measured against it), in the spec's order. One motion for most specs; one per trajectory for
    paper 003's."""
    out: dict[str, tuple[dict, list[dict]]] = {}
    by_name = {s["name"]: s for s in stages}
    for s in stages:
        ref = s.get("reference") or stages[0]["name"]
        if ref == s["name"] or s["name"] not in main:
            continue
        out.setdefault(ref, (by_name.get(ref, stages[0]), []))[1].append(s)
    return list(out.values())


def headline_stage(members: list[dict]) -> tuple[dict, bool]:
    """The stage a motion's headline judges, and whether the method declared it: its last stage
    marked ``headline`` (the stage whose numbers the paper publishes), else its last stage."""
    declared = [m for m in members if m.get("headline")]
    return (declared[-1], True) if declared else (members[-1], False)


def _reference_kind(ref: dict) -> str:
    """One ``references`` row's kind (:func:`balpipe.study.reference_kind`; a results.json of an
    older build has none)."""
    return ref.get("kind") or reference_kind(ref.get("status") or "", ref.get("expected") or "agree")


def references_verdict(refs: list[dict]) -> dict:
    """The published numbers counted apart: reproduced; explained (a misprint the page explains,
    or reproduced within the stated tolerance under stated assumptions), which never lowers the
    verdict; known not to reproduce (the note says why: ``warn``); unexpectedly not (``bad``)."""
    n = len(refs)
    kinds = [_reference_kind(r) for r in refs]
    count = {k: kinds.count(k) for k in REFERENCE_KINDS}
    explained = count["assumption"] + count["misprint"]
    out = {"reproduced": count["reproduced"], "total": n, "explained": explained,
           "misprint": count["misprint"], "assumption": count["assumption"],
           "known_not": count["not_reproduced"], "unexpected": count["unexpected"], "kinds": kinds}
    if not n:
        return {**out, "level": "neutral", "text": "no published numbers", "badge": ""}
    parts = []
    if count["reproduced"]:
        parts.append(f"{count['reproduced']} reproduced")
    if count["assumption"]:
        parts.append(f"{count['assumption']} reproduced within the stated tolerance under the stated assumptions")
    if count["misprint"]:
        parts.append(f"{count['misprint']} misprint{'s' if count['misprint'] > 1 else ''} the page explains")
    if count["not_reproduced"]:
        parts.append(f"{count['not_reproduced']} not reproduced (the notes say why)")
    if count["unexpected"]:
        parts.append(f"{count['unexpected']} unexpectedly not reproduced")
    level = "bad" if count["unexpected"] else ("warn" if count["not_reproduced"] else "good")
    # the index's short badge: reproduced / explained / not reproduced, apart
    badge = f"{count['reproduced'] + count['assumption']} of {n} reproduced"
    if count["assumption"]:
        badge += f" ({count['assumption']} within the stated tolerance)"
    if count["misprint"]:
        badge += f", {count['misprint']} misprint{'s' if count['misprint'] > 1 else ''} explained"
    if count["not_reproduced"] + count["unexpected"]:
        badge += f", {count['not_reproduced'] + count['unexpected']} not reproduced"
    return {**out, "level": level, "text": f"published numbers ({n}): " + ", ".join(parts), "badge": badge}


def _span(outs: list[dict]) -> dict:
    """One load's outcome over several motions: the worst outcome, the range of the ratios."""
    kind = max((o["outcome"] for o in outs), key=lambda k: _ORDER.get(k, 4))
    ratios = [o["ratio"] for o in outs if o["ratio"] is not None]
    if len(outs) == 1:
        return dict(outs[0])
    lo, hi = (min(ratios), max(ratios)) if ratios else (None, None)
    kinds = {o["outcome"] for o in outs}
    if kinds == {"reduced"}:
        a, b = percent(1 - hi), percent(1 - lo)
        text = f"reduced by {a} to {b}" if a != b else f"reduced by {a}"
    elif kinds == {"cancelled"}:
        text = "cancelled"
    elif kinds == {"zero"}:
        text = ZERO_TEXT
    else:
        text = ", ".join(f"{sum(o['outcome'] == k for o in outs)} {k}" for k in sorted(kinds, key=_ORDER.get))
    return {"outcome": kind, "ratio": hi, "ratio_min": lo, "claimed": any(o["claimed"] for o in outs),
            "text": f"{text} (over {len(outs)} motions)"}


def verdict(results: dict, weights: dict[str, float] | None = None, main: set[str] | None = None) -> dict[str, Any]:
    """The ``verdict`` object of ``results.json`` from its other fields (``stages``,
    ``references``, ``status``, ``paper``); ``weights``: per stage name, the moving links' weight
    (N), with gravity on; ``main``: the names of the main design's stages (default:
    :func:`main_design`). ``verdict``, ``words`` and ``costs`` are those of the headline stage
    (:func:`stage_words`), or of the first main-design stage whose claim fails (a later stage
    does not redeem it)."""
    weights = weights or {}
    stages = results.get("stages") or []
    paper = bool(results.get("paper"))
    per_stage = {}
    by_name = {s["name"]: s for s in stages}
    for s in stages:
        if s.get("reference", stages[0]["name"]) == s["name"]:
            continue  # a reference: nothing to judge
        per_stage[s["name"]] = stage_verdict(s, weights.get(s["name"]), by_name.get(s.get("reference", stages[0]["name"])),
                                             paper)
    groups = []
    failing: list[str] = []
    for ref, members in motions(stages, main if main is not None else main_design(results)):
        final, declared = headline_stage(members)
        v = per_stage[final["name"]]
        failing += [m["name"] for m in members if per_stage[m["name"]]["verdict"] == "fails"]
        groups.append({
            "reference": ref["name"], "reference_label": ref["label"], "final": final["name"],
            "final_label": final["label"], "declared": declared,
            "force": [ref["max_inertial_force"], final["max_inertial_force"]],
            "moment": [ref["max_inertial_moment"], final["max_inertial_moment"]],
            "weight": [weights.get(ref["name"]), weights.get(final["name"])] if weights else None,
            # an earlier stage may cost moment (counterweights before counter-rotations); one whose
            # claim fails sinks the motion's verdict even when a later stage recovers
            "level": "bad" if any(per_stage[m["name"]]["holds"] is False for m in members) else "good",
            "final_level": v["level"],
            "costs": cost_factors(results, ref["name"], final["name"]),
        })
    refs = references_verdict(results.get("references") or [])
    if not groups:
        force = moment = outcome(None, False, False)
        balance_level = "neutral"
        kind, words, costs = "unclaimed", "no change", []
    else:
        force = _span([per_stage[g["final"]]["force"] for g in groups])
        moment = _span([per_stage[g["final"]]["moment"] for g in groups])
        balance_level = worst([g["level"] for g in groups] + [g["final_level"] for g in groups])
        judged = [per_stage[failing[0]]] if failing else [per_stage[g["final"]] for g in groups]
        lead = max(judged, key=lambda x: LEVELS.index(x["level"]))  # the worst motion speaks
        kind, words = lead["verdict"], lead["words"]
        costs = list(dict.fromkeys(c for j in judged for c in j["costs"]))
        if failing and failing[0] not in {g["final"] for g in groups}:
            words += f" ({by_name[failing[0]]['label']})"
        if len(judged) > 1 and len({j["words"] for j in judged}) > 1:
            words += f" (the worst of {len(judged)} motions)"
    level = worst([balance_level, refs["level"] if refs["total"] else "good"])
    claims_fail = bool(failing) or any(s["holds"] is False for s in per_stage.values())
    if results.get("status") not in (None, "ok"):
        level = "bad"
        # "balancing fails" only where a claim of the analysis fails: a build that failed a check
        # while every claim holds (the simulation contradicts the analysis) says so instead, never
        # "balancing fails" beside loads the analysis finds cancelled
        if not claims_fail and balance_level != "bad":
            kind, words = "fails", check_failure(results.get("problems") or [], results.get("parts") or [])
        elif kind != "fails":
            kind, words = "fails", "balancing fails"
    unconfirmed = list(results.get("unconfirmed") or [])
    if unconfirmed and kind == "holds":
        kind = "unconfirmed"
    aimed = bool(groups) and all("aim" in per_stage[g["final"]] for g in groups)
    if aimed:  # judged by what it optimised: its objective, its caps, the shaking loads as side effects
        body = " | ".join(per_stage[g["final"]]["text"] for g in groups)
        text = body if words == "adds nothing" else f"{words}: {body}"
    elif len(groups) == 1 and kind != "fails" or failing:  # the judged stage's own words
        text = words + lead["text"][len(lead["words"]):]
    elif groups:
        text = f"{words}: force {force['text']}, moment {moment['text']}"
        if costs:
            text += f"; cost{'s' if len(costs) > 1 else ''}: " + ", ".join(costs)
    else:
        text = words
    if refs["total"]:
        text += f"; {refs['text']}"
    if unconfirmed:
        text += f"; simulation check unconfirmed for {len(unconfirmed)} run{'s' if len(unconfirmed) > 1 else ''}"
    return {"verdict": kind, "level": level, "words": words, "costs": costs, "text": text, "force": force,
            "moment": moment, "references": refs, "motions": groups, "stages": per_stage,
            "validation": "unconfirmed" if unconfirmed else None}


def check_failure(problems: list[str], parts: list[dict] | None = None) -> str:
    """The headline of a build that failed a check while every claim of the analysis holds, naming
    the claim shown false: the simulation contradicts the analysis (pymunk), a counterweight made
    as a part does not fit the region its spec allows (``parts``: results.json's, ``fits``), or
    the analysis' own cross-check fails."""
    if any(p.startswith(("pymunk validation", "torque-driven run")) for p in problems):
        return "the simulation contradicts the analysis"
    unfit = sorted({p["name"] for p in parts or [] if p.get("fits") is False})
    if unfit:
        return f"part{'s' if len(unfit) > 1 else ''} {', '.join(unfit)} cannot be made as specified"
    return "a cross-check fails"
