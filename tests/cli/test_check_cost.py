"""``balpipe check`` starts its costliest specs first (issue 23, "check in a blink"): a spec's cost
is what its template and method declare (:mod:`balpipe.site_files.check_cost`), read from the YAML events
without loading the spec; the messages still come in the specs' order."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from balpipe.runtime import pool
from balpipe import registry
from balpipe.site_files.check_cost import PLAIN, check_cost, check_hints, declared_names
from balpipe.cli import main

SPECS = Path(__file__).resolve().parents[2] / "specs"
PAPER003 = SPECS / "paper003_com_planning.yaml"
RRR4 = SPECS / "paper001_4rrr.yaml"
PLAIN_SPEC = SPECS / "scott_russell.yaml"


@pytest.mark.parametrize("text, names", [
    ("mechanism:\n  template: rrr4\nbalancing:\n  method: force_balance\n",
     {("mechanism", "template"): "rrr4", ("balancing", "method"): "force_balance"}),
    ("mechanism: {links: [{template: no}], template: 'five_bar'}\nbalancing: {method: stages}\n",
     {("mechanism", "template"): "five_bar", ("balancing", "method"): "stages"}),
    # only the top sections' own keys: not a nested mapping's, not a sequence's items, not other sections'
    ("a: {mechanism: {template: no}}\nbalancing:\n  stages: [{method: no}]\n  method: moment_balance\n",
     {("balancing", "method"): "moment_balance"}),
    ("balancing:\n  - method: no\nmechanism: &m {template: custom}\n", {("mechanism", "template"): "custom"}),
    ("{}", {}),
])
def test_the_names_come_from_the_top_sections_only(text, names):
    assert declared_names(text) == names


def test_declared_costs_order_the_repository_specs():
    costs = {p.name: check_cost(p) for p in SPECS.glob("*.yaml")}
    assert max(costs, key=costs.get) == PAPER003.name
    assert check_cost(PAPER003) > check_cost(RRR4) > check_cost(PLAIN_SPEC) == PLAIN
    assert registry.METHODS["com_motion_planning"].check_cost > registry.TEMPLATES["rrr4"].check_cost > 0
    # a partial balancing solves its optimum's cone programme in check too
    assert check_cost(SPECS / "partial_offset_slider_crank.yaml") > check_cost(PLAIN_SPEC)
    assert check_cost(PAPER003) > check_cost(SPECS / "partial_paper000_rpr3.yaml")


def test_the_hints_are_the_cost_and_the_method_from_one_read(tmp_path):
    """check_hints: what check_cost gives and the method the spec names (the parent loads that
    method's code before its workers fork), None where no name can be read."""
    for p in SPECS.glob("*.yaml"):
        method = declared_names(p.read_text(encoding="utf-8"))[("balancing", "method")]
        assert check_hints(p) == (check_cost(p), method)
    assert check_hints(PAPER003)[1] == "com_motion_planning"
    bad = tmp_path / "bad.yaml"
    bad.write_text("balancing: [unclosed\n", encoding="utf-8")
    assert check_hints(bad) == (PLAIN, None)
    assert check_hints(tmp_path / "gone.yaml") == (PLAIN, None)


@pytest.mark.parametrize("text", ["mechanism: [unclosed\n", "mechanism: {template: nothing_known}\n",
                                  "balancing: {method: *nowhere}\n", "\udcff"])
def test_what_cannot_be_read_costs_a_plain_spec(tmp_path, text):
    p = tmp_path / "bad.yaml"
    p.write_bytes(text.encode("utf-8", "surrogateescape"))
    assert check_cost(p) == PLAIN
    assert check_cost(tmp_path / "gone.yaml") == PLAIN
    assert check_cost(tmp_path) == PLAIN


def test_a_pipe_is_not_read(tmp_path):
    """The parent never blocks on a named pipe given as a spec (its worker reports it)."""
    import os

    fifo = tmp_path / "pipe.yaml"
    os.mkfifo(fifo)
    assert check_cost(fifo) == PLAIN


def test_check_starts_the_costliest_first_and_reports_in_the_specs_order(tmp_path, monkeypatch, capsys):
    """The pool receives the costs (paper 003's spec, last by name here, starts first); the
    messages keep the files' order. The pool is replaced by one that records the start order."""
    folder = tmp_path / "specs"
    folder.mkdir()
    names = ["a_plain.yaml", "b_rrr4.yaml", "z_paper003.yaml"]
    for name, src in zip(names, (PLAIN_SPEC, RRR4, PAPER003)):
        shutil.copy(src, folder / name)
    started: list[str] = []

    def recording(fn, items, jobs, *args, cost=None):
        assert jobs == 2 and cost is not None
        started.extend(Path(items[i][0]).name for i in sorted(range(len(items)), key=lambda i: -cost(items[i])))
        return (("ok", f"{f}: ok") for f, _ in items)  # a generator, as in_order's (pool.finished closes it)

    monkeypatch.setattr(pool, "in_order", recording)
    assert main(["check", "-j", "2", str(folder)]) == 0
    assert started == ["z_paper003.yaml", "b_rrr4.yaml", "a_plain.yaml"]
    assert capsys.readouterr().out.splitlines() == [f"{folder / n}: ok" for n in names]
