"""The laws of real machines in specs: durations from cycles, tables read beside the spec,
located errors through the CLI (exit 2, no traceback), and the laws reaching the engine."""

from __future__ import annotations

import math
import textwrap
from pathlib import Path

import balpipe  # noqa: F401
import numpy as np
import pytest
import yaml

from balpipe import registry
from balpipe.cli import main
from balpipe.loader import SpecErrors, load, load_text
from balpipe.study import run

ROOT = Path(__file__).resolve().parents[2]

FOUR_BAR = """\
name: four-bar on a law of real machines
mechanism:
  template: custom
  frame_points: {O2: [0, 0], O4: [0.30, 0]}
  bodies:
    - {name: crank, mass: 0.4 kg, com: [0.04, 0], inertia: 0.000213 kg m^2, pose: [0, 0, 0], points: {O2: [0, 0], A: [0.08, 0]}}
    - {name: coupler, mass: 1.2 kg, com: [0.14, 0], inertia: 0.00784 kg m^2, pose: [0.08, 0, 1.2], points: {A: [0, 0], B: [0.28, 0]}}
    - {name: rocker, mass: 0.9 kg, com: [0.11, 0], inertia: 0.00363 kg m^2, pose: [0.30, 0, 1.8], points: {O4: [0, 0], B: [0.22, 0]}}
  joints:
    - {type: revolute, name: O2, a: frame, b: crank, point_a: O2, point_b: O2}
    - {type: revolute, name: A, a: crank, b: coupler, point_a: A, point_b: A}
    - {type: revolute, name: B, a: coupler, b: rocker, point_a: B, point_b: B}
    - {type: revolute, name: O4, a: frame, b: rocker, point_a: O4, point_b: O4}
  drivers:
    - {name: crank, joint: O2}
analysis: {samples: 201}
validation: {enabled: false}
"""


def spec_text(motion: str) -> str:
    return FOUR_BAR + "motion:\n" + textwrap.indent(textwrap.dedent(motion), "  ")


def write(tmp_path: Path, motion: str, csv: str | None = None) -> Path:
    if csv is not None:
        (tmp_path / "crank.csv").write_text(csv)
    p = tmp_path / "spec.yaml"
    p.write_text(spec_text(motion))
    return p


def crank_law(path: Path):
    spec = load(path).spec
    return spec, registry.scalar_laws(spec.motion, spec.mechanism.drives())["crank"]


def test_constant_speed_over_cycles_sets_the_duration(tmp_path):
    spec, law = crank_law(write(tmp_path, """\
        cycles: 3
        drive:
          crank: {law: constant_speed, from: 10 deg, speed: 120 rpm}
    """))
    assert spec.motion.duration == pytest.approx(1.5) and spec.motion.period == pytest.approx(0.5)
    q, qd, qdd = law(np.array([0.0, 1.5]))
    assert qd[0] == pytest.approx(4 * math.pi) and qdd[0] == 0  # moving at t = 0: steady state
    assert q[1] - q[0] == pytest.approx(6 * math.pi)
    study = run(spec)  # the engine turns the crank three times
    th = study.unbalanced.analysis.frame_pose[:, study.unbalanced.analysis.names.index("crank"), 2]
    assert th[-1] - th[0] == pytest.approx(6 * math.pi)


def test_six_bar_example_turns_at_120_rpm():
    spec = load(ROOT / "specs" / "custom_stephenson_six_bar_120rpm.yaml").spec
    assert spec.motion.duration == pytest.approx(1.0)  # two turns at 120 rpm
    law = registry.scalar_laws(spec.motion, spec.mechanism.drives())["crank"]
    assert law(np.array([0.0]))[1][0] == pytest.approx(120 * 2 * math.pi / 60)


@pytest.mark.parametrize("motion, where, words", [
    ("drive:\n  crank: {law: constant_speed, speed: 2 rad/s}\n", "motion", "give the duration"),
    ("cycles: 2\ndrive:\n  crank: {law: constant_speed, speed: 2 m/s}\n", "motion", "cycles needs a periodic drive"),
    ("duration: 1 s\ncycles: 2\ndrive:\n  crank: {law: constant_speed, speed: 2 rad/s}\n", "motion", "not both"),
])
def test_motion_section_errors_are_located(motion, where, words):
    with pytest.raises(SpecErrors, match=words) as err:
        load_text(spec_text(motion), "s.yaml")
    assert err.value.errors[0].line is not None and err.value.errors[0].path == where


