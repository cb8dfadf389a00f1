"""Command benchmark: ``balpipe --help``, ``balpipe check`` of one spec and of a folder, against
another version (issue 23's targets: 0.2 s, 0.5 s and 5 s on 2 cores).

Each command runs ``--repeat`` times in a fresh interpreter (``python -m balpipe``), the versions
alternating so that the machine's load hits both alike; the table gives the least wall time and
the least CPU time (user + system of the process and its workers, which a busy machine inflates
less) and the largest peak memory (``ru_maxrss`` of the process or its largest worker, from
``os.wait4``). ``--against REV`` exports REV's ``pipeline/`` (``git archive``) into a temporary folder
and runs it with ``PYTHONPATH`` pointing there (bytecode written, as for an installed package).

    python benchmarks/bench_check.py --against HEAD~5
    python benchmarks/bench_check.py --one specs/paper004_five_bar.yaml --repeat 3
"""

from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def timed(python: str, pipeline: Path, args: list[str]) -> tuple[float, float, int, float]:
    """(wall s, CPU s of the process and its children, exit code, peak MB) of ``python -m
    balpipe ARGS``."""
    env = {**os.environ, "PYTHONPATH": str(pipeline)}
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    t0 = time.perf_counter()
    proc = subprocess.Popen([python, "-m", "balpipe", *args], cwd=ROOT, env=env, stdout=subprocess.DEVNULL,
                            stderr=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    return wall, usage.ru_utime + usage.ru_stime, os.waitstatus_to_exitcode(status), usage.ru_maxrss / 1024.0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--against", metavar="REV", help="git revision to compare with (run in the same loop)")
    ap.add_argument("--one", default="specs/scott_russell.yaml", help="the single spec to check")
    ap.add_argument("--folder", default="specs/", help="the folder to check")
    ap.add_argument("--repeat", type=int, default=5, help="runs of --help and of the single check (folder: 2)")
    ap.add_argument("--python", default=sys.executable, help="interpreter (default: this one)")
    args = ap.parse_args(argv)
    commands = {"--help": (["--help"], args.repeat), f"check {args.one}": (["check", args.one], args.repeat),
                f"check {args.folder}": (["check", args.folder], 2)}
    versions = {"this": ROOT / "pipeline"}
    with tempfile.TemporaryDirectory(prefix="bench_check_") as tmp:
        if args.against:
            archive = subprocess.run(["git", "-C", str(ROOT), "archive", args.against, "pipeline"], check=True,
                                     capture_output=True).stdout
            subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
            versions[args.against] = Path(tmp) / "pipeline"
        for pipeline in versions.values():  # bytecode written once, outside the timings
            timed(args.python, pipeline, ["check", args.one])
        print(f"{'command':34s}" + "".join(f"{v + ' wall':>14s}{v + ' cpu':>14s}{v + ' peak':>14s}" for v in versions))
        for label, (cmd, n) in commands.items():
            best = {v: [float("inf"), float("inf"), 0.0] for v in versions}
            for _ in range(n):
                for v, pipeline in versions.items():
                    wall, cpu, rc, peak = timed(args.python, pipeline, cmd)
                    if rc != 0:
                        print(f"{label} [{v}]: exit {rc}", file=sys.stderr)
                    best[v] = [min(best[v][0], wall), min(best[v][1], cpu), max(best[v][2], peak)]
            print(f"{label:34s}" + "".join(f"{best[v][0]:13.2f}s{best[v][1]:13.3f}s{best[v][2]:11.0f} MB"
                                           for v in versions))
    return 0


if __name__ == "__main__":
    sys.exit(main())
