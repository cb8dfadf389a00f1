"""Design sweeps (issue 13): mass sweeps through the regressor equal full engine analyses; the
``balpipe sweep`` command (grids, samples, bad input, failing designs, outputs); dask."""

from __future__ import annotations

import csv
import io
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.balancing.mass_sweep import MassSweep, check_parameters, geometry_key
from balpipe.model import Attachment
from balpipe.study import gravity_vector

ROOT = Path(__file__).resolve().parents[2]
SPECS = ROOT / "specs"
SR = SPECS / "scott_russell.yaml"


def balpipe(*args):
    return subprocess.run([sys.executable, "-m", "balpipe", *map(str, args)], capture_output=True, text=True)


def _random_masses(model, rng):
    """The same geometry with random link masses, centres of mass, inertias and a random
    counterweight on every body."""
    bodies = []
    for b in model.bodies:
        m = b.mass * rng.uniform(0.3, 3.0) + rng.uniform(0.0, 0.5)
        com = (b.com[0] + rng.uniform(-0.05, 0.05), b.com[1] + rng.uniform(-0.05, 0.05))
        cw = Attachment("sweep cw", float(rng.uniform(0, 2)), (float(rng.uniform(-0.1, 0.1)), float(rng.uniform(-0.1, 0.1))),
                        float(rng.uniform(0, 1e-3)))
        bodies.append(replace(b, mass=float(m), com=com, inertia=float(b.inertia * rng.uniform(0.5, 2) + 1e-4),
                              attachments=b.attachments + (cw,)))
    return replace(model, bodies=tuple(bodies))


def _rel(a, b):
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)))) / max(1.0, float(np.max(np.abs(b))))


@pytest.mark.parametrize("spec_file, gravity", [
    ("scott_russell.yaml", False),               # slider-crank, prismatic pair
    ("scott_russell.yaml", True),
    ("custom_four_bar_balancing.yaml", True),    # counter-rotating discs on gears, closed loop
    ("paper001_4rrr.yaml", False),               # redundant actuation: least-norm efforts
    ("paper004_five_bar.yaml", False),           # gear meshes with pitch radii (radial tooth forces)
])
def test_mass_sweep_equals_engine(spec_file, gravity):
    """Every design's loads, efforts and reactions from one analysis of the base design equal a
    full engine analysis of the design to 1e-9."""
    spec = load(SPECS / spec_file).spec
    result = registry.balance_designs(spec)
    t = registry.time_grid(spec)
    g = (0.0, -9.81) if gravity else (0.0, 0.0)
    point = (0.07, -0.03)
    base = result.stages[-1].model
    ms = MassSweep.build(base, t, g, point)
    rng = np.random.default_rng(13)
    designs = [_random_masses(base, rng) for _ in range(3)]
    P = np.array([ms.parameters(d) for d in designs])
    peaks = ms.peaks(P, chunk=2)
    for k, d in enumerate(designs):
        an = analyse(d, t, g, point)
        F, M, E = ms.loads(P[k])
        assert _rel(F, an.force) < 1e-9 and _rel(M, an.moment) < 1e-9
        for i, name in enumerate(ms.drivers):
            assert _rel(E[:, i], an.efforts[name]) < 1e-9
        rx = ms.reactions(P[k])
        for j, parts in an.reactions.items():
            for key, val in parts.items():
                assert _rel(rx[j][key], val) < 1e-9, (j, key)
        assert abs(peaks["max_shaking_force"][k] - an.max_force) <= 1e-9 * max(1.0, an.max_force)
        assert abs(peaks["max_shaking_moment"][k] - an.max_moment) <= 1e-9 * max(1.0, an.max_moment)
        eff = max(float(np.max(np.abs(e))) for e in an.efforts.values())
        assert abs(peaks["max_actuator_effort"][k] - eff) <= 1e-9 * max(1.0, eff)


