"""What a reader of the report pages sees: every relative figure names its reference, axes carry
their units (the review of the pages, after issue 11)."""

from __future__ import annotations

import html as html_mod
import re
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from balpipe import loader
from balpipe import study as study_mod
from balpipe.draw import figures, live
from balpipe.report import live_plots, page, results
from balpipe.study import ratio_reference

SPECS = Path(__file__).resolve().parents[2] / "specs"


@pytest.fixture
def study003(studies):
    """Paper 003's eight trajectories in one spec (no simulation)."""
    return studies("paper003_com_planning.yaml")


@pytest.fixture
def paper003(study003):
    """The same, each stage given a stand-in simulation whose load errors are 1e-3 N and
    1e-3 N m at every sample (no pymunk run), taken away afterwards."""
    for s in study003.stages:
        t = s.analysis.t
        s.validation = SimpleNamespace(t=t, force=s.analysis.force, moment=s.analysis.moment,
                                       force_error=np.full(len(t), 1e-3), moment_error=np.full(len(t), 1e-3),
                                       to_json=dict)
    yield study003
    for s in study003.stages:
        s.validation = None


def test_residuals_are_relative_to_each_stages_own_reference(paper003):
    st = paper003
    rows, caption = page.residual_rows(st, st.stages)
    recorded = {m["name"]: m["reference"] for m in results.results_dict(st, "x", "h", False)["stages"]}
    by_name = {s.stage.name: s for s in st.stages}
    firsts = {}
    for s in st.stages:  # the unbalanced stage of each motion: the first of its group
        firsts.setdefault(s.stage.group, s)
    refs = set()
    for s, (label, t, fe, me, F0, M0) in zip(st.stages, rows):
        own = firsts[s.stage.group]
        assert recorded[s.stage.name] == own.stage.name  # what results.json states
        expected = ratio_reference(by_name[recorded[s.stage.name]])
        assert (F0, M0) == (expected.force, expected.moment), s.stage.name
        refs.add((F0, M0))
        assert f"{F0:.4g} N" in caption and f"{M0:.4g} N m" in caption
    assert len(refs) == len(firsts) > 1  # eight motions, eight references: the test can tell them apart
    assert (rows[0][4], rows[0][5]) == (st.checks["reference"]["force"], st.checks["reference"]["moment"])
    # several references in one figure: the legend names each; one reference: the titles do
    groups = list(firsts)
    first = [r for r, s in zip(rows, st.stages) if s.stage.group == groups[0]]
    two = first + [r for r, s in zip(rows, st.stages) if s.stage.group == groups[1]]
    data = live.data(live_plots.residuals(two))
    titles = [p["title"] for p in data["panels"]]
    assert "F_ref per stage" in titles[0] and "M_ref per stage" in titles[1]
    for r, series in zip(two, data["series"]):
        assert series["label"].endswith(f"(F_ref {r[4]:.4g} N, M_ref {r[5]:.4g} N m)")
    one = live.data(live_plots.residuals(first))
    F0, M0 = first[0][4], first[0][5]
    assert f"F_ref = {F0:.4g} N" in one["panels"][0]["title"] and f"M_ref = {M0:.4g} N m" in one["panels"][1]["title"]
    assert "|F_sim − F_analytic| / F_ref" in one["panels"][0]["title"] and [p["axis"] for p in one["panels"]] == [
        "|ΔF| / F_ref", "|ΔM| / M_ref"]
    assert all(p["log"] for p in one["panels"])  # residuals span decades: a log axis
    # each curve is the stage's error over its own reference (1e-3 N / F_ref), to 6 digits
    assert one["series"][0]["y"]["force"][5] == pytest.approx(1e-3 / F0, rel=1e-5)


def test_the_pages_residual_figure_says_what_it_divides_by(paper003):
    figs = page.study_figures(paper003)
    [(title, html, caption)] = figs["residuals"]
    ref = paper003.reference
    assert 'id="live-residuals"' in html and "<svg" not in html  # drawn by the browser, no matplotlib
    assert f"F_ref = {ref.force:.4g} N" in html and f"F_ref = {ref.force:.4g} N" in caption
    assert f"M_ref = {ref.moment:.4g} N m" in caption and "'" + paper003.stages[0].stage.label + "'" in caption


