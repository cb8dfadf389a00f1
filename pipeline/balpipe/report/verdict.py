"""Did balancing work, and what did it cost? The ``verdict`` object of ``results.json``.

"Built and cross-checked" (the build's status, the validation) says nothing about whether a
stage balanced anything. This module reads a study's result rows (:class:`balpipe.study.StageMetrics` as results.json writes them:
peaks and ratios of the *inertial* loads to the stage's reference, the stage's claim) and says,
per stage and per spec, for the force and for the moment each: *cancelled* (at most the balance
tolerance of the reference), *reduced by x*, *unchanged* (within :data:`UNCHANGED`) or
*worse* (x % of the reference: one format, percent, for every ratio), against what the stage claims; and how many of the paper's
published numbers the build reproduces. A load that was already at round-off in the reference
(a Scotch yoke's shaking moment about its axis) and stays there reads *0 before and after*
(outcome ``zero``): nothing was cancelled, and nothing is lost.

Levels, worst first: ``bad`` (a claim fails, or the build failed), ``warn`` (a stage makes a
load worse than its reference, a part cannot be built, or a published number does not
reproduce), ``neutral`` (nothing changed), ``good``. A spec's level is the worst of its main
design's headline stages (below), of its stages' claims and of its references: a spec whose |M|
gets worse after a stage that claims moment balance is never ``good``. "Balancing fails" is said
only where a claim of the analysis fails: a build that failed a check while every claim holds (the
pymunk simulation contradicts the analysis) says so instead, and a check that could not resolve
its own error (``unconfirmed`` in results.json: nothing shown false) is named after the loads.

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

from .costs import cost_factors

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
    return f"{v:.3g} %" if abs(v) >= 1 else f"{v:.2g} %"


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
        kind, text = "worse", f"worse: {percent(r)} of the reference"
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
    parts += [f"{c['label']} {c['ratio']:.3g} x the unbalanced, cap {c['at_most']:g} x "
              f"{'kept' if c['kept'] else 'broken'}" for c in caps]
    if side:
        parts.append(", ".join(f"{p} {loads[p]['text']}" for p in side) + (" (side effects)" if len(side) > 1 else " (side effect)"))
    words = "; ".join(parts)
    if aim.get("nothing_added"):
        words = f"adds nothing: {aim['nothing_added']}; {words}"
    return level, words, {"objective": objective, "caps": caps, "side_effects": side,
                          "nothing_added": aim.get("nothing_added") or ""}


def stage_verdict(stage: dict, weight: float | None = None, reference: dict | None = None) -> dict:
    """The verdict of one stage against its own claim (see the module's docstring), or, for an
    optimised stage (its row has an ``aim``), against its objective and caps (:func:`aim_verdict`);
    ``reference``: the row of the stage it is measured against (a load at round-off there reads
    ``zero``)."""
    claims = claims_of(stage)
    loads = {p: outcome(stage.get(f"{p}_ratio"), bool(stage.get(f"{p}_balanced")), p in claims,
                        bool(reference and reference.get(f"{p}_balanced")))
             for p in ("force", "moment")}
    if stage.get("aim") and not claims:
        realisable = stage.get("realisable", True) is not False
        level, words, aim = aim_verdict(stage["aim"], loads, realisable)
        if not realisable:
            words += f"; {stage.get('not_realisable') or 'not realisable'} (on paper only)"
        return {"level": level, "text": words, "claims": [], "holds": None, "realisable": realisable,
                "force": loads["force"], "moment": loads["moment"], "weight": weight, "aim": aim}
    fails = [p for p in claims if loads[p]["outcome"] not in ("cancelled", "zero")]
    worse = [p for p in ("force", "moment") if loads[p]["outcome"] == "worse"]
    realisable = stage.get("realisable", True) is not False
    if fails:
        level = "bad"
    elif worse or not realisable:
        level = "warn"
    elif all(loads[p]["outcome"] in ("unchanged", "zero") for p in loads):
        level = "neutral"
    else:
        level = "good"
    words = f"force {loads['force']['text']}, moment {loads['moment']['text']}"
    if claims:
        words += f"; claims {' and '.join(claims)} balance: " + (
            f"fails ({' and '.join(fails)} not cancelled)" if fails else "holds")
    else:
        words += "; no balance claimed"
    if not realisable:
        words += f"; {stage.get('not_realisable') or 'not realisable'} (balanced on paper only)"
    return {
        "level": level, "text": words, "claims": claims, "holds": (not fails) if claims else None,
        "realisable": realisable, "force": loads["force"], "moment": loads["moment"],
        "weight": weight,
    }


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


def references_verdict(refs: list[dict]) -> dict:
    """Published numbers reproduced k of n; those the spec expects not to (a paper's typo,
    documented in its note) counted apart."""
    n = len(refs)
    k = sum(r.get("status") == "agrees" for r in refs)
    known = sum(r.get("status") != "agrees" and r.get("expected") == "differ" for r in refs)
    unexpected = n - k - known
    if not n:
        return {"reproduced": 0, "total": 0, "known_not": 0, "unexpected": 0, "level": "neutral",
                "text": "no published numbers"}
    text = f"published numbers reproduced {k} of {n}"
    if known:
        text += f" ({known} known not to: the paper's own numbers do not reproduce)"
    if unexpected:
        text += f", {unexpected} unexpectedly not"
    level = "bad" if unexpected else ("warn" if known else "good")
    return {"reproduced": k, "total": n, "known_not": known, "unexpected": unexpected, "level": level,
            "text": text}


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
    ``references``, ``status``); ``weights``: per stage name, the moving links' weight (N), with
    gravity on; ``main``: the names of the main design's stages (default: :func:`main_design`)."""
    weights = weights or {}
    stages = results.get("stages") or []
    per_stage = {}
    by_name = {s["name"]: s for s in stages}
    for s in stages:
        if s.get("reference", stages[0]["name"]) == s["name"]:
            continue  # a reference: nothing to judge
        per_stage[s["name"]] = stage_verdict(s, weights.get(s["name"]), by_name.get(s.get("reference", stages[0]["name"])))
    groups = []
    for ref, members in motions(stages, main if main is not None else main_design(results)):
        final, declared = headline_stage(members)
        v = per_stage[final["name"]]
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
    else:
        force = _span([per_stage[g["final"]]["force"] for g in groups])
        moment = _span([per_stage[g["final"]]["moment"] for g in groups])
        balance_level = worst([g["level"] for g in groups] + [g["final_level"] for g in groups])
    level = worst([balance_level, refs["level"] if refs["total"] else "good"])
    claims_fail = any(s["holds"] is False for s in per_stage.values())
    if results.get("status") not in (None, "ok"):
        level = "bad"
    claimed = any(per_stage[g["final"]]["claims"] for g in groups)
    aimed = bool(groups) and all("aim" in per_stage[g["final"]] for g in groups)
    good = "balanced as claimed" if claimed else "objective reduced" if aimed else "loads reduced"
    bad = "a cap broken" if aimed else "balancing fails"
    words = {"good": good, "neutral": "no change", "warn": "mixed", "bad": bad}[level]
    if level == "warn" and balance_level in ("good", "neutral"):
        words = f"{good if balance_level == 'good' else 'no change'}; published numbers not all reproduced"
    if aimed and any(o["outcome"] == "worse" for g in groups for o in per_stage[g["final"]]["aim"]["objective"]):
        words = "objective worse"
    if results.get("status") not in (None, "ok"):
        # "balancing fails" only where a claim of the analysis fails: a build that failed a check
        # while every claim holds (the simulation contradicts the analysis) says so instead, never
        # "balancing fails" beside loads the analysis finds cancelled
        words = ("balancing fails" if claims_fail or balance_level == "bad"
                 else check_failure(results.get("problems") or []))
    if aimed and level == "neutral" and all(per_stage[g["final"]]["aim"]["nothing_added"] for g in groups):
        words = "adds nothing"  # the stage's words say why
        text = " | ".join(per_stage[g["final"]]["text"] for g in groups)
    elif aimed:  # judged by what it optimised: its objective, its caps, the shaking loads as side effects
        text = f"{words}: " + " | ".join(per_stage[g["final"]]["text"] for g in groups)
    else:
        text = f"{words}: force {force['text']}, moment {moment['text']}"
    if refs["total"]:
        text += f"; {refs['text']}"
    unconfirmed = list(results.get("unconfirmed") or [])
    if unconfirmed:
        text += f"; simulation check unconfirmed for {len(unconfirmed)} run{'s' if len(unconfirmed) > 1 else ''}"
    return {"level": level, "words": words, "text": text, "force": force, "moment": moment,
            "references": refs, "motions": groups, "stages": per_stage,
            "validation": "unconfirmed" if unconfirmed else None}


def check_failure(problems: list[str]) -> str:
    """The headline of a build that failed a check while every claim of the analysis holds: the
    simulation contradicts the analysis (a claim shown false by pymunk), or the analysis' own
    cross-check fails."""
    if any(p.startswith(("pymunk validation", "torque-driven run")) for p in problems):
        return "the simulation contradicts the analysis"
    return "a cross-check fails"
