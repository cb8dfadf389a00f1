"""A stage that cannot be built is flagged, never green (issue 7, item 6), and paper 004's
point-mass alternative is analysed and validated like the other stages."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balpipe.mechanics import realisable
from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load_text
from balpipe.model import FRAME, Attachment, Body, Driver, Model, Revolute
from balpipe.motion import PROFILES, PointToPoint
from balpipe.report.results import results_dict
from balpipe.spec_parts import SpecFieldError
from _edits import replaced

ROOT = Path(__file__).resolve().parents[2]
SPEC = ROOT / "specs" / "paper004_five_bar.yaml"


def arm(*attachments: Attachment, inertia: float = 0.01, mass: float = 1.0) -> Model:
    body = Body("arm", mass, (0.1, 0.0), inertia, {"A": (0.0, 0.0)}, attachments=attachments)
    return Model("arm", (body,), (Revolute("A", FRAME, "arm", (0.0, 0.0), (0.0, 0.0)),),
                 (Driver("q", ("joint", "A"), PointToPoint(0.0, 1.0, 0.5, PROFILES["quintic"])),),
                 {"arm": (0.0, 0.0, 0.0)})


def test_negative_parts_are_found_even_when_the_body_total_is_positive():
    ok = arm(Attachment("cw", 2.0, (-0.1, 0.0), 0.001))
    assert realisable.verdict(ok) == "" and realisable.issues(ok) == []
    neg_i = arm(Attachment("cw", 2.0, (-0.1, 0.0), -0.02))
    assert neg_i.body("arm").mass_properties()[2] > 0  # the engine can analyse it ...
    analyse(neg_i, np.linspace(0, 0.5, 11))
    assert realisable.verdict(neg_i) == "not realisable: negative inertia"  # ... but nobody can build it
    assert "'cw' on 'arm': centroidal inertia -0.02 kg m^2" in realisable.details(neg_i)
    neg_m = arm(Attachment("cw", -0.5, (-0.1, 0.0), 0.0))
    assert realisable.verdict(neg_m) == "not realisable: negative mass"
    both = arm(Attachment("cw", -0.5, (-0.1, 0.0), -0.001), inertia=0.05)
    assert realisable.verdict(both) == "not realisable: negative inertia and mass"
    gear = arm(Attachment("gear", 0.0, (0.0, 0.0), 0.5, "gear"), inertia=-0.001)  # a computed gear/link inertia
    assert realisable.verdict(gear) == "not realisable: negative inertia"


@pytest.fixture(scope="module")
def paper(studies):
    s = studies(SPEC.name)
    spec = s.spec
    return spec, s, results_dict(s, "paper004_five_bar.yaml", "x", simulated=False)


def test_paper004_balanced_inertias_stages_are_flagged(paper):
    _, s, res = paper
    params = {p.name: p.value for p in s.balance.parameters}
    assert abs(params["Icw1"] - (-0.126)) < 0.001
    stages = {m["name"]: m for m in res["stages"]}
    for name in ("counterweights", "full"):
        assert stages[name]["realisable"] is False
        assert stages[name]["not_realisable"] == "not realisable: negative inertia"
        assert "'counterweight 1' on 'link1': centroidal inertia -0.1264 kg m^2" in stages[name]["not_realisable_parts"]
    for name in ("unbalanced", "full_point_masses"):
        assert stages[name]["realisable"] is True and stages[name]["not_realisable"] == ""


def test_paper004_point_mass_stage_is_fully_balanced_with_the_computed_inertias(paper):
    _, s, res = paper
    params = {p.name: p.value for p in s.balance.parameters}
    assert abs(params["I5_point_masses"] - 1.783) < 5e-4
    assert abs(params["I6_point_masses"] - 0.455) < 5e-4 and abs(params["I7_point_masses"] - 0.455) < 5e-4
    st = {r.stage.name: r for r in s.stages}
    pm = st["full_point_masses"]
    model = pm.stage.model
    for k in (5, 6, 7):
        assert abs(model.body(f"gear{k}").mass_properties()[2] - params[f"I{k}_point_masses"]) < 1e-12
    for b in ("link1", "link2", "link3", "link4"):
        assert all(a.inertia == 0.0 for a in model.body(b).attachments if a.kind == "counterweight")
    m = {x["name"]: x for x in res["stages"]}["full_point_masses"]
    assert m["balances"] == "force+moment" and m["force_balanced"] and m["moment_balanced"]
    assert m["force_ratio"] <= 1e-9 and m["moment_ratio"] <= 1e-9
    # balanced for any motion: its centre of mass stays put and its angular momentum is zero
    an = pm.analysis
    assert np.max(np.abs(an.com - an.com[0])) <= 1e-9 * 0.5
    assert np.max(np.abs(an.angular_momentum)) <= 1e-9 * np.max(np.abs(st["unbalanced"].analysis.angular_momentum))
    assert not s.problems


def test_point_mass_stage_needs_balanced_inertias():
    text = replaced(SPEC.read_text(), "  balanced_inertias: {proximal: 0.012 kg m^2, distal: 0.010 kg m^2}\n", "")
    spec, _ = load_text(text, "p.yaml")
    with pytest.raises(SpecFieldError) as exc:
        registry.balance(spec)
    assert exc.value.path == ("balancing", "point_mass_stage")


def test_simulated_build_flags_the_page_and_the_index_and_validates_the_point_mass_stage(tmp_path):
    d = tmp_path / "specs"
    d.mkdir()
    shutil.copy(SPEC, d / SPEC.name)
    r = subprocess.run([sys.executable, "-m", "balpipe", "build", "specs", "-o", "out"], cwd=tmp_path,
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stderr
    out = tmp_path / "out"
    res = json.loads((out / "paper004_five_bar" / "results.json").read_text())
    val = res["validation"]["full_point_masses"]
    assert val["passed"] and val["force_residual"] < 1e-3 and val["moment_residual"] < 1e-3
    page = (out / "paper004_five_bar" / "index.html").read_text()
    assert page.count('<span class="badge bad">not realisable: negative inertia</span>') == 2
    # the flagged stages are not shown green: balanced only "on paper", the simulation only "agrees"
    assert page.count('<span class="badge warn">balanced on paper</span>') == 2
    assert page.count('<span class="badge warn">simulation agrees</span>') == 2
    assert page.count('<span class="badge ok">balanced</span>') == 1  # the point-mass stage
    index = (out / "index.html").read_text()
    assert "not realisable: negative inertia" in index and "of the ok, 0 pass and 1 has stages that cannot be built" in index
    assert '<span class="badge warn">built</span>' in index
