"""The interactive plots' data (issue 22, report/live_plots.py): one builder per figure kind
(shaking loads, actuator efforts, joint loads), each curve the analysis's own values at the kept
samples, in its stage's line style, with its unit; thinned and rounded the same way every time."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from balpipe.loader import load
from balpipe.draw import live as LV
from balpipe.report import live_plots as LP
from balpipe.report import present
from balpipe.report.page import study_figures
from balpipe.report.results import joint_load_series, joint_load_table
from balpipe.study import run

SPECS = Path(__file__).parents[2] / "specs"


@pytest.fixture
def study(studies):
    """The offset slider-crank: a crank torque, three revolutes and a prismatic guide, 501 samples."""
    return studies("offset_slider_crank.yaml")


def _stages(study) -> list:
    return [(s.stage.label, s.analysis) for s in study.stages]


def _kept(data: dict, t: np.ndarray) -> np.ndarray:
    """Indices of the kept samples, found from their times."""
    k = np.searchsorted(t, data["t"])
    assert np.allclose(t[k], data["t"], rtol=1e-5, atol=0)
    return k


def _close(shown: list, exact: np.ndarray, floor: float = 0.0) -> None:
    """Shown values are the exact ones to the 6 significant digits they keep; those within the
    panel's round-off ``floor`` are written 0 (draw/live.py's _round)."""
    exact = np.where(np.abs(exact) <= floor, 0.0, exact)
    assert len(shown) == len(exact)
    assert np.allclose(shown, exact, rtol=1e-5, atol=1e-12 * max(1.0, float(np.max(np.abs(exact)))))


def test_efforts_are_the_analysis_efforts_at_the_kept_samples(study):
    units = {d.name: present.driver_unit(s.stage.model, d.name) for s in study.stages for d in s.stage.model.drivers}
    data = LV.data(LP.efforts(_stages(study), units))
    t = study.stages[0].analysis.t
    k = _kept(data, t)
    assert k[0] == 0 and k[-1] == len(t) - 1 and len(k) == min(len(t), LV.POINTS)  # first and last kept
    assert [p["key"] for p in data["panels"]] == ["crank"]
    assert data["panels"][0]["axis"] == "torque (N m)" and "(N m)" in data["panels"][0]["title"]
    for n, (s, series) in enumerate(zip(study.stages, data["series"])):
        assert series["label"] == s.stage.label
        assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(n)  # the static style
        _close(series["y"]["crank"], s.analysis.efforts["crank"][k])


def test_joint_loads_are_the_table_s_joint_loads_at_the_kept_samples(study):
    data = LV.data(LP.joints(_stages(study)))
    t = study.stages[0].analysis.t
    k = _kept(data, t)
    table = joint_load_table(study)
    # a panel per row of the joint-load table, in its order, with the row's unit
    assert [p["key"] for p in data["panels"]] == ["A.F", "B.F", "C.F", "guide.N"]
    assert [p["title"] for p in data["panels"]] == [f"{r['joint']}, {r['kind']} ({r['unit']})" for r in table]
    assert [p["axis"] for p in data["panels"]] == ["|F| (N)", "|F| (N)", "|F| (N)", "|N| (N)"]
    for s, series in zip(study.stages, data["series"]):
        for joint, comp, _, _, values in joint_load_series(s.analysis):
            _close(series["y"][f"{joint}.{comp}"], values[k])
            row = next(r for r in table if r["joint"] == joint)
            assert row["peaks"][s.stage.name] == float(np.max(values))  # one source for table and plot
    # the revolute's load is the magnitude of its reaction components
    comps = study.stages[0].analysis.reactions["A"]
    _close(data["series"][0]["y"]["A.F"], np.hypot(comps["Fx"], comps["Fy"])[k])


def test_loads_are_the_shaking_loads(study):
    data = LV.data(LP.loads(_stages(study)))
    k = _kept(data, study.stages[0].analysis.t)
    for s, series in zip(study.stages, data["series"]):
        F = s.analysis.force
        _close(series["y"]["Fx"], F[k, 0])
        _close(series["y"]["Fy"], F[k, 1])
        _close(series["y"]["F"], np.hypot(F[:, 0], F[:, 1])[k])
        _close(series["y"]["M"], s.analysis.moment[k])
    assert [p["axis"] for p in data["panels"]] == ["Fx (N)", "Fy (N)", "|F| (N)", "M (N m)"]


def test_the_loads_have_markers_pymunk_curves_and_the_coincidence_note():
    """What the printed loads figure drew, the live one draws (issue 22, its static SVG gone):
    each stage's markers at its staggered samples (figures.marked over the kept samples), each
    stage's pymunk run dotted in its simulation colour, and the note on coinciding curves."""
    from types import SimpleNamespace

    from balpipe.draw import figures

    t = np.linspace(0.0, 0.5, 101)
    F = np.stack([np.sin(9 * t), np.cos(9 * t)], axis=1)
    stages = [("unbalanced", SimpleNamespace(t=t, force=F, moment=np.sin(5 * t))),
              ("counterweights", SimpleNamespace(t=t, force=0 * F, moment=2 * np.sin(5 * t))),
              ("counter-rotations", SimpleNamespace(t=t, force=0 * F, moment=0 * t))]
    sims = [(t, F * 1.001, np.sin(5 * t)), None, None]
    data = LV.data(LP.loads(stages, sims))
    assert data == LV.data(LP.loads(stages, sims))
    assert [s["label"] for s in data["series"]] == ["unbalanced", "counterweights", "counter-rotations",
                                                     "unbalanced (pymunk)"]
    for k in range(3):
        start, every = figures.marked(k, len(t))["markevery"]
        assert data["series"][k]["marker"] == [figures.marker(k), start, every]
        assert {key: data["series"][k][key] for key in ("stroke", "dash", "width")} == LV.line_style(k)
    sim = data["series"][3]
    assert "marker" not in sim and sim["dash"] == LV.DASHES[":"] and sim["width"] == 1.0
    _close(sim["y"]["Fx"], 1.001 * F[:, 0])
    assert LP.coincide_notes(stages) == ["Coincide in force Fx, force Fy, force |F|: counterweights = counter-rotations"]


