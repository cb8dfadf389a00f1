"""The papers' names on the pages (issue 22, items 10 and 11): drivers, parts and joints in the
paper's symbols on the design card, the actuator and joint tables and the effort plots, the
spec's names kept beside them (and alone for ``custom``); the numerical detail of the
force-balance conditions in words, its jargon collapsed."""

from __future__ import annotations

import html as htmllib
import re
from pathlib import Path

import pytest

from balpipe import notation as N
from balpipe import registry, study
from balpipe.loader import load
from balpipe.report.notation_table import names_for
from balpipe.report.page import render_page
from balpipe.report.results import results_dict

SPECS = Path(__file__).parents[2] / "specs"


def _names(spec_file: str) -> N.Names:
    return names_for(load(SPECS / spec_file).spec).names


def test_symbol_text_is_plain_unicode():
    assert N.symbol_text("θ_1") == "θ₁"
    assert N.symbol_text("θ_{41}") == "θ₄₁"
    assert N.symbol_text("m_1^*") == "m₁*"
    assert N.symbol_text("m_{cp1} (leg 2)") == "m_cp1 (leg 2)"  # no subscript c: the underscore stays
    assert N.symbol_text("gear 1'") == "gear 1'"


@pytest.mark.parametrize("spec_file, driver, shown", [
    ("paper000_rpr3_idler_loop.yaml", "theta2", "θ₂"),
    ("paper000_rpr3_scott_russell.yaml", "theta3", "θ₃"),
    ("paper001_4rrr.yaml", "A4", "θ₄₁"),
    ("paper002_decoupling.yaml", "q2", "θ₂"),
    ("paper003_com_planning.yaml", "q3", "q₃"),
    ("paper004_five_bar.yaml", "theta1", "θ₁"),
    ("offset_slider_crank.yaml", "crank", "θ₁"),  # paper 000's slider-crank, Sec. 3.1
])
def test_every_paper_family_names_its_drivers_in_the_papers_symbols(spec_file, driver, shown):
    names = _names(spec_file)
    assert names.text("driver", driver) == shown
    assert names.text("driver", driver, spec_name=True) == f"{shown} [{driver}]"
    assert names.sym("driver", driver).paper
    # the page's markup: the symbol, and the model's name beside it to find it in the files
    h = names.html("driver", driver)
    assert '<span class="sym"' in h and f'<span class="spec-name"' in h and f">{driver}</span>" in h


@pytest.mark.parametrize("spec_file, part, symbol", [
    ("paper000_rpr3_idler_loop.yaml", "mcp1 (leg 2)", "m_{cp1} (leg 2)"),
    ("paper000_rpr3_idler_loop.yaml", "cr1.3", "I_{cr1} (leg 3)"),
    ("paper000_rpr3_idler_loop.yaml", "cr4", "I_{cr4}"),
    ("paper000_rpr3_idler_loop.yaml", "cyl2", "link 21"),  # Sec. 2: link i1
    ("paper000_rpr3_scott_russell.yaml", "cyl2", "link 4 (leg 2)"),  # Sec. 3 renumbers the leg
    ("paper000_rpr3_scott_russell.yaml", "mcp4 (leg 1)", "m_{cp4} (leg 1)"),
    ("paper001_4rrr.yaml", "link41", "l_{41}"),
    ("paper002_decoupling.yaml", "gear1p", "gear 1'"),
    ("paper004_five_bar.yaml", "counterweight 3", "m_{CW3}"),
    ("offset_slider_crank.yaml", "counterweight 2", "m_{cp2}"),
])
def test_parts_carry_the_papers_symbols(spec_file, part, symbol):
    assert _names(spec_file).sym("part", part).symbol == symbol


@pytest.mark.parametrize("spec_file, param, shown", [
    ("paper004_five_bar.yaml", "m1_star", "m₁*"),
    ("paper004_five_bar.yaml", "U63", "U₆₃"),
    ("paper000_rpr3_idler_loop.yaml", "Icr4", "I_cr4"),
    ("paper000_rpr3_scott_russell.yaml", "mcp3", "m_cp3"),
    ("paper002_decoupling.yaml", "J1", "J₁"),
])
def test_computed_parameters_carry_the_papers_symbols(spec_file, param, shown):
    assert _names(spec_file).text("param", param) == shown


def test_joints_carry_the_papers_points_and_gear_bearings_their_parts_names():
    n000, n002 = _names("paper000_rpr3_idler_loop.yaml"), _names("paper002_decoupling.yaml")
    assert n000.text("joint", "A1") == "A₁" and n000.text("joint", "B3") == "B₃"
    assert n000.sym("joint", "A1'") is None  # the Scott-Russell crank's pivot: no paper name, not A_1
    assert n002.text("joint", "J1") == "A" and n002.text("joint", "link1-gear1p") == "C"
    assert n002.text("joint", "frame-gear3") == "frame – gear 3"
    assert n000.sym("joint", "frame-cr1.1").symbol == "frame – I_{cr1} (leg 1)"
    assert n000.sym("joint", "SR-B1") is None


def test_a_custom_spec_keeps_the_specs_names():
    spec = load(SPECS / "custom_four_bar_balancing.yaml").spec
    names = names_for(spec).names
    model = registry.unbalanced_model(spec)
    every = ([("driver", d.name) for d in model.drivers] + [("part", b.name) for b in model.bodies]
             + [("joint", j.name) for j in model.joints])
    assert every
    for kind, name in every:
        assert names.sym(kind, name) is None
        assert names.html(kind, name) == htmllib.escape(name)


def test_a_name_of_ours_is_marked():
    names = _names("paper000_rpr3_idler_loop.yaml")
    s = names.sym("driver", "rho1")  # prismatic actuation: the leg length, which the paper does not name
    assert s is not None and not s.paper
    assert "(ours)" in names.html("driver", "rho1") and "not the paper" in names.html("driver", "rho1")


