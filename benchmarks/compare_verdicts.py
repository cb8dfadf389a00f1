"""Compare the simulation verdicts of two builds: every stage's validation, torque-driven run and
reactionless demonstration, spec by spec.

    python benchmarks/compare_verdicts.py DIR_A DIR_B

For a change to the validation's cost (shorter or fewer runs, another step): the same specs built
by both versions into DIR_A and DIR_B (``balpipe build specs -o DIR --force``). For every
results.json under DIR_A (and the one at the same place under DIR_B) it compares

* exactly: the build's ``status`` and ``unconfirmed`` list, and per stage and kind of run the
  verdict fields ``status``, ``passed``, ``reasons`` and ``remedy`` (the reactionless runs:
  their ``method``), and which stages have which runs;
* as numbers: every other number of those runs, printing the largest relative change per field
  (residuals, tracking errors, steps and solver iterations move when the runs change).

Exits 1 when a verdict differs (or a file or run is missing on one side), else 0.
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path

KINDS = ("validation", "torque_driven", "reactionless")
VERDICT = ("status", "passed", "reasons", "remedy", "method")


def _numbers(x, prefix: str = ""):
    if isinstance(x, bool) or x is None or isinstance(x, str):
        return
    if isinstance(x, (int, float)):
        yield prefix, float(x)
    elif isinstance(x, dict):
        for k, v in x.items():
            yield from _numbers(v, f"{prefix}.{k}" if prefix else k)
    elif isinstance(x, list):
        for i, v in enumerate(x):
            yield from _numbers(v, f"{prefix}[{i}]")


def _rel(a: float, b: float) -> float:
    if a == b or (math.isnan(a) and math.isnan(b)):
        return 0.0
    if not (math.isfinite(a) and math.isfinite(b)):
        return math.inf
    return abs(a - b) / max(abs(a), abs(b))


def compare(a_dir: Path, b_dir: Path) -> int:
    bad = 0
    changes: dict[str, tuple[float, str]] = {}
    files = sorted(a_dir.glob("*/results.json"))
    for fa in files:
        fb = b_dir / fa.parent.name / "results.json"
        spec = fa.parent.name
        if not fb.is_file():
            print(f"{spec}: missing in {b_dir}")
            bad += 1
            continue
        ra, rb = json.loads(fa.read_text()), json.loads(fb.read_text())
        for key in ("status", "unconfirmed"):
            if ra.get(key) != rb.get(key):
                print(f"{spec}: {key} {ra.get(key)!r} != {rb.get(key)!r}")
                bad += 1
        for kind in KINDS:
            ka, kb = ra.get(kind) or {}, rb.get(kind) or {}
            if set(ka) != set(kb):
                print(f"{spec}: {kind} stages {sorted(ka)} != {sorted(kb)}")
                bad += 1
            for stage in sorted(set(ka) & set(kb)):
                sa, sb = ka[stage], kb[stage]
                for f in VERDICT:
                    if sa.get(f) != sb.get(f):
                        print(f"{spec}/{stage} {kind}.{f}: {sa.get(f)!r} != {sb.get(f)!r}")
                        bad += 1
                na, nb = dict(_numbers(sa)), dict(_numbers(sb))
                for name in sorted(set(na) & set(nb)):
                    r = _rel(na[name], nb[name])
                    field = f"{kind}.{name}"
                    if r > changes.get(field, (0.0, ""))[0]:
                        changes[field] = (r, f"{spec}/{stage}: {na[name]:.4g} -> {nb[name]:.4g}")
    print(f"{len(files)} results compared; verdict differences: {bad}")
    if changes:
        print("largest relative change of the runs' numbers, per field:")
        for field, (r, where) in sorted(changes.items(), key=lambda kv: -kv[1][0]):
            print(f"  {field:45s} {r:9.2e}  {where}")
    return 1 if bad else 0


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path)
    ap.add_argument("b", type=Path)
    a = ap.parse_args(argv)
    return compare(a.a, a.b)


if __name__ == "__main__":
    sys.exit(main())
