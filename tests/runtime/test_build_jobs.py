"""``build``'s number of processes: by default one per usable core (at most one per spec), and
the same site, outcomes and progress order whatever the number."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from _edits import replaced
from balpipe import build as build_mod
from balpipe.runtime import pool as pool_mod
from balpipe.build import Options, build
from balpipe.runtime.pool import default_jobs, usable_cores

SPECS = Path(__file__).resolve().parents[2] / "specs"


def _site(tmp_path: Path, jobs: int | None, simulate: bool = True):
    """Three specs (two small ones, simulated, and an invalid one) built with ``jobs``: the
    outcomes, the progress calls and the output folder."""
    d = tmp_path / "specs"
    if not d.exists():
        d.mkdir()
        (d / "a_scott.yaml").write_text(replaced((SPECS / "scott_russell.yaml").read_text(),
                                                 "  samples: 501", "  samples: 41"))
        (d / "b_broken.yaml").write_text("name: broken\nmechanism: {template: slider_crank\n")
        (d / "c_offset.yaml").write_text((SPECS / "offset_slider_crank.yaml").read_text()
                                         + "analysis:\n  samples: 41\n")
    out = tmp_path / f"out-{jobs}"
    calls = []
    outcomes = build([str(d)], Options(out=out, simulate=simulate), jobs=jobs,
                     progress=lambda k, n, o: calls.append((k, n, o.source, o.status)))
    return outcomes, calls, out


def _files(out: Path) -> dict[str, bytes]:
    return {str(p.relative_to(out)): p.read_bytes() for p in sorted(out.rglob("*"))
            if p.is_file() and p.name != ".balpipe.lock"}


def test_output_and_progress_do_not_depend_on_jobs(tmp_path):
    o1, c1, out1 = _site(tmp_path, 1)
    o2, c2, out2 = _site(tmp_path, 2)
    assert [(o.source, o.status) for o in o1] == [(o.source, o.status) for o in o2]
    assert [o.status for o in o1] == ["ok", "error", "ok"]  # the specs' order
    assert c1 == c2 and [k for k, *_ in c1] == [1, 2, 3]
    f1, f2 = _files(out1), _files(out2)
    assert set(f1) == set(f2)
    timing = {f for f in f1 if Path(f).name in ("timing.json", "timing.js")}
    assert len(timing) == 4  # both simulated pages have them: the only files that may differ
    assert {f for f in f1 if f.endswith("results.json")} == {"a_scott/results.json", "c_offset/results.json"}
    # the simulation cache's entries: the same keys (names); each keeps its run's time, as timing.json
    sims = {f for f in f1 if f.startswith(".cache/sims/")}
    assert sims
    for f in sorted(set(f1) - timing - sims):
        assert f1[f] == f2[f], f


def test_default_is_one_process_per_usable_core_at_most_one_per_spec(tmp_path, monkeypatch):
    seen = []
    monkeypatch.setattr(build_mod, "_run", lambda todo, opts, jobs, progress, outcomes: seen.append((len(todo), jobs)))
    monkeypatch.setattr(pool_mod, "usable_cores", lambda: 3)
    d = tmp_path / "specs"
    d.mkdir()
    for k in range(5):
        (d / f"s{k}.yaml").write_text("name: x\n")
    build([str(d)], Options(out=tmp_path / "o"))
    build([str(d / "s0.yaml"), str(d / "s1.yaml")], Options(out=tmp_path / "o"))
    build([str(d / "s0.yaml")], Options(out=tmp_path / "o"))
    build([str(d)], Options(out=tmp_path / "o"), jobs=1)
    assert seen == [(5, 3), (2, 2), (1, 1), (5, 1)]


def test_usable_cores_follows_the_affinity_mask(monkeypatch):
    if hasattr(os, "process_cpu_count"):
        monkeypatch.setattr(os, "process_cpu_count", lambda: 1)
    elif hasattr(os, "sched_getaffinity"):
        monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {3})
    else:  # pragma: no cover
        pytest.skip("no affinity on this platform")
    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    assert usable_cores() == 1 and default_jobs(12) == 1
    assert default_jobs(0) == 1  # nothing to build: still a valid pool size


def test_cli_build_defaults_to_one_process_per_core_and_refuses_zero(tmp_path, monkeypatch, capsys):
    """``balpipe build`` without ``-j`` passes ``jobs=None`` (one process per usable core, at most
    one per spec); ``-j 0`` is a usage error (exit 2), not a traceback."""
    from balpipe.cli import main

    seen = []
    monkeypatch.setattr(build_mod, "build", lambda paths, opts, jobs, progress, scheduler=None: seen.append(jobs) or [])
    spec = tmp_path / "s.yaml"
    spec.write_text("name: x\n")
    main(["build", str(spec), "-o", str(tmp_path / "o"), "-q"])
    main(["build", str(spec), "-o", str(tmp_path / "o"), "-q", "-j", "1"])
    assert seen == [None, 1]
    assert main(["build", str(spec), "-o", str(tmp_path / "o"), "-j", "0"]) == 2
    assert "--jobs must be at least 1" in capsys.readouterr().err


def test_one_spec_on_spare_cores_simulates_its_stages_in_parallel_with_the_same_site(tmp_path, monkeypatch):
    """Fewer specs than cores: the cores left over run one spec's stage simulations in parallel
    (issue 23 item 5); the pages are the same bytes as a build on one core (timing files aside)."""
    import balpipe.validation_stage as vs

    seen = []
    real = vs.simulate_study
    monkeypatch.setattr(vs, "simulate_study", lambda st, workers=1: seen.append(workers) or real(st, workers=workers))
    spec = tmp_path / "scott_russell.yaml"  # 41 samples instead of 501: the same stages, simulated
    spec.write_text(replaced((SPECS / "scott_russell.yaml").read_text(), "  samples: 501", "  samples: 41"))
    one, two = tmp_path / "one", tmp_path / "two"
    build_mod.build([str(spec)], build_mod.Options(one), jobs=1)
    build_mod.build([str(spec)], build_mod.Options(two), jobs=2)
    assert seen == [1, 2]
    for f in ("index.html", "results.json", "timeseries.csv"):
        assert (one / "scott_russell" / f).read_bytes() == (two / "scott_russell" / f).read_bytes(), f


def test_ctrl_c_during_a_parallel_simulation_is_clean(tmp_path):
    """One spec on two cores simulates in forked processes; Ctrl-C stops them at once, with no
    traceback from any of them, and the site stays as it was."""
    import os
    import signal
    import subprocess
    import sys

    spec = Path(__file__).resolve().parents[2] / "specs" / "paper000_rpr3_idler_loop.yaml"
    from _terminal import balpipe_command, wait_for_children

    p = subprocess.Popen(balpipe_command("build", spec, "-o", tmp_path / "out", "-j", 2),
                         stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, start_new_session=True)
    wait_for_children(p, count=2)  # inside the simulations: the two forked processes run them
    assert p.poll() is None
    os.killpg(p.pid, signal.SIGINT)
    _, err = p.communicate(timeout=60)
    assert p.returncode == 130, err
    assert "Traceback" not in err and "KeyboardInterrupt" not in err, err
    assert not (tmp_path / "out" / "paper000_rpr3_idler_loop").exists()
