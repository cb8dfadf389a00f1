"""The command line as a user meets it: exit codes, messages, the site, determinism."""

import json
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
from _edits import replaced

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


def balpipe(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True, cwd=cwd)


TWO = ("scott_russell.yaml", "offset_slider_crank.yaml")


def _two_specs(folder: Path) -> Path:
    d = folder / "specs"
    d.mkdir()
    for name in TWO:
        shutil.copy(SPECS / name, d / name)
    return folder


@pytest.fixture
def work(tmp_path):
    """A folder with the two slider-crank specs (fast to build)."""
    return _two_specs(tmp_path)


@pytest.fixture
def built(shared_build):
    """The two specs built once per run for the tests that only read the site (-j 1, --no-sim,
    to ``a``): (folder, the build's completed process)."""
    return shared_build(TWO, "specs", "-o", "a", "--no-sim", "-j", "1")


@pytest.fixture
def simulated(shared_build):
    """scott_russell.yaml built once per run with its simulations, to ``a``: (folder, completed
    process)."""
    return shared_build(TWO, "specs/scott_russell.yaml", "-o", "a")


def test_help_for_every_command():
    for args in (["--help"], ["build", "--help"], ["check", "--help"], ["schema", "--help"]):
        r = balpipe(*args)
        assert r.returncode == 0 and "usage: balpipe" in r.stdout


def test_usage_errors_exit_2_without_traceback(tmp_path):
    for args in (["build"], ["frobnicate"], ["build", tmp_path / "nope"], ["build", tmp_path, "-j", "0"]):
        r = balpipe(*args)
        assert r.returncode == 2, args
        assert "Traceback" not in r.stderr


def test_build_writes_the_site(built, work):
    shared, r = built
    assert r.returncode == 0, r.stderr
    out = shared / "a"
    index = (out / "index.html").read_text()
    assert "scott_russell/index.html" in index and "offset_slider_crank/index.html" in index
    res = json.loads((out / "scott_russell" / "results.json").read_text())
    assert res["spec"].startswith("Scott-Russell")
    assert [s["name"] for s in res["stages"]] == ["unbalanced", "counterweights", "full"]
    for key in ("max_shaking_force", "max_shaking_moment", "max_actuator_effort", "added_mass"):
        assert all(key in s for s in res["stages"])
    assert {p["name"] for p in res["parameters"]} >= {"mcp1", "mcp2", "Icp2"}
    assert res["checks"]["reactions_vs_momentum"] < 1e-9
    full = res["stages"][-1]
    assert full["max_shaking_force"] <= 1e-9 * res["stages"][0]["max_shaking_force"]
    assert full["max_shaking_moment"] <= 1e-9 * res["stages"][0]["max_shaking_moment"]
    csv = (out / "scott_russell" / "timeseries.csv").read_text().splitlines()
    assert csv[0].startswith("t_s,unbalanced.Fx_N") and len(csv) == 1 + 501
    page = (out / "scott_russell" / "index.html").read_text()
    # the drawings are inline SVG, the plots over time are drawn in the browser from their data
    live = re.findall(r'<script type="application/json" data-live="([a-z-]+)">', page)
    assert set(live) == {"live-loads", "live-efforts", "live-joints", "live-whatif"}  # and the designs tried live
    assert all(f'<div class="live" id="{name}">' in page for name in live)
    assert page.count("<figure>") + page.count('<figure class="wide">') >= 5
    assert page.count("<svg") >= 3 and "skipped" in page
    assert (out / "balpipe.schema.json").exists()
    # unchanged specs are not rebuilt (a copy of the shared site, built again from the same specs)
    shutil.copytree(out, work / "out")
    again = balpipe("build", "specs", "-o", "out", "--no-sim", cwd=work)
    assert again.returncode == 0 and again.stderr.count("unchanged") == 2


def test_output_is_byte_identical(built, tmp_path):
    work, a = built
    assert a.returncode == 0
    b = tmp_path / "b"
    assert balpipe("build", "specs", "-o", b, "--no-sim", "--force", "-j", "1", cwd=work).returncode == 0
    files = sorted(p.relative_to(work / "a") for p in (work / "a").rglob("*") if p.is_file())
    assert len(files) >= 8
    for f in files:
        assert (work / "a" / f).read_bytes() == (b / f).read_bytes(), f


def test_bad_spec_does_not_stop_the_others_nor_damage_its_old_page(built, work):
    shared, first = built  # the earlier build: a copy of the shared one
    assert first.returncode == 0
    shutil.copytree(shared / "a", work / "out")
    page = work / "out" / "offset_slider_crank" / "index.html"
    before = page.read_bytes()
    spec = work / "specs" / "offset_slider_crank.yaml"
    spec.write_text(replaced(spec.read_text(), "mass: 600 g", "mass: -600 g"))
    (work / "specs" / "broken.yaml").write_text("name: broken\nmechanism: {template: slider_crank\n")
    r = balpipe("build", "specs", "-o", "out", "--no-sim", cwd=work)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr
    assert "specs/offset_slider_crank.yaml:15:" in r.stderr and "mechanism.slider.mass: must be >= 0" in r.stderr
    assert "specs/broken.yaml:3:1: malformed YAML" in r.stderr
    assert page.read_bytes() == before  # the earlier page is intact
    index = (work / "out" / "index.html").read_text()
    assert index.count("invalid spec") == 2 and "page from an earlier build" in index
    assert (work / "out" / "scott_russell" / "index.html").exists()


