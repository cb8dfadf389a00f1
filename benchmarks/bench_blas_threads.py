"""BLAS threads and balpipe's small-matrix linear algebra, run by hand:
``python benchmarks/bench_blas_threads.py``. Prints, asserts nothing.

balpipe sets OPENBLAS_NUM_THREADS / OMP_NUM_THREADS / MKL_NUM_THREADS to 1 unless the user set
them (``balpipe/__init__.py``). This measures why, each case in a fresh process with the variables
set explicitly: (1) a batched SVD of 328 Jacobians of 72 x 75 (the regressor's state sampler on a
25-body model), (2) the condition finder on paper 001's 4-RRR (``conditions.find``, best of 3).
CPU and wall seconds; on a machine shared with other jobs the threaded wall times are the ones
that suffer.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
CASE = r'''
import time, numpy as np
from balpipe import registry
from balpipe.balancing import conditions as C
from balpipe.families.rrr4 import counter_masses as recipe
from balpipe.loader import load_text
a = np.random.default_rng(0).normal(size=(328, 72, 75))
c0, w0 = time.process_time(), time.perf_counter(); np.linalg.svd(a)
print(f"batched SVD 328 x (72 x 75): cpu {time.process_time() - c0:.2f} s, wall {time.perf_counter() - w0:.2f} s")
spec, _ = load_text(open("specs/paper001_4rrr.yaml").read(), "specs/paper001_4rrr.yaml")
model = registry.unbalanced_model(spec)
best = None
for _ in range(3):
    c0, w0 = time.process_time(), time.perf_counter(); C.find(model, recipe.finder_grid(model))
    w = time.perf_counter() - w0; best = w if best is None else min(best, w)
print(f"finder on the 4-RRR: best wall {best * 1e3:.1f} ms")
'''


def main() -> None:
    for threads in ("1", str(os.cpu_count() or 2)):
        env = dict(os.environ, OPENBLAS_NUM_THREADS=threads, OMP_NUM_THREADS=threads, MKL_NUM_THREADS=threads)
        out = subprocess.run([sys.executable, "-c", CASE], cwd=ROOT, env=env, capture_output=True, text=True)
        print(f"-- BLAS threads {threads} (load average {os.getloadavg()[0]:.1f})")
        print(out.stdout.strip())
        if out.returncode:
            print(out.stderr.strip())


if __name__ == "__main__":
    main()