def test_laws_reach_the_engine_located_errors(tmp_path):
    bad = {
        # a linear speed on an angle
        "drive:\n  crank: {law: constant_speed, speed: 2 m/s}\nduration: 1 s\n": ("motion.drive.crank.speed", "linear unit"),
        # a velocity jump in a cycle: constant speed then a dwell
        "duration: 1 s\ndrive:\n  crank:\n    law: cycle\n    from: 0 deg\n    segments:\n"
        "      - {law: constant_speed, speed: 1 rad/s, duration: 0.5 s}\n      - {law: dwell, duration: 0.5 s}\n":
            ("motion.drive.crank.segments[1]", "velocity jumps"),
        "duration: 1 s\ndrive:\n  crank: {law: cam, from: 0 deg, to: 30 deg, period: 0.5 s, profile: harmonic, rise: 0.3, dwell: 0.2, return: 0.3}\n":
            ("motion.drive.crank.profile", "acceleration jumps"),
    }
    for motion, (where, words) in bad.items():
        loaded = load(write(tmp_path, motion))
        with pytest.raises(Exception) as err:
            run(loaded.spec)
        e = loaded.error(err.value).errors[0]
        assert e.path == where and words in e.message and e.line is not None, (e, motion)


def test_cycle_with_polynomial_blends_turns_and_stops(tmp_path):
    spec, law = crank_law(write(tmp_path, """\
        cycles: 2
        drive:
          crank:
            law: cycle
            from: 0 deg
            segments:
              - {law: constant_speed, speed: 60 rpm, duration: 0.5 s}
              - {law: polynomial, by: 45 deg, duration: 0.3 s}
              - {law: dwell, duration: 0.2 s}
              - {law: polynomial, by: 45 deg, duration: 0.3 s}
    """))
    assert spec.motion.duration == pytest.approx(2.6)
    t = np.linspace(0, 2.6, 26001)
    q, qd, qdd = law(t)
    h = t[1] - t[0]
    assert np.max(np.abs(np.gradient(q, h)[1:-1] - qd[1:-1])) < 1e-4 * np.max(np.abs(qd))
    assert np.max(np.abs(np.diff(qdd))) < 1e-2 * np.max(np.abs(qdd))  # no acceleration jumps either


def _csv(n: int = 201, period: float = 1.0) -> str:
    t = np.linspace(0, period, n)
    return "t [s], crank [deg]\n" + "".join(f"{float(a)!r}, {float(30 * (1 - math.cos(2 * math.pi * a / period)))!r}\n" for a in t)


def test_table_beside_the_spec(tmp_path):
    spec, law = crank_law(write(tmp_path, """\
        duration: 2 s
        drive:
          crank: {law: table, file: crank.csv, ends: periodic}
    """, _csv()))
    t = np.linspace(0, 2, 401)
    w = 2 * math.pi
    q, qd, qdd = law(t)
    ref = math.radians(30)
    assert np.max(np.abs(q - ref * (1 - np.cos(w * t)))) < 1e-6
    assert np.max(np.abs(qd - ref * w * np.sin(w * t))) < 1e-4 * ref * w
    assert np.max(np.abs(qdd - ref * w * w * np.cos(w * t))) < 1e-2 * ref * w * w
    assert main(["check", str(tmp_path / "spec.yaml")]) == 0


@pytest.mark.parametrize("csv, row, words", [
    (None, None, "cannot read the table 'crank.csv'"),
    ("t [s], crank [deg]\n0, 0\n0.5, 1\n0.4, 2\n", 4, "times must increase"),
    ("t [s], crank [deg]\n0, 0\n0.5, 1\n1, 2\n", None, "too coarse"),
    ("t [s], crank [mm]\n" + "".join(f"{k / 10}, {k}\n" for k in range(11)), 1, "not an angle unit"),
    ("t [s], crank [deg]\n" + "".join(f"{k / 20}, {k}\n" for k in range(11)), None, "not the whole motion"),
])
def test_bad_tables_are_located_errors_through_the_cli(tmp_path, capsys, csv, row, words):
    spec = write(tmp_path, """\
        duration: 1 s
        drive:
          crank: {law: table, file: crank.csv}
    """, csv)
    assert main(["check", str(spec)]) == 2
    err = capsys.readouterr().err
    assert "Traceback" not in err and words in err, err
    line = [ln for ln in err.splitlines() if words in ln][0]
    # file:line:column of the spec's file field, the field path, and the CSV's row
    assert line.startswith(f"{spec}:") and "motion.drive.crank.file" in line
    assert line.split(":")[1].isdigit() and line.split(":")[2].isdigit()
    if row is not None:
        assert f"crank.csv:{row}:" in line


