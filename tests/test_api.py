"""The Python API (docs/api.md): ``balpipe.load``, ``balpipe.run`` and the :class:`balpipe.Study`
give what the command line writes, through the same engine; specs changed by dotted paths and
built in Python are validated as files are."""

from __future__ import annotations

import csv
import io
import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

import balpipe
from balpipe.families.custom import builders as b

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"
NAMES = tuple(sorted(p.name for p in SPECS.glob("*.yaml")))
FOUR_BAR = "custom_four_bar_balancing.yaml"


@pytest.fixture(scope="module")
def cli_site(shared_build) -> Path:
    """``balpipe build specs -o site --no-sim`` of every spec (with the tables they read), once per run."""
    files = tuple(sorted(p.name for p in SPECS.iterdir() if p.is_file()))
    folder, r = shared_build(files, "specs", "-o", "site", "--no-sim")
    assert r.returncode in (0, 1), r.stderr
    return folder / "site"


def _slug(name: str) -> str:
    from balpipe.site_files.spec_files import slug_for

    return slug_for(Path("specs") / name)


@pytest.mark.parametrize("name", NAMES)
def test_run_gives_the_command_lines_results_json(name, api_studies, cli_site):
    """For every spec of specs/: ``balpipe.run(balpipe.load(p), simulate=False).results()`` is the
    ``results.json`` that ``balpipe build --no-sim`` wrote, but for the input hash (the build's
    also hashes the page folder's history)."""
    written = json.loads((cli_site / _slug(name) / "results.json").read_text(encoding="utf-8"))
    got = api_studies(name).results()
    assert got.pop("input_hash") and written.pop("input_hash")
    assert got == written


def test_write_writes_the_command_lines_page_files(api_studies, cli_site, tmp_path):
    """``study.write(folder)``: the files of the spec's page folder; the page and the time series
    byte for byte the build's, results.json the dict of :meth:`results`."""
    st = api_studies("offset_slider_crank.yaml")
    page = st.write(tmp_path / "osc")
    assert page == tmp_path / "osc" / "index.html"
    names = sorted(p.name for p in (tmp_path / "osc").iterdir())
    figures = [n for n in names if n.startswith("figure-") and n.endswith(".csv")]  # each live figure's data
    assert [n for n in names if n not in figures] == ["index.html", "results.json", "timeseries.csv"]
    assert {"figure-loads.csv", "figure-efforts.csv"} <= set(figures)
    built = cli_site / _slug("offset_slider_crank.yaml")
    for name in ("index.html", "timeseries.csv", *figures):
        assert (tmp_path / "osc" / name).read_bytes() == (built / name).read_bytes(), name
    assert json.loads((tmp_path / "osc" / "results.json").read_text(encoding="utf-8")) == st.results()


def test_stages_and_verdict_are_the_results(api_studies):
    st = api_studies(FOUR_BAR)
    r = st.results()
    assert [s.name for s in st.stages] == [m["name"] for m in r["stages"]]
    assert [s.metrics for s in st.stages] == r["stages"]
    assert st.verdict == r["verdict"] and st.ok == (r["status"] == "ok") and not st.simulated
    top = st.stages[-1]
    assert top.analysis.max_force == pytest.approx(top.metrics["max_shaking_force"], rel=1e-11)
    st.results()["stages"].clear()  # a copy: the study keeps its own
    assert len(st.results()["stages"]) == len(st.stages)


def test_timeseries_are_the_csv_columns(api_studies, cli_site, monkeypatch):
    st = api_studies("scott_russell.yaml")
    rows = list(csv.reader(io.StringIO((cli_site / _slug("scott_russell.yaml") / "timeseries.csv").read_text())))
    header, values = rows[0], np.array(rows[1:], dtype=float)
    df = st.timeseries()
    pd = pytest.importorskip("pandas")
    assert isinstance(df, pd.DataFrame) and list(df.columns) == header
    np.testing.assert_allclose(df.to_numpy(), values, rtol=1e-11, atol=1e-12 * np.abs(values).max())
    monkeypatch.setitem(sys.modules, "pandas", None)  # without pandas: a dict of arrays, the same columns
    plain = st.timeseries()
    assert isinstance(plain, dict) and list(plain) == header
    assert all(np.array_equal(plain[c], df[c].to_numpy()) for c in header)


