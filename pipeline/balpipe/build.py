"""Build the report site: every spec -> its page, results.json and CSV, then the index.

A spec is rebuilt only when its text, the build options or balpipe's own code changed (the
input hash is stored in results.json). Each page is written to a temporary folder and moved into
place only when complete, so a failing spec never damages a page built before.

The output folder is the only place written: files are created fresh (never opened through a
symlink planted in the folder; a planted link is replaced, its target untouched), the index and
schema are replaced atomically, a lock file serialises concurrent builds of the same folder,
and files and folders get the modes the umask gives (a web server can read the site).
"""

from __future__ import annotations

import hashlib
import json
import os
import sys
import time
import traceback
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import resources
from importlib.util import find_spec
from pathlib import Path

from . import plugins, runner
from .laws.drives import table_texts
from .loader import LoadedSpec, SpecErrors, load, load_text, schema
from .report import history_page
from .report.page import render_page
from .report.results import dumps, results_dict, timeseries_csv
from . import pool
from .fsutil import remove_path, remove_temporaries, tmp_name, write_atomic_dir, write_file_atomic, write_new
from .site_earlier import earlier_pages
from .spec_files import MAX_SLUG, clash_notes, clashes, find_specs, slug_for  # noqa: F401  (build.find_specs, build.slug_for as before)
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
    kept_previous: bool = False  # failed its checks: the earlier good page stays, this build is in failed/


@dataclass(frozen=True)
class Options:
    out: Path
    simulate: bool = True
    force: bool = False
    sim_workers: int = 1  # processes for one spec's simulations (cores left over by fewer specs than cores)


class SchedulerError(Exception):
    """``--scheduler``: the cluster cannot be reached, or its workers run another balpipe."""


class OutputError(Exception):
    """The output folder cannot be used (a file, not writable): nothing was written."""


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
    for name, f in _family_files():  # families from packages of their own: their code is part of the result
        h.update(name.encode())
        h.update(f.read_bytes())
    return h.hexdigest()


def _family_files() -> list[tuple[str, Path]]:
    """(name, path) of the Python files of the discovered families that are not part of balpipe:
    a package's files by their path in it, a single module by its file name."""
    out = set()
    for fam in plugins.discover():
        top = (fam.package or "").split(".")[0]
        spec = find_spec(top) if top and top != "balpipe" else None
        if spec is None or not spec.origin:
            continue
        origin = Path(spec.origin)
        if spec.submodule_search_locations:
            out.update((f.relative_to(origin.parent.parent).as_posix(), f) for f in origin.parent.rglob("*.py"))
        else:
            out.add((origin.name, origin))
    return sorted(out)


def input_hash(text: str, opts: Options) -> str:
    h = hashlib.sha256()
    h.update(text.encode())
    h.update(f"sim={opts.simulate}".encode())
    h.update(code_hash().encode())
    return h.hexdigest()[:16]


@dataclass(frozen=True)
class Job:
    """One spec to compute, as read by the process that writes the site: the spec's text and
    what its page folder holds that the page shows (the history), so that the computation
    itself reads and writes nothing of the site and can run on another machine."""

    path: Path
    text: str
    input_hash: str
    simulate: bool
    history: dict | None
    history_files: dict[str, str]
    sim_workers: int = 1  # the stages' simulations in that many processes (the same results)


@dataclass
class Computed:
    """What :func:`compute` made of a :class:`Job`: the page's files and the study's status, or
    the spec's located errors, or an internal error with its traceback."""

    status: str  # "ok", "failed", "error", "crash"
    message: str = ""
    results: dict | None = None
    files: dict[str, str] | None = None
    seconds: float = 0.0


def page_hash(loaded: LoadedSpec, target: Path, simulate: bool) -> str:
    """The input hash of a spec's page in ``target``: the spec's text and the CSV tables it reads,
    the simulation option, balpipe's code, and the page's history (a new history.json re-renders
    the page)."""
    h = input_hash(loaded.text + table_texts(loaded.spec), Options(out=target.parent, simulate=simulate))
    return history_page.mix_hash(h, target)


def plan_one(path: Path, opts: Options) -> Job | Outcome:
    """Read one spec and decide: an :class:`Outcome` when there is nothing to compute (invalid,
    or unchanged since the last build), else the :class:`Job` that computes it."""
    start = time.perf_counter()
    slug = slug_for(path)
    try:
        loaded = load(path)
    except SpecErrors as exc:
        return Outcome(str(path), slug, "error", str(exc), spec_error=True, seconds=time.perf_counter() - start)
    target = opts.out / slug
    h = page_hash(loaded, target, opts.simulate)
    if not opts.force:
        previous = _read_results(target)
        if previous is not None and previous.get("input_hash") == h:
            stale_failed = target / "failed"
            if stale_failed.exists() or stale_failed.is_symlink():  # the spec is back to its good page
                remove_path(stale_failed)
            return Outcome(str(path), slug, previous.get("status", "ok"), "unchanged", previous, skipped=True,
                           seconds=time.perf_counter() - start)
    return Job(path, loaded.text, h, opts.simulate, history_page.section(target), history_page.build_files(target),
               opts.sim_workers)