def _fits(fig) -> list[str]:
    """The axis labels of ``fig`` that leave the figure (cut off in the SVG)."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    W, H = fig.bbox.width, fig.bbox.height
    out = []
    for ax in fig.axes:
        for lab in (ax.xaxis.label, ax.yaxis.label, ax.title):
            x0, y0, x1, y1 = lab.get_window_extent(r).extents
            if lab.get_text() and (x0 < -0.5 or y0 < -0.5 or x1 > W + 0.5 or y1 > H + 0.5):
                out.append(lab.get_text())
    return out


def test_sweep_page_units_round_off_and_labels_that_fit(tmp_path, monkeypatch):
    from balpipe.report import sweep_page
    from balpipe.sweep import plan, run, write

    p = plan(str(Path(__file__).parents[1] / "fixtures" / "sweep_block.yaml"))
    res = run(p, jobs=1)
    write(res, str(tmp_path))
    html = (tmp_path / "index.html").read_text(encoding="utf-8")
    # the varied fields' SI values carry their unit, the effort its unit (a crank: N m)
    assert "mechanism.crank.mass (kg)" in html and "mechanism.slider.mass (kg)" in html and "(SI)" not in html
    assert "Peak effort (N m)" in html and "peak actuator effort (N m)" in html
    # the counterweight stage cancels the force: round-off, shown as such, not as 1e-13 N
    front = [r for r in res.rows if r.get("pareto_moment") or r.get("pareto_effort")]
    assert front and all(r["max_shaking_force"] <= 1e-9 * r["unbalanced_max_shaking_force"] for r in front)
    assert "0 (&lt; 1e-9 of unbalanced)" in html or "0 (< 1e-9 of unbalanced)" in html
    assert not re.search(r"<td class=\"num\">\d\.\d+e-1\d</td>", html)
    # every axis label of the Pareto figures lies inside its figure
    drawn = []
    monkeypatch.setattr(sweep_page, "to_svg", lambda fig, prefix: drawn.append(fig) or "<svg/>")
    sweep_page.render(res, set())
    assert len(drawn) == 2
    for fig in drawn:
        assert _fits(fig) == []
        figures.plt.close(fig)


def _legends_clear_of_the_data(fig) -> list[str]:
    """Legends (of the figure or of an axes) that cover part of an axes' plotting area."""
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    legends = list(fig.legends) + [ax.get_legend() for ax in fig.axes if ax.get_legend() is not None]
    out = []
    for leg in legends:
        lb = leg.get_window_extent(r)
        for ax in fig.axes:
            if lb.overlaps(ax.get_window_extent(r)):
                out.append(", ".join(t.get_text() for t in leg.get_texts()))
    return out


def test_simulation_figures_are_live_plots_with_every_stage(monkeypatch):
    """The time plots with one curve per stage of the simulation (residuals, tracking, drift) are
    drawn by the browser (uPlot's legend is under its plot, never over a curve): no matplotlib
    figure is drawn for them, and every stage, long names included, has its curve and legend entry."""
    drawn = []
    monkeypatch.setattr(figures, "to_svg", lambda fig, prefix: drawn.append(prefix) or "<svg/>")
    t = np.linspace(0.0, 0.5, 101)
    names = ["unbalanced", "counterweights", "counterweights + counter-rotations",
             "force balance only: least-mass counterweights", "crank counterweight only: 1 kg at 80 mm behind O2"]
    err = 1e-6 * (1 + np.abs(np.sin(20 * t)))
    figs = [live_plots.residuals([(n, t, err, err, 10.0, 2.0) for n in names]),
            live_plots.tracking(t, [(n + ": crank", err) for n in names]),
            live_plots.drift([(n, t, np.stack([err, err], 1), err) for n in names])]
    assert drawn == []
    for c in figs:
        data = live.data(c)
        assert [s.get("long", s["label"]) for s in data["series"]][:len(names)] in (names, [n + ": crank" for n in names])
        assert all(len(s["y"]) == len(data["panels"]) for s in data["series"])
    assert live.data(figs[2])["series"][0]["y"]["drift"][-1] == pytest.approx(1000 * np.hypot(err[-1], err[-1]), rel=1e-5)


def test_rpr3_factor_table_gives_the_effort_unit_and_one_full_stop(studies):
    st = studies("paper000_rpr3_idler_loop.yaml")
    table, caption = {title: (body, cap) for title, body, cap in st.extra_figures()}["Peak loads and the moment factor"]
    assert "peak actuator effort (N m)</th>" in table  # revolute actuators A_i
    assert caption.endswith("3-RPR).") and ".." not in caption and "reports 17 " in caption


