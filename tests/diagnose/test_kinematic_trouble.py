"""Kinematic trouble named as an engineer would (issue 20, items 4-5): a loop too short to
close and a pose far from every assembly are located errors (exit 2, no traceback, the site
built before untouched); a pass near a dead centre is a warning on the terminal, in
results.json, on the page and in the index."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from balpipe.diagnose import assembly, dead_centres, dyads
from balpipe import registry, study
from balpipe.engine import compile_model
from balpipe.loader import SpecErrors, load, load_text

ROOT = Path(__file__).resolve().parents[2]
FOUR_BAR = ROOT / "specs/custom_four_bar_balancing.yaml"


def _four_bar(coupler: float = 0.28, rocker_angle: float | None = None) -> dict:
    spec = yaml.safe_load(FOUR_BAR.read_text())
    spec.pop("compare")
    spec["balancing"] = {"method": "none"}
    bodies = {b["name"]: b for b in spec["mechanism"]["bodies"]}
    bodies["coupler"]["points"]["B"] = [coupler, 0]
    A, O4, L3 = np.array([0.08, 0.0]), np.array([0.30, 0.0]), 0.22
    d = float(np.linalg.norm(O4 - A))
    if abs(coupler - L3) <= d <= coupler + L3:  # poses of the assembly above the line A-O4
        a = (coupler**2 - L3**2 + d * d) / (2 * d)
        B = A + a * (O4 - A) / d + math.sqrt(max(coupler**2 - a * a, 0.0)) * np.array([0.0, 1.0])
        bodies["coupler"]["pose"][2] = math.atan2(B[1] - A[1], B[0] - A[0])
        bodies["rocker"]["pose"][2] = math.atan2(B[1] - O4[1], B[0] - O4[0])
    if rocker_angle is not None:
        bodies["rocker"]["pose"][2] = rocker_angle
    return spec


def _build(tmp_path: Path, *specs: Path) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "balpipe", "build", *(p.name for p in specs), "-o", "site",
                           "--no-sim", "-j", "1"], capture_output=True, text=True, timeout=600, cwd=tmp_path)


def _write(tmp_path: Path, name: str, spec: dict) -> Path:
    p = tmp_path / name
    p.write_text(yaml.safe_dump(spec, sort_keys=False))
    return p


def _snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


def test_loop_too_short_names_the_dyad_and_its_lengths():
    # coupler 0.05 m: |A O4| >= 0.22 m at the start, coupler + rocker = 0.27 m cannot reach 0.38 m
    spec, _ = load_text(yaml.safe_dump(_four_bar(coupler=0.05)), "short.yaml")
    with pytest.raises(Exception) as err:
        study.run(spec)
    exc = err.value
    assert exc.path[:3] == ("mechanism", "bodies", 2) or exc.path[:3] == ("mechanism", "bodies", 1)
    assert exc.path[3] == "points"
    msg = exc.message
    assert "dyad coupler-rocker" in msg and "joints A, B, O4" in msg
    # the numbers: the span it must cover is |A - O4| at the failing time, the lengths are 0.05 and 0.22
    span = float(msg.split("must span ")[1].split(" m")[0])
    t = float(msg.split("at t = ")[1].split(" s")[0])
    assert span > 0.05 + 0.22
    assert "is 0.05 m long" in msg and "rocker (O4 to B) 0.22 m" in msg
    need = float(msg.split("coupler needs at least ")[1].split(" m")[0])
    assert need == pytest.approx(span - 0.22, abs=1e-5) and "m (has 0.05 m)" in msg
    # and the span is the crank pin's distance from O4 at that time (crank angle from the law)
    th = 2 * math.pi * (10 * (t / 0.5) ** 3 - 15 * (t / 0.5) ** 4 + 6 * (t / 0.5) ** 5)
    assert span == pytest.approx(math.hypot(0.08 * math.cos(th) - 0.30, 0.08 * math.sin(th)), rel=1e-5)


def test_loop_that_cannot_close_at_the_start_is_located(tmp_path):
    from balpipe.runner import analyse as build_analyse

    p = _write(tmp_path, "x.yaml", _four_bar(coupler=0.5))  # |A O4| = 0.22 m at t = 0 is below 0.5 - 0.22
    with pytest.raises(SpecErrors) as err:
        build_analyse(load(p), simulate=False)
    e = err.value.errors[0]
    assert e.line is not None and "cannot be closed at t = 0 s" in e.message
    assert "coupler needs at most 0.44 m (has 0.5 m)" in e.message
    assert e.path.startswith("mechanism.bodies[")


def test_cli_loop_and_far_pose_exit_2_no_traceback_site_untouched(tmp_path):
    good = _write(tmp_path, "good.yaml", _four_bar())
    first = _build(tmp_path, good)
    assert first.returncode == 0, first.stderr
    before = _snapshot(tmp_path / "site" / "good")
    short = _write(tmp_path, "good.yaml", _four_bar(coupler=0.12))  # same page: must stay as it was
    far = _write(tmp_path, "far.yaml", _four_bar(rocker_angle=3.2))
    r = _build(tmp_path, short, far)
    assert r.returncode == 2
    assert "Traceback" not in r.stderr and "Traceback" not in r.stdout
    lines = r.stderr.splitlines()
    loop = next(line for line in lines if "cannot be closed" in line)
    assert loop.strip().startswith("good.yaml:") and "mechanism.bodies[" in loop and ".points.B" in loop
    assert "needs at least" in loop and "(has 0.12 m)" in loop or "(has 0.22 m)" in loop
    pose = next(line for line in lines if "far from every assembly" in line)
    assert pose.strip().startswith("far.yaml:") and "mechanism.bodies[2].pose" in pose
    # line and column point at the field
    line_no = int(pose.strip().split(":")[1])
    text = far.read_text().splitlines()
    assert "pose" in text[line_no - 1] or text[line_no - 2].strip() == "pose:"
    assert _snapshot(tmp_path / "site" / "good") == before
    index = (tmp_path / "site" / "index.html").read_text()
    assert "Traceback" not in index and str(tmp_path) not in index


def test_pose_on_the_other_branch_is_kept_and_far_pose_refused():
    """The branch rule: the assembly keeps the side the given poses show."""
    spec = _four_bar()
    s, _ = load_text(yaml.safe_dump(spec), "a.yaml")
    m = registry.unbalanced_model(s)
    c = compile_model(m)
    # mirror the coupler and rocker about the line A-O4: the other branch, confirmed as given
    A = np.array([0.08, 0.0])
    O4 = np.array([0.30, 0.0])
    L2, L3 = 0.28, 0.22
    d = np.linalg.norm(O4 - A)
    a = (L2**2 - L3**2 + d * d) / (2 * d)
    h = math.sqrt(L2**2 - a * a)
    for sign in (1, -1):
        B = A + a * (O4 - A) / d + sign * h * np.array([0.0, 1.0])
        bodies = {b["name"]: b for b in spec["mechanism"]["bodies"]}
        bodies["coupler"]["pose"] = [0.08, 0.0, math.atan2(B[1], B[0] - 0.08) + 0.2]
        bodies["rocker"]["pose"] = [0.30, 0.0, math.atan2(B[1], B[0] - 0.30) - 0.2]
        s, _ = load_text(yaml.safe_dump(spec), "a.yaml")
        model = registry.unbalanced_model(s)
        from balpipe.engine import analyse

        an = analyse(model, np.array([0.0]))
        assert np.sign(an.pose(0, "rocker")[2]) == sign  # B above or below the line of its ends
    assert c is not None
    assert assembly.ANGLE_TOLERANCE == pytest.approx(math.radians(30))


def _slider_dead_centre(to: float) -> dict:
    return {
        "name": "slider-crank driven by its slider into the dead centre",
        "mechanism": {"template": "slider_crank",
                      "crank": {"length": 0.1, "mass": 1, "com": 0.05, "inertia": 0.001},
                      "coupler": {"length": 0.3, "mass": 1, "com": 0.15, "inertia": 0.008},
                      "slider": {"mass": 1}},
        "motion": {"law": "quintic", "duration": 0.5, "drive": {"slider": {"from": 0.3, "to": to}}},
    }


def test_dead_centre_pass_is_a_warning_on_terminal_results_page_and_index(tmp_path):
    p = _write(tmp_path, "dead.yaml", _slider_dead_centre(0.3999999))
    r = _build(tmp_path, p)
    assert r.returncode == 0, r.stderr
    assert "warning:" in r.stderr and "dead centre" in r.stderr and "dyad crank-coupler" in r.stderr
    res = json.loads((tmp_path / "site/dead/results.json").read_text())
    w = [x for x in res["warnings"] if x["kind"] == "dead_centre"]
    assert len(w) == 1
    w = w[0]
    assert w["time"] == pytest.approx(0.5, abs=2e-3) and w["value"] < 1.0 and w["limit"] == 10
    assert set(w["configuration"]) == {"crank", "coupler", "slider"}
    assert w["configuration"]["crank"][2] == pytest.approx(0.0, abs=0.02)  # crank and coupler aligned
    spike = w["effort_spike"]
    assert spike["actuator"] == "slider" and spike["ratio_to_median"] > 100
    page = (tmp_path / "site/dead/index.html").read_text()
    assert "Warning:" in page
    assert page.count("dead centre") >= 2  # the note and the mark on the efforts figure
    assert "warning: dead centre" in (tmp_path / "site/index.html").read_text()


def test_no_warning_away_from_the_dead_centre():
    s, _ = load_text(yaml.safe_dump(_slider_dead_centre(0.36)), "ok.yaml")
    st = study.run(s)
    assert st.warnings == []


def test_transmission_angle_is_the_law_of_cosines():
    """The slider-crank's dyad crank-coupler between A and C: mu at B from |AC|."""
    s, _ = load_text(yaml.safe_dump(_slider_dead_centre(0.38)), "ok.yaml")
    st = study.run(s)
    an, model = st.stages[0].analysis, st.stages[0].stage.model
    c = compile_model(model)
    (d,) = [b.dyad for b in dyads.blocks(c, an.q.reshape(len(an.t), -1)[0]) if b.dyad is not None]
    poses = {n: an.frame_pose[:, k] for k, n in enumerate(an.names)}
    Ei, Ej = dyads.end_points(model, d, poses)
    x = an.frame_pose[:, an.names.index("slider"), 0]
    cos_mu = (0.1**2 + 0.3**2 - x**2) / (2 * 0.1 * 0.3)
    mu = np.arccos(cos_mu)
    assert np.allclose(dyads.transmission_angle(d, Ei, Ej), np.minimum(mu, np.pi - mu), atol=1e-9)
    assert dead_centres.TRANSMISSION_LIMIT == pytest.approx(math.radians(10))


def test_fewer_actuators_not_realisable_exit_2(tmp_path):
    spec = yaml.safe_load((ROOT / "specs/custom_3rrr_motors.yaml").read_text())
    spec["mechanism"]["actuators"] = ["A1", "A2"]
    p = _write(tmp_path, "two.yaml", spec)
    r = _build(tmp_path, p)
    assert r.returncode == 2 and "Traceback" not in r.stderr
    assert "two.yaml:" in r.stderr and "mechanism.actuators: not realisable" in r.stderr
