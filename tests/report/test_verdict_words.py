"""One verdict vocabulary: what was claimed and holds ("force balanced as designed", "balanced as
claimed"), the loads it does not claim that grow as costs ("moment × 12.6"), a claim that fails
("the paper's claim fails: moment × 6.74"), an optimised stage by its objective; the word "mixed"
nowhere. One function (:func:`balpipe.report.verdict.stage_words`) says it, for a StageMetrics as
for its results.json row; the papers' pages read it from their own computed numbers."""

from __future__ import annotations

import random
from dataclasses import fields

import pytest

from balpipe.report import verdict as V
from balpipe.report.costs import factor_text
from balpipe.report.results import results_dict
from balpipe.study import StageMetrics

CLAIMS = ("", "force", "moment", "force+moment")


def random_row(rng: random.Random, tol: float = 1e-9) -> dict:
    """A stage's results.json row with random ratios (round-off, reduced, about 1, grown) and claims."""
    def ratio() -> float:
        return rng.choice([rng.uniform(0, 1e-12), rng.uniform(0.0, 0.98), rng.uniform(0.995, 1.005),
                           10 ** rng.uniform(0.01, 2.0)])

    f, m = ratio(), ratio()
    return {"name": "s", "label": "s", "balances": rng.choice(CLAIMS), "paper_claims": rng.choice(CLAIMS),
            "force_ratio": f, "moment_ratio": m, "force_balanced": f <= tol, "moment_balanced": m <= tol,
            "realisable": rng.random() > 0.2, "not_realisable": "not realisable: negative inertia",
            "reference": "unbalanced", "max_inertial_force": 3.0 * f, "max_inertial_moment": 0.5 * m}


def test_the_words_follow_the_claims_and_the_ratios_for_random_metrics():
    rng = random.Random(40)
    seen = set()
    for _ in range(2000):
        row, paper = random_row(rng), rng.random() < 0.5
        v = V.stage_words(row, paper)
        claims = [p for p in ("force", "moment") if p in row["balances"] or p in row["paper_claims"]]
        fails = [p for p in claims if not row[f"{p}_balanced"]]
        grown = [p for p in ("force", "moment") if p not in claims and row[f"{p}_ratio"] > 1 + V.UNCHANGED]
        assert v["verdict"] in V.KINDS and "mixed" not in v["words"] + v["text"]
        assert v["text"].startswith(v["words"])
        seen.add(v["verdict"])
        if fails:
            beyond = [p for p in fails if p in row["paper_claims"] and p not in row["balances"]]
            whose = "the paper's claim" if paper or beyond else "the design's claim"
            assert v["verdict"] == "fails" and v["level"] == "bad" and v["holds"] is False
            assert v["words"].startswith(f"{whose} fails: ")
            for p in fails:  # each failing load named with what is left of it or its growth
                r = row[f"{p}_ratio"]
                assert (f"{p} {factor_text(r)}" if r >= 1 else f"{p} not cancelled ({V.percent(r)}") in v["words"]
        elif claims:
            complete = claims == ["force", "moment"]
            what = "balanced" if complete else f"{claims[0]} balanced"
            how = "as claimed" if paper and complete else "as designed"
            assert v["verdict"] == "holds" and v["holds"] is True
            assert v["words"] == f"{what} {how}" + ("" if row["realisable"] else " on paper only")
            assert v["level"] == ("good" if row["realisable"] else "warn")  # a cost never lowers it
        else:
            assert v["verdict"] == "unclaimed" and v["holds"] is None
            lower = any(row[f"{p}_ratio"] < 1 - V.UNCHANGED for p in ("force", "moment"))
            assert v["level"] == ("warn" if grown or not row["realisable"] else "good" if lower else "neutral")
            assert v["words"] == ("loads reduced" if lower and not grown else "no change" if not grown
                                  else "a load worse" if lower else "loads worse")
        if claims:  # the loads it does not claim that grow, and only those, are its costs
            assert v["costs"] == [f"{p} {factor_text(row[f'{p}_ratio'])}" for p in grown]
    assert seen == {"holds", "fails", "unclaimed"}


def test_a_stage_metrics_reads_as_its_results_json_row():
    rng = random.Random(7)
    for _ in range(50):
        row = random_row(rng)
        values = {f.name: row.get(f.name, 0.0) for f in fields(StageMetrics)}
        values.update({"description": "", "headline": False, "tolerance_source": "spec", "not_realisable_parts": "",
                       "reference_loads": None})
        metrics = StageMetrics(**values)
        assert V.stage_words(metrics, True) == V.stage_words(metrics.to_json(), True)


