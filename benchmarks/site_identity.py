"""Build specs/ at two git revisions into two folders and compare the sites file by file.

    python benchmarks/site_identity.py [--a 934af79] [--b HEAD] [--no-sim] [-j 2] [--out DIR]

Each revision is exported with ``git archive`` (its templates/ copied into the package, as an
install does) and built with this Python, ``PYTHONPATH`` pointing at the export; the working tree
and other checkouts are not touched. Fields that name the version or hash the code
(``balpipe_version``, ``input_hash``, ``code_hash``, and the index's site key, which hashes
the code) and the timing files and fields are ignored, in JSON by key and in other text files by
value. Prints every other difference and exits
1 when there is one, 0 when the sites are the same.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
IGNORED_KEYS = {"balpipe_version", "input_hash", "code_hash", "timing", "seconds", "elapsed"}
IGNORED_FILES = {"timing.json", "timing.js", ".balpipe.lock"}
IGNORED_DIRS = {".cache"}  # the build's figure cache (balpipe.cache.figures), not part of the site
# the index's site key hashes the code (balpipe.build.site_key starts from code_hash)
SITE_KEY = re.compile(rb'(<meta name="balpipe-site-key" content=")[0-9a-f]*(")')


def export(rev: str, into: Path) -> Path:
    into.mkdir(parents=True)
    archive = subprocess.run(["git", "archive", rev], cwd=ROOT, capture_output=True, check=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    tpl = into / "pipeline" / "balpipe" / "templates"
    if not tpl.exists():
        shutil.copytree(into / "templates", tpl)
    return into


def build(tree: Path, out: Path, simulate: bool, jobs: int) -> subprocess.CompletedProcess:
    env = dict(os.environ, PYTHONPATH=str(tree / "pipeline"))
    args = [sys.executable, "-m", "balpipe", "build", "specs", "-o", str(out), "-j", str(jobs), "-q"]
    if not simulate:
        args.append("--no-sim")
    return subprocess.run(args, cwd=tree, env=env, capture_output=True, text=True)


def _scrub_json(obj, values: set):
    if isinstance(obj, dict):
        out = {}
        for k, v in obj.items():
            if k in IGNORED_KEYS:
                if isinstance(v, str):
                    values.add(v)
                continue
            out[k] = _scrub_json(v, values)
        return out
    if isinstance(obj, list):
        return [_scrub_json(v, values) for v in obj]
    return obj


def snapshot(out: Path) -> tuple[dict[str, object], set[str]]:
    files: dict[str, object] = {}
    values: set[str] = set()
    for p in sorted(out.rglob("*")):
        rel = p.relative_to(out).as_posix()
        if not p.is_file() or p.name in IGNORED_FILES or rel.split("/")[0] in IGNORED_DIRS:
            continue
        if p.suffix == ".json":
            files[rel] = _scrub_json(json.loads(p.read_text(encoding="utf-8")), values)
        else:
            files[rel] = p.read_bytes()
    return files, values


def compare(a: Path, b: Path) -> list[str]:
    fa, va = snapshot(a)
    fb, vb = snapshot(b)
    ignored = sorted(v for v in (va | vb) if len(v) >= 6)
    pattern = re.compile("|".join(re.escape(v) for v in ignored).encode()) if ignored else None
    problems = [f"only in A: {n}" for n in sorted(set(fa) - set(fb))]
    problems += [f"only in B: {n}" for n in sorted(set(fb) - set(fa))]
    for name in sorted(set(fa) & set(fb)):
        x, y = fa[name], fb[name]
        if isinstance(x, bytes) and isinstance(y, bytes):
            x, y = SITE_KEY.sub(rb"\1<ignored>\2", x), SITE_KEY.sub(rb"\1<ignored>\2", y)
            if pattern is not None:
                x, y = pattern.sub(b"<ignored>", x), pattern.sub(b"<ignored>", y)
        if x != y:
            problems.append(f"differs: {name}")
    return problems


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--a", default="934af79", help="first revision (default: 934af79, main before issue 19)")
    ap.add_argument("--b", default="HEAD", help="second revision (default: HEAD)")
    ap.add_argument("--no-sim", action="store_true", help="build without the pymunk validation")
    ap.add_argument("-j", "--jobs", type=int, default=2)
    ap.add_argument("--out", help="keep the exports and sites here (default: a temporary folder, removed)")
    args = ap.parse_args(argv)
    base = Path(args.out) if args.out else Path(tempfile.mkdtemp(prefix="site-identity-"))
    try:
        sites = []
        for tag, rev in (("a", args.a), ("b", args.b)):
            tree = export(rev, base / f"tree-{tag}")
            out = base / f"site-{tag}"
            r = build(tree, out, not args.no_sim, args.jobs)
            print(f"{tag}: {rev}: build exit {r.returncode}; {r.stderr.strip().splitlines()[-1] if r.stderr.strip() else ''}")
            sites.append(out)
        problems = compare(*sites)
        for p in problems:
            print(p)
        n = sum(1 for p in sites[0].rglob("*") if p.is_file() and p.relative_to(sites[0]).parts[0] not in IGNORED_DIRS)
        print(f"{'identical' if not problems else f'{len(problems)} differences'} ({n} files in A; ignored: "
              f"{', '.join(sorted(IGNORED_KEYS))}, {', '.join(sorted(IGNORED_FILES))})")
        return 1 if problems else 0
    finally:
        if not args.out:
            shutil.rmtree(base, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