TWO_R_TIP = """\
name: 2R tip on a polyline
mechanism:
  template: custom
  bodies:
    - {name: l1, mass: 1, com: [0.1, 0], inertia: 0.01, pose: [0, 0, 0.3], points: {O: [0, 0], A: [0.3, 0]}}
    - {name: l2, mass: 1, com: [0.1, 0], inertia: 0.01, pose: [0.286, 0.0887, 1.9], points: {A: [0, 0], T: [0.25, 0]}}
  joints:
    - {type: revolute, name: O, a: frame, b: l1, point_a: [0, 0], point_b: O}
    - {type: revolute, name: A, a: l1, b: l2, point_a: A, point_b: A}
  drivers:
    - {name: tx, body: l2, coordinate: x, point: T}
    - {name: ty, body: l2, coordinate: y, point: T}
motion:
  duration: 1 s
  drive:
    tip:
      law: path
      components: [tx, ty]
      path: {type: polyline, points: [[0.2, 0.3], [0.35, 0.3], [0.35, 0.15]], corner_radius: 0.03}
      timing: {law: quintic}
analysis: {samples: 201}
validation: {enabled: false}
"""


def test_path_components_of_a_custom_point(tmp_path):
    """A path feeding two body-coordinate drivers of a custom mechanism (a 2R arm's tip)."""
    text = TWO_R_TIP
    spec, _ = load_text(text, str(tmp_path / "s.yaml"))
    study = run(spec)
    an = study.unbalanced.analysis
    k = an.names.index("l2")
    pose = an.frame_pose[:, k]
    tip = pose[:, :2] + 0.25 * np.stack([np.cos(pose[:, 2]), np.sin(pose[:, 2])], axis=1)
    assert tip[0] == pytest.approx([0.2, 0.3], abs=1e-9) and tip[-1] == pytest.approx([0.35, 0.15], abs=1e-9)
    # the corner is cut by the fillet: the tip never reaches (0.35, 0.3)
    assert np.min(np.hypot(tip[:, 0] - 0.35, tip[:, 1] - 0.3)) > 0.005


def test_a_changed_table_rebuilds_the_page(tmp_path, capsys):
    spec = write(tmp_path, """\
        duration: 2 s
        drive:
          crank: {law: table, file: crank.csv, ends: periodic}
    """, _csv())
    out = str(tmp_path / "site")
    assert main(["build", str(spec), "-o", out, "--no-sim", "-j", "1"]) == 0
    assert main(["build", str(spec), "-o", out, "--no-sim", "-j", "1"]) == 0
    assert "unchanged" in capsys.readouterr().err
    (tmp_path / "crank.csv").write_text(_csv(n=101))
    assert main(["build", str(spec), "-o", out, "--no-sim", "-j", "1"]) == 0
    assert "unchanged" not in capsys.readouterr().err


def test_a_path_on_the_3rpr_platform_pose(tmp_path):
    """The 3-RPR's platform x, y, phi fed by one path with heading: the platform's angle follows
    the tangent of an arc (plus an offset), and the engine's platform pose follows the path."""
    text = (ROOT / "specs" / "paper000_rpr3_idler_loop.yaml").read_text()
    data = yaml.safe_load(text)
    data["motion"] = {"duration": 0.5, "drive": {"platform": {
        "law": "path", "components": ["x", "y", "phi"], "heading": True, "angle": "-80 deg",
        "path": {"type": "arc", "centre": [-0.1, 0.0], "radius": 0.05, "from": "-90 deg", "to": "0 deg"},
        "timing": {"law": "cycloidal"}}}}
    data["validation"] = {"enabled": False}
    data.pop("references", None)
    p = tmp_path / "rpr3.yaml"
    p.write_text(yaml.safe_dump(data))
    study = run(load(p).spec)
    an = study.unbalanced.analysis
    pose = an.frame_pose[:, an.names.index("platform")]
    assert pose[0, :2] == pytest.approx([-0.1, -0.05], abs=1e-9) and pose[-1, :2] == pytest.approx([-0.05, 0.0], abs=1e-9)
    # heading: tangent of a counter-clockwise arc at angle a is a + 90 deg, plus the -80 deg offset
    assert pose[0, 2] == pytest.approx(math.radians(-90 + 90 - 80)) and pose[-1, 2] == pytest.approx(math.radians(0 + 90 - 80))


