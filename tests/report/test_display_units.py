"""A spec's ``report: {units: ...}`` chooses the units of the page's numbers (design card,
stage, actuator, comparison, joint-load and orders tables); results.json stays SI and says so."""

from __future__ import annotations

import re

import pytest

from balpipe.display.units import display_units
from balpipe.loader import SpecErrors, load_text
from balpipe.report.page import render_page
from balpipe.report.results import results_dict
from balpipe.study import run
from conftest import SPECS

TEXT = (SPECS / "offset_slider_crank.yaml").read_text(encoding="utf-8")


def _page(units: str | None):
    text = TEXT if units is None else TEXT + f"\nreport:\n  units: {units}\n"
    spec, _ = load_text(text, "specs/offset_slider_crank.yaml", SPECS)
    study = run(spec)
    r = results_dict(study, "specs/offset_slider_crank.yaml", "h", simulated=False)
    return r, render_page(study, r, text)


@pytest.fixture(scope="module")
def si_and_engineering():
    return _page(None), _page("engineering"), _page("{length: cm, mass: g, force: N, moment: N mm, power: kW}")


def _cells(html: str, head: str) -> list[list[str]]:
    """The number cells of each row of the table whose header holds ``head``."""
    table = next(t for t in re.findall(r"<table.*?</table>", html, re.S) if head in t)
    return [[re.sub(r"<[^>]+>", "", c).strip() for c in re.findall(r'<td class="num">(.*?)</td>', row, re.S)]
            for row in re.findall(r"<tr>.*?</tr>", table, re.S)]


def test_results_json_stays_si_and_says_so(si_and_engineering):
    (r_si, _), (r_eng, _), _ = si_and_engineering
    assert r_si["units"] == r_eng["units"] == "SI"
    assert r_si["stages"] == r_eng["stages"] and r_si["actuators"] == r_eng["actuators"]


def test_the_page_shows_the_chosen_units(si_and_engineering):
    (r, si), (_, eng), (_, mixed) = si_and_engineering
    s0 = r["stages"][0]
    assert "Peak |F| (N)" in si and "Peak |F| (kN)" in eng and "Peak |M| (kN m)" in eng and "Peak |M| (N mm)" in mixed
    row_si, row_eng = _cells(si, "Peak |F| (")[1], _cells(eng, "Peak |F| (")[1]
    assert float(row_si[0]) == pytest.approx(s0["max_shaking_force"], rel=1e-3)
    assert float(row_eng[0]) == pytest.approx(s0["max_shaking_force"] / 1000, rel=1e-3)
    assert float(row_eng[2]) == pytest.approx(s0["max_shaking_moment"] / 1000, rel=1e-3)
    # the design card: positions in mm (crank counterweight 0.1 m behind the crank's pivot), masses in kg,
    # inertias in kg mm²; with cm and g: cm, g and g cm²
    assert re.search(r"at \(-100, 0\) mm", eng) and re.search(r"at \(-0\.1, 0\) m", si) and re.search(r"at \(-10, 0\) cm", mixed)
    assert "Inertia (kg mm²)" in eng and "Mass (g)" in mixed and "Inertia (g cm²)" in mixed
    # what the ratios are relative to, in the same units
    assert re.search(r"stage&#39;s peak force \([\d.]+ kN\)", eng) and re.search(r"stage&#39;s peak force \([\d.]+ N\)", si)
    # the actuators' table: the crank's torque in kN m, its power in kW
    assert "Peak |effort| (kN m)" in eng and "Peak |power| (kW)" in eng and "Peak |power| (kW)" in mixed


@pytest.mark.parametrize("bad, says", [
    ("imperial", "unknown units preset 'imperial'"), ("{length: inch}", "unit 'inch' is not a length unit"),
    ("{temperature: K}", "unknown quantity 'temperature'"),
])
def test_an_unknown_unit_is_a_located_error(bad, says):
    with pytest.raises(SpecErrors) as e:
        load_text(TEXT + f"\nreport:\n  units: {bad}\n", "s.yaml", SPECS)
    assert says in str(e.value) and "s.yaml:" in str(e.value) and "report.units" in str(e.value)


def test_display_units_convert_every_quantity():
    u = display_units("engineering")
    assert u.text(21140.0, "force") == "21.14 kN" and u.text(51650.0, "N m") == "51.65 kN m"
    assert u.point((-0.05, 3e-18)) == "(-50, 0) mm" and u.text(628.3185307, "speed") == "6000 rpm"
    assert u.text(0.0123, "kg m^2") == "12300 kg mm²" and u.text(3.0, "angle") == "171.9 deg"
    assert display_units().text(0.05, "length") == "0.05 m" and display_units({"preset": "engineering", "force": "N"}).unit("force") == "N"


def test_the_interactive_plots_use_the_units_and_their_csv_stays_si(si_and_engineering):
    import json

    from balpipe.display.units import display_units
    from balpipe.draw import live

    (_, si), (_, eng), _ = si_and_engineering

    def loads(html):
        raw = re.search(r'<script type="application/json" data-live="live-loads">(.*?)</script>', html, re.S).group(1)
        return json.loads(raw)

    a, b = loads(si), loads(eng)
    assert [p["axis"] for p in b["panels"]] == [p["axis"].replace("(N)", "(kN)").replace("(N m)", "(kN m)") for p in a["panels"]]
    assert any("(kN)" in p["title"] for p in b["panels"]) and any("(kN m)" in p["title"] for p in b["panels"])
    for sa, sb in zip(a["series"], b["series"]):
        for key, ya in sa["y"].items():
            assert [y / 1000 if y is not None else None for y in ya] == pytest.approx(sb["y"][key], rel=1e-5, abs=1e-12)
    c = live.Curves([0.0, 1.0], [("a", {"F": [1500.0, -20.0]})], [{"key": "F", "title": "force (N)", "axis": "F (N)"}], [])
    shown = live.shown_in(c, display_units("engineering"))
    assert shown.panels[0]["axis"] == "F (kN)" and list(shown.stages[0][1]["F"]) == [1.5, -0.02]
    assert live.csv_text(shown) == live.csv_text(c)  # the figure's CSV in SI, whatever the page shows