def _section(page: str, start: str, end: str) -> str:
    i = page.index(start)
    return page[i:page.index(end, i)]


_COLLAPSED = re.compile(r'<details(?! class="section")[^>]*>(?:(?!<details).)*?</details>', re.S)


def _visible(page: str) -> str:
    """The page's text a reader sees with its sections open (the page's own ``details.section``
    wrappers, :mod:`balpipe.report.sections`) but nothing else opened: no collapsed
    ``<details>`` within them, scripts, styles or drawings."""
    for tag in ("script", "style", "svg"):
        page = re.sub(rf"<{tag}\b.*?</{tag}>", "", page, flags=re.S)
    while True:
        shorter = _COLLAPSED.sub("", page)
        if shorter == page:
            break
        page = shorter
    return htmllib.unescape(re.sub(r"<[^>]+>", " ", page))


@pytest.fixture(scope="module")
def page002():
    loaded = load(SPECS / "paper002_decoupling.yaml")
    st = study.run(loaded.spec)
    return render_page(st, results_dict(st, "paper002_decoupling.yaml", "h", simulated=False), loaded.text)


def test_paper002_page_names_drivers_parts_and_joints_as_the_paper_does(page002):
    card = _section(page002, 'id="design-summary"', "</section>")
    # the cost factors name the driver θ_2 (spec: q2), not the bare q2
    assert "peak actuator effort × " in card
    assert '(<span class="sym" title="angle of link 2 relative to link 1"><var>θ</var><sub>2</sub></span>' in card
    assert "(q2)" not in card
    # the parts: gear 1' (the model's gear1p beside it), on link 1
    assert re.search(r'<span class="sym"[^>]*>gear 1&#x27;</span> <span class="spec-name"[^>]*>gear1p</span>', card)
    assert re.search(r'on <span class="sym"[^>]*>link 1</span>', card)
    # the actuator table and the joint table
    acts = _section(page002, 'class="efforts-wide"', "</table>")
    assert 'class="group">q1</th>' not in acts and "<var>θ</var><sub>1</sub>" in acts
    joints = _section(page002, "<th>Joint</th>", "</table>")
    assert "<td>J1</td>" not in joints and re.search(r'<td><span class="sym"[^>]*><var>A</var></span>', joints)
    # the joint-load plots' panels, static and interactive: the paper's A, the model's J1 beside it
    assert "A [J1], revolute: |F| (N)" in page002 and "J1, revolute" not in page002
    # the effort plots' panels, static and interactive
    assert "actuator effort: θ₂ [q2]" in page002.lower()
    assert "effort: q2" not in page002
    # the computed parameters and the published numbers: J_1 (the model's J1 beside it)
    params = _section(page002, "Computed parameters</h2>", "</table>")
    assert "<td>J1</td>" not in params and re.search(r'<var>J</var><sub>1</sub></span> <span class="spec-name"', params)


def test_a_custom_page_keeps_the_specs_names_and_keeps_the_numerics_collapsed():
    loaded = load(SPECS / "custom_four_bar_balancing.yaml")
    st = study.run(loaded.spec)
    page = render_page(st, results_dict(st, "custom_four_bar_balancing.yaml", "h", simulated=False), loaded.text)
    card = _section(page, 'id="design-summary"', "</section>")
    assert "<td>cw_crank</td>" in card and 'class="sym"' not in card
    assert "actuator effort: crank" in page.lower()
    # the force-balance conditions in words; the singular values only inside a collapsed <details>
    seen = _visible(page)
    assert "Force-balance conditions" in seen and "clear of round-off by a factor over 10" in seen
    for jargon in ("singular value", "regressor", "row space", "rank tolerance", "sampled states"):
        assert jargon not in seen.lower(), jargon
    details = re.findall(r"<details\b.*?</details>", page, flags=re.S)
    assert any("singular value" in d for d in details)


def test_the_free_floating_run_says_what_the_small_masses_are_in_words():
    from balpipe.validate.floating import FreeFloating

    f = FreeFloating.__new__(FreeFloating)
    f.method, f.small_masses, f.small_mass_fraction = "pymunk", {"cr1": (0.1, 0.0)}, 1.0
    label = f.method_label
    assert label.startswith("simulation (pymunk)")
    assert "massless bodies" not in label and "100 % of the mechanism's mass" in label and "pymunk cannot" in label


def test_the_index_names_each_driver_by_the_papers_symbol():
    """results.json carries each driver's symbol, and the index's per-driver costs read
    "θ₁ [q1]: peak …" (the paper's symbol, the spec's name beside it); a custom spec's driver
    keeps its own name alone."""
    from balpipe.report.site import _costs

    loaded = load(SPECS / "paper002_decoupling.yaml")
    st = study.run(loaded.spec)
    res = results_dict(st, "paper002_decoupling.yaml", "h", simulated=False)
    assert {a["driver"]: a["symbol"] for a in res["actuators"]} == {"q1": "θ₁", "q2": "θ₂"}
    efforts = _costs(res, res["stages"][0], res["stages"][-1])["efforts"]
    assert [e.split(":")[0] for e in efforts] == ["θ₁ [q1]", "θ₂ [q2]"]
    custom = study.run(load(SPECS / "custom_four_bar_balancing.yaml").spec)
    res = results_dict(custom, "custom_four_bar_balancing.yaml", "h", simulated=False)
    assert res["actuators"] and all(a["symbol"] == a["driver"] for a in res["actuators"])
    efforts = _costs(res, res["stages"][0], res["stages"][-1])["efforts"]
    assert efforts and all("[" not in e.split(":")[0] for e in efforts)