def test_a_stage_that_misses_its_claim_fails_the_build(work):
    spec = work / "specs" / "scott_russell.yaml"
    spec.write_text(replaced(spec.read_text(), "samples: 501", "samples: 501\n  balance_tolerance: 1.0e-18"))
    r = balpipe("build", spec, "-o", "out", "--no-sim", cwd=work)
    assert r.returncode == 1
    res = json.loads((work / "out" / "scott_russell" / "results.json").read_text())
    assert res["status"] == "failed" and "should cancel" in res["problems"][0]
    assert "failed" in (work / "out" / "index.html").read_text()


def test_unreachable_geometry_is_a_located_spec_error(work):
    spec = work / "specs" / "offset_slider_crank.yaml"
    spec.write_text(replaced(spec.read_text(), "offset: 30 mm", "offset: 250 mm"))
    r = balpipe("check", spec)
    assert r.returncode == 2
    assert "offset_slider_crank.yaml:14:" in r.stderr and "mechanism.coupler.length: the coupler" in r.stderr


def test_check_and_schema(work):
    r = balpipe("check", "specs", cwd=work)
    assert r.returncode == 0 and r.stdout.count(": ok") == 2
    r = balpipe("schema")
    assert r.returncode == 0
    s = json.loads(r.stdout)
    assert "mechanism" in s["properties"] and s["additionalProperties"] is False


def test_a_counterweight_10_percent_off_fails_validation_visibly(work):
    """As built with mcp1 10 % heavier than eq. 15's 8.4 kg: the analysis and the pymunk
    simulation both see the residual force; the page and the index say so; exit 1."""
    spec = work / "specs" / "offset_slider_crank.yaml"
    spec.write_text(replaced(spec.read_text(), "coupler_counterweight: -0.15 m",
                                              "coupler_counterweight: -0.15 m\n  crank_counterweight_mass: 9.24 kg"))
    r = balpipe("build", spec, "-o", "out", cwd=work)
    assert r.returncode == 1, r.stderr
    assert "pymunk validation of stage 'counterweights' fails" in r.stderr
    res = json.loads((work / "out" / "offset_slider_crank" / "results.json").read_text())
    v = res["validation"]["counterweights"]
    assert v["passed"] is False and v["force_peak"] > 0.01
    assert res["validation"]["unbalanced"]["passed"] is True  # the simulation itself is fine
    page = (work / "out" / "offset_slider_crank" / "index.html").read_text()
    assert '<span class="badge bad">fail</span>' in page
    index = (work / "out" / "index.html").read_text()
    assert '<span class="badge bad">fail</span>' in index and '<span class="badge bad">failed</span>' in index


def test_simulated_build_passes_and_reports_validation(simulated):
    work, r = simulated
    assert r.returncode == 0, r.stderr
    res = json.loads((work / "a" / "scott_russell" / "results.json").read_text())
    for name, v in res["validation"].items():
        assert v["passed"], (name, v["reasons"])
        assert v["force_residual"] <= 0.01 and v["moment_residual"] <= 0.01
    rl = res["reactionless"]
    assert rl["unbalanced"]["max_drift"] > 1e3 * rl["full"]["max_drift"]
    assert rl["unbalanced"]["max_rotation"] > 1e3 * rl["full"]["max_rotation"]
    out = work / "a" / "scott_russell"
    page = (out / "index.html").read_text()
    assert "timing.js" in page and (out / "timing.json").exists()
    # the run-time column: every run of a stage, also where its torque-driven run alone proves it
    times = json.loads((out / "timing.json").read_text())
    for t in times.values():
        parts = t.get("total_s", 0.0) + t.get("torque_driven_s", 0.0) + t.get("reactionless_s", 0.0)
        assert t["all_runs_s"] == parts > 0
    shown = json.loads((out / "timing.js").read_text().split("var T=")[1].split(";")[0])
    assert shown == {k: round(t["all_runs_s"], 4) for k, t in times.items()}
    assert "<canvas" in page and "Reactionless demonstration" in page and "Residuals of the simulation" in page
    # the torque-driven run (issue 7, item 7): every stage follows its plan under the engine's efforts
    td = res["torque_driven"]
    assert set(td) == {"unbalanced", "counterweights", "full"}
    for name, q in td.items():
        assert q["passed"], (name, q["reasons"])
        assert q["tracking_error_max"] < 1e-4 and q["resolution"] > 100
    assert "Torque-driven run" in page and all(v["method"] == "pymunk" for v in rl.values())
    assert "simulation (pymunk)" in page and "conservation solution" in page


def test_parallel_build_gives_the_same_site_and_quiet_hides_progress(built, tmp_path):
    work, a = built
    b = balpipe("build", "specs", "-o", tmp_path / "b", "--no-sim", "-j", "2", "-q", cwd=work)
    assert a.returncode == b.returncode == 0
    assert "[1/2]" in a.stderr and "[1/2]" not in b.stderr and "2 ok" in b.stderr
    for f in sorted(p.relative_to(work / "a") for p in (work / "a").rglob("*") if p.is_file()):
        assert (work / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes(), f


def test_simulated_output_is_byte_identical_but_for_the_timing_files(simulated, tmp_path):
    work, a = simulated
    assert a.returncode == 0
    assert balpipe("build", "specs/scott_russell.yaml", "-o", tmp_path / "b", "--force", cwd=work).returncode == 0
    files = sorted(p.relative_to(work / "a") for p in (work / "a").rglob("*") if p.is_file())
    assert {f.name for f in files} >= {"index.html", "results.json", "timeseries.csv", "timing.json", "timing.js"}
    for f in files:
        # the caches are not part of the site (a simulation's entry keeps its run time, as timing.json)
        if not f.name.startswith("timing.") and f.parts[0] != ".cache":
            assert (work / "a" / f).read_bytes() == (tmp_path / "b" / f).read_bytes(), f