def test_index_lead_agrees_in_number():
    from balpipe.report import site_filter
    from balpipe.report.render import environment

    def lead(flagged: int) -> str:
        html = environment().get_template("index.html").render(
            entries=[], n_ok=12, n_failed=0, n_flagged=flagged, n_invalid=0, n_ok_cli=12 + flagged,
            filters=site_filter.options([]))
        return html[html.index('class="lead"'):][:600]

    assert "12 pass and 1 has stages that cannot be built" in lead(1)
    assert "12 pass and 2 have stages that cannot be built" in lead(2)


def _stage_rows(html: str) -> dict:
    """Stage table of a page: label -> the row's HTML."""
    table = html[html.index('<h2 id="balancing-stages"'):]
    table = table[:table.index("</table>")]
    rows = {}
    for row in table.split("<tr>")[2:]:
        m = re.search(r"<strong>(.*?)</strong>", row)
        rows[m.group(1)] = row
    return rows


def test_stage_table_names_each_ratios_reference_and_claims_only_what_is_claimed(study003):
    st = study003
    html = page.render_page(st, results.results_dict(st, "x", "h", False), "")
    rows = _stage_rows(html)
    by_name = {s.stage.name: s.stage.label for s in st.stages}
    for s in st.stages:
        row = rows[s.stage.label]
        ref = st.reference_stage(s)
        if ref is s:
            assert ">reference</span>" in row  # its own reference: the claim column says so
            if s is not st.stages[0]:
                assert "reference of the ratios of its motion" in row
        else:
            assert "— (no claim)" in row and ">reference</span>" not in row, s.stage.name
            if ref is not st.stages[0]:
                assert f"ratios vs {by_name[ref.stage.name]}" in row, s.stage.name
    assert "for the stages of the first motion (" + st.stages[0].stage.label + ")" in html


def test_single_motion_page_keeps_one_reference_sentence(pages):
    html = pages("paper000_rpr3_idler_loop.yaml")
    rows = _stage_rows(html)
    assert ">reference</span>" in rows["unbalanced"] and "— (no claim)" in rows["idler loop"]
    assert "first motion" not in html and "ratios vs" not in html


def test_tracking_error_caption_gives_each_travel():
    st = study_mod.run(loader.load(SPECS / "offset_slider_crank.yaml").spec)
    for s in st.stages:
        t = s.analysis.t
        s.torque = SimpleNamespace(t=t, travel={"crank": 2.5}, tracking={"crank": np.full(len(t), 1e-6)})
    [(title, svg, caption)] = page.study_figures(st)["torque"]
    assert "relative to its travel" in caption and "θ₁ [crank] 2.5 rad" in caption  # the paper's symbol, then the spec's name
    assert "|q_sim − q_plan| / travel" in svg and 'id="live-tracking"' in svg  # over time, drawn by the browser


def test_no_two_stages_look_alike_and_the_caption_names_each_style(monkeypatch, studies, pages):
    """A spec with compared designs has seven stages: the loads figure draws each in its own
    line, colour and marker, and the page's key says which is which (it named only four): each
    stage's words, its short name, its long label as the tooltip."""
    looks = [(str(figures.style(k)["color"]), figures.style(k)["linestyle"], figures.marked(k, 100)["marker"])
             for k in range(10)]
    assert len(set(looks)) == len(looks)
    assert len({figures.style_text(k) for k in range(10)}) == 10
    st = studies("paper000_rpr3_scott_russell_corrected.yaml")
    shown = page.shown_stages(st)
    assert len(shown) == 7
    html = pages("paper000_rpr3_scott_russell_corrected.yaml")
    key = html[html.index('id="style-legend"'):]
    key = html_mod.unescape(key[:key.index("</p>")])
    styles = page.stage_styles(st)
    for k, s in enumerate(shown):
        entry = key[key.index(f'data-stage="{styles[s.stage.name][1]}"'):]
        entry = entry[:entry.index("</span></span>")]
        assert f'title="{s.stage.label}"' in entry and f"({figures.style_text(k)})" in entry, (k, entry)


