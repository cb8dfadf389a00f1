"""The live what-if's maps (balpipe.report.whatif) against the engine: at random slider values the
maps' loads equal the engine's analysis of the model with those parts, to 1e-9 of each series'
scale (counterweights, discs on links of their own, gears, gravity); Coulomb friction keeps the
shaking loads and leaves the efforts out, saying why; a map that is not affine is refused; the
page's data decode to the maps exactly, and are deterministic."""

from __future__ import annotations

import base64
import json
import re

import numpy as np
import pytest

from balpipe.balancing.mass_sweep import MassSweep
from balpipe.draw import live
from balpipe.mechanics.sampling import spread_indices
from balpipe.report import whatif
from balpipe.report.results import results_dict


def _whatif(studies, name: str):
    st = studies(name)
    return st, whatif.build(st, results_dict(st, name, "h", simulated=False))


def _random(w, rng) -> np.ndarray:
    lo = np.array([p.lo for p in w.parts]).reshape(-1, 4)
    hi = np.array([p.hi for p in w.parts]).reshape(-1, 4)
    return rng.uniform(lo, hi)


def _scale(key: str, exact: dict) -> float:
    return float(np.max(np.abs(exact["F" if key in ("Fx", "Fy") else key])))


@pytest.mark.parametrize("name", ["offset_slider_crank.yaml", "custom_four_bar_balancing.yaml",
                                  "paper002_decoupling.yaml", "custom_slider_driven_slider_crank_gravity.yaml",
                                  "paper001_4rrr_fig6c.yaml"])
def test_the_maps_give_the_engines_loads_at_random_parts(studies, name):
    """Each part's mass, position and inertia drawn at random within its sliders' ranges (three
    designs), and every slider at either end of its range: Fx, Fy, |F|, M and every effort from
    the maps equal the engine's analysis of the model with those parts to 1e-9 of the series'
    scale (gears, discs on bodies of their own, gravity, four redundant actuators); at the
    computed design they are the engine's series of the stage itself, exactly."""
    st, w = _whatif(studies, name)
    assert isinstance(w, whatif.WhatIf), w
    assert any(k.startswith("effort:") for k in w.keys)
    rng = np.random.default_rng(11)
    lo = np.array([p.lo for p in w.parts]).reshape(-1, 4)
    hi = np.array([p.hi for p in w.parts]).reshape(-1, 4)
    for values in [_random(w, rng) for _ in range(3)] + [lo, hi]:
        got, exact = whatif.series(w, values), whatif.engine_series(w, values)
        assert set(got) == set(w.keys) | {"F"}
        for k in got:
            assert np.max(np.abs(got[k] - exact[k])) <= 1e-9 * _scale(k, exact), (name, k)
        assert any(np.max(np.abs(got[k] - w.design[k])) > 1e-3 * _scale(k, exact) for k in w.keys)  # the parts moved them
    at_design = whatif.series(w, w.values())
    for k in w.keys:
        assert np.array_equal(at_design[k], w.design[k])
    final = next(s for s in st.stages if s.stage.name == w.stage)
    assert np.array_equal(w.design["Fx"], final.analysis.force[w.index, 0])


def test_discs_and_counterweights_are_parts_with_their_own_bodies(studies):
    """The four-bar's counter-rotations stage: the counterweights move on their links, each disc is
    a body of its own (its mass, centre and inertia), and the sliders' ranges hold the design."""
    _, w = _whatif(studies, "custom_four_bar_balancing.yaml")
    kinds = {p.kind for p in w.parts}
    assert "counter-rotation" in kinds and "counterweight" in kinds
    for p in w.parts:
        assert p.own == (p.kind == "counter-rotation")
        assert all(lo <= v <= hi for lo, v, hi in zip(p.lo, p.design, p.hi)), p
        assert p.lo[0] >= 0 or p.design[0] < 0  # no negative mass unless the design has one


def test_coulomb_friction_keeps_the_shaking_loads_and_says_why_not_the_efforts(studies):
    """Coulomb friction: the efforts follow the reactions (not affine in the parts), so only the
    shaking force and moment have maps, which still equal the engine's."""
    _, w = _whatif(studies, "custom_four_bar_loaded.yaml")
    assert isinstance(w, whatif.WhatIf)
    assert w.keys == ["Fx", "Fy", "M"] and [p["key"] for p in w.panels] == ["Fx", "Fy", "F", "M"]
    assert any("Coulomb friction" in n and "O2_bearing" in n for n in w.notes)
    values = _random(w, np.random.default_rng(3))
    got, exact = whatif.series(w, values), whatif.engine_series(w, values)
    for k in ("Fx", "Fy", "F", "M"):
        assert np.max(np.abs(got[k] - exact[k])) <= 1e-9 * _scale(k, exact)