def test_mass_sweep_scales_with_mass():
    """Scaling every mass parameter by k scales the shaking loads and efforts by k (no gravity
    needed for linearity: with gravity too)."""
    spec = load(SR).spec
    res = registry.balance_designs(spec)
    ms = MassSweep.build(res.stages[0].model, registry.time_grid(spec), (0.0, -9.81))
    p = ms.parameters(res.stages[0].model)
    a, b = ms.peaks(p), ms.peaks(3.5 * p)
    for key in a:
        assert b[key][0] == pytest.approx(3.5 * a[key][0], rel=1e-12)


def test_geometry_key_separates_geometry_from_masses():
    spec = load(SR).spec
    res = registry.balance_designs(spec)
    t = registry.time_grid(spec)
    m0, m2 = res.stages[0].model, res.stages[-1].model
    assert geometry_key(m0, t) == geometry_key(m2, t)  # counterweights: masses only
    crank = m0.body("crank")
    moved = m0.replace_body(replace(crank, points={**crank.points, "B": (0.25, 0.0)}))
    assert geometry_key(moved, t) != geometry_key(m0, t)
    ms = MassSweep.build(m0, t)
    with pytest.raises(ValueError):
        ms.parameters(moved)


def test_negative_mass_or_inertia_is_flagged():
    names = ["a", "b"]
    P = np.array([[1, 0.1, 0, 0.02, 1, 0, 0, 0.01],
                  [-1, 0, 0, 0.01, 1, 0, 0, 0.01],
                  [1, 0.3, 0, 0.05, 1, 0, 0, 0.01]])  # I_c = 0.05 - 0.09 < 0
    out = check_parameters(names, P)
    assert out[0] is None and "'a'" in out[1] and "'a'" in out[2]


def _rows(path: Path) -> list[dict]:
    return list(csv.DictReader(io.StringIO(path.read_text())))


def test_sweep_cli_grid_fast_path_matches_full_analysis(tmp_path):
    out = tmp_path / "s"
    r = balpipe("sweep", SR, "--vary", "mechanism.crank.mass=500 g:2 kg:3", "--vary", "mechanism.slider.mass=0.2,0.7",
                "--stage", "counterweights", "-o", out, "-q", "-j", "2")
    assert r.returncode == 0, r.stderr
    assert "sweep [" not in r.stderr  # -q: no progress bar
    rows = _rows(out / "sweep.csv")
    assert len(rows) == 6 and all(x["status"] == "ok" and x["route"] == "mass" for x in rows)
    assert [float(x["mechanism.crank.mass"]) for x in rows[::2]] == [0.5, 1.25, 2.0]  # SI, units converted
    # each row equals a full engine analysis of the design's own spec
    from balpipe.sweep import design_spec_text, plan, run

    p = plan(str(SR), ["mechanism.crank.mass=500 g:2 kg:3", "mechanism.slider.mass=0.2,0.7"], stage="counterweights")
    res = run(p, jobs=1)
    for k in (0, 5):
        f = tmp_path / f"d{k}.yaml"
        f.write_text(design_spec_text(res, k))
        spec = load(f).spec
        stage = [s for s in registry.balance_designs(spec).stages if s.name == "counterweights"][0]
        an = analyse(stage.model, registry.time_grid(spec), gravity_vector(spec), tuple(spec.analysis.moment_point))
        row = rows[k]
        assert float(row["max_shaking_moment [N m]"]) == pytest.approx(an.max_moment, rel=1e-9)
        assert float(row["max_shaking_force [N]"]) == pytest.approx(an.max_force, rel=1e-9, abs=1e-9)
        eff = max(float(np.max(np.abs(e))) for e in an.efforts.values())
        assert float(row["max_actuator_effort [N m or N]"]) == pytest.approx(eff, rel=1e-9)
        an0 = analyse(registry.balance_designs(spec).stages[0].model, registry.time_grid(spec))
        assert float(row["unbalanced_max_shaking_moment [N m]"]) == pytest.approx(an0.max_moment, rel=1e-9)
        assert float(row["moment_ratio [1]"]) == pytest.approx(an.max_moment / an0.max_moment, rel=1e-9)
    page = (out / "index.html").read_text()
    assert "Pareto front" in page and "<svg" in page
    linked = sorted((out / "designs").glob("*.yaml"))
    assert linked and all(load(f).spec for f in linked)  # every linked design is a valid spec