def compute(job: Job) -> Computed:
    """Balance, analyse, validate and render one spec; never raises (errors become the result)."""
    start = time.perf_counter()
    source = str(job.path)
    loaded = None
    try:
        spec, node = load_text(job.text, source)
        loaded = LoadedSpec(job.path, job.text, spec, node)
        st = runner.analyse(loaded, simulate=job.simulate)
        extra: dict[str, str] = {}
        if job.simulate and runner.simulate(loaded, st, workers=job.sim_workers):
            from .validation_stage import timing, timing_script

            times = timing(st)
            extra = {"timing.json": json.dumps(times, indent=2, sort_keys=True) + "\n",
                     "timing.js": timing_script(times)}
        results = results_dict(st, source, job.input_hash, simulated=st.stages[0].validation is not None)
        files = {
            "index.html": render_page(st, results, job.text, history=job.history),
            "results.json": dumps(results),
            "timeseries.csv": timeseries_csv(st),
            **extra,
            **job.history_files,
        }
        return Computed("ok" if st.ok else "failed", "; ".join(st.problems), results, files,
                        time.perf_counter() - start)
    except SpecErrors as exc:
        return Computed("error", str(exc), seconds=time.perf_counter() - start)
    except SpecFieldError as exc:
        message = str(loaded.error(exc)) if loaded is not None else f"{source}: {exc}"
        return Computed("error", message, seconds=time.perf_counter() - start)
    except Exception as exc:  # a bug in balpipe: keep going, report it with its traceback
        tb = traceback.format_exc(limit=6)
        return Computed("crash", f"{source}: internal error: {exc!r}\n{tb}", seconds=time.perf_counter() - start)


def finish(job: Job, done: Computed, opts: Options) -> Outcome:
    """Write what :func:`compute` made into the site: the page folder, replaced whole; a build
    that fails its checks after a good one goes beside it, in ``failed/``."""
    source, slug = str(job.path), slug_for(job.path)
    if done.status in ("error", "crash"):
        return Outcome(source, slug, done.status, done.message, spec_error=done.status == "error", seconds=done.seconds)
    target = opts.out / slug
    previous = _read_results(target) if not target.is_symlink() else None
    if done.status == "failed" and previous is not None and previous.get("status") == "ok":
        # the README's promise: a failing spec never replaces a good page; its own page goes
        # beside it, in failed/
        write_atomic_dir(target / "failed", done.files)
        return Outcome(source, slug, done.status, done.message, done.results, seconds=done.seconds, kept_previous=True)
    write_atomic_dir(target, done.files)
    return Outcome(source, slug, done.status, done.message, done.results, seconds=done.seconds)


def build_one(path: Path, opts: Options) -> Outcome:
    """Build one spec in this process (:func:`plan_one`, :func:`compute`, :func:`finish`);
    never raises (errors become the outcome)."""
    start = time.perf_counter()
    job = plan_one(path, opts)
    if isinstance(job, Outcome):
        return job
    out = finish(job, compute(job), opts)
    out.seconds = time.perf_counter() - start
    return out


