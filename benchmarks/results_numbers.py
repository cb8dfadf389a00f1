"""Compare every number of the results.json files of two build folders, to a relative tolerance.

    python benchmarks/results_numbers.py DIR_A DIR_B [--rel 1e-9] [--abs 0] [--common]

For a change that should not move any result beyond round-off (a faster solver path, a cache):
build the same specs with both versions into DIR_A and DIR_B (``balpipe build spec.yaml -o DIR``),
then every results.json found under DIR_A is compared, at the same relative path under DIR_B,
number by number (recursively through objects and lists): |a - b| <= rel max(|a|, |b|).
Strings, booleans, keys and lengths must be equal. The fields that name the version or hash
the code, and the timing fields, are ignored (:data:`site_identity.IGNORED_KEYS`). Prints, per
file, how many numbers, how many bit-identical, the largest relative difference and every
difference beyond the tolerance; exits 1 when there is one (or a file is missing), else 0.

``--abs A`` also accepts |a - b| <= A (an absolute floor: a balanced stage's residual force of
1e-13 N is round-off whose relative change means nothing; the count of numbers accepted only by
the floor is printed). ``--common`` compares a version with an older one that wrote fewer fields:
keys present on one side only are counted and printed, not failures (lengths must still agree).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
from dataclasses import dataclass, field
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from site_identity import _scrub_json  # noqa: E402  (the same ignored fields as the site comparison)


@dataclass
class Comparison:
    numbers: int = 0
    identical: int = 0
    largest: float = 0.0
    floored: int = 0
    problems: list[str] = field(default_factory=list)
    one_sided: list[str] = field(default_factory=list)


def compare(a, b, rel: float, path: str = "", out: Comparison | None = None, *, floor: float = 0.0,
            common: bool = False) -> Comparison:
    """Walk ``a`` and ``b`` together; numbers within ``rel`` of each other (or within ``floor``
    absolutely), everything else equal; with ``common`` a key on one side only is listed in
    ``one_sided`` instead of ``problems``."""
    out = Comparison() if out is None else out
    if isinstance(a, dict) and isinstance(b, dict):
        if set(a) != set(b):
            (out.one_sided if common else out.problems).append(f"{path or '/'}: keys differ: {sorted(set(a) ^ set(b))}")
        for k in sorted(set(a) & set(b)):
            compare(a[k], b[k], rel, f"{path}/{k}", out, floor=floor, common=common)
    elif isinstance(a, list) and isinstance(b, list):
        if len(a) != len(b):
            out.problems.append(f"{path}: lengths {len(a)} and {len(b)}")
        for i, (x, y) in enumerate(zip(a, b)):
            compare(x, y, rel, f"{path}[{i}]", out, floor=floor, common=common)
    elif all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in (a, b)):
        out.numbers += 1
        if a == b or (isinstance(a, float) and isinstance(b, float) and math.isnan(a) and math.isnan(b)):
            out.identical += 1
            return out
        d = abs(a - b) / max(abs(a), abs(b))
        out.largest = max(out.largest, d)
        if not d <= rel and abs(a - b) <= floor:
            out.floored += 1
        elif not d <= rel:
            out.problems.append(f"{path}: {a!r} and {b!r} (relative {d:.3g})")
    elif a != b:
        out.problems.append(f"{path}: {str(a)[:60]!r} and {str(b)[:60]!r}")
    return out


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("a", type=Path)
    ap.add_argument("b", type=Path)
    ap.add_argument("--rel", type=float, default=1e-9, help="relative tolerance (default 1e-9)")
    ap.add_argument("--abs", type=float, default=0.0, dest="floor",
                    help="absolute floor: |a - b| below it is accepted whatever the relative difference (default 0)")
    ap.add_argument("--common", action="store_true",
                    help="compare the keys both sides have; list the others (an older version wrote fewer fields)")
    args = ap.parse_args(argv)
    files = sorted(args.a.rglob("results.json"))
    bad = 0 if files else 1
    for fa in files:
        rel = fa.relative_to(args.a)
        fb = args.b / rel
        if not fb.is_file():
            print(f"{rel}: missing in {args.b}")
            bad += 1
            continue
        load = lambda p: _scrub_json(json.loads(p.read_text(encoding="utf-8")), set())  # noqa: E731
        c = compare(load(fa), load(fb), args.rel, floor=args.floor, common=args.common)
        floored = f", {c.floored} only within the floor {args.floor:g}" if args.floor else ""
        print(f"{rel}: {c.numbers} numbers, {c.identical} bit-identical, largest relative difference "
              f"{c.largest:.3g}{floored}, {len(c.problems)} beyond {args.rel:g}")
        for p in c.problems[:20]:
            print(f"  {p}")
        if c.one_sided:
            print(f"  {len(c.one_sided)} objects with keys on one side only, e.g. {c.one_sided[0][:160]}")
        bad += bool(c.problems)
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main())
