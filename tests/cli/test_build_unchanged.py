"""A build with nothing changed (issue 23): decided from the spec's text and the page's
results.json alone, without loading numpy, pydantic, jinja2 or matplotlib, and writing nothing;
a changed spec, table, history or missing site file is still noticed."""

from __future__ import annotations

import math
import subprocess
import sys
from pathlib import Path

import pytest

from balpipe.build import Options, build, plan_one, up_to_date

from test_motion_specs import spec_text

ROOT = Path(__file__).resolve().parents[2]
HEAVY = ("numpy", "pydantic", "yaml", "jinja2", "matplotlib", "scipy", "pymunk")


def _csv(amplitude: float) -> str:
    rows = "".join(f"{k / 100!r}, {amplitude * (1 - math.cos(2 * math.pi * k / 100))!r}\n" for k in range(101))
    return "t [s], crank [deg]\n" + rows


@pytest.fixture()
def site(tmp_path: Path):
    """A spec whose motion is a table beside it and a paper spec, built without simulation."""
    specs = tmp_path / "specs"
    specs.mkdir()
    (specs / "crank.csv").write_text(_csv(30.0))
    (specs / "table.yaml").write_text(spec_text("duration: 1 s\ndrive:\n  crank: {law: table, file: crank.csv, ends: periodic}\n"))
    (specs / "sr.yaml").write_text((ROOT / "specs" / "scott_russell.yaml").read_text())
    out = tmp_path / "site"
    outcomes = build([str(specs)], Options(out=out, simulate=False), jobs=1)
    assert [o.status for o in outcomes] == ["ok", "ok"], [o.message for o in outcomes]
    return specs, out


def _files(out: Path) -> dict[str, tuple[int, bytes]]:
    return {str(p.relative_to(out)): (p.stat().st_mtime_ns, p.read_bytes()) for p in sorted(out.rglob("*")) if p.is_file()}


def test_the_page_records_the_tables_its_spec_read(site):
    specs, out = site
    import json

    table = json.loads((out / "table" / "results.json").read_text())
    plain = json.loads((out / "sr" / "results.json").read_text())
    assert table["input_tables"] == ["crank.csv"] and "input_tables" not in plain


def test_an_unchanged_rebuild_loads_no_heavy_library_and_writes_nothing(site):
    specs, out = site
    before = _files(out)
    code = ("import sys; from balpipe.cli import main; "
            f"rc = main(['build', {str(specs)!r}, '-o', {str(out)!r}, '--no-sim']); "
            f"print(rc, sorted(m for m in {HEAVY!r} if m in sys.modules))")
    r = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=300)
    assert r.returncode == 0, r.stderr
    assert r.stdout.strip().splitlines()[-1] == "0 []", r.stdout + r.stderr
    assert r.stderr.count(": unchanged (") == 2, r.stderr
    assert _files(out) == before  # not one file rewritten, the index and schema included


def test_the_quick_decision_agrees_with_reading_the_spec(site):
    specs, out = site
    opts = Options(out=out, simulate=False)
    for name in ("table.yaml", "sr.yaml"):
        quick = up_to_date(specs / name, opts)
        full = plan_one(specs / name, opts)
        assert quick is not None and quick == full.results and full.skipped
    # with the other simulation option, neither counts the page as up to date
    other = Options(out=out, simulate=True)
    assert up_to_date(specs / "sr.yaml", other) is None and not hasattr(plan_one(specs / "sr.yaml", other), "skipped")


def test_a_changed_table_or_spec_is_rebuilt_and_the_index_rewritten(site):
    specs, out = site
    opts = Options(out=out, simulate=False)
    index = (out / "index.html").read_text()
    (specs / "crank.csv").write_text(_csv(40.0))
    assert up_to_date(specs / "table.yaml", opts) is None and up_to_date(specs / "sr.yaml", opts) is not None
    outcomes = build([str(specs)], opts, jobs=1)
    assert [o.skipped for o in outcomes] == [True, False]  # sorted by file: sr.yaml, table.yaml
    assert (out / "index.html").read_text() != index  # the key in its head names the new results
    (specs / "sr.yaml").write_text((specs / "sr.yaml").read_text() + "\n# a comment changes the text\n")
    assert up_to_date(specs / "sr.yaml", opts) is None


def test_a_missing_schema_or_a_foreign_index_is_written_again(site):
    specs, out = site
    opts = Options(out=out, simulate=False)
    (out / "balpipe.schema.json").unlink()
    build([str(specs)], opts, jobs=1)
    assert (out / "balpipe.schema.json").is_file()
    # an index without the key (an older build, or edited by hand) is rendered again
    (out / "index.html").write_text("<html>by hand</html>")
    build([str(specs)], opts, jobs=1)
    assert 'name="balpipe-site-key"' in (out / "index.html").read_text()


def test_forcing_rebuilds_whatever_the_pages_say(site):
    specs, out = site
    outcomes = build([str(specs)], Options(out=out, simulate=False, force=True), jobs=1)
    assert not any(o.skipped for o in outcomes)


def test_a_built_spec_is_read_once_and_computed_from_the_planned_spec(site, monkeypatch):
    """build_one hands the spec plan_one loaded to compute (the same text under the same name):
    each changed spec's YAML is validated once, not once to plan and again to compute; the page
    is the same as computed from the job's text (a spec loaded for another text is not used)."""
    import balpipe.build as build_mod
    import balpipe.loader as loader

    specs, out = site
    calls = []
    real = loader.load_text
    monkeypatch.setattr(loader, "load_text", lambda text, *a, **k: calls.append(text) or real(text, *a, **k))
    outcomes = build([str(specs)], Options(out=out, simulate=False, force=True), jobs=1)
    assert [o.status for o in outcomes] == ["ok", "ok"] and len(calls) == 2, [o.message for o in outcomes]
    opts = Options(out=out, simulate=False, force=True)
    job, planned = build_mod._plan(specs / "table.yaml", opts)
    assert planned.text == job.text and planned.name == job.source
    calls.clear()
    reused, again = build_mod.compute(job, planned), build_mod.compute(job)
    assert len(calls) == 1  # the second, without the planned spec
    assert reused.files["index.html"] == again.files["index.html"] and reused.results == again.results
    _, other = build_mod._plan(specs / "sr.yaml", opts)
    calls.clear()
    assert build_mod.compute(job, other).files["index.html"] == again.files["index.html"] and len(calls) == 1