def test_point_and_pose_drives_of_templates(tmp_path, capsys):
    """The n-RRR's platform on a path (pose with heading); a five-bar's gripper on a law that is
    not a path, and a path on the gear-coupled five-bar: located errors."""
    data = yaml.safe_load((ROOT / "specs" / "paper001_4rrr.yaml").read_text())
    start = data["motion"]["drive"]["platform"]["from"]
    data["motion"] = {"duration": 1, "drive": {"platform": {
        "law": "path", "path": {"type": "line", "from": start[:2], "to": [0.02, 0.02]}, "timing": {"law": "quintic"},
        "angle": start[2]}}}
    data["validation"] = {"enabled": False}
    data.pop("references", None)
    data["balancing"] = {"method": "none"}
    p = tmp_path / "rrr4.yaml"
    p.write_text(yaml.safe_dump(data))
    an = run(load(p).spec).unbalanced.analysis
    assert np.isfinite(an.max_force) and an.max_force > 0
    five = yaml.safe_load((ROOT / "specs" / "paper004_five_bar.yaml").read_text())
    five["motion"] = {"duration": 1, "drive": {"gripper": {"law": "constant_speed", "speed": 1}}}
    five.pop("references", None)
    p = tmp_path / "five.yaml"
    p.write_text(yaml.safe_dump(five))
    assert main(["check", str(p)]) == 2
    assert "motion.drive.gripper.law: 'gripper' is a point or a pose" in capsys.readouterr().err
    five["motion"]["drive"]["gripper"] = {"law": "path", "path": {"type": "circle", "centre": [0, 0.45], "radius": 0.05},
                                          "timing": {"law": "quintic"}}
    p.write_text(yaml.safe_dump(five))
    assert main(["check", str(p)]) == 2
    assert "a path needs the plain five-bar" in capsys.readouterr().err


def test_a_serial_arms_tip_on_a_circle(tmp_path):
    """The 2R arm's tip drive takes a path: the analysed tip follows the circle at its speed."""
    data = {
        "name": "2R tip on a circle",
        "mechanism": {"template": "serial_arm", "links": [
            {"length": 0.35, "mass": 1.6, "com": 0.175, "inertia": 0.0163},
            {"length": 0.30, "mass": 0.9, "com": 0.15, "inertia": 0.00675}]},
        "motion": {"cycles": 1, "drive": {"tip": {"law": "path", "timing": {"law": "constant_speed", "speed": "0.5 m/s"},
                                                   "path": {"type": "circle", "centre": [0.3, 0.25], "radius": 0.08}}}},
        "analysis": {"samples": 201}, "validation": {"enabled": False},
    }
    p = tmp_path / "arm.yaml"
    p.write_text(yaml.safe_dump(data))
    spec = load(p).spec
    assert spec.motion.duration == pytest.approx(2 * math.pi * 0.08 / 0.5)
    an = run(spec).unbalanced.analysis
    pose = an.frame_pose[:, an.names.index("link2")]
    tip = pose[:, :2] + 0.30 * np.stack([np.cos(pose[:, 2]), np.sin(pose[:, 2])], axis=1)
    assert np.allclose(np.hypot(tip[:, 0] - 0.3, tip[:, 1] - 0.25), 0.08, atol=1e-9)
    assert tip[0] == pytest.approx([0.38, 0.25], abs=1e-9) and tip[-1] == pytest.approx([0.38, 0.25], abs=1e-9)


FIVE_BAR_ON = """\
name: five-bar on a polyline
mechanism:
  template: five_bar
  pivots: {{A1: [-0.08 m, 0 m], A2: [0.08 m, 0 m]}}
  links:
    proximal: {{length: 0.22 m, mass: 0.9 kg, com: 0.11 m, inertia: 0.0045 kg m^2}}
    distal:   {{length: 0.34 m, mass: 0.6 kg, com: 0.17 m, inertia: 0.0062 kg m^2}}
  working_modes: [+1, -1]
motion:
  duration: {duration}
  drive:
    gripper:
      law: path
      path: {{type: polyline, points: [[-0.10 m, 0.42 m], [-0.10 m, 0.36 m], [0.12 m, 0.36 m]]{radius}}}
      timing: {timing}
analysis: {{samples: 201}}
validation: {{enabled: false}}
"""