def test_the_residual_figure_names_curves_drawn_over_each_other():
    """Two stages whose simulations leave the same residuals draw one curve over the other: the
    page says which. On a log axis, residuals of 1e-12 and 2e-12 under a 1e-3 peak are no match."""
    t = np.linspace(0.0, 1.0, 51)
    big = 1e-3 * (1.0 + np.sin(7 * t) ** 2)
    rows = [("unbalanced", t, big, big, 10.0, 2.0), ("crank only", t, 1e-12 + 0 * t, big.copy(), 10.0, 2.0),
            ("balanced", t, 2e-12 + 0 * t, 1e-12 + 0 * t, 10.0, 2.0)]
    assert LP.residual_notes(LP.residuals(rows)) == ["Coincide in moment residual: unbalanced = crank only"]
    rows[1] = ("crank only", t, 1e-12 + 0 * t, big * (1 + 1e-3), 10.0, 2.0)
    assert LP.residual_notes(LP.residuals(rows)) == []


def test_a_figure_of_many_curves_keeps_fewer_samples():
    t = np.linspace(0.0, 1.0, 1001)
    panels = [{"key": f"p{i}", "title": f"p{i} (N)", "axis": "(N)"} for i in range(40)]
    stages = [(f"s{j}", {p["key"]: np.sin(t * (j + 1)) for p in panels}) for j in range(3)]
    data = LV.data(LV.Curves(t, stages, panels, []))
    n = len(data["t"])
    assert LV.MIN_POINTS <= n < LV.POINTS and n * 40 * 3 <= LV.VALUES
    assert data["t"][0] == 0.0 and data["t"][-1] == 1.0
    # a stage without a panel's curve has none there (the plot shows a gap, not zeros)
    data = LV.data(LV.Curves(t, [("a", {"p0": t}), ("b", {})], panels[:1], [(0.5, "dead centre")]))
    assert "p0" in data["series"][0]["y"] and data["series"][1]["y"] == {}
    assert data["marks"] == [[0.5, "dead centre"]]


