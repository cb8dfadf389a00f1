"""The spec's ``loads``: located errors, the references at the motion's start, tables with
branches, and the loaded examples of specs/ built and validated by pymunk at default settings."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from balpipe import loader, registry, study
from balpipe.engine import analyse
from balpipe.loader import load_text
from balpipe.mechanics.sampling import gravity_vector
from balpipe.spec_parts import SpecFieldError

ROOT = Path(__file__).resolve().parents[1]
SPECS = ROOT / "specs"

BASE = """
name: loaded slider-crank
mechanism:
  template: slider_crank
  offset: 0 m
  crank:   {length: 50 mm, mass: 1.0 kg, com: 25 mm, inertia: 0.0003 kg m^2}
  coupler: {length: 200 mm, mass: 0.6 kg, com: 80 mm, inertia: 0.0025 kg m^2}
  slider:  {mass: 1.2 kg}
motion:
  drive:
    crank: {law: constant_speed, speed: 600 rpm, from: 0 deg}
  duration: 0.1 s
analysis:
  samples: 121
loads:
"""


def _run(loads: str, folder: Path | None = None):
    text = BASE + loads
    if folder is None:
        return study.run(load_text(text, "s.yaml")[0])
    (folder / "s.yaml").write_text(text)
    return study.run(loader.load(folder / "s.yaml").spec)


@pytest.mark.parametrize("loads, path, words", [
    ("  - {type: spring, name: s, a: {body: wheel, point: A}, b: {body: slider, point: C}, stiffness: 1 kN/m, free_length: 0.1}",
     ("loads", 0, "a", "body"), "no body 'wheel'"),
    ("  - {type: spring, name: s, a: {body: frame, point: Z}, b: {body: slider, point: C}, stiffness: 1 kN/m, free_length: 0.1}",
     ("loads", 0, "a", "point"), "frame has no point 'Z'"),
    ("  - {type: spring, name: s, a: {body: frame, point: A}, b: {body: slider, point: C}, stiffness: 1 kN/m, free_length: 0.1, preload: 3 N}",
     ("loads", 0, "preload"), "not both"),
    ("  - {type: spring, name: s, a: {body: frame, point: A}, b: {body: slider, point: C}, stiffness: 1 kN/m}",
     ("loads", 0, "stiffness"), "free length or its preload"),
    ("  - {type: damper, name: d, a: {body: crank, point: B}, b: {body: slider, point: C}, damping: 3, source: external}",
     ("loads", 0, "source"), "one end on the frame"),
    ("  - {type: torsion, name: t, joint: guide, stiffness: 3}",
     ("loads", 0, "joint"), "not a revolute"),
    ("  - {type: friction, name: f, joint: nowhere, viscous: 1}",
     ("loads", 0, "joint"), "no joint 'nowhere'"),
    ("  - {type: friction, name: f, joint: guide, coefficient: 0.1, pin_radius: 1 mm}",
     ("loads", 0, "pin_radius"), "no pin"),
    ("  - {type: force, name: f, at: {body: frame, point: A}, force: [1 N, 0 N]}",
     ("loads", 0, "at", "body"), "moves nothing"),
    ("  - {type: force, name: f, at: {body: slider, point: C}}",
     ("loads", 0), "give a force"),
    ("  - {type: force, name: f, at: {body: slider, point: C}, force: [1 N, 0 N]}\n"
     "  - {type: force, name: f, at: {body: slider, point: C}, torque: 1 N m}",
     ("loads", 1, "name"), "used twice"),
    ("  - {type: force, name: f, at: {body: slider, point: C}, direction: [1, 0],"
     " table: {file: t.csv, against: {driver: wheel}}}",
     ("loads", 0, "table", "against", "driver"), "no driver 'wheel'"),
])
def test_semantic_errors_are_located(loads, path, words, tmp_path):
    (tmp_path / "t.csv").write_text("crank [deg], F [N]\n0, 0\n360, 0\n")
    with pytest.raises(SpecFieldError) as err:
        _run(loads, tmp_path)
    assert err.value.path == path, err.value.message
    assert words in err.value.message


def test_units_of_the_wrong_kind_are_schema_errors():
    from balpipe.loader import SpecErrors
    with pytest.raises(SpecErrors) as err:
        load_text(BASE + "  - {type: damper, name: d, a: {body: frame, point: A}, b: {body: slider, point: C}, damping: 3 N/m}\n", "s.yaml")
    assert "loads[0].damping" in str(err.value) and "not a damping unit" in str(err.value)


def test_a_table_row_that_is_not_numbers_names_its_row(tmp_path):
    (tmp_path / "t.csv").write_text("crank [deg], F [kN]\n0, 0\n90, x\n360, 0\n")
    with pytest.raises(SpecFieldError) as err:
        _run("  - {type: force, name: f, at: {body: slider, point: C}, direction: [1, 0],"
             " table: {file: t.csv, against: {driver: crank}}}", tmp_path)
    assert err.value.path == ("loads", 0, "table", "file") and "t.csv:3:" in err.value.message


def test_a_missing_table_is_a_located_error(tmp_path):
    (tmp_path / "s.yaml").write_text(BASE + "  - {type: force, name: f, at: {body: slider, point: C}, direction: [1, 0],"
                                     " table: {file: nothere.csv}}\n")
    from balpipe.loader import SpecErrors
    with pytest.raises((SpecErrors, SpecFieldError)) as err:
        loader.load(tmp_path / "s.yaml")
    assert "nothere.csv" in str(err.value)


def test_check_reports_file_line_and_field_with_exit_2(tmp_path):
    (tmp_path / "s.yaml").write_text(BASE + "  - {type: friction, name: f, joint: A, coefficient: 0.1}\n")
    r = subprocess.run([sys.executable, "-m", "balpipe", "check", str(tmp_path / "s.yaml")],
                       capture_output=True, text=True)
    assert r.returncode == 2, r.stdout + r.stderr
    out = r.stdout + r.stderr
    assert "s.yaml:" in out and "loads[0].pin_radius" in out and "Traceback" not in out


def test_preload_torsion_and_stroke_refer_to_the_motion_start(tmp_path):
    (tmp_path / "t.csv").write_text("s [mm], F [N]\n-200, -200\n200, 200\n")
    (tmp_path / "d.csv").write_text("s [mm], F [N]\n-200, 0\n200, 0\n")
    st = _run("  - {type: spring, name: s, a: {body: frame, point: [0.4, 0.1]}, b: {body: slider, point: C}, stiffness: 2 kN/m, preload: 7 N}\n"
              "  - {type: torsion, name: t, joint: B, stiffness: 3 N m/rad, preload: 0.5 N m}\n"
              "  - {type: force, name: f, at: {body: slider, point: C}, direction: [1, 0],"
              " table: {file: t.csv, falling: {file: d.csv}, against: {stroke: {body: slider, point: C, direction: [1, 0]}}}}",
              tmp_path)
    an = st.unbalanced.analysis
    assert an.loads["s"]["tension"][0] == pytest.approx(7.0, rel=1e-12)
    assert an.loads["t"]["torque"][0] == pytest.approx(0.5, rel=1e-12)
    # the stroke is the slider's displacement from its start; the rising branch is F = 1000 s (N, m)
    x = an.q[:, an.names.index("slider"), 0]
    s, v = x - x[0], an.v[:, an.names.index("slider"), 0]
    F = an.loads["f"]["Fx"]
    up = v > 0
    assert np.allclose(F[up], 1000.0 * s[up], rtol=1e-12, atol=1e-9)
    assert np.all(F[v < 0] == 0.0)


def test_angle_tables_repeat_every_turn(tmp_path):
    (tmp_path / "t.csv").write_text("crank [deg], F [N]\n0, 0\n180, 180\n360, 0\n")
    spec = BASE.replace("duration: 0.1 s", "duration: 0.2 s") + (
        "  - {type: force, name: f, at: {body: slider, point: C}, direction: [0, 1],"
        " table: {file: t.csv, against: {driver: crank}}}\n")
    (tmp_path / "s.yaml").write_text(spec)
    sp = loader.load(tmp_path / "s.yaml").spec
    model, t = registry.unbalanced_model(sp), registry.time_grid(sp)
    an = analyse(model, t, gravity_vector(sp))
    deg = np.degrees(2 * math.pi * 10 * t) % 360  # 600 rpm from 0 deg
    expected = np.where(deg <= 180, deg, 360 - deg)
    assert np.allclose(an.loads["f"]["Fy"], expected, atol=1e-9)


LOADED = ("custom_pumpjack_rod_load.yaml", "custom_compressor_gas_pressure.yaml", "custom_four_bar_loaded.yaml")


def test_loaded_examples_build_and_validate_at_default_settings(tmp_path):
    out = tmp_path / "site"
    r = subprocess.run([sys.executable, "-m", "balpipe", "build", *[str(SPECS / n) for n in LOADED], "-o", str(out)],
                       capture_output=True, text=True, cwd=ROOT)
    assert r.returncode == 0, r.stdout + r.stderr
    for name in LOADED:
        res = json.loads((out / name[:-5] / "results.json").read_text())
        assert res["status"] == "ok"
        for stage, v in res["validation"].items():
            assert v["passed"], (name, stage)
        for stage, v in res["torque_driven"].items():
            assert v["passed"] and v["tracking_error_max"] < v["tracking_tolerance"], (name, stage)
        assert res["loads"]["loads"]
        header = (out / name[:-5] / "timeseries.csv").read_text().split("\n", 1)[0]
        assert "unbalanced.frame.Fx_N" in header and ".load." in header


def test_pumpjack_frame_load_is_the_shaking_load_plus_the_rod_load(studies):
    st = studies("custom_pumpjack_rod_load.yaml")
    for sr in st.stages:
        an = sr.analysis
        rod = an.loads["rod_load"]
        F, M = an.frame_load
        assert np.max(np.abs(F - an.force - np.stack([rod["Fx"], rod["Fy"]], axis=1))) <= 1e-9 * np.max(np.abs(F))
        # the counterbalance lowers the peak net gearbox torque
    peaks = [float(np.max(np.abs(s.analysis.efforts["crank"]))) for s in st.stages]
    assert peaks[1] < 0.5 * peaks[0]


def test_force_deflection_law_and_torque_table(tmp_path):
    """A tabulated force-deflection law gives the table's tension at the element's own deflection;
    a torque table (no direction) acts as a torque; both enter the power balance of the motor."""
    (tmp_path / "k.csv").write_text("d [mm], T [N]\n-100, -300\n0, 0\n20, 40\n100, 500\n")
    (tmp_path / "m.csv").write_text("t [s], M [N m]\n0, 0\n0.05, 2\n0.1, 0\n")
    st = _run("  - {type: force_law, name: k, a: {body: frame, point: [0.5, 0.05]}, b: {body: slider, point: C},"
              " free_length: 0.26, table: {file: k.csv, against: deflection}}\n"
              "  - {type: force, name: m, at: {body: coupler, point: B}, table: {file: m.csv}}", tmp_path)
    an = st.unbalanced.analysis
    k = an.loads["k"]
    expected = np.interp(k["length"] - 0.26, [-0.1, 0.0, 0.02, 0.1], [-300.0, 0.0, 40.0, 500.0])
    assert np.allclose(k["tension"], expected, rtol=1e-13, atol=1e-10)
    m = an.loads["m"]
    assert np.allclose(m["torque"], np.interp(an.t, [0, 0.05, 0.1], [0, 2, 0]), rtol=1e-13, atol=1e-12)
    assert np.all(m["Fx"] == 0) and np.all(m["Fy"] == 0)
    # power balance: motor power = d(kinetic energy)/dt + the loads' absorbed power
    model = st.unbalanced.stage.model
    mass = np.array([b.mass_properties()[0] for b in model.bodies])
    inertia = np.array([b.mass_properties()[2] for b in model.bodies])
    dKE = np.einsum("k,nkd,nkd->n", mass, an.v[:, :, :2], an.a[:, :, :2]) + np.einsum("k,nk,nk->n", inertia, an.v[:, :, 2], an.a[:, :, 2])
    w_coupler = an.v[:, an.names.index("coupler"), 2]
    motor = an.efforts["crank"] * an.v[:, an.names.index("crank"), 2]
    expected_power = dKE - k["power"] - m["torque"] * w_coupler
    assert np.max(np.abs(motor - expected_power)) <= 1e-9 * np.max(np.abs(motor))