def test_loads_that_are_not_affine_get_no_sliders_and_the_page_says_why(studies, monkeypatch):
    """An engine whose shaking force grew with the square of a part's mass: the check design finds
    it and the stage gets a sentence instead of sliders; efforts alone off: left out with a note."""
    st = studies("offset_slider_crank.yaml")
    res = results_dict(st, "offset_slider_crank.yaml", "h", simulated=False)
    real = whatif.engine_series

    def squared(w, values):
        out = real(w, values)
        out["Fx"] = out["Fx"] + 1e-3 * float(np.asarray(values)[0, 0]) ** 2
        return out

    monkeypatch.setattr(whatif, "engine_series", squared)
    reason = whatif.build(st, res)
    assert isinstance(reason, str) and "not affine" in reason
    assert whatif.section(st, res) == {"reason": reason}

    def efforts_off(w, values):
        out = real(w, values)
        out["effort:crank"] = out["effort:crank"] * 1.001
        return out

    monkeypatch.setattr(whatif, "engine_series", efforts_off)
    w = whatif.build(st, res)
    assert isinstance(w, whatif.WhatIf) and w.keys == ["Fx", "Fy", "M"] and "not affine" in w.notes[-1]


def test_a_design_without_parts_has_no_what_if(studies):
    """Paper 003's designs change the motion, not the masses: no section."""
    st = studies("paper003_com_planning.yaml")
    assert whatif.section(st, results_dict(st, "paper003_com_planning.yaml", "h", simulated=False)) is None


def _f64(text: str) -> np.ndarray:
    return np.frombuffer(base64.b64decode(text), dtype="<f8")


def test_the_pages_data_are_the_maps_exactly_and_deterministic(studies):
    """The JSON the page ships decodes (base64, little-endian float64) to the maps bit for bit,
    zero columns left out; building it twice gives the same text; the samples are those of the
    live figure, no more than the page's charts draw."""
    st, w = _whatif(studies, "custom_four_bar_balancing.yaml")
    d = whatif.data(w)
    assert np.array_equal(_f64(d["t"]), w.t) and d["n"] == len(w.t) <= 400
    for k in w.keys:
        assert np.array_equal(_f64(d["design"][k]), w.design[k])
        for b in w.bodies:
            for c, shipped in zip(w.columns[k][b], d["columns"][k][b]):
                assert (c is None) == (shipped is None)
                if c is not None:
                    assert np.array_equal(_f64(shipped), c) and np.any(c != 0)
    assert [p["design"] for p in d["parts"]] == [list(p.design) for p in w.parts]
    res = results_dict(st, "custom_four_bar_balancing.yaml", "h", simulated=False)
    a, b = whatif.section(st, res), whatif.section(st, res)
    assert a == b and a is not None and a["reason"] is None
    figure = json.loads(re.search(r'data-live="live-whatif">(.*)</script>', a["figure"], re.S).group(1))
    assert len(figure["t"]) == d["n"] and [s["label"] for s in figure["series"]][-1] == "design tried"


@pytest.mark.parametrize("name", ["paper000_rpr3_scott_russell.yaml", "offset_slider_crank.yaml",
                                  "custom_four_bar_loaded.yaml"])
def test_the_maps_are_built_at_the_kept_samples_only(studies, monkeypatch, name):
    """Issue 43: the maps of a 20,000-sample grid held every sample's Jacobian and per-parameter
    multipliers (3.5 GB) for a page that keeps a few hundred. Every map array is built at the
    samples the page may keep, one row per such sample: first the charts' most
    (:data:`balpipe.draw.live.POINTS` spread over the grid), then, where the maps' size keeps fewer
    (the Scott-Russell's 100 of 501), those; never one row per grid sample (Coulomb friction's
    shaking maps alike)."""
    built, sweeps = [], []
    real_maps, real_build = whatif._maps, MassSweep.build

    def maps(model, an, samples):
        out = real_maps(model, an, samples)
        built.append((np.asarray(samples), out))
        return out

    def build(*args, **kwargs):
        sweeps.append(real_build(*args, **kwargs))
        return sweeps[-1]

    monkeypatch.setattr(whatif, "_maps", maps)
    monkeypatch.setattr(whatif.MassSweep, "build", build)
    _, w = _whatif(studies, name)
    assert isinstance(w, whatif.WhatIf), w
    N = len(w.grid)
    assert N > live.POINTS and len(w.index) < N
    assert np.array_equal(built[0][0], spread_indices(N, live.POINTS))
    assert np.array_equal(built[-1][0], w.index) and len(built) == (1 if len(w.index) == live.POINTS else 2)
    for samples, (YF, YM, G, _, _) in built:
        n = len(samples)
        assert YF.shape[0] == YM.shape[0] == n and (G is None or G.shape[0] == n)
    assert len(sweeps) == (0 if whatif.coulomb_friction(w.model) else len(built))
    for sweep, (samples, _) in zip(sweeps, built):
        assert sweep.Lam.shape[0] == sweep.G.shape[0] == len(sweep.t) == len(samples)


@pytest.mark.parametrize("name", ["paper001_4rrr_fig6c.yaml", "custom_pumpjack_rod_load.yaml",
                                  "paper002_decoupling.yaml"])