def test_figures_are_the_pages_curves(api_studies):
    from matplotlib.figure import Figure

    st = api_studies("offset_slider_crank.yaml")
    assert st.figure_names == ("loads", "efforts", "joints", "mechanism")
    fig = st.figure("loads")
    assert isinstance(fig, Figure)
    axes = fig.axes
    assert [ax.get_title(loc="left") for ax in axes] == ["shaking force Fx (N)", "shaking force Fy (N)",
                                               "shaking force |F| (N)", "shaking moment M (N m)"]
    moment = {line.get_label(): line.get_ydata() for line in axes[3].get_lines()}
    for s in st.stages:
        np.testing.assert_array_equal(moment[s.label], s.analysis.moment)
    with pytest.raises(KeyError, match="no figure 'nope'; figures: loads, efforts, joints, mechanism"):
        st.figure("nope")
    drawn = st.figure("mechanism")  # the page's drawings: a panel per stage, named as the paper does
    assert [ax.get_title() for ax in drawn.axes] == [s.label for s in st.stages]
    assert [[t.get_text() for t in ax.texts] for ax in drawn.axes] == [
        ["A", "B", "C", "link 1", "link 2"], ["A", "B", "C", "counterweight 1", "counterweight 2", "link 1", "link 2"]]


def test_the_notebook_view_shows_verdict_card_and_a_live_plot(api_studies):
    st = api_studies(FOUR_BAR)
    view = st._repr_html_()
    assert st.verdict["text"] in view.replace("&#x27;", "'")
    assert "Design summary: " in view and "cw_crank" in view
    assert view.count("<iframe srcdoc=") == 1 and "data-live=&quot;live-loads&quot;" in view
    assert "uPlot" in view and "src=&quot;http" not in view and "src=\"http" not in view  # self-contained


def test_load_reads_a_path_or_text_and_locates_errors(tmp_path):
    text = (SPECS / "offset_slider_crank.yaml").read_text(encoding="utf-8")
    assert balpipe.load(text).parsed == balpipe.load(SPECS / "offset_slider_crank.yaml").parsed
    bad = tmp_path / "bad.yaml"
    bad.write_text(text.replace("mass: 600 g", "mass: -600 g"))
    with pytest.raises(balpipe.SpecError) as err:
        balpipe.load(str(bad))
    e = err.value
    assert Path(e.file).name == "bad.yaml" and not Path(e.file).is_absolute()  # never a machine path
    assert (e.line, e.column, e.field) == (15, 19, "mechanism.slider.mass") and e.message.startswith("must be >= 0")
    assert str(e) == f"{e.file}:15:19: mechanism.slider.mass: {e.message}"
    with pytest.raises(balpipe.SpecError, match=r"^<text>:1:1: ") as err:
        balpipe.load("- a list\n- not a spec\n")
    with pytest.raises(balpipe.SpecError, match="cannot read the file"):
        balpipe.load(tmp_path / "missing.yaml")


def test_with_values_changes_fields_and_refuses_as_the_file_would():
    spec = balpipe.load(SPECS / "offset_slider_crank.yaml")
    heavier = spec.with_values({"mechanism.slider.mass": "1.2 kg", "motion.duration": 0.25})
    assert heavier.parsed.mechanism.slider.mass == 1.2 and heavier.parsed.motion.duration == 0.25
    assert spec.parsed.mechanism.slider.mass == pytest.approx(0.6)  # unchanged
    assert heavier.path == spec.path and "mass: 1.2 kg" in heavier.text
    # half the duration: four times the loads (the invariant, through the API)
    a, c = balpipe.run(spec.with_values({"motion.duration": 0.5})), balpipe.run(spec.with_values({"motion.duration": 0.25}))
    fa, fc = (s.results()["stages"][0]["max_shaking_force"] for s in (a, c))
    assert fc == pytest.approx(4 * fa, rel=1e-9)
    with pytest.raises(balpipe.SpecError) as err:
        spec.with_values({"mechanism.slider.mass": "-1 kg"})
    assert (err.value.file, err.value.line, err.value.field) == (spec.source, 15, "mechanism.slider.mass")
    with pytest.raises(balpipe.SpecError, match=r"offset_slider_crank.yaml:11:3: mechanism.slidr: unknown path"):
        spec.with_values({"mechanism.slidr.mass": "1 kg"})
    with pytest.raises(balpipe.SpecError, match="mechanism.crank.colour: unknown key"):
        spec.with_values({"mechanism.crank.colour": "red"})


