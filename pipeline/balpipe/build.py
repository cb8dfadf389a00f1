"""Build the report site: every spec -> its page, results.json and CSV, then the index.

A spec is rebuilt only when its text, the build options or balpipe's own code changed (the
input hash is stored in results.json). Each page is written to a temporary folder and moved into
place only when complete, so a failing spec never damages a page built before.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
import time
import traceback
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

from . import study as study_mod
from .loader import SpecErrors, load, schema
from .report import history_page
from .report.page import render_page
from .report.results import dumps, results_dict, timeseries_csv
from .spec_parts import SpecFieldError


@dataclass
class Outcome:
    """What happened to one spec in a build."""

    source: str
    slug: str
    status: str  # "ok", "failed" (built, checks fail), "error" (invalid spec), "crash", "skipped"
    message: str = ""
    results: dict | None = None
    seconds: float = 0.0
    spec_error: bool = False
    skipped: bool = False


@dataclass(frozen=True)
class Options:
    out: Path
    simulate: bool = True
    force: bool = False


def find_specs(paths: list[str]) -> list[Path]:
    """Spec files named on the command line or found (*.yaml, *.yml) in named folders, sorted."""
    found: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            found += sorted(q for q in p.rglob("*") if q.suffix in (".yaml", ".yml") and q.is_file())
        else:
            found.append(p)
    seen, unique = set(), []
    for f in found:
        key = f.resolve()
        if key not in seen:
            seen.add(key)
            unique.append(f)
    return unique


def slug_for(path: Path) -> str:
    return "".join(c if c.isalnum() or c in "-_" else "-" for c in path.stem)


@lru_cache(maxsize=1)
def code_hash() -> str:
    """Hash of balpipe's own code and templates: a new version rebuilds everything."""
    h = hashlib.sha256()
    pkg = resources.files("balpipe")
    files = sorted(Path(str(pkg)).rglob("*.py"))
    tpl = Path(str(resources.files("balpipe.templates")))
    files += sorted(p for p in tpl.iterdir() if p.suffix in (".html", ".css", ".js"))
    for f in files:
        h.update(f.name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def input_hash(text: str, opts: Options) -> str:
    h = hashlib.sha256()
    h.update(text.encode())
    h.update(f"sim={opts.simulate}".encode())
    h.update(code_hash().encode())
    return h.hexdigest()[:16]


def _write_atomic_dir(target: Path, files: dict[str, str]) -> None:
    target.parent.mkdir(parents=True, exist_ok=True)
    tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.", dir=target.parent))
    try:
        for name, content in files.items():
            (tmp / name).write_text(content, encoding="utf-8")
        old = None
        if target.exists():
            old = target.with_name(f".{target.name}.old-{os.getpid()}")
            target.rename(old)
        tmp.rename(target)
        if old is not None:
            shutil.rmtree(old, ignore_errors=True)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise


def build_one(path: Path, opts: Options) -> Outcome:
    """Build one spec; never raises (errors become the outcome)."""
    start = time.perf_counter()
    slug = slug_for(path)
    source = str(path)
    try:
        loaded = load(path)
    except SpecErrors as exc:
        return Outcome(source, slug, "error", str(exc), spec_error=True, seconds=time.perf_counter() - start)
    h = input_hash(loaded.text, opts)
    target = opts.out / slug
    h = history_page.mix_hash(h, target)  # a new history.json re-renders the page
    if not opts.force:
        previous = _read_results(target)
        if previous is not None and previous.get("input_hash") == h:
            return Outcome(source, slug, previous.get("status", "ok"), "unchanged", previous, skipped=True,
                           seconds=time.perf_counter() - start)
    try:
        st = study_mod.run(loaded.spec)
        extra: dict[str, str] = {}
        if opts.simulate and loaded.spec.validation.enabled:
            from .validation_stage import simulate_study, timing, timing_script

            simulate_study(st)
            times = timing(st)
            extra = {"timing.json": json.dumps(times, indent=2, sort_keys=True) + "\n",
                     "timing.js": timing_script(times)}
        results = results_dict(st, source, h, simulated=st.stages[0].validation is not None)
        page = render_page(st, results, loaded.text, history=history_page.section(target))
        _write_atomic_dir(target, {
            "index.html": page,
            "results.json": dumps(results),
            "timeseries.csv": timeseries_csv(st),
            **extra,
            **history_page.build_files(target),
        })
        status = "ok" if st.ok else "failed"
        return Outcome(source, slug, status, "; ".join(st.problems), results, seconds=time.perf_counter() - start)
    except SpecFieldError as exc:
        return Outcome(source, slug, "error", str(loaded.error(exc)), spec_error=True, seconds=time.perf_counter() - start)
    except Exception as exc:  # a bug in balpipe: keep going, report it with its traceback
        tb = traceback.format_exc(limit=6)
        return Outcome(source, slug, "crash", f"{source}: internal error: {exc!r}\n{tb}", seconds=time.perf_counter() - start)


def _read_results(folder: Path) -> dict | None:
    try:
        return json.loads((folder / "results.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


def build(paths: list[str], opts: Options, jobs: int = 1, progress=None) -> list[Outcome]:
    """Build every spec (in parallel with ``jobs`` > 1), then the site index and schema."""
    specs = find_specs(paths)
    slugs: dict[str, Path] = {}
    outcomes: list[Outcome] = []
    todo: list[Path] = []
    for p in specs:
        s = slug_for(p)
        if s in slugs:
            outcomes.append(Outcome(str(p), s, "error", f"{p}: same page name as {slugs[s]}; rename one", spec_error=True))
            continue
        slugs[s] = p
        todo.append(p)
    opts.out.mkdir(parents=True, exist_ok=True)
    total = len(todo)
    if jobs > 1 and total > 1:
        with ProcessPoolExecutor(max_workers=jobs) as pool:
            futures = [pool.submit(build_one, p, opts) for p in todo]
            for k, f in enumerate(futures):
                o = f.result()
                outcomes.append(o)
                if progress:
                    progress(k + 1, total, o)
    else:
        for k, p in enumerate(todo):
            o = build_one(p, opts)
            outcomes.append(o)
            if progress:
                progress(k + 1, total, o)
    from .report.site import write_site

    write_site(opts.out, outcomes)
    (opts.out / "balpipe.schema.json").write_text(json.dumps(schema(), indent=2, sort_keys=True) + "\n", encoding="utf-8")
    return outcomes
