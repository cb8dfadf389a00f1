"""Build benchmark: where the time of ``balpipe build`` goes, phase by phase, against another version.

Builds each spec cold (a fresh temporary output folder, one new Python process per spec and
version, ``-j 1``) and prints, per spec and in total, the wall-clock seconds of each phase:

    import        importing balpipe's command line and the modules of the phases below
    load          reading and checking the spec (``build.load``)
    balance       the balancing designs (``registry.balance_designs``)
    analyse       the stages' analyses (``study.run_stage_analyses``)
    validate      pymunk, prescribed motion (``validate``), one column per kind of run:
    torque        pymunk, torque-driven run (``torque_driven``)
    reactionless  pymunk, free-floating frame (``free_floating``)
    figures       the page's figures (``report.page.study_figures``)
    page          the rest of the page (``render_page`` less its figures)
    write         results, time series and writing the files
    other         the rest of ``build`` (checks, site index, schema)
    total         the build's wall time (process start to exit, imports included)

The phases are measured from outside: a small driver wraps those functions by name before it
calls the command line's ``main(["build", ...])``, so nothing in balpipe changes and any
revision can be measured the same way (a function it does not have counts under ``other``).
Times are exclusive (a phase nested in another is subtracted from it).

``--against REV`` checks REV out with ``git worktree add`` into a temporary folder and builds
the same specs with ``PYTHONPATH`` pointing at it, in the same run, spec by spec alternating
with this version, and prints the ratio this / REV of every phase. Run from the repository:

    python benchmarks/bench_build.py --specs scott_russell offset_slider_crank --against HEAD~3
    python benchmarks/bench_build.py --no-sim            # every spec of specs/, this version only
    python benchmarks/bench_build.py --cpu --specs scott_russell --against main   # CPU seconds (a busy machine)

``--warm`` times instead a rebuild of each spec whose text changed where nothing is computed
from it (a comment appended; issue 23's "one spec changed"): each spec is built once untimed
into its output folder from a copy of its folder, its copy changed, and built again, timed.
Where the figures, simulations and balancing searches are cached by content
(``balpipe.cache.figures``, ``balpipe.cache.simulation``, ``balpipe.cache.balance``) the second build
computes none of them. (The driver's wrappers carry the wrapped function's module and name, so
that a cache keys a wrapped function as itself: the simulations' cache refuses an unnamed
closure, and before this a warm build here ran every simulation again.)
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path
from typing import Iterator

ROOT = Path(__file__).resolve().parents[1]

#: (module, function, phase), wrapped in the build's process; the first phase wins when nested
WRAPS = [
    ("balpipe.build", "load", "load"),
    ("balpipe.registry", "balance_designs", "balance"),
    ("balpipe.study", "run_stage_analyses", "analyse"),
    ("balpipe.validation_stage", "validate", "validate"),
    ("balpipe.validation_stage", "torque_driven", "torque"),
    ("balpipe.validation_stage", "free_floating", "reactionless"),
    ("balpipe.report.page", "study_figures", "figures"),
    ("balpipe.build", "render_page", "page"),
    ("balpipe.build", "results_dict", "write"),
    ("balpipe.build", "timeseries_csv", "write"),
    ("balpipe.build", "_write_atomic_dir", "write"),
    ("balpipe.report.site", "write_site", "write"),
    ("balpipe.build", "schema", "write"),
]
PHASES = ["import", "load", "balance", "analyse", "validate", "torque", "reactionless", "figures", "page",
          "write", "other", "total"]

#: imports balpipe from a source tree on PYTHONPATH and uses that tree's templates/ folder
#: (beside pipeline/, installed as balpipe.templates), not another tree's that an install provides
#: (a revision's pages rendered with today's templates crash; a non-editable install has none of a
#: source tree's): the start of every benchmark's child process that runs a version's balpipe
SOURCE_TREE = r'''
import importlib.util as _util, os as _os, sys as _sys
import balpipe
_tpl = _os.path.join(_os.path.dirname(_os.path.dirname(_os.path.dirname(balpipe.__file__))), "templates")
_found = _util.find_spec("balpipe.templates")
_theirs = _found is None or _os.path.dirname(_os.path.realpath(_found.origin or "")) != _os.path.realpath(_tpl)
if _theirs and _os.path.isdir(_tpl):
    _s = _util.spec_from_file_location("balpipe.templates", _os.path.join(_tpl, "__init__.py"),
                                       submodule_search_locations=[_tpl])
    balpipe.templates = _sys.modules["balpipe.templates"] = _util.module_from_spec(_s)
    _s.loader.exec_module(balpipe.templates)
'''

@contextlib.contextmanager
def versions(against: str | None, prefix: str) -> Iterator[tuple[dict[str, Path], Path]]:
    """``({"this": <this tree's pipeline/>, REV: <REV's>}, a temporary folder)``: REV (``against``,
    when given) checked out with ``git worktree add --detach`` into that folder, removed with it on
    the way out, whatever happened; the benchmarks that compare a revision alternate their runs
    over these ``pipeline/`` folders (each run's child on PYTHONPATH, :data:`SOURCE_TREE`)."""
    found = {"this": ROOT / "pipeline"}
    with tempfile.TemporaryDirectory(prefix=prefix) as tmp:
        tree = Path(tmp) / "against"
        if against:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", str(tree), against],
                           check=True, capture_output=True)
            found[against] = tree / "pipeline"
        try:
            yield found, Path(tmp)
        finally:
            if against:
                subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], capture_output=True)