def _located(tmp_path, text: str):
    """The first located error of ``text``'s spec, raised where check and build meet it (the laws
    are built with the model)."""
    path = tmp_path / "s.yaml"
    path.write_text(text, encoding="utf-8")
    loaded = load(path)
    with pytest.raises(Exception) as err:
        run(loaded.spec)
    return loaded.error(err.value).errors[0]


def test_a_sharp_corner_passed_at_speed_is_a_located_error(tmp_path):
    """A polyline without a corner radius, timed by a point-to-point law that passes the corner
    moving: the velocity would turn at once (an infinite acceleration, which the sampled
    analysis would not show): an error at the path naming the corner, the speed and the time."""
    from balpipe.motion import PointToPoint, quintic

    e = _located(tmp_path, FIVE_BAR_ON.format(duration="0.4 s", radius="", timing="{law: quintic}"))
    assert e.path == "motion.drive.gripper.path" and e.line == 14  # the path: line
    assert "turns 90 deg at (-0.1, 0.36) m with no rounded corner" in e.message
    # the speed there: s' of the quintic law over the path (0.06 + 0.22 m) where s = 0.06 m
    law = PointToPoint(0.0, 0.28, 0.4, quintic)
    t = np.linspace(0, 0.4, 400001)
    tc = t[np.argmin(np.abs(law(t)[0] - 0.06))]
    assert f"passes at {law(np.array([tc]))[1][0]:.4g} m/s (t = {tc:.4g} s)" in e.message
    assert "corner_radius" in e.message


def test_a_sharp_corner_is_accepted_where_the_timing_stops_and_rounded_corners_anywhere():
    stop = ("{law: cycle, from: 0 m, segments: [{law: quintic, to: 0.06 m, duration: 0.2 s}, "
            "{law: dwell, duration: 0.05 s}, {law: quintic, to: 0.28 m, duration: 0.25 s}]}")
    spec, _ = load_text(FIVE_BAR_ON.format(duration="0.5 s", radius="", timing=stop), "s.yaml")
    an = run(spec).unbalanced.analysis  # the gripper stops at the corner, then turns
    assert np.isfinite(an.moment).all() and an.max_force > 0
    spec, _ = load_text(FIVE_BAR_ON.format(duration="0.4 s", radius=", corner_radius: 15 mm", timing="{law: quintic}"), "s.yaml")
    assert run(spec).unbalanced.analysis.max_force > 0


def test_a_sharp_corner_on_a_path_with_heading_is_an_error_even_where_the_timing_stops(tmp_path):
    """With heading, the pose's angle follows the tangent: at a sharp corner it would jump by the
    turn, whatever the speed (here the timing stops at the corner)."""
    e = _located(tmp_path, """\
name: 3R hand on a polyline
mechanism:
  template: custom
  bodies:
    - {name: l1, mass: 1, com: [0.15, 0], inertia: 0.01, pose: [0, 0, 0.3], points: {O: [0, 0], A: [0.3, 0]}}
    - {name: l2, mass: 1, com: [0.12, 0], inertia: 0.01, pose: [0.28660, 0.08866, 1.9], points: {A: [0, 0], B: [0.25, 0]}}
    - {name: l3, mass: 0.5, com: [0.05, 0], inertia: 0.001, pose: [0.20577, 0.32529, 0], points: {B: [0, 0], T: [0.1, 0]}}
  joints:
    - {type: revolute, name: O, a: frame, b: l1, point_a: [0, 0], point_b: O}
    - {type: revolute, name: A, a: l1, b: l2, point_a: A, point_b: A}
    - {type: revolute, name: B, a: l2, b: l3, point_a: B, point_b: B}
  drivers:
    - {name: tx, body: l3, coordinate: x, point: T}
    - {name: ty, body: l3, coordinate: y, point: T}
    - {name: ta, body: l3, coordinate: angle}
motion:
  duration: 1 s
  drive:
    hand:
      law: path
      components: [tx, ty, ta]
      heading: true
      path: {type: polyline, points: [[0.30577, 0.32529], [0.38, 0.32529], [0.38, 0.25]]}
      timing: {law: cycle, from: 0 m, segments: [{law: quintic, to: 0.07423 m, duration: 0.5 s}, {law: quintic, to: 0.14952 m, duration: 0.5 s}]}
analysis: {samples: 101}
validation: {enabled: false}
""")
    assert e.path == "motion.drive.hand.path" and "the heading" in e.message and "jump by that much" in e.message, e