def _example():
    import importlib.util

    spec = importlib.util.spec_from_file_location("parameter_study", ROOT / "docs" / "examples" / "parameter_study.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _four_bar() -> balpipe.Spec:
    """specs/custom_four_bar_balancing.yaml built in Python, part by part."""
    twin = balpipe.load(SPECS / FOUR_BAR).parsed
    mech = _example().my_mechanism()  # the example's machine (docs/examples/parameter_study.py)
    cws = [b.counterweight("crank", "cw_crank", segment=((0, 0), (-0.08, 0))),
           b.counterweight("coupler", "cw_coupler", disc=((0.14, 0), 0.25)),
           b.counterweight("rocker", "cw_rocker", segment=((0, 0), (-0.12, 0)))]
    discs = [b.counter_rotation("disc_crank", carrier="frame", at="O2", geared_to="crank", ratio=-1, radius=0.04),
             b.counter_rotation("disc_coupler", carrier="crank", at="O2", geared_to="coupler", ratio=-1, radius=0.03),
             b.counter_rotation("disc_rocker", carrier="frame", at="O4", geared_to="rocker", ratio=-1, radius=0.04)]
    return balpipe.Spec.from_parts(
        twin.name, mech, {"law": "quintic", "duration": "0.5 s", "drive": {"crank": {"from": "0 deg", "to": "360 deg"}}},
        b.moment_balance(cws, discs), description=twin.description, path=Path("specs") / FOUR_BAR,
        compare=[{"name": "force_only", "label": "force balance only", "balancing": b.force_balance(cws)},
                 {"name": "crank_only", "label": "crank counterweight only",
                  "balancing": twin.compare[1].balancing}],
        analysis={"samples": 401})


def test_a_four_bar_built_in_python_is_its_yaml_twin(api_studies):
    """The same spec (every field, in SI units) and the same results to round-off."""
    spec = _four_bar()
    yaml_twin = api_studies(FOUR_BAR)
    assert spec.parsed == yaml_twin.spec.parsed
    mine, theirs = balpipe.run(spec).results(), yaml_twin.results()
    mine.pop("input_hash"), theirs.pop("input_hash")
    assert json.dumps(mine, sort_keys=True) == json.dumps(theirs, sort_keys=True)


def test_a_built_mechanism_is_refused_as_its_yaml_would_be():
    """A joint naming a body that is not there: the same field and message as from the file."""
    good = _four_bar()
    data = good.data()
    data["mechanism"]["joints"][1]["b"] = "couplr"
    from_file = balpipe.SpecError
    with pytest.raises(from_file) as yaml_err:
        balpipe.run(balpipe.loads(balpipe.api.spec.dump(data)))
    mech = good.parsed.mechanism.model_copy(deep=True)
    mech.joints[1] = b.revolute("A", "crank", "couplr", "A", "A")
    with pytest.raises(balpipe.SpecError) as built_err:
        balpipe.run(balpipe.Spec.from_parts("x", mech, data["motion"]))
    assert built_err.value.field == yaml_err.value.field == "mechanism.joints[1].b"
    assert built_err.value.message == yaml_err.value.message
    with pytest.raises(ValueError, match="greater than or equal to 0"):  # pydantic's, at once
        b.body("crank", "-1 kg")


def test_the_api_is_lazy_and_listed():
    probe = ("import sys, balpipe; print(sorted(m for m in ('numpy', 'pydantic', 'balpipe.api') if m in sys.modules)); "
             "balpipe.load; print('balpipe.api' in sys.modules, sorted(set(balpipe.__all__) - set(dir(balpipe))))")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert r.stdout.split("\n")[:2] == ["[]", "True []"], r.stderr
    for name in balpipe.__all__:
        assert name == "__version__" or getattr(balpipe, name).__doc__, name
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        balpipe.nope  # noqa: B018