def test_sweep_geometry_change_takes_full_route_and_failures_are_rows(tmp_path):
    out = tmp_path / "s"
    # the duration changes the time grid (full route); a 0.35 m crank cannot be followed by the
    # 0.2 m coupler, and a counterweight at +0.05 m needs a negative mass: rows with their errors
    r = balpipe("sweep", SR, "--vary", "motion.duration=250 ms,125 ms", "--vary", "mechanism.crank.length=0.2,0.35",
                "--vary", "balancing.crank_counterweight=-0.1 m,0.05 m", "--stage", "counterweights",
                "-o", out, "-q", "-j", "1")
    assert r.returncode == 0, r.stderr
    rows = _rows(out / "sweep.csv")
    assert len(rows) == 8
    ok = [x for x in rows if x["status"] == "ok"]
    assert [(x["motion.duration"], x["route"]) for x in ok] == [("0.25", "mass"), ("0.125", "full")]
    # halving the duration multiplies the loads by 4
    m = [float(x["max_shaking_moment [N m]"]) for x in ok]
    assert m[1] == pytest.approx(4 * m[0], rel=1e-9)
    bad = [x for x in rows if x["status"] == "error"]
    assert len(bad) == 6
    assert any("negative counterweight" in x["error"] for x in bad)
    assert any("cannot reach the guide" in x["error"] for x in bad)


def _main(capsys, *args) -> tuple[int, str]:
    """``balpipe ARGS`` in this process, as ``python -m balpipe`` runs it (an argparse error exits
    with its code): (exit code, stderr). An exception escaping it fails the test (a traceback)."""
    from balpipe.cli import main

    try:
        code = main([str(a) for a in args])
    except SystemExit as exc:
        code = exc.code
    return code, capsys.readouterr().err


def test_sweep_bad_input_is_refused_before_work(tmp_path, capsys):
    """Each refusal in this process (the same ``main`` as the command; a process start each cost
    about 1 s), the last one by the command itself."""
    out = tmp_path / "s"
    cases = [
        (["mechanism.crank.mas=1:2:3"], "scott_russell.yaml:", "unknown path"),
        (["mechanism.crnk.mass=1:2:3"], "scott_russell.yaml:", "unknown path"),
        (["mechanism.crank.length=1 kg:2 kg:3"], "mechanism.crank.length", "not a length unit"),
        (["mechanism.crank.mass=-1:2:3"], "mechanism.crank.mass", ">= 0"),
        (["mechanism.crank=1:2:3"], "mechanism.crank", "not a numeric field"),
        (["mechanism.crank.mass=1:2"], "mechanism.crank.mass", "grid needs"),
        (["mechanism.crank.mass=1:2:400", "mechanism.slider.mass=1:2:400"], "160000 designs", "limit"),
        (["mechanism.crank.mass"], "PATH=RANGE", ""),
    ]
    for vary, where, what in cases:
        args = [a for v in vary for a in ("--vary", v)]
        code, err = _main(capsys, "sweep", SR, *args, "-o", out)
        assert code == 2, (vary, err)
        assert "Traceback" not in err and where in err and what in err, (vary, err)
    assert not out.exists()  # nothing was written: refused before any work
    r = balpipe("sweep", SR, "--vary", "mechanism.crank.mass=1:2:2", "--max-designs", "1", "-o", out)
    assert r.returncode == 2 and "limit of 1" in r.stderr


