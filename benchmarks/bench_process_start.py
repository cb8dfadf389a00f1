"""What a build process pays once: the CPU of its first build of a spec less that of the same build
done again in the same process (imports, the templates' compilation, matplotlib's set-up).

Every worker of ``balpipe build -j N`` pays it, in parallel with the others: it adds to the wall
time of a build of ``specs/`` whole, where the work of the specs adds only a share. Each sample is
a new process of one of the given Python interpreters (a venv with balpipe installed: an install,
not a source tree, carries the compiled templates), which runs
``balpipe build SPEC --no-sim -j 1`` three times into new folders and prints the CPU seconds of
each; the interpreters alternate, so that they see the same load::

    python benchmarks/bench_process_start.py /venvs/new/bin/python /venvs/old/bin/python --repeat 5

Nothing is asserted: it prints each sample and the medians.
"""

from __future__ import annotations

import argparse
import json
import statistics
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]

#: one process: three builds of the same spec, the CPU seconds of each
DRIVER = """
import json, shutil, sys, tempfile, time
from balpipe.cli import main
spec, cpu = sys.argv[1], []
for _ in range(3):
    out = tempfile.mkdtemp(prefix="bench_start_")
    c = time.process_time()
    main(["build", spec, "-j", "1", "-q", "-o", out, "--no-sim"])
    cpu.append(time.process_time() - c)
    shutil.rmtree(out, ignore_errors=True)
print(json.dumps(cpu))
"""


def sample(python: str, spec: str) -> list[float]:
    out = subprocess.run([python, "-c", DRIVER, spec], capture_output=True, text=True, check=True, cwd=str(ROOT))
    return json.loads(out.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("pythons", nargs="+", help="Python interpreters with balpipe installed, alternated")
    ap.add_argument("--spec", default=str(ROOT / "specs" / "offset_slider_crank.yaml"))
    ap.add_argument("--repeat", type=int, default=3, help="processes per interpreter (default 3)")
    args = ap.parse_args(argv)
    rows: dict[str, list[list[float]]] = {p: [] for p in args.pythons}
    for _ in range(args.repeat):
        for p in args.pythons:
            cpu = sample(p, args.spec)
            rows[p].append(cpu)
            print(f"{p}: first {cpu[0]:.3f} s, then {cpu[1]:.3f} and {cpu[2]:.3f} s of CPU", flush=True)
    print(f"\nmedians of {args.repeat} processes, {Path(args.spec).name}, --no-sim")
    for p, cpus in rows.items():
        first = statistics.median(c[0] for c in cpus)
        again = statistics.median(min(c[1:]) for c in cpus)
        print(f"{p}: first build {first:.3f} s, again {again:.3f} s: {first - again:.3f} s paid once per process")
    return 0


if __name__ == "__main__":
    sys.exit(main())
