"""``balpipe check`` at speed (issue 23): it leaves out what only the page shows (a method's
``page_only`` fields, such as the partial balancing's Pareto fronts) and checks several specs in
``--jobs`` processes, saying the same as one after another."""

from __future__ import annotations

import shutil
import subprocess
import sys
import typing
from pathlib import Path

import pytest
from _edits import replaced

from balpipe import registry
from balpipe.loader import load

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"


def test_page_only_fields_are_optional_fields_of_their_method():
    declared = [(m, f) for m in registry.METHODS.values() for f in m.page_only]
    assert declared, "no method declares page-only fields: check computes everything"
    for m, f in declared:
        assert f in m.section.model_fields, (m.name, f)
        assert type(None) in typing.get_args(m.section.model_fields[f].annotation), (m.name, f)


def test_without_the_page_the_design_is_the_same_and_the_fronts_are_left_out():
    spec = load(SPECS / "partial_offset_slider_crank.yaml").spec
    assert spec.balancing.fronts is not None
    full, quick = registry.balance(spec), registry.balance(spec, page=False)
    assert "fronts" in full.details["partial_balance"] and "fronts" not in quick.details["partial_balance"]
    assert [(p.name, p.value) for p in quick.parameters] == [(p.name, p.value) for p in full.parameters]
    assert [s.name for s in quick.stages] == [s.name for s in full.stages]
    for a, b in zip(quick.stages, full.stages):
        assert a.model == b.model


def _check(*args, cwd):
    return subprocess.run([sys.executable, "-m", "balpipe", "check", *map(str, args)], capture_output=True,
                          text=True, cwd=cwd, timeout=600)


@pytest.fixture
def folder(tmp_path):
    """Three specs, the middle one invalid."""
    d = tmp_path / "specs"
    d.mkdir()
    for k, name in enumerate(("scott_russell.yaml", "offset_slider_crank.yaml", "paper002_decoupling.yaml")):
        shutil.copy(SPECS / name, d / f"{k}_{name}")
    bad = d / "1_offset_slider_crank.yaml"
    bad.write_text(replaced(bad.read_text(), "offset: 30 mm", "offset: 250 mm"))
    return tmp_path


def test_in_parallel_check_says_what_it_says_one_after_another(folder):
    one, two = _check("-j", "1", "specs", cwd=folder), _check("-j", "2", "specs", cwd=folder)
    assert one.returncode == two.returncode == 2
    assert (one.stdout, one.stderr) == (two.stdout, two.stderr)
    assert one.stdout.splitlines() == ["specs/0_scott_russell.yaml: ok", "specs/2_paper002_decoupling.yaml: ok"]
    assert "1_offset_slider_crank.yaml:14:" in one.stderr and "2 valid, 1 invalid" in one.stderr
    assert "Traceback" not in one.stderr + two.stderr


def test_jobs_below_one_is_a_usage_error(folder):
    r = _check("-j", "0", "specs", cwd=folder)
    assert r.returncode == 2 and "--jobs must be at least 1" in r.stderr and "Traceback" not in r.stderr


def test_check_and_sweep_never_compute_the_fronts(tmp_path, monkeypatch, capsys):
    from balpipe.balancing.partial import fronts as partial_fronts
    from balpipe.cli import main

    def refuse(*a, **k):
        raise AssertionError("the Pareto fronts were computed")

    monkeypatch.setattr(partial_fronts, "compute", refuse)
    spec = str(SPECS / "partial_offset_slider_crank.yaml")
    assert main(["check", spec]) == 0
    assert main(["sweep", spec, "--vary", "mechanism.crank.length=0.19 m:0.21 m:2", "-o", str(tmp_path / "s"),
                 "-j", "1"]) == 0, capsys.readouterr().err
    with pytest.raises(AssertionError, match="fronts were computed"):  # the page's balancing does need them
        registry.balance(load(spec).spec)


def test_every_spec_of_the_repository_passes_check():
    """What the README builds passes check (a spec whose references name a method's derived
    numbers, paper 003's, once failed check while it built)."""
    r = _check(SPECS, "-j", "2", cwd=ROOT)
    assert r.returncode == 0 and "invalid" not in r.stdout.replace("0 invalid", ""), r.stdout + r.stderr