def test_the_spec_speaks_with_its_headline_stage_or_its_first_failing_claim():
    rng = random.Random(41)
    for _ in range(300):
        rows = [random_row(rng) for _ in range(rng.randint(1, 3))]
        for k, r in enumerate(rows):
            r["name"] = r["label"] = f"s{k}"
        res = {"status": "ok", "references": [], "paper": rng.choice([None, "001: a paper"]),
               "stages": [{"name": "unbalanced", "label": "unbalanced", "force_ratio": 1.0, "moment_ratio": 1.0,
                           "max_inertial_force": 3.0, "max_inertial_moment": 0.5}] + rows}
        v = V.verdict(res)
        failing = [r for r in rows if v["stages"][r["name"]]["verdict"] == "fails"]
        judged = V.stage_words(failing[0] if failing else rows[-1], bool(res["paper"]))
        assert v["verdict"] == judged["verdict"] and v["words"].startswith(judged["words"])
        assert v["costs"] == judged["costs"] and "mixed" not in v["text"]
        assert v["level"] == V.worst([judged["level"]] + ["bad"] * bool(failing))


def test_published_numbers_counted_apart():
    refs = [{"status": "agrees", "expected": "agree"}] * 3 + [
        {"status": "agrees", "expected": "assumption"}, {"status": "differs", "expected": "misprint"}]
    v = V.references_verdict(refs)
    assert (v["reproduced"], v["explained"], v["misprint"], v["assumption"], v["known_not"]) == (3, 2, 1, 1, 0)
    assert v["level"] == "good" and v["badge"] == "4 of 5 reproduced (1 within the stated tolerance), 1 misprint explained"
    assert "the paper's own numbers" not in v["text"]
    v = V.references_verdict(refs + [{"status": "differs", "expected": "differ"}])
    assert v["level"] == "warn" and v["known_not"] == 1 and v["badge"].endswith("1 not reproduced")
    v = V.references_verdict(refs + [{"status": "differs", "expected": "assumption"}])  # beyond its stated tolerance
    assert v["level"] == "bad" and v["unexpected"] == 1


def _verdict(studies, name: str) -> dict:
    return results_dict(studies(name), name, "h", simulated=False)["verdict"]


def test_scott_russell_as_printed_fails_the_papers_claim_and_the_build_stands(studies):
    """Paper 000 claims the Scott-Russell legs balance force and moment; with its printed I2 (eq.
    30e broken) the moment remains: the verdict says the paper's claim fails, by the computed
    factor, while the build (which checks what the design as given guarantees) is sound."""
    st = studies("paper000_rpr3_scott_russell.yaml")
    v = _verdict(studies, "paper000_rpr3_scott_russell.yaml")
    cr = next(s for s in st.stages if s.stage.name == "counter_rotations").metrics
    assert cr.balances == "force" and cr.paper_claims == "force+moment"
    assert v["verdict"] == "fails" and v["level"] == "bad" and st.ok
    assert v["words"] == f"the paper's claim fails: moment {factor_text(cr.moment_ratio)}" and cr.moment_ratio > 2
    assert v["references"]["known_not"] == 3 and "the paper's own numbers" not in v["text"]


@pytest.mark.parametrize("name", ["paper001_4rrr.yaml", "custom_five_bar_circle.yaml"])
def test_a_force_balance_reads_as_designed_with_its_moment_a_cost(studies, name):
    v = _verdict(studies, name)
    final = next(s for s in studies(name).stages if s.stage.name == v["motions"][0]["final"]).metrics
    assert v["verdict"] == "holds" and v["words"] == "force balanced as designed" and v["level"] == "good"
    assert v["costs"] == [f"moment {factor_text(final.moment_ratio)}"] and final.moment_ratio > 1


def test_paper_004_balanced_as_claimed_its_misprint_counted_apart(studies):
    v = _verdict(studies, "paper004_five_bar.yaml")
    assert v["words"] == "balanced as claimed" and v["level"] == "good" and v["costs"] == []
    refs = v["references"]
    assert refs["misprint"] == 1 and refs["known_not"] == 0 and refs["unexpected"] == 0
    assert refs["reproduced"] == refs["total"] - 1 and refs["badge"].endswith("1 misprint explained")
