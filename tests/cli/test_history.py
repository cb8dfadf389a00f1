"""balpipe history: each spec's headline figures along its git history, the cache, and how
build takes the history in."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from _gitrepo import Repo, balpipe, edit, git

from balpipe import history
from balpipe.build import Options, build


def hist(out: str, cache: str = "cache") -> history.SpecHistory:
    """In-process history of ``specs/`` (the current folder is the repository)."""
    return history.run(["specs"], Path(out), Path(cache), simulate=False)[0]


def build_(out: str):
    return build(["specs"], Options(out=Path(out), simulate=False))[0]

SPEC = "specs/osc.yaml"


def three_commits(tmp_path: Path) -> tuple[Repo, list[str]]:
    """The acceptance repository: a spec, then a mass changed, then a counterweight moved."""
    repo = Repo(tmp_path / "repo")
    repo.copy_spec("offset_slider_crank.yaml", SPEC)
    text = repo.read(SPEC) + "analysis:\n  samples: 81\n"  # coarse: these tests are about history
    h1 = repo.commit("first design", {SPEC: text})
    h2 = repo.commit("heavier slider", {SPEC: edit(repo.read(SPEC), "slider:  {mass: 600 g}", "slider:  {mass: 800 g}")})
    h3 = repo.commit("crank counterweight further out",
                     {SPEC: edit(repo.read(SPEC), "crank_counterweight: -0.1 m", "crank_counterweight: -0.12 m")})
    return repo, [h1, h2, h3]


def recorded(point: dict) -> dict:
    """The fields of a history point that the tests compare."""
    return {
        "status": point["status"],
        "parameters": [(p["name"], p["value"], p["unit"]) for p in point["parameters"]],
        "stages": [(s["name"], s["max_shaking_force"], s["max_shaking_moment"], s["added_mass"])
                   for s in point["stages"]],
        "validation": point["validation"],
    }


def headline(results: dict) -> dict:
    """What a history point must hold, read from a build's results.json: the same fields, the
    validation as one word."""
    v = results["validation"]
    return recorded({**results, "validation": "skipped" if v is None else
                     ("pass" if all(x["passed"] for x in v.values()) else "fail")})


def params(point: dict) -> dict[str, float]:
    return {p["name"]: p["value"] for p in point["parameters"]}


def test_history_of_three_commits_matches_a_build_of_each_revision(tmp_path):
    repo, hashes = three_commits(tmp_path)
    r = balpipe("history", "specs", "-o", "out", "--no-sim", "--cache", "cache", cwd=repo.path)
    assert r.returncode == 0, r.stderr
    assert "3 commits (3 computed, 0 cached" in r.stderr
    data = json.loads((repo.path / "out" / "osc" / "history.json").read_text())
    points = data["commits"]
    assert [c["hash"] for c in points] == hashes  # oldest first
    assert [c["subject"] for c in points] == ["first design", "heavier slider", "crank counterweight further out"]
    assert [c["date"] for c in points] == ["2026-11-30T10:01:00+00:00", "2026-11-30T10:02:00+00:00",
                                           "2026-11-30T10:03:00+00:00"]
    assert data["simulated"] is False and data["shallow"] is False and data["uncommitted_changes"] is False
    # every point equals a build of that revision, to the last digit
    for k, h in enumerate(hashes):
        rev = tmp_path / f"rev{k}"
        rev.mkdir()
        (rev / "osc.yaml").write_text(git(repo.path, "show", f"{h}:{SPEC}"))
        assert build([str(rev)], Options(out=tmp_path / f"build{k}", simulate=False))[0].status == "ok"
        built = json.loads((tmp_path / f"build{k}" / "osc" / "results.json").read_text())
        assert recorded(points[k]) == headline(built)
        assert points[k]["input_hash"] == built["input_hash"]  # no history.json in that build
    p1, p2, p3 = map(params, points)
    # a heavier slider (600 g -> 800 g) needs heavier counterweights on both links (eq. 15)
    assert p2["mcp1"] > p1["mcp1"] and p2["mcp2"] > p1["mcp2"]
    assert p2["mcp2"] - p1["mcp2"] == pytest.approx(0.2 * 0.3 / 0.15, rel=1e-9)
    # moving the crank's counterweight out keeps its static moment: m r constant, coupler's untouched
    assert p3["mcp1"] * 0.12 == pytest.approx(p2["mcp1"] * 0.1, rel=1e-9)
    assert p3["mcp2"] == p2["mcp2"]
    # the force stays cancelled at every commit
    for c in points:
        assert c["stages"][1]["max_shaking_force"] <= 1e-9 * c["stages"][0]["max_shaking_force"]


def test_second_run_computes_nothing_and_writes_the_same_bytes(tmp_path, monkeypatch):
    repo, _ = three_commits(tmp_path)
    monkeypatch.chdir(repo.path)
    out, cache = repo.path / "out", repo.path / "cache"
    first = history.run(["specs"], out, cache, simulate=False)
    assert [(o.commits, o.computed, o.cached) for o in first] == [(3, 3, 0)]
    files = {p.name: p.read_bytes() for p in (out / "osc").iterdir()}
    assert set(files) == {"history.json", "history.html"}
    assert len(list(cache.glob("*.json"))) == 3

    def no_compute(job):
        raise AssertionError("a cached revision was recomputed")

    monkeypatch.setattr(history, "_compute_job", no_compute)
    second = history.run(["specs"], out, cache, simulate=False)
    assert [(o.commits, o.computed, o.cached) for o in second] == [(3, 0, 3)]
    assert {p.name: p.read_bytes() for p in (out / "osc").iterdir()} == files
    # a fresh output folder from the warm cache: the same bytes again
    third = history.run(["specs"], repo.path / "out2", cache, simulate=False)
    assert third[0].computed == 0
    assert {p.name: p.read_bytes() for p in (repo.path / "out2" / "osc").iterdir()} == files
    # computed again in two processes, from an empty cache: the same bytes
    monkeypatch.undo()
    monkeypatch.chdir(repo.path)
    fourth = history.run(["specs"], repo.path / "out3", repo.path / "cache3", simulate=False, jobs=2)
    assert fourth[0].computed == 3
    assert {p.name: p.read_bytes() for p in (repo.path / "out3" / "osc").iterdir()} == files


def test_only_the_new_commit_is_computed(tmp_path, monkeypatch):
    repo, _ = three_commits(tmp_path)
    monkeypatch.chdir(repo.path)
    history.run(["specs"], Path("out"), Path("cache"), simulate=False)
    repo.commit("lighter coupler", {SPEC: edit(repo.read(SPEC), "mass: 0.9 kg", "mass: 0.8 kg")})
    # an unrelated commit is not a point of this spec's history
    repo.commit("readme", {"README.md": "notes\n"})
    o = history.run(["specs"], Path("out"), Path("cache"), simulate=False)[0]
    assert (o.commits, o.computed, o.cached) == (4, 1, 3)
    data = json.loads(Path("out/osc/history.json").read_text())
    assert [c["subject"] for c in data["commits"]][-1] == "lighter coupler"


def test_renames_are_followed(tmp_path):
    repo, hashes = three_commits(tmp_path)
    git(repo.path, "mv", SPEC, "specs/renamed.yaml")
    h4 = repo.commit("rename the spec")
    r = balpipe("history", "specs/renamed.yaml", "-o", "out", "--no-sim", "--cache", "cache", cwd=repo.path)
    assert r.returncode == 0, r.stderr
    data = json.loads((repo.path / "out" / "renamed" / "history.json").read_text())
    assert [c["hash"] for c in data["commits"]] == hashes + [h4]
    assert [c["path"] for c in data["commits"]] == [SPEC] * 3 + ["specs/renamed.yaml"]
    # the rename changed no byte: the last point is the third one, taken from the cache
    assert "(3 computed, 1 cached" in r.stderr
    assert data["commits"][3]["input_hash"] == data["commits"][2]["input_hash"]


def test_an_invalid_revision_is_a_located_gap(tmp_path):
    repo, _ = three_commits(tmp_path)
    repo.commit("typo", {SPEC: edit(repo.read(SPEC), "slider:  {mass: 800 g}", "slider:  {mass: -800 g}")})
    repo.commit("fixed", {SPEC: edit(repo.read(SPEC), "slider:  {mass: -800 g}", "slider:  {mass: 800 g}")})
    r = balpipe("history", "specs", "-o", "out", "--no-sim", "--cache", "cache", cwd=repo.path)
    assert r.returncode == 0, r.stderr
    points = json.loads((repo.path / "out" / "osc" / "history.json").read_text())["commits"]
    bad = points[3]
    assert bad["status"] == "invalid" and bad["stages"] == [] and bad["parameters"] == []
    assert any("mechanism.slider.mass" in p and "osc.yaml:" in p for p in bad["problems"])
    assert points[4]["input_hash"] == points[2]["input_hash"]  # the fix is the third design again
    page = (repo.path / "out" / "osc" / "history.html").read_text()
    assert "invalid" in page and "mechanism.slider.mass" in page


def test_history_outside_git_is_a_usage_error(tmp_path):
    (tmp_path / "specs").mkdir()
    (tmp_path / "specs" / "a.yaml").write_text((Path(__file__).parents[2] / "specs" / "scott_russell.yaml").read_text())
    r = balpipe("history", "specs", "-o", "out", "--no-sim", cwd=tmp_path)
    assert r.returncode == 2
    assert "not in a git repository" in r.stderr and "Traceback" not in r.stderr
    h = balpipe("history", "--help", cwd=tmp_path)
    assert h.returncode == 0 and "usage: balpipe history" in h.stdout and "--cache" in h.stdout
    assert "history" in balpipe("--help", cwd=tmp_path).stdout
    for args in (["history"], ["history", "nope"], ["history", "specs", "-j", "0"], ["history", "specs", "--max-commits", "0"]):
        r = balpipe(*args, cwd=tmp_path)
        assert r.returncode == 2 and "Traceback" not in r.stderr, args


def test_uncommitted_spec_and_uncommitted_changes(tmp_path):
    repo, _ = three_commits(tmp_path)
    repo.copy_spec("scott_russell.yaml", "specs/new.yaml")  # not committed
    (repo.path / SPEC).write_text(edit(repo.read(SPEC), "duration: 0.5 s", "duration: 0.4 s"))
    r = balpipe("history", "specs", "-o", "out", "--no-sim", "--cache", "cache", cwd=repo.path)
    assert r.returncode == 0, r.stderr
    assert "specs/new.yaml: untracked" in r.stderr
    data = json.loads((repo.path / "out" / "osc" / "history.json").read_text())
    assert data["uncommitted_changes"] is True and len(data["commits"]) == 3
    assert "changes that are not committed" in (repo.path / "out" / "osc" / "history.html").read_text()


def test_max_commits_keeps_the_newest(tmp_path):
    repo, hashes = three_commits(tmp_path)
    r = balpipe("history", "specs", "-o", "out", "--no-sim", "--cache", "cache", "--max-commits", "2", cwd=repo.path)
    assert r.returncode == 0, r.stderr
    data = json.loads((repo.path / "out" / "osc" / "history.json").read_text())
    assert [c["hash"] for c in data["commits"]] == hashes[1:]


def test_build_puts_the_history_in_the_study_page_and_the_index(tmp_path, monkeypatch):
    repo, hashes = three_commits(tmp_path)
    monkeypatch.chdir(repo.path)
    hist("out")
    assert build_("out").status == "ok"
    folder = repo.path / "out" / "osc"
    page = (folder / "index.html").read_text()
    # the history's plots are the pages' interactive ones, no static figure
    assert 'id="history"' in page and all(f'data-live="live-hist-{k}"' in page for k in ("loads", "added", "params"))
    # per commit, which inputs it changed, in SI units, and the verdict in the pages' words
    data = json.loads((folder / "history.json").read_text())
    changed = [c["inputs_changed"]["fields"] for c in data["commits"]]
    assert changed == [None, [{"field": "mechanism.slider.mass", "old": 0.6, "new": 0.8}],
                       [{"field": "balancing.crank_counterweight", "old": -0.1, "new": -0.12}]]
    assert all(c["inputs_changed"]["files"] == [] for c in data["commits"])
    assert "mechanism.slider.mass: 0.6 → 0.8" in page and "first commit of the spec" in page
    assert [c["verdict"]["words"] for c in data["commits"]] == ["force balanced as designed"] * 3
    for h in hashes:
        assert h[:7] in page
    assert "history.json" in page and "crank counterweight further out" in page
    hist_page = (folder / "history.html").read_text()
    assert 'href="index.html"' in hist_page  # the study page exists now: linked
    # parameters that change are plotted and listed per commit; the others are named once
    assert "same value at every commit: rcp2 = -0.5." in hist_page
    assert "mcp2 = 2.1, mcp1 = 8.4, rcp1 = -0.5<" in hist_page
    assert json.loads((folder / "history.json").read_text())["commits"][0]["hash"] == hashes[0]
    index = (repo.path / "out" / "index.html").read_text()
    assert 'href="osc/history.html"' in index and "3 commits" in index
    # nothing new: the build skips the spec
    assert build_("out").skipped
    # a new commit: history, then build rebuilds the page with four commits
    h4 = repo.commit("lighter coupler", {SPEC: edit(repo.read(SPEC), "mass: 0.9 kg", "mass: 0.8 kg")})
    hist("out")
    assert not build_("out").skipped
    assert h4[:7] in (folder / "index.html").read_text()
    assert "4 commits" in (repo.path / "out" / "index.html").read_text()
    # build after history, or history after build and build again: the same site
    o = build_("b")
    assert o.status == "ok" and not (repo.path / "b" / "osc" / "history.json").exists()
    o = hist("b", "cache-b")
    assert (o.computed, o.cached, o.reused) == (3, 0, 1)  # the newest commit taken from the build
    assert not build_("b").skipped
    for name in ("index.html", "osc/index.html", "osc/history.html", "osc/history.json", "osc/results.json"):
        assert (repo.path / "out" / name).read_bytes() == (repo.path / "b" / name).read_bytes(), name


def test_with_the_simulation_the_validation_status_is_recorded(tmp_path, monkeypatch):
    repo = Repo(tmp_path / "repo")
    repo.copy_spec("offset_slider_crank.yaml", SPEC)
    repo.commit("first design", {SPEC: repo.read(SPEC) + "analysis:\n  samples: 81\n"})
    monkeypatch.chdir(repo.path)
    o = history.run(["specs"], Path("out"), Path("cache"), simulate=True)[0]
    assert (o.commits, o.computed) == (1, 1)
    point = json.loads(Path("out/osc/history.json").read_text())["commits"][0]
    assert point["validation"] == "pass"
    assert [s["validation"] for s in point["stages"]] == ["pass", "pass"]
    b = build(["specs"], Options(out=Path("built"), simulate=True))[0]
    assert b.status == "ok"
    built = json.loads(Path("built/osc/results.json").read_text())
    assert recorded(point) == headline(built)
    # the build's results serve a history with an empty cache: nothing computed, same figures
    o = history.run(["specs"], Path("built"), Path("cache2"), simulate=True)[0]
    assert (o.computed, o.reused) == (0, 1)
    assert json.loads(Path("built/osc/history.json").read_text()) == json.loads(Path("out/osc/history.json").read_text())
    # figures without the simulation are another cache entry, with the validation skipped
    o = history.run(["specs"], Path("nosim"), Path("cache"), simulate=False)[0]
    assert o.computed == 1
    assert json.loads(Path("nosim/osc/history.json").read_text())["commits"][0]["validation"] == "skipped"


def test_a_spec_that_build_rejects_is_rejected_by_history(tmp_path):
    """One path (balpipe.runner): a revision whose loads overflow fails build's finite-value
    check, and history records it as invalid with the same located problem, not as a point."""
    root = Path(__file__).resolve().parents[2]
    text = (root / "specs" / "offset_slider_crank.yaml").read_text(encoding="utf-8")
    text = edit(text, "duration: 0.5 s", "duration: 1.0e-100 s")
    (tmp_path / "specs").mkdir()
    p = tmp_path / "specs" / "fast.yaml"
    p.write_text(text, encoding="utf-8")
    outcome = build([str(p)], Options(out=tmp_path / "out", simulate=False))[0]
    assert outcome.status == "error" and "motion.duration" in outcome.message and "overflows" in outcome.message
    point = history.compute(text, outcome.source, False, "h")  # the name build publishes: fast.yaml
    assert point["status"] == "invalid" and point["stages"] == []
    assert point["problems"] == outcome.message.splitlines()
