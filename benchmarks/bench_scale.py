"""Scale benchmark: ``balpipe check`` of ladders of N four-bar loops (:mod:`ladder`, 2 N + 1
bodies, one degree of freedom, ``force_balance``), ``balpipe build --no-sim`` of the 100-loop
ladder (201 bodies) and of a 10-loop ladder (21 bodies) analysed at 20,000 samples; against
another version in one alternated run (this, REV, this, REV, ...).

Every command runs in a fresh interpreter (``python -m balpipe ...`` through a small driver
that puts the version's own ``templates/`` beside its package). Per command and version the
table gives the least wall time, the least CPU time (user + system, of that child alone:
``os.wait4``'s ``resource`` usage, which a busy machine inflates less than the wall time) and
the largest peak memory (the child's ``ru_maxrss``) over the repeats; the ratio is this / REV
of the CPU times. ``--against REV`` checks REV out with ``git worktree add`` into a temporary
folder (removed after). The growth of ``check``'s CPU from 20 to 40 loops is printed as an
exponent (log(cpu_40 / cpu_20) / log 2). Nothing is asserted about speed.

    python benchmarks/bench_scale.py --against ab64d4b
    python benchmarks/bench_scale.py --loops 2 5 10 20 40 --no-build --repeat 3
    python benchmarks/bench_scale.py --against ab64d4b --loops --builds 20k --repeat 3

Ladders above ``--against-loops`` loops (default 40) are not run with REV, check or build (before
the block sampler, its dense SVDs of a 100-loop ladder's states would hold some 19 GB: the table
says "not run").
"""

from __future__ import annotations

import argparse
import math
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_build import SOURCE_TREE  # noqa: E402  (a version's balpipe with its own templates)
from ladder import ladder_spec  # noqa: E402

DRIVER = r'''
import sys
''' + SOURCE_TREE + r'''
import balpipe.cli as cli
try:
    rc = cli.main(sys.argv[1:])
except SystemExit as e:
    rc = e.code
sys.exit(rc or 0)
'''


def run(python: str, pipeline: Path, args: list[str]) -> tuple[float, float, float, int]:
    """(wall s, CPU s, peak MB, exit code) of balpipe ``args`` in a new process with
    ``pipeline`` first on the path."""
    env = dict(os.environ, PYTHONPATH=str(pipeline), PYTHONHASHSEED="0")
    env.pop("PYTHONDONTWRITEBYTECODE", None)
    with tempfile.TemporaryFile() as log:
        t0 = time.perf_counter()
        proc = subprocess.Popen([python, "-c", DRIVER, *args], env=env, stdout=log, stderr=log, cwd=str(pipeline.parent))
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.perf_counter() - t0
        proc.returncode = os.waitstatus_to_exitcode(status)
        if proc.returncode != 0:
            log.seek(0)
            sys.stderr.write(log.read().decode(errors="replace")[-2000:])
    return wall, usage.ru_utime + usage.ru_stime, usage.ru_maxrss / 1024.0, proc.returncode


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--against", metavar="REV", help="git revision to compare with, alternated in the same run")
    ap.add_argument("--loops", type=int, nargs="*", default=[2, 5, 10, 20, 40, 100],
                    help="ladders to check (none: no check)")
    ap.add_argument("--against-loops", type=int, default=40, help="the largest ladder REV checks")
    ap.add_argument("--no-build", action="store_true", help="check only (no builds)")
    ap.add_argument("--builds", nargs="+", choices=["100", "20k"], default=["100", "20k"],
                    help="which builds: the 100-loop ladder, the 10-loop one at 20,000 samples")
    ap.add_argument("--repeat", type=int, default=2, help="alternated runs of each command")
    ap.add_argument("--python", default=sys.executable)
    args = ap.parse_args(argv)
    versions = {"this": ROOT / "pipeline"}
    with tempfile.TemporaryDirectory(prefix="bench_scale_") as tmp:
        work = Path(tmp)
        tree = work / "against"
        if args.against:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), args.against],
                           check=True, capture_output=True)
            versions[args.against] = tree / "pipeline"
        try:
            cases: list[tuple[str, list[str], int]] = []  # label, balpipe args, ladder size (for REV's limit)
            for n in args.loops:
                f = work / f"ladder{n}.yaml"
                f.write_text(ladder_spec(n))
                cases.append((f"check, {n} loops ({2 * n + 1} bodies)", ["check", "-j", "1", str(f)], n))
            if not args.no_build and "100" in args.builds:
                f = work / "ladder100.yaml"
                f.write_text(ladder_spec(100))
                cases.append(("build --no-sim, 100 loops (201 bodies)", ["build", str(f), "--no-sim", "--force", "-j", "1",
                                                                          "-o", str(work / "out100")], 100))
            if not args.no_build and "20k" in args.builds:
                f = work / "ladder10_20k.yaml"
                f.write_text(ladder_spec(10, samples=20_000))
                cases.append(("build --no-sim, 10 loops, 20,000 samples", ["build", str(f), "--no-sim", "--force", "-j", "1",
                                                                            "-o", str(work / "out20k")], 10))
            for _, cmd, _ in cases[:1]:  # bytecode written once, outside the timings
                for pipeline in versions.values():
                    run(args.python, pipeline, cmd)
            best: dict[tuple[str, str], list[float]] = {}
            for _ in range(args.repeat):
                for label, cmd, n in cases:
                    for v, pipeline in versions.items():
                        if v != "this" and n > args.against_loops:
                            continue
                        wall, cpu, mb, rc = run(args.python, pipeline, cmd)
                        if rc != 0:
                            print(f"{label} [{v}]: exit {rc}", file=sys.stderr)
                        b = best.setdefault((label, v), [math.inf, math.inf, 0.0])
                        best[(label, v)] = [min(b[0], wall), min(b[1], cpu), max(b[2], mb)]
                    print(".", end="", file=sys.stderr, flush=True)
            print(file=sys.stderr)
        finally:
            if args.against:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)
    names = list(versions)
    head = "| command | " + " | ".join(f"{v}: wall / CPU / peak" for v in names)
    head += " | CPU this / " + names[1] + " |" if len(names) > 1 else " |"
    print(head)
    print("|" + " --- |" * (len(names) + 1 + (len(names) > 1)))
    for label, _, _ in cases:
        cells = []
        for v in names:
            r = best.get((label, v))
            cells.append("not run" if r is None else f"{r[0]:.2f} s / {r[1]:.2f} s / {r[2]:.0f} MB")
        ratio = ""
        if len(names) > 1:
            a, b = best.get((label, "this")), best.get((label, names[1]))
            ratio = f" | {a[1] / b[1]:.3f}" if a and b else " | -"
        print(f"| {label} | " + " | ".join(cells) + ratio + " |")
    for v in names:
        c20, c40 = best.get(("check, 20 loops (41 bodies)", v)), best.get(("check, 40 loops (81 bodies)", v))
        if c20 and c40:
            print(f"\n{v}: check CPU grows as N^{math.log(c40[1] / c20[1]) / math.log(2):.2f} from 20 to 40 loops")
    return 0


if __name__ == "__main__":
    sys.exit(main())
