"""The engine's general (dense) path on paper 001's 4-RRR (redundant actuation), this version
against REV in one alternated run (issue 43).

    python benchmarks/bench_dense.py --against ac36467
    python benchmarks/bench_dense.py --specs specs/paper001_4rrr.yaml --samples 1003 4001 --repeat 3

Per spec, version and number of samples, a fresh interpreter (the version's ``pipeline/`` first
on the path, one BLAS thread as ``balpipe`` runs its analyses) runs the spec's study, then
``balpipe.engine.analyse`` of its first stage on 5 fresh grids (N, N + 1, ... samples over the
motion: a geometry and grid first seen, its frame motion followed, factorised and screened), then
of its other stages on the same grids (placed in that motion). A repeated grid would be served by
the memo, hence the fresh ones. Printed: the median CPU time of each (``time.process_time``, ms)
and the least over the alternated runs. Nothing is asserted.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "benchmarks"))
from bench_build import SOURCE_TREE, versions as versions_of  # noqa: E402  (a version's balpipe with its own templates)

CHILD = SOURCE_TREE + r"""
import json, statistics, sys, time
import numpy as np
import balpipe
from balpipe.engine import analyse
spec, N = sys.argv[1], int(sys.argv[2])
stages = balpipe.run(balpipe.load(spec)).engine_study.stages
first, placed = [], []
for i in range(5):
    a = stages[0].analysis
    t = np.linspace(a.t[0], a.t[-1], N + i)
    c0 = time.process_time(); analyse(stages[0].stage.model, t, a.gravity, a.moment_point); first.append(time.process_time() - c0)
    for st in stages[1:]:
        c0 = time.process_time(); analyse(st.stage.model, t, a.gravity, a.moment_point); placed.append(time.process_time() - c0)
print(json.dumps({"first": statistics.median(first), "placed": statistics.median(placed) if placed else float("nan")}))
"""


def run(python: str, pipeline: Path, spec: str, N: int) -> dict:
    env = dict(os.environ, PYTHONPATH=str(pipeline), OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    out = subprocess.run([python, "-c", CHILD, spec, str(N)], env=env, cwd=ROOT, capture_output=True, text=True)
    if out.returncode != 0:
        sys.stderr.write(out.stderr[-2000:])
        return {}
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--against", metavar="REV", help="git revision to compare with, alternated in the same run")
    ap.add_argument("--specs", nargs="+", default=["specs/paper001_4rrr.yaml", "specs/paper001_4rrr_fig6b.yaml"])
    ap.add_argument("--samples", type=int, nargs="+", default=[1003, 4001])
    ap.add_argument("--repeat", type=int, default=3, help="alternated runs of each case")
    ap.add_argument("--python", default=sys.executable)
    args = ap.parse_args(argv)
    best: dict[tuple[str, int, str], dict] = {}
    with versions_of(args.against, "bench_dense_") as (versions, _):
        for _ in range(args.repeat):
            for spec in args.specs:
                for N in args.samples:
                    for v, pipeline in versions.items():
                        b = best.setdefault((spec, N, v), {})
                        for k, x in run(args.python, pipeline, spec, N).items():
                            b[k] = min(b.get(k, x), x)
                print(".", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
    heads = ["spec", "samples"] + [f"{v}: first seen / placed (ms)" for v in versions]
    print("| " + " | ".join(heads) + " |")
    print("|" + " --- |" * len(heads))
    for spec in args.specs:
        for N in args.samples:
            row = [Path(spec).stem, f"{N:,}"]
            for v in versions:
                b = best.get((spec, N, v), {})
                row.append(f"{1e3 * b['first']:.1f} / {1e3 * b['placed']:.1f}" if "first" in b else "failed")
            print("| " + " | ".join(row) + " |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