def test_dimensionless_parameters_say_so_and_round_off_before_counter_rotations_is_zero():
    st = study_mod.run(loader.load(SPECS / "scott_russell.yaml").spec)
    html = page.render_page(st, results.results_dict(st, "x", "h", False), "")
    params = html[html.index("Computed parameters</h2>"):]
    params = params[:params.index("</table>")]
    row = next(r for r in params.split("<tr>") if ">rcp1</span></td>" in r)  # r_cp1, the model's rcp1 beside it
    assert '<td class="unit">1</td>' in row  # rcp1 = position / L1: a ratio, unit 1
    side = html[html.index("Designs side by side</h2>"):]
    side = side[:side.index("</table>")]
    last = side.split("<tr>")[-1]  # the fully balanced stage: its moment before counter-rotations is round-off
    cells = re.findall(r"<td[^>]*>(.*?)</td>", last, re.S)
    assert html_mod.unescape(cells[-1]).startswith("0 (< 1e-9 of reference)"), cells


def test_player_writes_no_negative_zero():
    """The player's frame readout ('frame: (0.00, 0.00) mm, 0.000 deg') never shows -0.000 for a
    balanced stage's round-off rotation: its fixed() helper, run by node."""
    import shutil
    import subprocess

    from balpipe.draw import player

    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed")
    st = study_mod.run(loader.load(SPECS / "scott_russell.yaml").spec)
    stages = [{"label": s.stage.label, "model": s.stage.model, "t": s.analysis.t, "base": np.zeros((len(s.analysis.t), 3)),
               "poses": np.asarray(s.analysis.frame_pose)} for s in st.stages]
    html = player.player_html(stages)
    fn = re.search(r"^function fixed\(v, d\) \{.*?\}  // no \"-0.000\"$", html, re.M)
    assert fn, "fixed() not in the player"
    assert "${fixed(rot, 3)} deg" in html and "rot.toFixed" not in html
    js = fn.group(0) + "\nconsole.log([fixed(-1e-6, 3), fixed(-0.0, 2), fixed(-0.004, 2), fixed(-0.5, 3), fixed(2.25, 1)].join('|'))"
    out = subprocess.run([node, "-e", js], capture_output=True, text=True, check=True).stdout.strip()
    assert out == "0.000|0.00|0.00|-0.500|2.3" or out == "0.000|0.00|0.00|-0.500|2.2", out


def test_paper003_square_figure_keeps_names_and_legends_off_the_paths(study003, monkeypatch):
    """Fig. 2 of paper 003 (matplotlib; the φ figure is a live plot, its legend under the plot)."""
    from matplotlib.text import Text

    from balpipe.draw import labels

    drawn = {}
    monkeypatch.setattr(figures, "to_svg", lambda fig, prefix: drawn.setdefault(prefix, fig) and "<svg/>")
    list(study003.extra_figures())
    assert "com-phi" not in drawn
    assert _legends_clear_of_the_data(drawn["com-square"]) == []
    assert _fits(drawn["com-square"]) == []
    fig = drawn["com-square"]
    ax = fig.axes[0]
    fig.canvas.draw()
    r = fig.canvas.get_renderer()
    px = ax.transData.transform
    segs = []
    for t in ax.texts:  # the tip's paths: arrows from the start to the end point
        if not t.get_text() and getattr(t, "arrow_patch", None) is not None:
            segs.append((tuple(px(t.xyann)), tuple(px(t.xy))))
    for line in ax.lines:
        if line.get_linestyle() not in ("None", "", " ") and len(line.get_xydata()) >= 2:
            xy = px(line.get_xydata())
            segs += [(tuple(a), tuple(b)) for a, b in zip(xy[:-1], xy[1:])]
    names = [t for t in ax.texts if t.get_text()]
    assert len(names) == 17  # P1-P16 and E
    for t in names:
        box = Text.get_window_extent(t, r).extents
        hits = [sg for sg in segs if labels.segment_hits_box(sg, box)]
        assert not hits, (t.get_text(), hits[:2])
    for prefix, f in drawn.items():
        figures.plt.close(f)


def test_history_table_shows_round_off_as_zero():
    from balpipe.report import history_page

    c = {"stages": [{"max_shaking_force": 3.661, "max_shaking_moment": 1.328},
                    {"max_shaking_force": 3.178e-14, "max_shaking_moment": 0.5}]}
    assert history_page._peaks(c, "max_shaking_force") == "3.661 → 0 (< 1e-9 of unbalanced)"
    assert history_page._peaks(c, "max_shaking_moment") == "1.328 → 0.5"  # a real peak stays


def test_unrealisable_parts_write_their_units_as_the_page_does(pages):
    html = pages("paper004_five_bar.yaml")
    table = html[html.index('<h2 id="balancing-stages"'):]
    table = table[:table.index("</table>")]
    assert "centroidal inertia" in table and "kg m²" in table and "kg m^2" not in table