DRIVER = r'''
import functools, importlib, importlib.util, json, os, sys, time
clock = time.process_time if os.environ.get("BENCH_CLOCK") == "cpu" else time.perf_counter
t_start = clock()
''' + SOURCE_TREE + r'''
import balpipe.cli as cli
stack = []

def wrap(module, name, phase):
    try:
        mod = importlib.import_module(module)
        fn = getattr(mod, name)
    except (ImportError, AttributeError):
        return
    @functools.wraps(fn)  # fn's module and name: a content cache keys the wrapper as fn, not as a closure it refuses
    def timed(*a, **k):
        t0 = clock()
        stack.append(0.0)
        try:
            return fn(*a, **k)
        finally:
            inner = stack.pop()
            dt = clock() - t0
            times[phase] = times.get(phase, 0.0) + dt - inner
            if stack:
                stack[-1] += dt
    setattr(mod, name, timed)

for module, name, phase in json.loads(sys.argv[1]):
    wrap(module, name, phase)
times = {"import": clock() - t_start}
args = ["build", sys.argv[2], "-o", sys.argv[3], "-j", "1"] + sys.argv[4:]
try:
    rc = cli.main(args)
except SystemExit as e:
    rc = e.code
times["total"] = clock() - t_start
times["other"] = times["total"] - sum(v for k, v in times.items() if k != "total")
print("@@BENCH@@" + json.dumps({"rc": rc, "times": times}))
'''


def run_one(python: str, pipeline: Path, spec: Path, out: Path, extra: list[str], cpu: bool = False) -> dict:
    """Build one spec in a new process with ``pipeline`` first on the path; its phase times
    (``cpu``: the process's CPU seconds, its total from balpipe's import on)."""
    env = dict(os.environ, PYTHONPATH=str(pipeline), PYTHONHASHSEED="0", BENCH_CLOCK="cpu" if cpu else "wall")
    t0 = time.perf_counter()
    proc = subprocess.run([python, "-c", DRIVER, json.dumps(WRAPS), str(spec), str(out), *extra],
                          env=env, capture_output=True, text=True, cwd=str(pipeline.parent))
    wall = time.perf_counter() - t0
    for line in proc.stdout.splitlines():
        if line.startswith("@@BENCH@@"):
            res = json.loads(line[len("@@BENCH@@"):])
            if cpu:
                return res
            res["times"]["total"] = wall  # the process's wall time, interpreter start included
            res["times"]["other"] = wall - sum(res["times"].get(p, 0.0) for p in PHASES if p not in ("total", "other"))
            return res
    raise RuntimeError(f"{spec} did not build:\n{proc.stdout[-2000:]}\n{proc.stderr[-4000:]}")


WARM_EDIT = "\n# bench_build --warm: the text changed, nothing computed from it did\n"


def warm_one(python: str, pipeline: Path, spec: Path, out: Path, extra: list[str], work: Path,
             cpu: bool = False) -> dict:
    """:func:`run_one` of a rebuild: ``spec``'s folder copied to ``work`` (its tables with it),
    built once into ``out`` (untimed), the copy's text changed by a comment, built again (timed)."""
    shutil.copytree(spec.parent, work)
    copy = work / spec.name
    run_one(python, pipeline, copy, out, extra, cpu)
    copy.write_text(copy.read_text(encoding="utf-8") + WARM_EDIT, encoding="utf-8")
    return run_one(python, pipeline, copy, out, extra, cpu)


