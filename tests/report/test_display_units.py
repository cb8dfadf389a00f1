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