def _read_results(folder: Path) -> dict | None:
    try:
        data = json.loads((folder / "results.json").read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None
    return data if isinstance(data, dict) else None


def prepare_output(out: Path) -> None:
    """Create the output folder and make sure it can be written, before any work: raises
    :class:`OutputError` (nothing written) for a path that is a file or a folder that cannot be
    written."""
    if out.exists() and not out.is_dir():
        raise OutputError(f"the output path {out} is a file, not a folder; choose another -o")
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise OutputError(f"cannot create the output folder {out}: {exc.strerror or exc}") from None
    probe = out / tmp_name("probe")
    try:
        write_new(probe, "")
        probe.unlink()
    except OSError as exc:
        raise OutputError(f"cannot write to the output folder {out}: {exc.strerror or exc}; "
                          "the site there was left as it was") from None


LOCK_NAME = ".balpipe.lock"


@contextmanager
def locked(out: Path):
    """Hold an exclusive lock on ``out/.balpipe.lock`` for the build: a second build of the same
    folder waits, so pages and the index of two builds never interleave. The lock file is removed
    when the build ends, so it is never published with the site; a build that waited on a removed
    file locks the current one instead."""
    try:
        import fcntl
    except ImportError:  # pragma: no cover - not POSIX
        yield
        return
    lock = out / LOCK_NAME
    while True:
        fd = os.open(lock, os.O_RDWR | os.O_CREAT | getattr(os, "O_NOFOLLOW", 0), 0o666)
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            import sys

            print(f"balpipe: waiting for another build of {out} to finish", file=sys.stderr)
            fcntl.flock(fd, fcntl.LOCK_EX)
        try:
            current = os.stat(lock, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
        except FileNotFoundError:
            current = False
        if current:
            break
        os.close(fd)
    try:
        yield
    finally:
        try:
            os.unlink(lock)
        except OSError:
            pass
        os.close(fd)


def build(paths: list[str], opts: Options, jobs: int | None = None, progress=None,
          scheduler: str | None = None) -> list[Outcome]:
    """Build every spec (in parallel with ``jobs`` > 1; default, None: :func:`default_jobs`,
    one process per usable core, at most one per spec; 1: one after another in this process),
    then the site index and schema. The pages, the index and the order of the outcomes (and of
    the ``progress`` calls: the specs' order) do not depend on ``jobs``. With ``scheduler`` (the
    address of a dask.distributed scheduler) the specs are computed on that cluster's workers and
    written here: the same site byte for byte (:func:`compute` reads and writes nothing of the site).

    Raises :class:`OutputError` before any work when the output folder cannot be used. On
    KeyboardInterrupt (Ctrl-C, or SIGTERM turned into one by the CLI) the workers are stopped,
    temporaries removed and the exception re-raised; the index is not rewritten, so the previous
    site stays whole."""
    problems: list[str] = []
    specs = find_specs(paths, problems)
    outcomes: list[Outcome] = [Outcome(msg.split(":", 1)[0], "", "error", msg, spec_error=True) for msg in problems]
    clash = clashes(specs)
    todo: list[Path] = []
    for p in specs:
        if p in clash:
            outcomes.append(Outcome(str(p), slug_for(p), "error", clash[p], spec_error=True))
        else:
            todo.append(p)
    prepare_output(opts.out)
    if progress:
        for o in outcomes:  # refused before any work: k = 0
            progress(0, len(todo), o)
        for p, note in clash_notes(specs).items():  # said before any work too; built as usual
            progress(0, len(todo), Outcome(str(p), slug_for(p), "ok", note))
    cores = jobs if jobs is not None else pool.usable_cores()
    if jobs is None:
        jobs = pool.default_jobs(len(todo))
    if todo and not scheduler and cores > len(todo):  # fewer specs than cores: their stages share the rest
        opts = replace(opts, sim_workers=cores // len(todo))
    with locked(opts.out):
        remove_temporaries(opts.out)
        try:
            if scheduler:
                _run_on_cluster(scheduler, todo, opts, progress, outcomes)
            else:
                _run(todo, opts, jobs, progress, outcomes)
        except BaseException:
            remove_temporaries(opts.out)
            raise
        from .report.site import write_site

        built = [o for o in outcomes if o.slug]
        write_site(opts.out, built, earlier_pages(opts.out, {o.slug for o in built}, page_hash))
        write_file_atomic(opts.out / "balpipe.schema.json", json.dumps(schema(), indent=2, sort_keys=True) + "\n")
    return outcomes


def _run(todo: list[Path], opts: Options, jobs: int, progress, outcomes: list[Outcome]) -> None:
    total = len(todo)
    for k, o in enumerate(pool.in_order(build_one, todo, jobs, opts)):
        outcomes.append(o)
        if progress:
            progress(k + 1, total, o)


def _installed_code_hash() -> str:
    """:func:`code_hash` of the balpipe installed where this runs (sent to workers by name)."""
    return sys.modules[__name__].code_hash()


def _run_on_cluster(address: str, todo: list[Path], opts: Options, progress, outcomes: list[Outcome]) -> None:
    """Plan every spec here, compute the jobs on the dask.distributed cluster at ``address`` (all
    submitted at once, so every worker is busy), write each result here in the specs' order."""
    try:
        from distributed import Client
    except ImportError:
        raise SchedulerError("--scheduler needs dask.distributed (pip install 'balpipe[sweep]')") from None
    try:
        client = Client(address, timeout="20s")
    except (OSError, TimeoutError, ValueError) as exc:
        raise SchedulerError(f"cannot reach the dask scheduler at {address}: {exc}") from None
    with client:
        ours = code_hash()
        theirs = client.run(_installed_code_hash)
        other = sorted(w for w, h in theirs.items() if h != ours)
        if other:
            raise SchedulerError(f"the workers {', '.join(other)} run another balpipe than this one (its code hash "
                                 f"differs): install the same version on every worker")
        plans = [plan_one(p, opts) for p in todo]
        futures = {k: client.submit(compute, job, pure=False) for k, job in enumerate(plans) if isinstance(job, Job)}
        total = len(todo)
        for k, job in enumerate(plans):
            o = job if isinstance(job, Outcome) else finish(job, futures[k].result(), opts)
            outcomes.append(o)
            if progress:
                progress(k + 1, total, o)