def resolve_specs(names: list[str] | None, root: Path) -> list[Path]:
    if not names:
        return sorted((root / "specs").glob("*.yaml"))
    out = []
    for n in names:
        p = Path(n)
        if not p.suffix:
            p = root / "specs" / f"{n}.yaml"
        out.append(p.resolve())
    return out


def table(results: dict[str, dict[str, dict]], versions: list[str]) -> str:
    """Per spec and in total: each phase's seconds per version, and this / other."""
    lines = []
    head = f"{'spec':34s} {'phase':13s}" + "".join(f"{v[:12]:>13s}" for v in versions)
    if len(versions) == 2:
        head += f"{'ratio':>9s}"
    lines.append(head)
    totals = {v: dict.fromkeys(PHASES, 0.0) for v in versions}
    for spec, per in list(results.items()) + [("TOTAL", None)]:
        for ph in PHASES:
            vals = []
            for v in versions:
                x = (per[v]["times"].get(ph, 0.0) if per else totals[v][ph])
                if per:
                    totals[v][ph] += x
                vals.append(x)
            if max(vals) < 5e-4 and ph not in ("total",):
                continue
            row = f"{spec[:34]:34s} {ph:13s}" + "".join(f"{x:13.3f}" for x in vals)
            if len(vals) == 2:
                row += f"{(vals[0] / vals[1] if vals[1] > 0 else float('nan')):9.3f}"
            lines.append(row)
        if per:
            lines.append(f"{'':34s} {'status':13s}" + "".join(f"{str(per[v]['rc']):>13s}" for v in versions))
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--specs", nargs="*", help="spec names (in specs/) or paths; default: all of specs/")
    ap.add_argument("--against", metavar="REV", help="git revision to compare with (built in the same run)")
    ap.add_argument("--no-sim", action="store_true", help="build without the pymunk validation")
    ap.add_argument("--python", default=sys.executable, help="interpreter to build with (default: this one)")
    ap.add_argument("--json", metavar="FILE", help="also write the raw times to FILE")
    ap.add_argument("--warm", action="store_true",
                    help="time a rebuild after a change of each spec's text that nothing is computed from (a comment)")
    ap.add_argument("--cpu", action="store_true",
                    help="CPU seconds of the build's process instead of wall-clock seconds (a machine shared with "
                         "other work; the build runs with -j 1, so its simulations run in that process)")
    args = ap.parse_args(argv)
    specs = resolve_specs(args.specs, ROOT)
    extra = ["--no-sim"] if args.no_sim else []
    versions = {"this": ROOT / "pipeline"}
    tmp = Path(tempfile.mkdtemp(prefix="bench_build_"))
    tree = None
    try:
        if args.against:
            tree = tmp / "against"
            subprocess.run(["git", "-C", str(ROOT), "worktree", "add", "--detach", "-q", str(tree), args.against],
                           check=True)
            versions[args.against] = tree / "pipeline"
        results: dict[str, dict[str, dict]] = {}
        for spec in specs:
            results[spec.stem] = {}
            for v, pipeline in versions.items():  # alternate, so that the machine's load hits both alike
                out = tmp / f"site-{len(results)}-{v.replace('/', '_')}"
                if args.warm:
                    work = tmp / f"specs-{len(results)}-{v.replace('/', '_')}"
                    results[spec.stem][v] = warm_one(args.python, pipeline, spec, out, extra, work, args.cpu)
                else:
                    results[spec.stem][v] = run_one(args.python, pipeline, spec, out, extra, args.cpu)
                print(f"  {spec.stem} [{v}] {results[spec.stem][v]['times']['total']:.2f} s", file=sys.stderr)
        print(table(results, list(versions)))
        if args.json:
            Path(args.json).write_text(json.dumps(results, indent=2, sort_keys=True) + "\n")
    finally:
        if tree is not None:
            subprocess.run(["git", "-C", str(ROOT), "worktree", "remove", "--force", str(tree)], check=False)
        subprocess.run(["rm", "-rf", str(tmp)], check=False)
    return 0


if __name__ == "__main__":
    sys.exit(main())
