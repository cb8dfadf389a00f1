"""``balpipe history`` benchmark, run by hand: ``python benchmarks/history_bench.py``.

Makes a throw-away git repository holding the repository's specs (default: the two slider-crank
specs), commits ``--commits`` revisions of each (a different slider or coupler mass every
time, so every commit is a new design), then runs ``python -m balpipe history specs -o OUT
--cache CACHE`` three times as a user would (a new process each time, imports included):

1. cold: empty cache, every revision computed;
2. warm: the same command again, nothing computed (the figures come from the cache and the
   pages are left as they are);
3. one more commit: only that revision is computed.

Prints the wall time of each run and the counts that balpipe history reports. Asserts nothing
about speed. ``--sim`` includes the pymunk validation of every revision (much slower).
"""

from __future__ import annotations

import argparse
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
ENV = {**os.environ, "GIT_AUTHOR_NAME": "bench", "GIT_AUTHOR_EMAIL": "bench@example.org",
       "GIT_COMMITTER_NAME": "bench", "GIT_COMMITTER_EMAIL": "bench@example.org",
       "GIT_CONFIG_GLOBAL": os.devnull, "GIT_CONFIG_NOSYSTEM": "1"}
VARIED = {  # a mass line of each spec, rewritten with a new value at each commit
    "scott_russell.yaml": (r"slider:\s*\{mass: ([0-9.]+) kg\}", "slider:  {{mass: {:.3f} kg}}"),
    "offset_slider_crank.yaml": (r"slider:\s*\{mass: ([0-9.]+) g\}", "slider:  {{mass: {:.1f} g}}"),
}


def git(repo: Path, *args: str) -> None:
    subprocess.run(["git", *args], cwd=repo, env=ENV, check=True, capture_output=True)


def vary(text: str, name: str, k: int) -> str:
    pattern, fmt = VARIED[name]
    m = re.search(pattern, text)
    if m is None:
        raise SystemExit(f"{name}: no line matching {pattern!r} to vary")
    value = float(m.group(1)) * (1 + 0.05 * k)
    return text[:m.start()] + fmt.format(value) + text[m.end():]


def run_history(repo: Path, sim: bool, jobs: int) -> tuple[float, float, str]:
    cmd = [sys.executable, "-m", "balpipe", "history", "specs", "-o", "out", "--cache", "cache", "-j", str(jobs)]
    if not sim:
        cmd.append("--no-sim")
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    r = subprocess.run(cmd, cwd=repo, capture_output=True, text=True)
    seconds = time.perf_counter() - start
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    if r.returncode != 0:
        raise SystemExit(f"balpipe history failed ({r.returncode}):\n{r.stderr}")
    summary = r.stderr.strip().splitlines()[-1]
    summary = re.sub(r"; pages: .*$", "", summary.removeprefix("balpipe: history of "))
    return seconds, cpu, summary


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--commits", type=int, default=5, help="revisions of each spec (default 5)")
    ap.add_argument("--specs", nargs="+", default=sorted(VARIED), choices=sorted(VARIED), help="specs from specs/")
    ap.add_argument("--sim", action="store_true", help="with the pymunk validation of every revision")
    ap.add_argument("-j", "--jobs", type=int, default=1, help="balpipe history -j")
    args = ap.parse_args()

    tmp = Path(tempfile.mkdtemp(prefix="balpipe-history-bench-"))
    try:
        repo = tmp / "repo"
        (repo / "specs").mkdir(parents=True)
        git(repo, "init", "-q")
        texts = {n: (ROOT / "specs" / n).read_text() for n in args.specs}
        for k in range(args.commits):
            for n in args.specs:
                (repo / "specs" / n).write_text(vary(texts[n], n, k))
            git(repo, "add", "-A")
            git(repo, "commit", "-qm", f"revision {k + 1}")
        revisions = args.commits * len(args.specs)
        print(f"balpipe history: {len(args.specs)} specs x {args.commits} commits = {revisions} revisions, "
              f"{'with' if args.sim else 'without'} the simulation, -j {args.jobs}; python {sys.version.split()[0]}, "
              f"{os.cpu_count()} cores")
        rows = [("1. cold cache", *run_history(repo, args.sim, args.jobs)),
                ("2. same command again", *run_history(repo, args.sim, args.jobs))]
        for n in args.specs:
            (repo / "specs" / n).write_text(vary(texts[n], n, args.commits))
            break
        git(repo, "commit", "-qam", "one more")
        rows.append(("3. after one new commit", *run_history(repo, args.sim, args.jobs)))
        # the import cost alone, for reference: what a run that does nothing must pay
        imp = subprocess.run([sys.executable, "-c", "import time; t = time.perf_counter(); "
                              "import balpipe.build, balpipe.history; print(time.perf_counter() - t)"],
                             capture_output=True, text=True, check=True)
        width = max(len(r[0]) for r in rows)
        print(f"\n{'run'.ljust(width)}  {'wall (s)':>9}  {'CPU (s)':>8}  balpipe history's summary (time inside the run)")
        print("-" * (width + 100))
        for name, t, cpu, s in rows:
            print(f"{name.ljust(width)}  {t:9.2f}  {cpu:8.2f}  {s}")
        print(f"\nwarm / cold: wall {rows[1][1] / rows[0][1]:.3f}, CPU {rows[1][2] / rows[0][2]:.3f}; "
              f"importing balpipe.build and balpipe.history alone: {float(imp.stdout):.2f} s")
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    main()