def test_the_json_is_deterministic_and_safe_in_a_script(study):
    again = run(load(SPECS / "offset_slider_crank.yaml").spec)
    one, two = study_figures(study), study_figures(again)
    for name in ("loads", "efforts", "joints"):
        assert one[name] == two[name], name  # the same bytes from a second run of the spec
        html = one[name]
        assert html.startswith(f'<div class="live" id="live-{name}"><noscript>')
        assert "<svg" not in html and "static-plot" not in html  # no static figure of the same curves
        script = html[html.index(f'data-live="live-{name}">') + len(f'data-live="live-{name}">'):html.rindex("</script>")]
        assert json.loads(script)["series"]
    t = np.linspace(0.0, 1.0, 5)
    text = LV.as_script(LV.data(LV.Curves(t, [("</script><!--", {"F": t})], [{"key": "F", "title": "F", "axis": "F"}], [])))
    assert "</script" not in text and "<!--" not in text
    assert json.loads(text)["series"][0]["label"] == "</script><!--"


def test_without_javascript_the_figure_says_where_its_numbers_are(study):
    """No static figure: a reader without JavaScript reads, in the plot's place, that it needs
    JavaScript and which files beside the page hold its numbers."""
    html = study_figures(study)["joints"]
    note = html[html.index("<noscript>"):html.index("</noscript>")]
    assert "JavaScript" in note and 'href="timeseries.csv"' in note and 'href="results.json"' in note
    assert html.index("</noscript>") < html.index("</div>")  # inside the live element