def test_a_sweep_at_some_samples_is_the_whole_grids_at_those_samples(studies, name):
    """MassSweep.build(samples=...) from the analysis of the whole grid: every matrix equals the
    whole grid's sweep at those samples bit for bit (redundant actuators, loads, gears), in the
    order given, so the page's maps are the same numbers whichever samples are mapped."""
    st = studies(name)
    final = st.stages[-1]
    model, an = final.stage.model, final.analysis
    full = MassSweep.build(model, an.t, an.gravity, an.moment_point, analysis=an)
    samples = np.random.default_rng(5).choice(len(an.t), 37, replace=False)
    sub = MassSweep.build(model, an.t, an.gravity, an.moment_point, analysis=an, samples=samples)
    assert np.array_equal(sub.t, an.t[samples])
    for key in ("YF", "YM", "Lam", "G"):
        assert getattr(sub, key).shape[0] == len(samples)
        assert np.array_equal(getattr(sub, key), getattr(full, key)[samples]), key
    if model.loads:
        assert np.array_equal(sub.G0, full.G0[samples]) and np.array_equal(sub.Lam0, full.Lam0[samples])
    p = sub.parameters(model)
    assert np.array_equal(sub.multipliers(p), full.multipliers(p)[samples])


def test_parts_of_one_name_on_two_links_are_two_parts(studies):
    """Two counterweights both named 'cw', on the crank and on the coupler: each is its own part on
    its own link, and moving them moves each on its own link."""
    from balpipe.balancing.parts import add_counterweight

    base = studies("offset_slider_crank.yaml").stages[0].stage.model
    final = add_counterweight(add_counterweight(base, "crank", "cw", 1.5, (-0.05, 0.01), 1e-4),
                              "coupler", "cw", 0.7, (0.02, -0.01))
    parts = whatif.parts_of(base, final)
    assert [(p.name, p.body, p.design[0]) for p in parts] == [("cw", "crank", 1.5), ("cw", "coupler", 0.7)]
    moved = whatif.with_parts(final, parts, np.array([[2.0, -0.1, 0.0, 0.0], [0.3, 0.05, 0.02, 1e-3]]))
    assert [a.mass for b in moved.bodies for a in b.attachments] == [2.0, 0.3]


def test_the_pages_display_units_show_the_figure_and_sliders_while_the_maps_stay_si(studies):
    """report.units: the data's maps are the SI ones whatever the units; ``params`` gives each
    slider value's unit and factor to SI (kg, mm, mm, kg mm² on the V-twin's page) and ``factors``
    each panel's (1000 for its forces in kN, 1 for its moment, still N m; 1000 for both in the
    engineering preset); the figure's curves are the SI series over those factors, its titles and
    axes in the shown units, and its CSV in SI again."""
    from balpipe.display.units import display_units
    from balpipe.draw import live

    st, w = _whatif(studies, "custom_v_twin_6000rpm.yaml")
    u = display_units(st.spec.report.units)
    d, si = whatif.data(w, u), whatif.data(w)
    assert {k: v for k, v in d.items() if k not in ("params", "factors")} == \
        {k: v for k, v in si.items() if k not in ("params", "factors")}
    assert [(q["name"], q["unit"], q["factor"]) for q in si["params"]] == [
        ("mass", "kg", 1.0), ("x", "m", 1.0), ("y", "m", 1.0), ("inertia", "kg m²", 1.0)]
    assert [(q["name"], q["unit"]) for q in d["params"]] == [("mass", "kg"), ("x", "mm"), ("y", "mm"), ("inertia", "kg mm²")]
    assert [q["factor"] for q in d["params"]] == [1.0, 1e-3, 1e-3, u.factor("inertia")] and u.factor("inertia") == pytest.approx(1e-6)
    assert set(si["factors"].values()) == {1.0}
    efforts = [k for k in d["factors"] if k.startswith("effort:")]
    assert efforts and d["factors"] == {"Fx": 1e3, "Fy": 1e3, "F": 1e3, "M": 1.0, **{k: 1.0 for k in efforts}}
    eng = whatif.data(w, display_units("engineering"))["factors"]
    assert eng == {"Fx": 1e3, "Fy": 1e3, "F": 1e3, "M": 1e3, **{k: 1e3 for k in efforts}}  # torques in kN m
    c, c_si = whatif.curves(w, u), whatif.curves(w)
    assert [p["axis"] for p in c.panels][:4] == ["Fx (kN)", "Fy (kN)", "|F| (kN)", "M (N m)"]
    assert all(p["title"].endswith("(kN)") for p in c.panels if p["key"] in ("Fx", "Fy", "F"))
    for (_, shown), (_, exact) in zip(c.stages, c_si.stages):
        for k, y in shown.items():
            assert np.array_equal(y, np.asarray(exact[k]) / d["factors"][k]), k
    a, b = live.csv_text(c).splitlines(), live.csv_text(c_si).splitlines()
    assert a[0] == b[0] and "(N)" in a[0] and "kN" not in a[0]
    np.testing.assert_allclose(np.array([r.split(",") for r in a[1:]], dtype=float),
                               np.array([r.split(",") for r in b[1:]], dtype=float), rtol=1e-11, atol=0)
