"""balpipe diff: two designs, their input changes and what they did to the results."""

import json
import shutil
import subprocess
import sys
from pathlib import Path
from _edits import replaced

ROOT = Path(__file__).resolve().parents[2]


def balpipe(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True, cwd=cwd)


def test_diff_of_two_spec_files_in_every_format(tmp_path):
    old = tmp_path / "old.yaml"
    new = tmp_path / "new.yaml"
    shutil.copy(ROOT / "specs" / "scott_russell.yaml", old)
    new.write_text(replaced(old.read_text(), "crank_counterweight: -0.1 m", "crank_counterweight: -0.12 m"))
    r = balpipe("diff", old, new, "--no-sim", "-f", "json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    # each input with the paper's symbol (the page's inputs table's): r_cp1 L_1 of eq. 15
    assert d["inputs"] == [{"field": "balancing.crank_counterweight", "symbol": "r_cp1 L₁", "old": -0.1, "new": -0.12,
                            "unit": "m"}]
    mcp1 = next(p for p in d["parameters"] if p["name"] == "mcp1")
    # eq. 15: mcp1 scales as 1 / rcp1
    assert abs(mcp1["new"] - mcp1["old"] * 0.1 / 0.12) < 1e-9
    full = next(s for s in d["stages"] if s["name"] == "full")
    assert full["added_mass"]["delta"] < 0
    text = balpipe("diff", old, new, "--no-sim").stdout
    assert "balancing.crank_counterweight" in text and "mcp1" in text
    # loads cancelled to round-off in both designs are not reported as changes
    assert "force_ratio" not in text
    md = balpipe("diff", old, new, "--no-sim", "-f", "markdown").stdout
    assert md.startswith("## balpipe diff") and "| mcp1 |" in md
    out = tmp_path / "d.html"
    assert balpipe("diff", old, new, "--no-sim", "-f", "html", "-o", out).returncode == 0
    html = out.read_text()
    # a live (interactive) overlay per stage, no static figure
    assert html.count('data-live="live-diff') == 3 and "<svg" not in html and "Design comparison" in html
    # readable names with units; round-off stages drawn as zero, said so
    assert "added mass (kg)" in html and "unit (SI)" in html and "max_shaking_force" not in html
    assert "is round-off in both designs" in html
    assert "report site" not in html  # no site beside the file: no dead link
    (tmp_path / "index.html").write_text("<title>balpipe report site</title>")
    assert balpipe("diff", old, new, "--no-sim", "-f", "html", "-o", out).returncode == 0
    assert '<a href="index.html">&larr; report site</a>' in out.read_text()


def test_diff_against_a_git_revision(tmp_path):
    repo = tmp_path / "repo"
    (repo / "specs").mkdir(parents=True)
    spec = repo / "specs" / "sc.yaml"
    shutil.copy(ROOT / "specs" / "offset_slider_crank.yaml", spec)
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t"]
    subprocess.run(["git", "init", "-q"], cwd=repo, check=True)
    subprocess.run(git + ["add", "."], cwd=repo, check=True)
    subprocess.run(git + ["commit", "-qm", "one"], cwd=repo, check=True)
    spec.write_text(replaced(spec.read_text(), "mass: 600 g", "mass: 700 g"))
    r = balpipe("diff", "HEAD:specs/sc.yaml", "specs/sc.yaml", "--no-sim", "-f", "json", cwd=repo)
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["inputs"] == [{"field": "mechanism.slider.mass", "symbol": "m₃", "old": 0.6, "new": 0.7, "unit": "kg"}]
    text = balpipe("diff", "HEAD:specs/sc.yaml", "specs/sc.yaml", "--no-sim", cwd=repo).stdout
    inputs = text[text.index("Inputs:"):].splitlines()
    assert inputs[1].split()[:3] == ["symbol", "(paper)", "field"] and inputs[2].split()[:2] == ["m₃", "mechanism.slider.mass"]
    bad = balpipe("diff", "NOPE:specs/sc.yaml", "specs/sc.yaml", cwd=repo)
    assert bad.returncode == 2 and "cannot read it from git" in bad.stderr and "Traceback" not in bad.stderr


def test_diff_with_simulation_reports_residual_changes(tmp_path):
    old = ROOT / "specs" / "offset_slider_crank.yaml"
    new = tmp_path / "new.yaml"
    new.write_text(replaced(old.read_text(), "coupler_counterweight: -0.15 m",
                                           "coupler_counterweight: -0.15 m\n  crank_counterweight_mass: 9.24 kg"))
    r = balpipe("diff", old, new, "-f", "json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    cw = next(s for s in d["stages"] if s["name"] == "counterweights")
    assert cw["validation"]["passed"] == {"old": True, "new": False}
    text = balpipe("diff", old, new).stdout
    stages, _, sim = text.partition("Simulation residuals (numerical, not a design change):")
    assert "pymunk validation passed" in stages and "residual" not in stages.split("Stages:")[1]
    assert "pymunk force residual" in sim
    assert d["status"] == {"old": "ok", "new": "failed"}


def test_round_off_is_never_a_change():
    from balpipe.diff import same

    assert same(0.1, 0.1 + 1.39e-16) and same(0.0, 1.39e-16) and same(263.2, 263.2 * (1 + 1e-12))
    assert not same(0.1, 0.12) and not same(0.0, 1e-6) and not same(None, 0.0) and not same(True, False)
    assert not same(1e-3, 1e-3 + 1e-11)  # a real change of a small quantity is still a change


def test_diff_leads_with_the_results(tmp_path):
    old = ROOT / "specs" / "offset_slider_crank.yaml"
    new = tmp_path / "new.yaml"
    new.write_text(replaced(old.read_text(), "coupler_counterweight: -0.15 m", "coupler_counterweight: -0.15000000000000002 m"))
    text = balpipe("diff", old, new, "--no-sim").stdout
    assert "Inputs: no change" in text and "Stages: no change" in text  # round-off of an input: no change
    new.write_text(replaced(old.read_text(), "{mass: 600 g}", "{mass: 700 g}"))
    text = balpipe("diff", old, new, "--no-sim").stdout
    # whether each side is still balanced first, then the inputs that changed, then what they did
    assert text.splitlines()[1].startswith("Verdict: still force balanced as designed; costs moment × 10.6 → moment × 11.4")
    assert text.index("Verdict:") < text.index("Inputs:") < text.index("Stages:") < text.index("Computed parameters")


def test_the_diff_says_whether_each_side_is_still_balanced_in_the_pages_words(tmp_path):
    """The printed Scott-Russell legs against the corrected ones: each side's verdict is the
    one its page shows (the same function), the still-balanced sentence says it is lost, and the
    HTML page links to the page of each side that the site beside it holds."""
    from balpipe.build import Options, build

    old, new = ROOT / "specs" / "paper000_rpr3_scott_russell_corrected.yaml", ROOT / "specs" / "paper000_rpr3_scott_russell.yaml"
    site = tmp_path / "site"
    build([str(new)], Options(out=site, simulate=False))
    page = json.loads((site / "paper000_rpr3_scott_russell" / "results.json").read_text())["verdict"]
    r = balpipe("diff", old, new, "--no-sim", "-f", "json")
    assert r.returncode == 0, r.stderr
    v = json.loads(r.stdout)["verdict"]
    assert v["new"]["words"] == page["words"] and v["new"]["costs"] == page["costs"] and v["new"]["verdict"] == "fails"
    assert v["old"]["words"] == "balanced as claimed"
    assert v["still"] == f"no longer balanced: {page['words']} (was: balanced as claimed)"
    assert all(s["label"] for s in json.loads(r.stdout)["stages"])  # each stage by its page's label too
    out = site / "diff.html"
    assert balpipe("diff", old, new, "--no-sim", "-f", "html", "-o", out).returncode == 0
    html = out.read_text()
    assert html.index('id="verdict"') < html.index('id="headline"') < html.index("<h2>Inputs</h2>") < html.index("<h2>Stages</h2>")
    assert 'href="paper000_rpr3_scott_russell/index.html" class="page-link"' in html
    # what changed: the stages both designs have (the corrected spec's compared idler loop is not one)
    head = html[html.index('id="headline"'):html.index("<h2>Inputs</h2>")]
    assert "counter-rotations: peak |M|" in head and "idler" not in head
    assert html.count('class="page-link"') == 1  # the corrected design has no page on this site: no dead link
    text = balpipe("diff", old, new, "--no-sim").stdout
    stages = text[text.index("Stages:"):text.index("References")]
    assert "counter-rotations" in stages and "counter_rotations" not in stages  # one name: the page's label


def test_diff_page_opens_with_the_headline_changes(tmp_path):
    old = ROOT / "specs" / "offset_slider_crank.yaml"
    new = tmp_path / "new.yaml"
    new.write_text(replaced(old.read_text(), "{mass: 600 g}", "{mass: 700 g}"))
    out = tmp_path / "d.html"
    assert balpipe("diff", old, new, "--no-sim", "-f", "html", "-o", out).returncode == 0
    html = out.read_text()
    head = html[html.index('id="headline"'):html.index("<h2>")]
    assert "What changed" in head and "counterweights: peak |M| (N m) 78.0642 &rarr; <strong>85.57</strong>" in head


def _stage(name: str, **values) -> dict:
    from balpipe.diff import STAGE_KEYS, _change

    row = {"name": name}
    for key in STAGE_KEYS:
        old, new = values.get(key, (1.0, 1.0))
        row[key] = _change(old, new)
    return row


def test_a_load_cancelled_to_round_off_reads_zero_and_a_long_text_is_cut():
    """The corrected Scott-Russell legs: |M| 11.5 N m -> 2.8e-13 N m is 'cancelled', shown as
    0 (< tolerance), never as a number of round-off; a new stage's cancelled load too; a spec's
    description of a thousand characters is shown by its start and its length."""
    from balpipe.diff import ROUND_OFF_TEXT, _rows

    data = {
        "stages": [_stage("counter_rotations", max_shaking_moment=(11.51, 2.84e-13), moment_ratio=(6.74, 1.66e-13)),
                   _stage("idler:counterweights", max_shaking_force=(None, 3.46e-13), force_ratio=(None, 1.0e-14)),
                   _stage("worse", max_shaking_moment=(1e-13, 2.0), moment_ratio=(1e-14, 3.0))],
        "references": [], "parameters": [],
        "inputs": [{"field": "description", "old": "a" * 1097, "new": "short", "unit": ""}],
    }
    sections = dict((title, rows) for title, rows, _ in _rows(data))
    rows = {(r[0], r[1]): r[2:] for r in sections["Stages"]}
    assert rows["counter_rotations", "peak |M| (N m)"] == ["11.51", ROUND_OFF_TEXT, "cancelled"]
    assert rows["counter_rotations", "|M| vs unbalanced"] == ["6.74", ROUND_OFF_TEXT, "cancelled"]
    assert rows["idler:counterweights", "peak |F| (N)"] == ["—", ROUND_OFF_TEXT, ""]
    assert rows["worse", "peak |M| (N m)"][:2] == [ROUND_OFF_TEXT, "2"]  # from round-off to a real load
    assert not any("e-1" in c for r in sections["Stages"] for c in r)
    (symbol, field, old, new, _), = sections["Inputs"]
    assert symbol == "—" and field == "description"  # no symbol: a text of the spec's
    assert old.startswith("a" * 20) and old.endswith("… (1097 characters)") and len(old) < 70 and new == "short"


def test_the_diff_says_what_the_frame_on_its_mounts_feels_now(tmp_path):
    """The V-twin's front mount made stiffer: the floor force and vibration velocity of each
    stage, old and new, in a section of its own (JSON, text and HTML), with no round-off shown as
    a change; a spec without ``frame`` has no such section."""
    old, new = ROOT / "specs" / "custom_v_twin_6000rpm.yaml", tmp_path / "new.yaml"
    new.write_text(replaced(old.read_text(), "{name: front, at: [0.18, -0.12], kx: 250 kN/m",
                            "{name: front, at: [0.18, -0.12], kx: 500 kN/m"))
    r = balpipe("diff", old, new, "--no-sim", "-f", "json")
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert d["inputs"] == [{"field": "frame.mounts[0].kx", "symbol": "k_x,0", "old": 250000.0, "new": 500000.0, "unit": "N/m"}]
    rows = {m["name"]: m for m in d["mounts"]}
    assert set(rows) == {s["name"] for s in d["stages"]}
    un = rows["unbalanced"]
    assert un["floor_force_peak"]["old"] > 0 and un["floor_force_peak"]["new"] != un["floor_force_peak"]["old"]
    assert un["velocity_rms"]["relative"] is not None
    text = balpipe("diff", old, new, "--no-sim").stdout
    section = text[text.index("The frame on its mounts"):text.index("References")]
    assert "largest peak floor force (N)" in section and "largest RMS vibration velocity (mm/s)" in section
    assert "e-" not in section and "e+" not in section
    out = tmp_path / "d.html"
    assert balpipe("diff", old, new, "--no-sim", "-f", "html", "-o", out).returncode == 0
    assert "The frame on its mounts" in out.read_text()
    plain = balpipe("diff", ROOT / "specs" / "scott_russell.yaml", ROOT / "specs" / "scott_russell.yaml", "--no-sim", "-f", "json")
    assert json.loads(plain.stdout)["mounts"] == []


def test_the_diffs_numbers_are_the_pages_numbers():
    """An input of 1.5 MN/m reads 1500000 (not 1.5e+06), a relative change of a millionth
    +0.0001 % (not +1.00e-06): balpipe.display.numbers, as on the pages."""
    from balpipe.diff import _fmt, _rel

    assert _fmt(1.5e6) == "1500000" and _fmt(0.000123456789) == "0.000123457"
    assert _rel({"relative": 1e-6}) == "+0.0001 %" and _rel({"relative": -0.25}) == "-25 %"
    assert _rel({"relative": 0.0}) == "=" and _rel({"relative": float("inf")}) == "new"
