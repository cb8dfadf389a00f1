"""Did balancing work? The verdict per stage and per spec (issue 22): separate from "built",
against each stage's claim, from the main design only, and the same on the index as in
results.json."""

from __future__ import annotations

import json
import random
import re
from pathlib import Path

import pytest

from balpipe.build import Options, build
from balpipe.report import verdict as V
from balpipe.report.results import results_dict

SPECS = Path(__file__).parents[2] / "specs"


def stage(name, balances="", f=1.0, m=1.0, ref="unbalanced", tol=1e-9, realisable=True, **kw):
    out = {"name": name, "label": name, "balances": balances, "force_ratio": f, "moment_ratio": m,
           "force_balanced": f <= tol, "moment_balanced": m <= tol, "reference": ref,
           "max_inertial_force": 10.0 * f, "max_inertial_moment": 2.0 * m, "added_mass": 1.0,
           "added_inertia": 0.1, "realisable": realisable, "not_realisable": "" if realisable else "not realisable: negative inertia"}
    out.update(kw)
    return out


def results(*stages, refs=()):
    """A results.json of ``stages``; a stage given ``design=`` is one of that compared design (its
    ``comparison`` row says so, as results.json's do)."""
    stages = [stage("unbalanced")] + list(stages)
    rows = [{"stage": s["name"], "design": s.pop("design", "main")} for s in stages]
    return {"status": "ok", "stages": stages, "references": list(refs),
            "moving_mass": 2.0, "actuators": [], "comparison": {"rows": rows}}


def test_moment_worse_after_a_stage_claiming_moment_balance_is_never_positive():
    rng = random.Random(22)
    for _ in range(200):
        worse = 1.0 + 10 ** rng.uniform(-1.5, 2)
        later = rng.choice([1e-12, rng.uniform(0.0, 3.0)])  # a later stage may even cancel it
        r = results(stage("cw", "force", f=1e-13, m=rng.uniform(0, 5)),
                    stage("cr", "force+moment", f=1e-13, m=worse),
                    stage("extra", rng.choice(["", "force+moment"]), f=1e-13, m=later))
        v = V.verdict(r)
        assert v["level"] == "bad" and v["stages"]["cr"]["level"] == "bad", v["text"]
        assert v["stages"]["cr"]["holds"] is False
        assert v["stages"]["cr"]["moment"]["outcome"] == "worse"
        assert "fails" in v["stages"]["cr"]["text"]


def test_outcomes_in_words():
    assert V.outcome(1e-14, True, True)["text"] == "cancelled"
    assert V.outcome(0.397, False, False)["text"] == "reduced by 60.3 %"
    assert V.outcome(1.004, False, False)["outcome"] == "unchanged"
    w = V.outcome(6.7404, False, False)
    assert w["outcome"] == "worse" and w["text"] == "worse: 674 % of the reference"
    # the site's one ratio convention: a factor from ten times on, never "4173 %"
    assert V.outcome(41.73, False, False)["text"] == "worse: × 41.7 the reference"


def test_a_force_balance_holds_as_designed_its_moment_a_cost_and_references_count_apart():
    r = results(stage("cw", "force", f=1e-13, m=6.74),
                refs=[{"status": "agrees"}, {"status": "differs", "expected": "differ"}])
    v = V.verdict(r)
    assert v["words"] == "force balanced as designed" and v["verdict"] == "holds"
    assert v["costs"] == ["moment × 6.74"] and "cost: moment × 6.74" in v["text"]
    assert v["level"] == "warn"  # a published number known not to reproduce, never the moment's growth
    assert V.verdict(results(stage("cw", "force", f=1e-13, m=6.74)))["level"] == "good"
    assert v["references"]["reproduced"] == 1 and v["references"]["total"] == 2
    assert v["references"]["known_not"] == 1 and "mixed" not in v["text"]
    r = results(stage("all", "force+moment", f=1e-13, m=1e-13))
    assert V.verdict(r)["level"] == "good" and V.verdict(r)["words"] == "balanced as designed"
    r["paper"] = "004: a paper"
    assert V.verdict(r)["words"] == "balanced as claimed"
    r = results(stage("all", "force+moment", f=1e-13, m=1e-13), refs=[{"status": "differs", "expected": "agree"}])
    assert V.verdict(r)["level"] == "bad"  # a published number that should reproduce and does not
    r = results(stage("all", "force+moment", f=1e-13, m=1e-13, realisable=False))
    assert V.verdict(r)["level"] == "warn"  # balanced on paper only


