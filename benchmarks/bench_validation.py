"""What the pymunk validation costs: ``balpipe build specs`` with and without the simulation.

Each build is a new process, ``python -m balpipe build SPECS -o <tmp> --force -j J`` (and the
same with ``--no-sim``), and the script prints, per build, the wall seconds, the CPU seconds of
the process and its children (user + system, from ``os.wait4``: the figure that does not move
with the load of a shared machine) and the peak resident memory of the largest process; then,
per version, the medians, the ratio CPU(simulated) / CPU(--no-sim) and the validation's share
of the simulated build's CPU, 1 - CPU(--no-sim) / CPU(simulated).

``--against REV`` checks REV out with ``git worktree add`` into a temporary folder and builds it
with ``PYTHONPATH`` on its ``pipeline/`` (its ``templates/`` folder loaded as ``balpipe.templates``
when no install provides it), alternating with this tree build by build (this sim, REV sim,
this no-sim, REV no-sim, repeated), so that both see the same load. Run from the repository:

    python benchmarks/bench_validation.py --against main --repeat 2
    python benchmarks/bench_validation.py -j 2                   # this tree only, 2 processes
    python benchmarks/bench_validation.py --specs specs/scott_russell.yaml --sim-only
    python benchmarks/bench_validation.py --against main --keep /tmp/b   # then compare_verdicts.py /tmp/b/main-sim-0 /tmp/b/this-sim-0
    python benchmarks/bench_validation.py --python /venvs/new/bin/python --against-python /venvs/old/bin/python \
        --against old --repeat 6        # two installed versions (`pip install .` in each venv)

A source tree runs its templates from their text; an installed balpipe runs them compiled
(``balpipe.report.template_build``): ``--python`` and ``--against-python`` measure what the
README's quick start runs.

Nothing is asserted: it prints a table (and ``--json FILE`` writes the raw rows).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_build import DRIVER  # noqa: E402  (balpipe's command line from a source tree on PYTHONPATH)



def build_once(python: str, pipeline: Path | None, specs: str, jobs: int, sim: bool, keep: Path | None = None) -> dict:
    """One build in a new process: wall, CPU (process and children) and peak RSS (MB). ``keep``:
    the output folder, kept (else a temporary one, removed). ``pipeline`` None: the balpipe
    installed for ``python`` (``python -m balpipe build``, as the README's quick start runs it)."""
    out = str(keep) if keep is not None else tempfile.mkdtemp(prefix="bench_validation_")
    env = dict(os.environ, PYTHONHASHSEED="0")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    options = ["--force", "-j", str(jobs)] + ([] if sim else ["--no-sim"])
    if pipeline is None:
        env.pop("PYTHONPATH", None)
        args = [python, "-m", "balpipe", "build", specs, "-o", out] + options
    else:
        env["PYTHONPATH"] = str(pipeline)
        # bench_build's driver with no phase wrapped: ``build SPECS -o OUT -j 1`` and these options (the last -j wins)
        args = [python, "-c", DRIVER, "[]", specs, out] + options
    t0 = time.perf_counter()
    proc = subprocess.Popen(args, env=env, cwd=str(pipeline.parent if pipeline is not None else ROOT),
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT)
    output = proc.stdout.read() if proc.stdout else b""
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    # wait4's usage of the build process includes its reaped children (the forked workers of -j N);
    # RUSAGE_CHILDREN of this script would sum every build, so the figure is wait4's
    cpu = usage.ru_utime + usage.ru_stime
    rss = usage.ru_maxrss / 1024.0
    if keep is None:
        shutil.rmtree(out, ignore_errors=True)
    rc = os.waitstatus_to_exitcode(status)
    lines = output.decode(errors="replace").splitlines()
    summary = [ln for ln in lines if ln.startswith("balpipe:")]
    not_ok = [ln.split("] ", 1)[-1][:160] for ln in lines if ln.startswith("[") and ": ok" not in ln]
    return {"wall": wall, "cpu": cpu, "rss_mb": rss, "rc": rc, "not_ok": not_ok,
            "summary": summary[-1] if summary else "\n".join(lines[-5:])}


def worktree(rev: str, where: Path) -> Path:
    subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(where), rev], check=True,
                   capture_output=True)
    return where


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--specs", default="specs", help="the folder or spec built (default specs)")
    ap.add_argument("--against", metavar="REV", help="git revision built in the same run, alternated")
    ap.add_argument("-j", "--jobs", type=int, default=1, help="balpipe build -j (default 1)")
    ap.add_argument("--repeat", type=int, default=1, help="builds of each kind per version (default 1)")
    ap.add_argument("--sim-only", action="store_true", help="only the simulated build")
    ap.add_argument("--json", help="write the rows to this file")
    ap.add_argument("--keep", type=Path, help="keep each build's output in KEEP/<version>-<sim|no-sim>-<repeat> "
                    "(for benchmarks/compare_verdicts.py)")
    ap.add_argument("--python", metavar="PYTHON",
                    help="build this version as installed for PYTHON (a venv's python after `pip install .`: "
                    "python -m balpipe, no source tree, so that what an install adds counts, the compiled templates)")
    ap.add_argument("--against-python", metavar="PYTHON",
                    help="the version compared with, installed for PYTHON (named by --against, default 'against')")
    a = ap.parse_args(argv)
    versions: dict[str, tuple[str, Path | None]] = {"this": (a.python or sys.executable, None if a.python else ROOT / "pipeline")}
    tmp = None
    if a.against_python:
        a.against = a.against or "against"
        versions[a.against] = (a.against_python, None)
    elif a.against:
        tmp = Path(tempfile.mkdtemp(prefix="bench_validation_rev_"))
        versions[a.against] = (sys.executable, worktree(a.against, tmp / "tree") / "pipeline")
    kinds = [True] if a.sim_only else [True, False]
    rows = []
    try:
        for r in range(a.repeat):
            for sim in kinds:
                for name, (python, pipeline) in versions.items():
                    keep = a.keep / f"{name.replace('/', '_')}-{'sim' if sim else 'no-sim'}-{r}" if a.keep else None
                    res = build_once(python, pipeline, a.specs, a.jobs, sim, keep)
                    res.update(version=name, sim=sim, repeat=r)
                    rows.append(res)
                    print(f"{name:>12s} {'sim' if sim else 'no-sim':>7s}  wall {res['wall']:7.2f} s  CPU "
                          f"{res['cpu']:7.2f} s  peak RSS {res['rss_mb']:6.0f} MB  rc {res['rc']}  {res['summary']}",
                          flush=True)
                    for ln in res["not_ok"]:
                        print(f"{'':>21s}{ln}", flush=True)
    finally:
        if tmp is not None:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tmp / "tree")],
                           capture_output=True)
            shutil.rmtree(tmp, ignore_errors=True)
    print(f"\nmedians of {a.repeat} build(s), specs {a.specs}, -j {a.jobs}")
    print(f"{'version':>12s} {'build':>7s} {'wall s':>8s} {'CPU s':>8s} {'RSS MB':>7s}")
    med: dict[tuple[str, bool], dict] = {}
    for name in versions:
        for sim in kinds:
            sel = [x for x in rows if x["version"] == name and x["sim"] == sim]
            m = {k: statistics.median(x[k] for x in sel) for k in ("wall", "cpu", "rss_mb")}
            med[(name, sim)] = m
            print(f"{name:>12s} {'sim' if sim else 'no-sim':>7s} {m['wall']:8.2f} {m['cpu']:8.2f} {m['rss_mb']:7.0f}")
    if not a.sim_only:
        print()
        for name in versions:
            s, n = med[(name, True)], med[(name, False)]
            print(f"{name:>12s}: CPU sim / no-sim {s['cpu'] / n['cpu']:.2f}x, validation share of the simulated build "
                  f"{100 * (1 - n['cpu'] / s['cpu']):.0f} % ({s['cpu'] - n['cpu']:.1f} s of CPU)")
    if len(versions) == 2:
        other = a.against
        for sim in kinds:
            t, o = med[("this", sim)], med[(other, sim)]
            print(f"this / {other}, {'sim' if sim else 'no-sim'}: CPU {t['cpu'] / o['cpu']:.2f}, wall {t['wall'] / o['wall']:.2f}")
    if a.json:
        Path(a.json).write_text(json.dumps(rows, indent=1))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
