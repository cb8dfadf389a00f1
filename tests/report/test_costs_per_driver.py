"""What balancing costs the actuators, per driver: each cost factor names its driver, says it is
the worst of them, and gives every other driver's factor, on the page, on the index and in
results.json (``verdict.motions[].costs.<name>_drivers``)."""

from __future__ import annotations

import json
import re

import markupsafe
import pytest

from balpipe.report.costs import cost_factors, drivers_text


def _results(peaks: dict[str, tuple[float, float]]) -> dict:
    acts = [{"stage": st, "driver": d, "peak": p[k], "rms": p[k] / 2, "power": 3 * p[k]}
            for k, st in enumerate(("unbalanced", "balanced")) for d, p in peaks.items()]
    return {"actuators": acts, "stages": [{"name": "unbalanced"}, {"name": "balanced", "added_mass": 1.0}],
            "moving_mass": 4.0}


def test_every_driver_has_its_factor_the_worst_first(rng):
    peaks = {f"q{k}": (float(rng.uniform(1, 10)), float(rng.uniform(0.1, 40))) for k in range(1, 5)}
    c = cost_factors(_results(peaks), "unbalanced", "balanced")
    for name in ("effort", "rms", "power"):
        per = c[f"{name}_drivers"]
        assert {d["driver"]: d["factor"] for d in per} == pytest.approx({d: b / a for d, (a, b) in peaks.items()}, rel=1e-12)
        assert [d["factor"] for d in per] == sorted((d["factor"] for d in per), reverse=True)
        assert c[name] == per[0]["factor"] and c[f"{name}_driver"] == per[0]["driver"]


def test_the_text_names_the_worst_and_every_other_driver():
    c = cost_factors(_results({"q1": (2.0, 1.0), "q2": (1.0, 1.2), "q3": (1.0, 14.0)}), "unbalanced", "balanced")
    assert drivers_text(c, "power") == "q3, the worst of 3 drivers; q2 × 1.2, q1 × 0.5"
    one = cost_factors(_results({"crank": (2.0, 3.0)}), "unbalanced", "balanced")
    assert drivers_text(one, "effort") == "crank"  # one driver: nothing to compare it with
    shown = drivers_text(c, "effort", lambda d: markupsafe.Markup("<var>{}</var>").format(d))
    assert isinstance(shown, markupsafe.Markup) and shown.startswith("<var>q3</var>, the worst of 3")


def test_page_and_results_name_the_worst_driver(api_studies, pages):
    """custom_3rrr_motors: three motors, the design card's cost names the worst and the others;
    results.json carries every driver's factor, equal to the actuator table's peaks' ratios."""
    name = "custom_3rrr_motors.yaml"
    html = pages(name)
    card = re.search(r"Cost against the unbalanced mechanism:</strong>(.*?)</p>", html, re.S).group(1)
    text = re.sub(r"<[^>]+>", "", card)
    assert text.count("the worst of 3 drivers") == 3, text  # peak effort, RMS effort, peak power
    r = api_studies(name).results()
    costs = r["verdict"]["motions"][0]["costs"]
    g = r["verdict"]["motions"][0]
    acts = {(a["stage"], a["driver"]): a for a in r["actuators"]}
    for d in costs["power_drivers"]:
        assert d["factor"] == pytest.approx(acts[(g["final"], d["driver"])]["power"] / acts[(g["reference"], d["driver"])]["power"])
    assert len(costs["effort_drivers"]) == 3


def test_index_names_the_worst_driver(shared_build):
    from conftest import SPECS

    folder, r = shared_build(tuple(sorted(p.name for p in SPECS.iterdir() if p.is_file())), "specs", "-o", "site", "--no-sim")
    html = (folder / "site" / "index.html").read_text(encoding="utf-8")
    cell = re.search(r'data-spec="paper003_com_planning".*?data-label="Cost" class="cost">(.*?)</td>', html, re.S).group(1)
    assert re.search(r"peak power × [\d.]+ \(q₃, the worst of 3 drivers; q₂ × [\d.]+, q₁ × 0\.\d+\)", cell), cell
    costs = json.loads((folder / "site" / "paper003_com_planning" / "results.json").read_text())["verdict"]["motions"][0]["costs"]
    assert [d["driver"] for d in costs["power_drivers"]] == ["q3", "q2", "q1"]