def test_headline_from_the_main_design_never_a_compared_one():
    r = results(stage("cw", "force", f=1e-13, m=2.0), stage("cr", "force+moment", f=1e-13, m=1e-13),
                stage("other:cw", "force", f=0.4, m=1.1, design="other"))
    v = V.verdict(r)
    assert [g["final"] for g in v["motions"]] == ["cr"]
    assert V.verdict(r, main={"unbalanced", "cw", "cr"}) == v  # the study's own list, as results.json gives it
    assert [g["final"] for g in V.verdict(r, main={"unbalanced", "cw", "cr", "other:cw"})["motions"]] == ["other:cw"]
    assert v["force"]["outcome"] == "cancelled" and v["moment"]["outcome"] == "cancelled"
    assert "other:cw" in v["stages"]  # judged, but not the spec's headline


def test_several_motions_each_judged():
    r = {"status": "ok", "references": [], "stages": [
        stage("a_ref", ref="a_ref"), stage("a_plan", f=0.5, m=0.6, ref="a_ref"),
        stage("b_ref", ref="b_ref"), stage("b_plan", f=0.4, m=0.3, ref="b_ref")]}
    v = V.verdict(r)
    assert [g["final"] for g in v["motions"]] == ["a_plan", "b_plan"]
    assert v["force"]["text"] == "reduced by 50 % to 60 % (over 2 motions)"
    assert v["level"] == "good" and v["words"] == "loads reduced" and v["verdict"] == "unclaimed"


def test_the_headline_judges_the_declared_stage_else_the_last():
    """Issue 22: a method that declares the stage whose numbers the paper publishes (paper 003:
    case 2, followed by a case 3) has its headline judged on that stage; every stage keeps its own
    verdict; without the declaration the motion's last stage is judged."""
    case2, case3 = stage("case2", f=0.5, m=0.6, headline=True), stage("case3", f=1.3, m=0.9)
    v = V.verdict(results(case2, case3))
    g = v["motions"][0]
    assert g["final"] == "case2" and g["declared"] is True
    assert v["force"]["outcome"] == "reduced" and v["force"]["ratio"] == 0.5  # not case 3's worse force
    assert g["force"][1] == case2["max_inertial_force"] and v["level"] == "good"
    assert v["stages"]["case3"]["force"]["outcome"] == "worse" and v["stages"]["case3"]["level"] == "warn"
    plain = V.verdict(results(stage("case2", f=0.5, m=0.6), stage("case3", f=1.3, m=0.9)))
    assert plain["motions"][0]["final"] == "case3" and plain["motions"][0]["declared"] is False
    assert plain["force"]["outcome"] == "worse" and plain["level"] == "warn"


@pytest.fixture(scope="module")
def four_bar(studies):
    study = studies("custom_four_bar_balancing.yaml")
    return study, results_dict(study, "custom_four_bar_balancing.yaml", "h", simulated=False)


def test_results_json_carries_the_verdict_with_the_main_designs_costs(four_bar):
    study, r = four_bar
    v = r["verdict"]
    assert set(v) >= {"level", "text", "force", "moment", "references", "motions", "stages"}
    g = v["motions"][0]
    assert g["final"] == "counter_rotations"  # not crank_only:crank_cw
    design = {row["stage"]: row["design"] for row in r["comparison"]["rows"]}
    assert design[g["final"]] == "main" and design["crank_only:crank_cw"] == "crank_only"
    assert next(s for s in study.stages if s.stage.name == "crank_only:crank_cw").stage.design == "crank_only"
    assert v["level"] == "good"
    main = next(s for s in r["stages"] if s["name"] == g["final"])
    assert g["force"][1] == main["max_inertial_force"] and g["moment"][1] == main["max_inertial_moment"]
    c = g["costs"]
    assert c["moving_mass"] == pytest.approx((r["moving_mass"] + main["added_mass"]) / r["moving_mass"])
    json.dumps(r)  # plain JSON


