"""The inputs table in the papers' notation (issue 11, item 6): every input of a paper spec has
the paper's symbol (or a name of ours, marked), a unit and its spec field path."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from balpipe import notation as N
from balpipe.loader import load
from balpipe.registry import METHODS, TEMPLATES
from balpipe.report.inputs import input_rows
from balpipe.report.notation_table import notation_groups, notation_rows

from conftest import slider_crank_spec

SPECS = Path(__file__).parents[2] / "specs"
ALL_SPECS = sorted(SPECS.glob("*.yaml"))


def _rows(name: str) -> dict[str, dict]:
    return {r["path"]: r for r in notation_rows(load(SPECS / name).spec)}


def _numeric(value: str) -> bool:
    return bool(re.fullmatch(r"\(?[-+0-9.e, ]+\)?", value)) and any(c.isdigit() for c in value)


def test_every_template_and_method_declares_its_notation():
    assert {k for k, t in TEMPLATES.items() if t.notation is None} == set()
    assert {k for k, m in METHODS.items() if m.notation is None} == set()


@pytest.mark.parametrize("path", ALL_SPECS, ids=lambda p: p.stem)
def test_every_input_of_every_spec_has_a_symbol(path):
    spec = load(path).spec
    rows = notation_rows(spec)
    numeric = [r for r in rows if _numeric(r["value"])]
    assert len(numeric) > 10
    assert [r["path"] for r in rows if r["missing"]] == []
    # every quantity with a dimension carries its unit (counts and ratios have none)
    for r in numeric:
        leaf = r["path"].rsplit(".", 1)[-1]
        if leaf in ("length", "mass", "inertia", "com", "duration", "start", "end"):
            assert r["unit"], r["path"]
    # every input of input_rows is in the table once (merged drive components count once)
    shown = {r["path"] for r in rows}
    for r in input_rows(spec):
        p = r["path"]
        base = p.split("[", 1)[0] if p.startswith("motion.drive.") else p
        assert p in shown or base in shown or p.startswith(("motion.drive.", "motion.accel_fraction")), p


@pytest.mark.parametrize("path", [p for p in ALL_SPECS if not p.stem.startswith("custom")], ids=lambda p: p.stem)
def test_paper_specs_use_the_papers_symbols_for_their_mass_parameters(path):
    """The masses of a paper spec carry the paper's own symbol, never one of ours: a mass marked
    "not in the paper" would mean a missing reading (inertias and some lengths may be ours:
    paper 001 gives no inertia symbol, paper 002 none for link 2's length)."""
    spec = load(path).spec
    assert spec.paper
    masses = [r for r in notation_rows(spec) if r["path"].startswith("mechanism.") and r["path"].endswith(".mass")]
    assert masses
    assert [r["path"] for r in masses if r["not_in_paper"] and r["value"] != "0"] == []


def test_paper004_symbols():
    rows = _rows("paper004_five_bar.yaml")
    m1 = rows["mechanism.links.proximal.mass"]
    assert str(m1["symbol"]) == "<var>m</var><sub>1</sub> = <var>m</var><sub>2</sub>"
    assert (m1["value"], m1["unit"], m1["group"]) == ("1.2", "kg", "Mass parameters")
    assert str(rows["mechanism.links.proximal.length"]["symbol"]) == "<var>l</var><sub>1</sub>"
    assert str(rows["mechanism.coupling.r1p"]["symbol"]) == "<var>r</var><sub>1&#x27;</sub>"
    assert rows["mechanism.links.proximal.length"]["group"] == "Geometry"
    cw = rows["balancing.counterweights.proximal"]
    assert "<sub>CW1</sub>" in str(cw["symbol"]) and cw["unit"] == "m" and cw["group"] == "Balancing method"
    assert "<var>U</var><sub>63</sub>" in str(rows["balancing.counter_rotation.ratio"]["symbol"])
    # the gripper's end positions as the paper writes them, both components in one row, in SI
    p = rows["motion.drive.gripper.start"]
    assert "<var>P</var><sub>i</sub>" in str(p["symbol"]) and (p["value"], p["unit"]) == ("(-0.06, 0.45)", "m")
    # the duration is ours: the paper gives none; balpipe's settings are not paper quantities
    assert rows["motion.duration"]["not_in_paper"]
    assert not rows["analysis.samples"]["not_in_paper"] and not rows["balancing.method"]["not_in_paper"]
    assert not rows["balancing.point_mass_stage"]["not_in_paper"]


def test_paper001_leg_symbols_carry_the_leg_number():
    rows = _rows("paper001_4rrr.yaml")
    assert str(rows["mechanism.legs.3.proximal.mass"]["symbol"]) == "<var>m</var><sub>31</sub>"
    assert str(rows["mechanism.legs.2.distal.com"]["symbol"]) == "<var>p</var><sub>22</sub>"
    assert str(rows["mechanism.legs.4.distal.com_offset"]["symbol"]) == "<var>q</var><sub>42</sub>"
    assert str(rows["mechanism.platform.half_width"]["symbol"]) == "<var>c</var><sub>5</sub>"
    assert "leg 3" in rows["mechanism.legs.3.pivot"]["text"]


def test_a_method_renames_the_templates_parts_as_its_paper_section_does():
    """Paper 000 calls the 3-RPR's cylinder link 1 in Sec. 2 (idler loop) and link 4 in Sec. 3
    (Scott-Russell legs); the compared idler design keeps its own method's symbols."""
    idler = _rows("paper000_rpr3_idler_loop.yaml")
    sr = _rows("paper000_rpr3_scott_russell_corrected.yaml")
    assert str(idler["mechanism.cylinder.mass"]["symbol"]) == "<var>m</var><sub>1</sub>"
    assert str(sr["mechanism.cylinder.mass"]["symbol"]) == "<var>m</var><sub>4</sub>"
    assert str(sr["mechanism.piston.length"]["symbol"]) == "<var>L</var><sub>3</sub>"
    design = sr["compare[0].balancing.link5.mass"]
    assert str(design["symbol"]) == "<var>m</var><sub>5</sub>" and design["group"].startswith("Compared design: idler")


def test_serial_arm_symbols_follow_the_paper_of_the_method():
    p2, p3 = _rows("paper002_decoupling.yaml"), _rows("paper003_com_planning.yaml")
    assert str(p2["mechanism.links[0].com"]["symbol"]) == "<var>l</var><sub>AS1</sub>"
    assert str(p2["mechanism.links[1].inertia"]["symbol"]) == "<var>I</var><sub>S2</sub>"
    assert str(p2["motion.drive.q1.start"]["symbol"]) == "<var>θ</var><sub>1</sub>(0)"
    assert str(p3["mechanism.links[1].length"]["symbol"]) == "<var>l</var><sub>AB</sub>"
    assert str(p3["mechanism.links[0].com"]["symbol"]) == "<var>r</var><sub>1</sub>"
    assert str(p3["mechanism.payload.mass"]["symbol"]) == "<var>m</var><sub>p</sub>"
    assert p3["balancing.torque_rate_limit"]["unit"] == "N m/s"


def test_custom_symbols_are_named_after_the_specs_bodies():
    text = (SPECS / "custom_four_bar_balancing.yaml").read_text().replace("crank", "kurbel")
    from balpipe.loader import load_text

    spec, _ = load_text(text, "x.yaml")
    rows = {r["path"]: r for r in notation_rows(spec)}
    assert str(rows["mechanism.bodies[0].mass"]["symbol"]) == "<var>m</var><sub>kurbel</sub>"
    assert str(rows["mechanism.bodies[0].inertia"]["symbol"]) == "<var>I</var><sub>kurbel</sub>"
    assert str(rows["motion.drive.kurbel.start"]["symbol"]) == "<var>q</var><sub>kurbel</sub>(0)"
    assert str(rows["balancing.counter_rotations[0].ratio"]["symbol"]) == "<var>U</var><sub>disc_kurbel</sub>"
    # a spec without a paper marks nothing "not in the paper"
    assert not any(r["not_in_paper"] for r in rows.values())
    # the pose mixes lengths and an angle: each element has its unit
    assert rows["mechanism.bodies[1].pose"]["unit"] == "m, m, rad"


def test_pose_units_in_input_rows():
    """input_rows (also used by balpipe diff) gave a pose's angle the unit of its lengths."""
    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    units = {r["path"]: r["unit"] for r in input_rows(spec)}
    assert units["mechanism.bodies[1].pose"] == "m, m, rad"
    assert units["mechanism.bodies[1].com"] == "m"


def test_groups_in_order_and_compared_designs_last():
    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    names = [g["name"] for g in notation_groups(spec)]
    assert names[:5] == list(N.GROUPS)
    assert names[5:] == ["Compared design: force balance only", "Compared design: crank counterweight only"]


def test_drive_ends_in_si_and_idle_settings_left_out():
    rows = _rows("scott_russell.yaml")
    start = rows["motion.drive.crank.start"]
    assert (start["value"], start["unit"]) == ("-1.396", "rad")  # -80 deg
    assert str(rows["motion.duration"]["symbol"]) == "<var>t</var><sub>f</sub>"
    # quintic law: the boundary rates and the trapezoidal fraction have no effect, not shown
    assert "motion.drive.crank.start_velocity" not in rows and "motion.accel_fraction" not in rows


@pytest.mark.parametrize("seed", range(4))
def test_random_slider_cranks_with_polynomial_and_trapezoidal_laws(seed):
    rng = np.random.default_rng(seed)
    poly = slider_crank_spec(rng, law="polynomial")
    rows = {r["path"]: r for r in notation_rows(poly)}
    assert [p for p, r in rows.items() if r["missing"]] == []
    v = rows["motion.drive.crank.start_velocity"]
    assert v["unit"] == "rad/s" and "θ̇" in str(v["symbol"])
    assert rows["motion.drive.crank.end_acceleration"]["unit"] == "rad/s^2"
    trap = slider_crank_spec(rng, law="trapezoidal")
    rows = {r["path"]: r for r in notation_rows(trap)}
    assert "motion.accel_fraction" in rows and "motion.drive.crank.start_velocity" not in rows


def test_symbol_markup():
    assert N.symbol_html("m_{CW1} = m_2") == "<var>m</var><sub>CW1</sub> = <var>m</var><sub>2</sub>"
    assert N.symbol_html("θ̇_1(t_f)") == "<var>θ̇</var><sub>1</sub>(<var>t</var><sub>f</sub>)"
    assert N.symbol_html("law") == "law"  # a word, not a product of variables
    assert N.symbol_html("`cw_a<b>`") == '<span class="name">cw_a&lt;b&gt;</span>'
    assert N.symbol_html("m_{<script>}") == "<var>m</var><sub>&lt;script&gt;</sub>"
    assert N.text_html("along A_jB_j from S_{1i}") == "along A<sub>j</sub>B<sub>j</sub> from S<sub>1i</sub>"
    assert N.text_html("mass of `cw_crank`") == 'mass of <span class="name">cw_crank</span>'
    assert N.dotted("θ_1", 2) == "θ̈_1"


def test_lookup_first_table_wins_and_captures_fill_in():
    a = {"mechanism.x": N.Sym("a", "from a")}
    b = {"mechanism.x": N.Sym("b", "from b"), "mechanism.legs.<i>.mass": N.Sym("m_{<i>1}", "leg <i>")}
    assert N.lookup([a, b], "mechanism.x").symbol == "a"
    s = N.lookup([a, b], "mechanism.legs.3.mass")
    assert (s.symbol, s.text) == ("m_{31}", "leg 3")
    assert N.lookup([a, b], "mechanism.legs.3.x.mass") is None  # a capture is one segment


def test_page_shows_the_inputs_in_the_papers_notation():
    """Paper 004's page: m1 = m2 with kg, grouped, the field path beside it, the YAML below."""
    from balpipe import study
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict

    loaded = load(SPECS / "paper004_five_bar.yaml")
    st = study.run(loaded.spec)
    html = render_page(st, results_dict(st, "paper004_five_bar.yaml", "h", simulated=False), loaded.text)
    table = html[html.index('<table class="inputs notation">'):]
    table = table[:table.index("</table>")]
    row = next(r for r in table.split("<tr>") if "<code>mechanism.links.proximal.mass</code>" in r)
    assert '<td class="sym"><var>m</var><sub>1</sub> = <var>m</var><sub>2</sub></td>' in row
    assert '<td class="num">1.2</td><td class="unit">kg</td>' in row
    for group in N.GROUPS:
        assert f'<th colspan="5" scope="rowgroup">{group}</th>' in table
    assert table.index("Geometry") < table.index("Mass parameters") < table.index("Motion")
    assert "(not in the paper)" in table  # e.g. the duration, which the paper does not give
    assert "kg m²" in table
    assert html.index('<table class="inputs notation">') < html.index("<pre>" + loaded.text[:40])


def test_the_external_loads_and_the_frame_on_its_mounts_are_inputs_in_groups_of_their_own():
    """The compressor's gas pressure and friction and the V-twin's frame and mounts are in the
    inputs table with their units, each in its own group after the analysis settings."""
    groups = {g["name"]: g["rows"] for g in notation_groups(load(SPECS / "custom_v_twin_6000rpm.yaml").spec)}
    frame = {r["path"]: r for r in groups["The frame on its mounts"]}
    assert frame["frame.mounts[0].kx"]["value"] == "250000" and frame["frame.mounts[0].kx"]["unit"] == "N/m"
    assert frame["frame.limits.velocity_rms"]["unit"] == "m/s" and frame["frame.mass"]["unit"] == "kg"
    names = list(groups)
    assert names.index("Analysis and validation") < names.index("The frame on its mounts")
    loads = {r["path"]: r for r in dict((g["name"], g["rows"]) for g in
             notation_groups(load(SPECS / "custom_compressor_gas_pressure.yaml").spec))["External loads"]}
    assert loads["loads[0].area"]["unit"] == "m^2" and loads["loads[0].type"]["value"] == "pressure"
    assert not any(r["missing"] for r in list(frame.values()) + list(loads.values()))