def test_the_papers_time_series_are_interactive_in_their_stage_styles():
    """Paper 004's Fig. 12 draws the force-balanced stage: its live curve has that stage's line
    style of the page (its place in the stage table), and the values of its analysis."""
    from balpipe.report import paper_figures as PF

    st = run(load(SPECS / "paper004_five_bar.yaml").spec)
    from balpipe.families.five_bar import figures as P4

    force_only = next(s for s in st.stages if s.stage.balances == "force" and s.stage.design is None)
    _, html, _ = next(f for f in PF.own_figures(st) if f[0].startswith("Fig. 12"))
    script = html[html.index('data-live="live-p004fig12">') + len('data-live="live-p004fig12">'):html.rindex("</script>")]
    data = json.loads(script)
    [series] = data["series"]
    k = P4.style_of(st, force_only)
    assert k > 0 and {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(k)
    assert data["panels"] == [{"key": "y", "title": "", "axis": "M (N m)",
                               "floor": pytest.approx(1e-9 * np.max(np.abs(force_only.analysis.moment)), rel=1e-2)}]
    _close(series["y"]["y"], force_only.analysis.moment[_kept(data, force_only.analysis.t)])


def test_a_familys_own_time_series_is_interactive_too():
    """Paper 002's Fig. 2 is drawn by its family (families/serial_arm/figures.py), below the report
    layer: it is live as well (draw/live.py), with the unbalanced stage's values of Fˢʰ = |F| and
    Mˢʰ = M, in that stage's line style of the page."""
    from balpipe.balancing.base import style_index

    st = run(load(SPECS / "paper002_decoupling.yaml").spec)
    _, html, _ = next(f for f in st.extra_figures() if f[0].startswith("Fig. 2 of paper 002"))
    assert html.startswith('<div class="live" id="live-p002fig2"><noscript>') and "<svg" not in html
    data = json.loads(html[html.index('data-live="live-p002fig2">') + len('data-live="live-p002fig2">'):html.rindex("</script>")])
    [series] = data["series"]
    an = st.unbalanced.analysis
    k = _kept(data, an.t)
    _close(series["y"]["F"], np.linalg.norm(an.force, axis=1)[k])
    _close(series["y"]["M"], an.moment[k])
    assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(style_index(st.stages, st.unbalanced))
    assert [p["axis"] for p in data["panels"]] == ["Fˢʰ (N)", "Mˢʰ (N m)"]


def test_the_3rpr_paper_figure_is_interactive_with_every_stage_in_its_page_style(studies):
    """Paper 000's Fig. 4 (the idler-loop method's hook): three live panels, F_x, F_y and M, one
    curve per stage of the main design in its line style of the page, with the analysis's values."""
    from balpipe.balancing.base import style_index

    st = studies("paper000_rpr3_idler_loop.yaml")
    _, html, _ = next(f for f in st.extra_figures() if "(Fig. 4 of paper 000)" in f[0])
    data = json.loads(html[html.index('data-live="live-rpr3-loads">') + len('data-live="live-rpr3-loads">'):html.rindex("</script>")])
    assert [p["axis"] for p in data["panels"]] == ["F_x (N)", "F_y (N)", "M (N m)"]
    own = {s.stage.label: s for s in st.stages if ":" not in s.stage.name}
    assert sorted(x["label"] for x in data["series"]) == sorted(own)
    for series in data["series"]:
        s = own[series["label"]]
        k = _kept(data, s.analysis.t)
        floor = {p["key"]: p["floor"] for p in data["panels"]}
        _close(series["y"]["x"], s.analysis.force[k, 0], floor["x"])
        _close(series["y"]["M"], s.analysis.moment[k], floor["M"])
        assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(style_index(st.stages, s))


def test_a_figure_of_many_joints_shows_the_largest_load_first(study, monkeypatch):
    """Issue 22: past MANY_JOINTS panels the joint figure is shown a joint at a time (``choose``),
    first the panel of the largest force over every stage (a larger torque, in N m, does not
    count against forces); a figure of few joints shows every panel."""
    assert "choose" not in LV.data(LP.joints(_stages(study)))  # the slider-crank's 4 joint loads
    t = np.linspace(0.0, 1.0, 11)
    n = LP.MANY_JOINTS + 2
    # n revolutes with |F| peaks 1 .. n N, but J2's 50 N the largest; a gear mesh of 1000 N m
    loads = [(f"J{i}", "F", "revolute", "N", (50.0 if i == 2 else i + 1) * np.sin(np.pi * t)) for i in range(n)]
    loads.append(("mesh", "T", "gear mesh", "N m", 1e3 * np.sin(np.pi * t)))
    monkeypatch.setattr(LP, "joint_load_series", lambda an: [(j, c, k, u, v * an.scale) for j, c, k, u, v in loads])
    stage = lambda scale: type("Analysis", (), {"t": t, "scale": scale})()  # noqa: E731
    data = LV.data(LP.joints([("one", stage(0.5)), ("two", stage(1.0))]))
    assert len(data["panels"]) == n + 1 > LP.MANY_JOINTS
    assert data["panels"][data["choose"]]["key"] == "J2.F"


def test_a_partial_balancings_front_is_interactive_over_its_budget():
    """Issue 22: each Pareto front of a partial balancing is a live plot over its budget (not
    time): the front's designs at their budgets with their objective values, every marked design
    a marker alone at its own values, every sample kept (a front of 1000 points too) and a
    missing value null, never NaN (which JSON.parse refuses)."""
    from balpipe.report import partial_figures as PFG

    st = run(load(SPECS / "partial_offset_slider_crank.yaml").spec)
    det = st.balance.details["partial_balance"]
    figs = PFG.figures(st)
    assert len(figs) == 4 and all('<div class="live" id="live-partial_' in html for _, html, _ in figs)
    for key, x, y, _, _ in PFG.FRONTS:
        pts = det["fronts"][key]
        marks = PFG._marks(st, det, x, y)
        data = LV.data(PFG.front_curves(pts, x, y, marks))
        assert data["x"] == PFG.AXES[x] and data["panels"][0]["axis"] == PFG.AXES[y]
        front, *marked = data["series"]
        assert front.get("long", front["label"]) == PFG.FRONT and "points" not in front and all(s["points"] for s in marked)
        shown = sorted((xv, yv) for xv, yv in zip(data["t"], front["y"]["y"]) if yv is not None)
        floor = data["panels"][0]["floor"]  # a design's round-off, written 0
        exact = sorted((float(f"{p[x]:.6g}"), float(f"{p[y]:.6g}") if abs(p[y]) > floor else 0.0) for p in pts)
        assert shown == exact  # every design of the front, none thinned away
        for s, (label, vx, vy) in zip(marked, marks):
            at = [(xv, yv) for xv, yv in zip(data["t"], s["y"]["y"]) if yv is not None]
            assert s.get("long", s["label"]) == label and at == [(float(f"{vx:.6g}"), float(f"{vy:.6g}") if abs(vy) > floor else 0.0)]
        assert data["t"] == sorted(data["t"])  # uPlot's x runs forward
        json.loads(LV.as_script(data))  # valid JSON: null, not NaN
    many = [{"added_mass": m, "shaking_force": 100.0 - m} for m in np.linspace(0.0, 10.0, 1000)]
    data = LV.data(PFG.front_curves(many, "added_mass", "shaking_force", [("a design", 5.0, 50.0)]))
    assert len(data["t"]) == 1001


def test_each_panel_carries_its_round_off_floor(study):
    """A balanced stage's residual (1.9e-13 N m beside 11.5 N m) hovers as "0 (< tolerance)", as
    the tables write it: each panel carries 1e-9 of its largest value over every stage, and the
    script formats a value at or below it so; the JSON writes such a value as 0."""
    t = np.linspace(0.0, 1.0, 101)
    panels = [{"key": "M", "title": "M (N m)", "axis": "M (N m)"}, {"key": "z", "title": "z", "axis": "z"}]
    stages = [("unbalanced", {"M": 11.5 * np.sin(2 * np.pi * t), "z": 0 * t}),
              ("balanced", {"M": 1.9e-13 * np.cos(2 * np.pi * t), "z": 0 * t})]
    data = LV.data(LV.Curves(t, stages, panels, []))
    assert [p["floor"] for p in data["panels"]] == [pytest.approx(1.15e-8, rel=1e-2), 0.0]
    assert max(abs(v) for v in data["series"][1]["y"]["M"]) <= data["panels"][0]["floor"]
    assert set(data["series"][1]["y"]["M"]) == {0.0}  # written 0: 3 bytes a sample, not 12
    assert 11.5 * np.sin(2 * np.pi * 0.01) > data["panels"][0]["floor"]  # a real value stays a number
    _close(data["series"][0]["y"]["M"], 11.5 * np.sin(2 * np.pi * t))
    script = (Path(__file__).parents[2] / "templates" / "live_plots.js").read_text()
    assert 'if (floor && a <= floor) return "0 (< tolerance)";' in script and "fmt(v, p.floor)" in script
    # the real study's pages: the balanced stage's |F| is under its panel's floor
    data = LV.data(LP.loads(_stages(study)))
    force = next(p for p in data["panels"] if p["key"] == "F")
    assert force["key"] == "F" and force["floor"] > 0


def _live(html: str, name: str) -> dict:
    """The JSON of the live figure ``#live-<name>`` in ``html`` (no static SVG beside it)."""
    assert html.startswith(f'<div class="live" id="live-{name}"><noscript>') and "<svg" not in html
    start = html.index(f'data-live="live-{name}">') + len(f'data-live="live-{name}">')
    return json.loads(html[start:html.rindex("</script>")])


def _figure(st, title: str) -> str:
    return next(body for t, body, _ in st.extra_figures() if t == title)


def test_the_prismatic_forces_are_live_on_log_axes_with_the_unbounded_samples_left_out(studies):
    """The 3-RPR's axial forces of prismatic actuators (the family's own figure): a log panel per
    leg, the unbalanced stage and the last stage each in its style on the page (its key), |f_i| of
    ``prismatic_equivalent`` at the kept samples; no value (null) where a force is unbounded (NaN,
    at the parallel singularity of phi = 0) or zero."""
    from balpipe.balancing.base import style_index
    from balpipe.families.rpr3.template import pose_of, prismatic_equivalent

    st = studies("paper000_rpr3_idler_loop.yaml")
    data = _live(_figure(st, "Axial forces that prismatic actuators would need"), "rpr3-prismatic")
    assert [(p["key"], p["log"]) for p in data["panels"]] == [("leg1", True), ("leg2", True), ("leg3", True)]
    assert data["grid"] is True
    last = [s for s in st.stages if ":" not in s.stage.name][-1]
    pose = pose_of(st.unbalanced.stage.model)
    nulls = 0
    for series, s in zip(data["series"], (st.stages[0], last)):
        style = style_index(st.stages, s)
        assert series["label"] == s.stage.label
        assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(style)
        an = s.analysis
        f = np.abs(prismatic_equivalent(st.spec.mechanism, pose, an.t,
                                        np.stack([an.efforts[f"theta{i}"] for i in (1, 2, 3)], axis=1)))
        k = _kept(data, an.t)
        for i in range(3):
            shown = series["y"][f"leg{i + 1}"]
            ok = np.isfinite(f[k, i]) & (f[k, i] > 0)
            assert [v is None for v in shown] == list(~ok)
            nulls += int(np.sum(~ok))
            _close([v for v in shown if v is not None], f[k, i][ok])
    assert nulls >= 6  # the singular first sample, a gap in every leg's curve of both stages
    assert series["width"] > data["series"][0]["width"]  # the grey line is the thick one, drawn first
    assert data["draw"][0] == 1


def test_the_decoupled_arms_mass_matrix_along_the_motion_is_live(studies):
    """Paper 002's mass matrix along the motion: panels D11, D12, D22, a curve per stage in its
    line style of the page with the engine's joint-space mass matrix; the decoupled arm's D12 is 0
    and its D11, D22 constant."""
    from balpipe.balancing.base import style_index
    from balpipe.engine.joint_space import mass_matrix

    st = studies("paper002_decoupling.yaml")
    data = _live(_figure(st, "Mass matrix along the motion"), "decoupling-mass")
    assert [p["key"] for p in data["panels"]] == ["D11", "D12", "D22"]
    by = {s.stage.name: s for s in st.stages}
    for series, name in zip(data["series"], ("unbalanced", "decoupled")):
        s = by[name]
        assert series["label"] == s.stage.label
        assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(style_index(st.stages, s))
        M = mass_matrix(s.stage.model, s.analysis.t)[1]
        k = _kept(data, s.analysis.t)
        floor = {p["key"]: p["floor"] for p in data["panels"]}
        for key, (i, j) in (("D11", (0, 0)), ("D12", (0, 1)), ("D22", (1, 1))):
            _close(series["y"][key], M[k, i, j], floor[key])
    decoupled = data["series"][1]["y"]
    assert set(decoupled["D12"]) == {0.0} and len(set(decoupled["D11"])) == 1 and len(set(decoupled["D22"])) == 1
    assert len(set(data["series"][0]["y"]["D12"])) > 1  # coupled before


def test_the_five_bars_input_angles_are_live(studies):
    """Paper 004's Figs. 8-9: theta1 and theta2 of the analysis (template.input_angles), a panel
    each, at the kept samples."""
    from balpipe.families.five_bar.template import input_angles

    st = studies("paper004_five_bar.yaml")
    data = _live(_figure(st, "Input angles (Figs. 8-9)"), "fivebar-angles")
    assert [p["title"] for p in data["panels"]] == ["theta1 (rad)", "theta2 (rad)"]
    an = st.stages[0].analysis
    k = _kept(data, an.t)
    for key, th in zip(("theta1", "theta2"), input_angles(an)):
        _close(data["series"][0]["y"][key], th[k])


def test_paper_003s_other_trajectories_are_live_one_curve_per_case_in_its_style(studies):
    """The trajectories Figs. 3-4 do not show: a pair of panels (|F|, M) per trajectory, a curve per
    case with that trajectory's stage's values, in the case's line style, which is the same on
    every trajectory (the style order of each trajectory's stages)."""
    from balpipe.balancing.base import style_index
    from balpipe.families.serial_arm.com_planning import CASES

    st = studies("paper003_com_planning.yaml")
    main = st.stages[0].stage.group
    others = sorted({s.stage.group for s in st.stages} - {main})
    data = _live(_figure(st, f"Shaking force and moment on the other {len(others)} trajectories"), "com-loads")
    assert sorted(p["key"] for p in data["panels"]) == sorted(f"{q} {g}" for g in others for q in "FM")
    labels = dict(CASES)
    assert sorted(x.get("long", x["label"]) for x in data["series"]) == sorted(labels.values())
    for series in data["series"]:
        case = next(key for key, label in labels.items() if label == series.get("long", series["label"]))
        for g in others:
            s = next(x for x in st.stages if x.stage.name == f"{g}_{case}")
            assert {key: series[key] for key in ("stroke", "dash", "width")} == LV.line_style(style_index(st.stages, s))
            k = _kept(data, s.analysis.t)
            floor = {p["key"]: p["floor"] for p in data["panels"]}
            _close(series["y"][f"F {g}"], np.linalg.norm(s.analysis.force, axis=1)[k], floor[f"F {g}"])
            _close(series["y"][f"M {g}"], s.analysis.moment[k], floor[f"M {g}"])


def test_paper_003s_optimised_orientation_is_live_from_each_plans_ends(studies):
    """φ(t) of case 2 per trajectory and the 3-4-5 law, live: each trajectory's curve runs from its
    plan's start orientation to its end orientation (degrees), in a colour of its own; the 3-4-5
    law in the line style of the stage that uses it."""
    from balpipe.balancing.base import style_index
    from balpipe.families.serial_arm.com_planning import replan

    st = studies("paper003_com_planning.yaml")
    data = _live(_figure(st, "Optimised end-effector orientation φ"), "com-phi")
    _, plans = replan(st.spec, {p.name: p.value for p in st.balance.parameters})
    *trajectories, law = data["series"]
    assert [x["label"] for x in trajectories] == [p.name for p in plans] and law["label"] == "3-4-5 law"
    assert len({x["stroke"] for x in trajectories}) == len(plans)
    for x, p in zip(trajectories, plans):
        phi = x["y"]["phi"]
        assert phi[0] == pytest.approx(np.degrees(p.start[2]), abs=1e-4) and phi[-1] == pytest.approx(np.degrees(p.end[2]), abs=1e-4)
    main = st.stages[0].stage.group
    uses = next(s for s in st.stages if s.stage.name == f"{main}_com_bang_bang")
    assert {key: law[key] for key in ("stroke", "dash", "width")} == LV.line_style(style_index(st.stages, uses))


def test_a_log_panel_keeps_sixteen_decades_below_its_largest_value():
    """A residual of 8e-322 (a zero's round-off) next to 1e-4 gave uPlot 318 decades, and it drew
    no plot at all: a log panel has no value below LOG_RANGE (1e-16) of its largest, nor at or
    below 0; the values above are kept to their 6 digits."""
    t = np.linspace(0.0, 1.0, 5)
    y = np.array([8.2e-322, 3.0e-21, 2.0e-20, 1.0e-4, 0.0])
    c = LV.Curves(t, [("a", {"r": y})], [{"key": "r", "title": "", "axis": "", "log": True}], [])
    shown = LV.data(c)["series"][0]["y"]["r"]
    assert LV.LOG_RANGE == 1e-16
    assert shown == [None, None, 2e-20, 1e-4, None]


def test_a_figures_csv_holds_its_plotted_samples_exactly_in_si_with_units(rng):
    """live.csv_text: the samples the plot keeps, 12 significant digits (not the plot's 6), a
    column per curve and panel named with its unit in parentheses, the drift's mm as m and its
    deg as rad; live.html links the file while collecting it, and not otherwise."""
    import csv as csv_mod
    import io

    from balpipe.report import live_plots as LP

    n = int(rng.integers(500, 900))
    t = np.linspace(0.0, 1.0, n)
    d = rng.normal(size=(n, 2)) * 1e-3
    rot = rng.normal(size=n)
    c = LP.drift([("first stage (a remark)", t, d, rot), ("second", t, 2 * d, -rot)])
    rows = list(csv_mod.reader(io.StringIO(LV.csv_text(c))))
    head, body = rows[0], np.array([[float(v) for v in r] for r in rows[1:]])
    assert head == ["t (s)", "first stage: drift (m)", "second: drift (m)", "first stage: rotation (rad)",
                    "second: rotation (rad)"]
    k = LV._thin(n, 4)
    assert len(body) == len(k) < n
    assert np.allclose(body[:, 0], t[k], rtol=1e-11, atol=0)
    assert np.allclose(body[:, 1], np.hypot(d[k, 0], d[k, 1]), rtol=1e-11, atol=0)  # in m: SI
    assert np.allclose(body[:, 4], -rot[k], rtol=1e-11, atol=1e-300)  # rad
    six = LV.data(c)["series"][0]["y"]["drift"]  # the plot's own values: 6 digits, in mm
    assert np.allclose(np.array(six) / 1000, body[:, 1], rtol=1e-5)
    assert "figure-drift.csv" not in LV.html("drift", c)
    with LV.collecting() as files:
        markup = LV.html("drift", c)
    assert list(files) == ["figure-drift.csv"] and files["figure-drift.csv"] == LV.csv_text(c)
    assert 'href="figure-drift.csv"' in markup
    assert LV.column_unit("|ΔF| / F_ref") == ("|ΔF| / F_ref", "1", 1.0)


def test_a_pareto_front_fills_its_axes_and_outliers_are_named():
    """A front's plot takes its axes from the front (and the marks near it): a mark far off
    (the unbalanced mechanism's peak, a complete balance's mass) is left outside and named with
    its values in the caption, so the front spans at least half of each axis."""
    from balpipe.report import partial_figures as PFG

    pts = [{"m": 1.0 + 0.1 * i, "f": 10.0 - i} for i in range(6)]
    marks = [("near", 1.2, 7.5), ("far", 9.0, 300.0)]
    (x0, x1), (y0, y1), off = PFG.limits(pts, "m", "f", marks)
    assert off == [("far", 9.0, 300.0)]
    assert x0 < 1.0 and x1 > 1.5 and y0 < 5.0 and y1 > 10.0 and y1 < 20.0


def test_the_specs_fronts_fill_their_axes(studies):
    """On every spec with a partial balancing, each front spans at least half of both axes of its plot."""
    from balpipe.report import partial_figures as PFG

    for name in ("partial_offset_slider_crank.yaml", "partial_paper000_rpr3.yaml", "partial_paper004_five_bar.yaml"):
        st = studies(name)
        det = st.balance.details["partial_balance"]
        figs = {t: (svg, cap) for t, svg, cap in PFG.figures(st)}
        for key, x, y, title, _ in PFG.FRONTS:
            pts = det["fronts"].get(key) or []
            if len(pts) < 2:
                continue
            d = _live(figs[title][0], f"partial_{key}")
            p = d["panels"][0]
            fx, fy = [q[x] for q in pts], [q[y] for q in pts]
            for lo_hi, v in ((p["xrange"], fx), (p["range"], fy)):
                span = max(v) - min(v)
                assert span == 0 or span >= 0.5 * (lo_hi[1] - lo_hi[0]), (name, key, lo_hi, span)
            for label, vx, vy in PFG.limits(pts, x, y, PFG._marks(st, det, x, y))[2]:
                assert label in figs[title][1], (name, key, label)