def test_index_agrees_with_results_json_and_leads_with_it(tmp_path):
    out = tmp_path / "site"
    build([str(SPECS / "custom_four_bar_balancing.yaml"), str(SPECS / "paper000_rpr3_scott_russell.yaml")],
          Options(out=out, simulate=False))
    html = (out / "index.html").read_text(encoding="utf-8")
    head = html[html.index('<table id="studies"'):]
    assert re.search(r'>Spec</button></th><th aria-sort="none"><button [^>]*>Verdict</button>', head)
    for slug in ("custom_four_bar_balancing", "paper000_rpr3_scott_russell"):
        level = json.loads((out / slug / "results.json").read_text())["verdict"]["level"]
        m = re.search(rf'data-spec="{slug}" data-verdict="(\w+)"', html)
        assert m and m.group(1) == level
        page = (out / slug / "index.html").read_text(encoding="utf-8")
        assert f'data-verdict="{level}"' in page and 'id="design-summary"' in page
    sr = json.loads((out / "paper000_rpr3_scott_russell" / "results.json").read_text())["verdict"]
    assert sr["level"] != "good" and sr["moment"]["outcome"] == "worse"  # |M| 674 % after counter-rotations
    # the index's headline |F| of the four-bar is its balanced design's (0), not the crank-only 26.67 N
    row = html[html.index('data-spec="custom_four_bar_balancing"'):]
    row = row[:row.index("</tbody>")]
    assert "26.67" not in row and "67.33 → 0 (&lt; 1e-9 of unbalanced)" in row


def test_designs_of_one_mechanism_side_by_side():
    """The index compares the specs whose unbalanced linkage is the same (results.json's
    mechanism_key), whatever their template's name; a mechanism with one spec has no table."""
    from balpipe.report.site import comparisons

    def entry(title, method, key, *st):
        r = results(*st)
        r.update({"mechanism": "rpr3", "method": method, "mechanism_key": key, "moving_bodies": ["a", "b", "c"],
                  "comparison": {"rows": [{"stage": s["name"], "design": "main", "counter_rotations": 3} for s in r["stages"]]}})
        return {"title": title, "link": f"{title}/index.html", "results": r, "verdict": V.verdict(r)}

    a = entry("idler", "idler_loop", "k1", stage("cr", "force+moment", f=1e-13, m=1e-13, added_mass=1.0))
    b = entry("legs", "scott_russell", "k1", stage("cr", "force+moment", f=1e-13, m=6.7, added_mass=3.0))
    c = entry("other", "idler_loop", "k2", stage("cw", "force", f=1e-13, m=2.0))
    c["results"]["mechanism"] = "rpr3"  # the same template, another linkage: not compared with a and b
    got = comparisons([a, b, c])
    assert [(g["key"], g["bodies"], g["methods"]) for g in got] == [("k1", "a, b and c", 2)]
    rows = {r["title"]: r for r in got[0]["rows"]}
    assert rows["idler"]["moment"] == "cancelled" and rows["legs"]["level"] == "bad"
    assert rows["legs"]["moment"].startswith("worse") and rows["idler"]["counter_rotations"] == 3
    # the added mass relative to the moving mass (2 kg), and the rows best verdict first
    assert rows["legs"]["added_relative_value"] == pytest.approx(1.5) and rows["legs"]["added_relative"] == "× 1.5"
    assert [r["title"] for r in got[0]["rows"]] == ["idler", "legs"]


def test_the_mechanism_key_names_the_linkage_not_its_motion_or_round_off():
    from dataclasses import replace

    from balpipe.report.mechanism_key import mechanism_key
    from balpipe.model import FRAME, Body, Model, Revolute

    crank = Body("crank", 1.0, (0.05, 0.0), 1e-3, points={"O": (0.0, 0.0), "A": (0.1, 0.0)})
    model = Model("m", (crank,), (Revolute("O", FRAME, "crank", (0.0, 0.0), (0.0, 0.0)),),
                  (), {"crank": (0.0, 0.0, 0.0)})
    k = mechanism_key(model)
    assert len(k) == 12 and k == mechanism_key(replace(model, name="other", initial={"crank": (0.0, 0.0, 1.0)}))
    # 6.1e-17 (cos 90 deg) is round-off of 0, not another linkage; a real change of mass is
    same = replace(model, bodies=(replace(crank, com=(0.05, 6.123233995736766e-17)),))
    assert mechanism_key(same) == k
    assert mechanism_key(replace(model, bodies=(replace(crank, mass=1.0 + 1e-9),))) != k


def test_a_spec_without_balancing_stages_has_a_neutral_verdict_and_an_index_row():
    from balpipe.report.site import headline

    v = V.verdict(results())
    assert v["level"] == "neutral" and v["motions"] == []
    h = headline(v, 1e-9)
    assert h["force"] == "—" and h["costs"] == [] and h["realisable"]


def test_design_card_positions_show_round_off_as_zero():
    """A counterweight computed on a link's axis has a lateral coordinate of round-off: the card
    reads 0 there, and keeps a real offset."""
    from balpipe.report.design_card import _position

    assert _position((-0.2, 7.285e-17)) == "(-0.2, 0) m"
    assert _position((-0.2, 3e-4)) == "(-0.2, 0.0003) m"
    assert _position((0.0, 0.0)) == "(0, 0) m"