def test_sweep_random_and_lhs_are_seeded_and_in_bounds():
    from balpipe.sweep import plan

    for sample in ("random", "lhs"):
        a = plan(str(SR), ["mechanism.crank.mass=1 kg:2 kg", "mechanism.slider.mass=0.1:0.5"], sample, 20, seed=4)
        b = plan(str(SR), ["mechanism.crank.mass=1 kg:2 kg", "mechanism.slider.mass=0.1:0.5"], sample, 20, seed=4)
        c = plan(str(SR), ["mechanism.crank.mass=1 kg:2 kg", "mechanism.slider.mass=0.1:0.5"], sample, 20, seed=5)
        assert a.designs == b.designs != c.designs and len(a.designs) == 20
        x = np.array([[float(d[0].split()[0]), d[1]] for d in a.designs])
        assert np.all((x[:, 0] >= 1) & (x[:, 0] <= 2) & (x[:, 1] >= 0.1) & (x[:, 1] <= 0.5))
        if sample == "lhs":  # one point in each of the 20 strata of every variable
            strata = np.floor((x[:, 0] - 1) / 1 * 20).astype(int)
            assert sorted(strata) == list(range(20))


def test_sweep_output_is_deterministic(tmp_path):
    args = ["--vary", "mechanism.coupler.mass=0.5:1.5:4", "--sample", "grid", "-q"]
    a, b = tmp_path / "a", tmp_path / "b"
    assert balpipe("sweep", SR, *args, "-o", a, "-j", "1").returncode == 0
    assert balpipe("sweep", SR, *args, "-o", b, "-j", "2").returncode == 0
    c = tmp_path / "c"
    assert balpipe("sweep", SR, *args, "-o", c).returncode == 0  # default: all cores when worth it
    for f in ("sweep.csv", "index.html"):
        assert (a / f).read_bytes() == (b / f).read_bytes() == (c / f).read_bytes()


def test_sweep_on_a_local_two_worker_dask_cluster_equals_local_run():
    distributed = pytest.importorskip("distributed")
    from balpipe.sweep import csv_text, plan, run

    p = plan(str(SR), ["mechanism.crank.mass=0.5:2:4", "motion.duration=0.25,0.2"], stage="counterweights")
    local = run(p, jobs=1)
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None) as cl:
        remote = run(p, scheduler=cl.scheduler_address)
    assert local.fast == 4 and local.full == 4
    assert csv_text(remote) == csv_text(local)


def test_design_values_never_modify_the_base_spec():
    from balpipe.sweep import with_values

    base = {"a": {"b": [1.0, {"c": 2.0}], "d": 3.0}, "e": 4.0}
    d = with_values(base, [("a", "b", 1, "c"), ("a", "d"), ("e",)], ("5 m", 6.0, 7.0))
    assert d == {"a": {"b": [1.0, {"c": "5 m"}], "d": 6.0}, "e": 7.0}
    assert base == {"a": {"b": [1.0, {"c": 2.0}], "d": 3.0}, "e": 4.0}
    with pytest.raises(KeyError):
        with_values(base, [("a", "x", "y")], (1.0,))


def test_sweep_help_progress_and_exit_codes(tmp_path):
    r = balpipe("sweep", "--help")
    assert r.returncode == 0 and "--vary" in r.stdout and "--scheduler" in r.stdout
    r = balpipe("sweep", SR, "--vary", "mechanism.slider.mass=0.5,1", "-o", tmp_path / "a", "-j", "1")
    assert r.returncode == 0 and "sweep [" in r.stderr and "2/2 designs" in r.stderr  # progress on stderr
    # every design fails (the coupler cannot follow a 0.35 m crank): exit 1, rows with errors
    r = balpipe("sweep", SR, "--vary", "mechanism.crank.length=0.3,0.35", "-o", tmp_path / "b", "-q", "-j", "1")
    assert r.returncode == 1 and "2 failed" in r.stderr
    rows = _rows(tmp_path / "b" / "sweep.csv")
    assert [x["status"] for x in rows] == ["error", "error"]
    r = balpipe("sweep", tmp_path / "missing.yaml", "--vary", "a.b=1,2", "-o", tmp_path / "c")
    assert r.returncode == 2 and "Traceback" not in r.stderr
