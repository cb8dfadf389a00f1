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
import re
import sys
import time
import traceback
from contextlib import contextmanager
from dataclasses import dataclass, replace
from functools import lru_cache
from importlib import resources
from importlib.util import find_spec
from pathlib import Path
from typing import Any

from . import FAMILY_GROUP
from .runtime import pool
from .report import history_file
from .runtime.inputs import MAX_TABLE_BYTES, InputFileError, read_input_text
from .runtime.fsutil import LeftBehind, describe, remove_path, remove_temporaries, tmp_name, write_atomic_dir, write_file_atomic, write_new
from .site_files.site_earlier import earlier_pages
from .site_files.spec_files import MAX_SLUG, clash_notes, clashes, find_specs, published_names, slug_for  # noqa: F401  (build.find_specs, build.slug_for as before)

# The phases' modules (numpy, pydantic, matplotlib, jinja2) are imported when a spec is computed,
# not when an unchanged site is checked (a rebuild with nothing changed takes 0.3 s). The
# names below stay this module's, so that a caller (the build benchmark) can wrap them.


def load(path, name=None):
    """:func:`balpipe.loader.load`."""
    from .loader import load as f
    return f(path, name)


def schema() -> dict:
    """:func:`balpipe.loader.schema`."""
    from .loader import schema as f
    return f()


def schema_text() -> str:
    """The site's ``balpipe.schema.json``: :func:`schema` as indented JSON, keys sorted."""
    return json.dumps(schema(), indent=2, sort_keys=True) + "\n"


def render_page(*args, **kwargs) -> str:
    """:func:`balpipe.report.page.render_page`."""
    from .report.page import render_page as f
    return f(*args, **kwargs)


def results_dict(*args, **kwargs) -> dict:
    """:func:`balpipe.report.results.results_dict`."""
    from .report.results import results_dict as f
    return f(*args, **kwargs)


def timeseries_file(*args, **kwargs) -> Any:
    """:func:`balpipe.report.results.timeseries_file` (written by pieces)."""
    from .report.results import timeseries_file as f
    return f(*args, **kwargs)


def dumps(results: dict) -> str:
    """:func:`balpipe.report.results.dumps`."""
    from .report.results import dumps as f
    return f(results)


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
    #: the published name of each spec path (:func:`published_names`); others as if their folder had been given
    names: tuple[tuple[Path, str], ...] = ()
    #: when the build started (``time.time()``, set by :func:`build`): with ``force``, a cache entry
    #: written since then was computed by this build and is used (the same simulation in two specs
    #: runs once; :attr:`balpipe.cache.content.Store.fresh_since`)
    started: float | None = None

    def name(self, path: Path) -> str:
        """How published files and messages name the spec ``path``: never a path of the machine.
        A path the command line did not name (a caller in Python) is named as if its folder had
        been given (:func:`published_names`)."""
        known = dict(self.names).get(path)
        return known if known is not None else published_names([str(path.parent)], [path])[path]


class SchedulerError(Exception):
    """``--scheduler``: the cluster cannot be reached, or its workers run another balpipe."""


class OutputError(Exception):
    """The output folder cannot be used (a file, not writable): nothing was written; or, found at
    the end (a full disk), the index could not be written: the pages built are in place, the index
    is the previous build's."""


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
    """(name, path) of the Python files of the families installed from packages other than
    balpipe: the package that each ``balpipe.families`` entry point names, a package's files by
    their path in it, a single module by its file name. Read from the entry points' metadata,
    without importing a family (an unchanged site is checked without numpy or pydantic); the
    families of the in-tree scan are balpipe's own files."""
    from importlib.metadata import entry_points

    out = set()
    for ep in entry_points(group=FAMILY_GROUP):
        top = ep.module.split(".")[0]
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
    #: the output folder whose caches the figures are drawn through (draw/cache.py:
    #: <out>/.cache/figures/<slug>/), the simulations run through (sim_cache.py:
    #: <out>/.cache/sims/<slug>/) and the balancing's searches computed through
    #: (balance_cache.py: <out>/.cache/balance/<slug>/); None (a dask worker, which has no
    #: access to it): all computed
    figure_cache: Path | None = None
    redraw: bool = False  # --force: every figure drawn, simulation run and search computed, its cache entry rewritten
    #: with ``redraw``: entries written since this time (this build's) are used all the same
    fresh_since: float | None = None
    figure_keys: frozenset[str] = frozenset()  # the cache entries the planning used (history figures): kept
    source: str = ""  # the spec's published name (Options.name), "" for str(path)


@dataclass
class Computed:
    """What :func:`compute` made of a :class:`Job`: the page's files and the study's status, or
    the spec's located errors, or an internal error with its traceback."""

    status: str  # "ok", "failed", "error", "crash"
    message: str = ""
    results: dict | None = None
    files: dict[str, Any] | None = None  # text, bytes, or content written by pieces (fsutil.Streamed)
    seconds: float = 0.0


def page_hash(loaded, target: Path, simulate: bool) -> str:
    """The input hash of a spec's page in ``target`` (``loaded``: a :class:`balpipe.loader.LoadedSpec`):
    the spec's text and the CSV tables it reads, the simulation option, balpipe's code, and the
    page's history (a new history.json re-renders the page)."""
    from .laws.drives import table_texts

    return _mixed_hash(loaded.text + table_texts(loaded.spec), target, simulate)


def _mixed_hash(inputs: str, target: Path, simulate: bool) -> str:
    return history_file.mix_hash(input_hash(inputs, Options(out=target.parent, simulate=simulate)), target)


def _unchanged(path: Path | str, slug: str, target: Path, previous: dict, seconds: float) -> Outcome:
    stale_failed = target / "failed"
    if stale_failed.exists() or stale_failed.is_symlink():  # the spec is back to its good page
        remove_path(stale_failed)
    return Outcome(str(path), slug, previous.get("status", "ok"), "unchanged", previous, skipped=True,
                   seconds=seconds)


def up_to_date(path: Path, opts: Options) -> dict | None:
    """The results of the spec's page when the page is up to date, decided without reading the
    spec's YAML (nothing is written). The page's ``results.json`` names the tables the spec read
    (``input_tables``, as written in the spec, relative to its folder), so the input hash of
    :func:`page_hash` is recomputed from the spec's text and those tables' texts: that list is the
    one the same text gives, and the text is part of the hash, so a match is exact. Anything else
    (no page, a changed spec or table, an unreadable file) gives None, and the spec is planned in
    full (:func:`plan_one`)."""
    if opts.force:
        return None
    target = opts.out / slug_for(path)
    previous = _read_results(target)
    if previous is None or not previous.get("input_hash"):
        return None
    try:
        text = path.read_text(encoding="utf-8")
        tables = "".join(f"\0table {f}\0" + read_input_text(path.parent, f, MAX_TABLE_BYTES, "table")
                         for f in previous.get("input_tables") or [])
    except (OSError, UnicodeDecodeError, TypeError, InputFileError):
        return None
    return previous if _mixed_hash(text + tables, target, opts.simulate) == previous["input_hash"] else None


def plan_one(path: Path, opts: Options, figure_cache: bool = True) -> Job | Outcome:
    """Read one spec and decide: an :class:`Outcome` when there is nothing to compute (invalid,
    or unchanged since the last build), else the :class:`Job` that computes it. The history
    figures of the page (drawn here, where the page folder is read) and, with ``figure_cache``,
    the job's figures go through the output folder's figure cache (:mod:`balpipe.cache.figures`)."""
    return _plan(path, opts, figure_cache)[0]


def _plan(path: Path, opts: Options, figure_cache: bool = True) -> tuple[Job | Outcome, Any]:
    """:func:`plan_one`, and the spec it loaded (a :class:`balpipe.loader.LoadedSpec` of the
    job's text; None with an outcome): what :func:`compute` would load again in this process."""
    from .loader import SpecErrors

    start = time.perf_counter()
    slug = slug_for(path)
    try:
        loaded = load(path, opts.name(path))
    except SpecErrors as exc:
        return Outcome(opts.name(path), slug, "error", str(exc), spec_error=True,
                       seconds=time.perf_counter() - start), None
    target = opts.out / slug
    h = page_hash(loaded, target, opts.simulate)
    if not opts.force:
        previous = _read_results(target)
        if previous is not None and previous.get("input_hash") == h:
            return _unchanged(opts.name(path), slug, target, previous, time.perf_counter() - start), None
    from .cache import figures as cache
    from .report import history_page

    store = cache.Store(opts.out, slug, code_hash(), reuse=not opts.force) if figure_cache else None
    from .draw import live

    with cache.using(store), live.collecting() as figure_files:  # the history figures' data files too
        history, files = history_page.section(target), history_page.build_files(target)
    files = {**files, **figure_files}
    return Job(path, loaded.text, h, opts.simulate, history, files, opts.sim_workers, source=opts.name(path),
               figure_cache=opts.out if figure_cache else None, redraw=opts.force,
               fresh_since=opts.started if opts.force else None,
               figure_keys=frozenset(store.used) if store is not None else frozenset()), loaded


def compute(job: Job, loaded: Any = None) -> Computed:
    """Balance, analyse, validate and render one spec; never raises (errors become the result).
    With ``job.figure_cache``, the figures, the simulations and the balancing's searches come
    from that folder's caches where their inputs are unchanged (:mod:`balpipe.cache.figures`,
    :mod:`balpipe.cache.simulation`, :mod:`balpipe.cache.balance`), and the spec's entries this build
    did not use are removed when its page is made. ``loaded``: the spec as :func:`plan_one` loaded
    it in this process (:func:`_plan`, a :class:`balpipe.loader.LoadedSpec`), used when it holds
    the job's text under the job's name instead of loading that text again (the same spec);
    None: loaded from ``job.text``."""
    from .cache import balance as balance_cache, simulation as sim_cache
    from .cache import figures as cache

    slug = slug_for(job.path)
    store = None if job.figure_cache is None else \
        cache.Store(job.figure_cache, slug, code_hash(), reuse=not job.redraw, used=set(job.figure_keys),
                    fresh_since=job.fresh_since)
    sims = None if job.figure_cache is None or not job.simulate else \
        sim_cache.Store(job.figure_cache, slug, code_hash(), reuse=not job.redraw, fresh_since=job.fresh_since)
    searches = None if job.figure_cache is None else \
        balance_cache.Store(job.figure_cache, slug, code_hash(), reuse=not job.redraw, fresh_since=job.fresh_since)
    with cache.using(store), sim_cache.using(sims):
        done = _compute(job, balance_cache.Memo(searches), loaded)
    if done.status in ("ok", "failed"):
        for used in (store, sims, searches):
            if used is not None:
                used.prune()
    return done


def _compute(job: Job, memo: Any = None, planned: Any = None) -> Computed:
    """:func:`compute` without the caches' set-up; the balancing's searches through ``memo``
    (a :class:`balpipe.cache.balance.Memo`; default: computed, no cache); the spec ``planned``
    (:func:`compute`'s ``loaded``) where it holds the job's text and name."""
    from .loader import LoadedSpec, SpecErrors, load_text
    from .spec_parts import SpecFieldError

    start = time.perf_counter()
    source = job.source or str(job.path)
    loaded = None
    try:
        if planned is not None and planned.text == job.text and planned.path == job.path and planned.name == source:
            loaded = planned
        else:
            spec, node = load_text(job.text, source, job.path.parent)
            loaded = LoadedSpec(job.path, job.text, spec, node, source)
        st = study_of(loaded, job.simulate, job.sim_workers, memo)
        results = page_results(loaded, st, job.input_hash)
        files = page_files(loaded, st, results, job.history, job.history_files)
        return Computed("ok" if st.ok else "failed", "; ".join(st.problems), results, files,
                        time.perf_counter() - start)
    except SpecErrors as exc:
        return Computed("error", str(exc), seconds=time.perf_counter() - start)
    except SpecFieldError as exc:
        message = str(loaded.error(exc)) if loaded is not None else f"{source}: {exc}"
        return Computed("error", message, seconds=time.perf_counter() - start)
    except Exception as exc:  # a bug in balpipe: keep going, report it with its traceback
        tb = _TB_FILE.sub(lambda m: f'File "{_code_file(m.group(1))}"', traceback.format_exc(limit=6))
        return Computed("crash", f"{source}: internal error: {exc!r}\n{tb}", seconds=time.perf_counter() - start)


_TB_FILE = re.compile(r'File "([^"\n]+)"')


def _code_file(path: str) -> str:
    """A traceback's file as the index may show it: from the package folder on
    (``balpipe/engine/x.py``, ``numpy/linalg/y.py``), never the machine's path to it."""
    parts = Path(path).parts
    for k in range(len(parts) - 2, -1, -1):
        if parts[k] in ("site-packages", "dist-packages", "pipeline", "lib-dynload") or parts[k].startswith("python3"):
            return "/".join(parts[k + 1:])
    return parts[-1] if parts else path


def study_of(loaded, simulate: bool, workers: int = 1, memo: Any = None):
    """The study of a loaded spec (:class:`balpipe.loader.LoadedSpec`) as a page shows it:
    :func:`balpipe.runner.analyse` (the balancing's searches through ``memo``, a
    :class:`balpipe.cache.balance.Memo`; default: computed, no cache), then with ``simulate`` the
    pymunk validation of every stage (:func:`balpipe.runner.simulate`, its stages in ``workers``
    processes). ``balpipe build`` and :func:`balpipe.run` both compute their studies here;
    raises the loader's ``SpecErrors``."""
    from . import runner
    from .balancing.context import compute as no_cache

    with pool.spare_workers(workers):  # the cores left over also serve the spec's independent work
        st = runner.analyse(loaded, simulate=simulate, memo=memo if memo is not None else no_cache)
    if simulate:
        runner.simulate(loaded, st, workers=workers)
    return st


def page_results(loaded, st, input_hash: str) -> dict:
    """The study's ``results.json`` as a dict (:func:`balpipe.report.results.results_dict`), with
    the tables the spec read (``input_tables``, what :func:`up_to_date` reads to recompute the
    input hash)."""
    from .laws.drives import table_files

    results = results_dict(st, loaded.name or str(loaded.path), input_hash,
                           simulated=st.stages[0].validation is not None)
    if table_files(loaded.spec):
        results["input_tables"] = table_files(loaded.spec)
    return results


def page_files(loaded, st, results: dict, history: dict | None = None,
               history_files: dict[str, str] | None = None) -> dict[str, Any]:
    """The files of a study's page folder, by name: ``index.html`` (the page, with the spec's
    text and its ``history``), ``results.json`` (``results``), ``timeseries.csv`` (written by
    pieces: :class:`balpipe.report.results.CsvFile`), each interactive figure's data
    (``figure-<name>.csv``, :func:`balpipe.draw.live.collecting`), with parts the bill of materials
    (``parts.csv``) and each part's drawings (``part-*.dxf``, ``part-*.svg``), with the
    simulation the wall times of its runs (``timing.json``, ``timing.js``), and the history's
    files. ``balpipe build`` and :meth:`balpipe.Study.write` both write these."""
    extra: dict[str, str] = {}
    if st.stages[0].validation is not None:
        from .validation_stage import timing, timing_script

        times = timing(st)
        extra = {"timing.json": json.dumps(times, indent=2, sort_keys=True) + "\n",
                 "timing.js": timing_script(times)}
    if results.get("parts"):  # the bill of materials and a drawing per part (docs/parts.md)
        from .report.part_drawings import drawing_files
        from .report.parts_table import bom_csv

        extra.update({"parts.csv": bom_csv(results["parts"]), **drawing_files(st)})
    from .draw import live

    with live.collecting() as figure_files:  # each interactive figure's data, linked under it
        page = render_page(st, results, loaded.text, history=history)
    return {
        "index.html": page,
        **figure_files,
        "results.json": dumps(results),
        "timeseries.csv": timeseries_file(st),
        **extra,
        **(history_files or {}),
    }


def finish(job: Job, done: Computed, opts: Options) -> Outcome:
    """Write what :func:`compute` made into the site: the page folder, replaced whole; a build
    that fails its checks after a good one goes beside it, in ``failed/``."""
    source, slug = job.source or str(job.path), slug_for(job.path)
    if done.status in ("error", "crash"):
        return Outcome(source, slug, done.status, done.message, spec_error=done.status == "error", seconds=done.seconds)
    target = opts.out / slug
    previous = _read_results(target) if not target.is_symlink() else None
    keep = done.status == "failed" and previous is not None and previous.get("status") == "ok"
    # the README's promise: a failing spec never replaces a good page; its own page goes beside
    # it, in failed/
    folder = f"{slug}/failed/" if keep else f"{slug}/"
    try:
        write_atomic_dir(target / "failed" if keep else target, done.files)
    except LeftBehind as exc:
        return Outcome(source, slug, "failed", f"{source}: its page {folder} was written, but the earlier copy "
                       f"{Path(exc.filename).name} beside it could not be removed ({describe(exc, '')}); "
                       "remove it by hand",
                       done.results, seconds=done.seconds, kept_previous=keep)
    except OSError as exc:
        return Outcome(source, slug, "failed", f"{source}: its page {folder} was not written ({describe(exc, '')}); "
                       "its earlier page, if any, is as it was", seconds=done.seconds)
    return Outcome(source, slug, done.status, done.message, done.results, seconds=done.seconds, kept_previous=keep)


def build_one(path: Path, opts: Options) -> Outcome:
    """Build one spec in this process (:func:`plan_one`, :func:`compute`, :func:`finish`);
    never raises (errors become the outcome)."""
    start = time.perf_counter()
    job, loaded = _plan(path, opts)
    if isinstance(job, Outcome):
        return job
    out = finish(job, compute(job, loaded), opts)
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
    opts = replace(opts, names=tuple(published_names(paths, specs).items()),
                   started=opts.started if opts.started is not None else time.time())
    outcomes: list[Outcome] = [Outcome(msg.split(":", 1)[0], "", "error", msg, spec_error=True) for msg in problems]
    clash = clashes(specs, opts.name)
    todo: list[Path] = []
    for p in specs:
        if p in clash:
            outcomes.append(Outcome(opts.name(p), slug_for(p), "error", clash[p], spec_error=True))
        else:
            todo.append(p)
    prepare_output(opts.out)
    if progress:
        for o in outcomes:  # refused before any work: k = 0
            progress(0, len(todo), o)
        for p, note in clash_notes(specs, opts.name).items():  # said before any work too; built as usual
            progress(0, len(todo), Outcome(opts.name(p), slug_for(p), "ok", note))
    cores = jobs if jobs is not None else pool.usable_cores()
    changed = len(todo) if scheduler else sum(up_to_date(p, opts) is None for p in todo)
    if jobs is None:
        jobs = pool.default_jobs(changed)
    if changed and not scheduler and cores > changed:  # fewer specs to compute than cores: their stages share the rest
        opts = replace(opts, sim_workers=cores // changed)
    with locked(opts.out):
        remove_temporaries(opts.out)
        try:
            text = None  # the schema, when a worker made it (:data:`SCHEMA_TASK`)
            if scheduler:
                _run_on_cluster(scheduler, todo, opts, progress, outcomes)
            else:
                text = _run(todo, opts, jobs, progress, outcomes)
        except BaseException:
            remove_temporaries(opts.out)
            raise
        built = [o for o in outcomes if o.slug]
        if any(not o.skipped for o in built):  # the caches of specs that have no page any more
            from .cache import content as content_cache
            from .cache.balance import BALANCE
            from .cache.figures import FIGURES
            from .cache.simulation import SIMS

            for kind in (FIGURES, SIMS, BALANCE):
                content_cache.prune_specs(opts.out, {o.slug for o in built}, kind)
        earlier = earlier_pages(opts.out, {o.slug for o in built}, page_hash)
        key = site_key(opts.out, built) if not earlier else ""
        if not (key and _site_is_current(opts.out, key)):
            from .report.site import write_site

            try:
                write_site(opts.out, built, earlier, site_key=key)
                write_file_atomic(opts.out / "balpipe.schema.json", text if text is not None else schema_text())
            except OSError as exc:
                remove_temporaries(opts.out)
                raise OutputError(f"the site's index was not written ({describe(exc, opts.out)}); the pages built are "
                                  "in place, the index is the previous build's") from None
    return outcomes


SITE_FILES = ("index.html", "site_nav.js", "balpipe.schema.json")
_KEY_META = re.compile(r'<meta name="balpipe-site-key" content="([0-9a-f]{64})">')


def site_key(out: Path, outcomes: list[Outcome]) -> str:
    """A hash of everything the site index and the schema are made of when the index lists only
    this build's ``outcomes``: balpipe's code, each outcome as the index reads it (its message
    only where the index shows it: an invalid, crashed or failed spec), and the files of each page
    folder that the index reads (``results.json``, the history) or links to (the page, the
    history page, ``failed/``). A build whose key equals the one in the index's head leaves the
    index, its script and the schema as they are (nothing they show changed)."""
    h = hashlib.sha256(code_hash().encode())
    for o in sorted(outcomes, key=lambda o: (o.source, o.slug)):
        shown = o.message if o.status != "ok" else ""
        h.update(json.dumps([o.source, o.slug, o.status, shown, o.spec_error, o.kept_previous]).encode())
        folder = out / o.slug
        for name in ("results.json", history_file.HISTORY_FILE):
            try:
                h.update(b"\0" + name.encode() + b"\0" + (folder / name).read_bytes())
            except OSError:
                h.update(b"\0" + name.encode() + b"\0-")
        for name in ("index.html", history_file.HISTORY_PAGE, "failed"):
            h.update(b"\1" if (folder / name).exists() else b"\2")
    return h.hexdigest()


def _site_is_current(out: Path, key: str) -> bool:
    """Whether the site in ``out`` was written with ``key`` and has all its files."""
    if not all((out / name).is_file() for name in SITE_FILES):
        return False
    try:
        with open(out / "index.html", encoding="utf-8") as f:
            head = f.read(4096)
    except (OSError, UnicodeDecodeError):
        return False
    m = _KEY_META.search(head)
    return m is not None and m.group(1) == key


#: the process pool's last task, after every spec: the schema's text (:func:`schema_text`), made by
#: the first worker left without a spec while another builds its last, not by this process once
#: they are all done (0.3 s of CPU, which a build of specs/ on two processes waited for at its end)
SCHEMA_TASK = "balpipe.schema.json"


def build_or_schema(item: Path | str, opts: Options) -> Outcome | str:
    """A pool task of :func:`_run`: :func:`build_one` of a spec, or the schema's text for :data:`SCHEMA_TASK`."""
    return schema_text() if item == SCHEMA_TASK else build_one(Path(item), opts)


def _run(todo: list[Path], opts: Options, jobs: int, progress, outcomes: list[Outcome]) -> str | None:
    """Build ``todo`` in its order: the specs whose pages are up to date are told here at once
    (:func:`up_to_date`), the others go to the process pool, and the outcomes come back in
    the specs' order whatever ``jobs``. With a pool (``jobs`` > 1, more than one spec to
    build), its last task makes the site's schema: returned (else None)."""
    total = len(todo)
    known: dict[Path, tuple[dict | None, float]] = {}
    for p in todo:
        start = time.perf_counter()
        known[p] = (up_to_date(p, opts), time.perf_counter() - start)
    rest: list[Path | str] = [p for p in todo if known[p][0] is None]
    pooled = jobs > 1 and len(rest) > 1
    tasks = rest + [SCHEMA_TASK] if pooled else rest
    cost = {p: spec_cost(p, opts.simulate) for p in rest}
    text = None
    with pool.finished(pool.in_order(build_or_schema, tasks, jobs, opts, cost=lambda p: cost.get(p, -1.0))) as built:
        for k, p in enumerate(todo):
            previous, seconds = known[p]
            o = next(built) if previous is None else _unchanged(opts.name(p), slug_for(p), opts.out / slug_for(p),
                                                                previous, seconds)
            outcomes.append(o)
            if progress:
                progress(k + 1, total, o)
        if pooled:
            text = next(built)
    return text


def spec_cost(path: Path, simulate: bool = True) -> float:
    """A spec's expected build work, to start the longest first (:func:`balpipe.runtime.pool.in_order`):
    the length of its text, which grows with its stages, comparisons and references (measured on
    specs/, 24 specs, 2 processes: 86.2 s for the longest texts first against 92.2 s in name
    order and 85.7 s for the true longest-first order). Without the simulation the balancing and
    the figures weigh more: a second per 5000 characters, plus the ``build_cost`` its template and
    method declare (:func:`balpipe.site_files.check_cost.declared_cost`); by the text alone the four 4-RRR
    specs (2-3 s each, short texts) started 14th to 18th of 24, and one core ran the last of them
    alone for 1.4 s (--no-sim 11.7 s; 11.0 s in the order by the true times)."""
    try:
        size = float(path.stat().st_size)
    except OSError:
        return 0.0
    if simulate:
        return size
    from .site_files.check_cost import declared_cost

    return size / 5000.0 + declared_cost(path, "build_cost")


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
    from .runtime.cluster import unreachable

    why = unreachable(address)
    if why is not None:
        raise SchedulerError(f"cannot reach the dask scheduler at {address}: {why}")
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
        plans = [plan_one(p, opts, figure_cache=False) for p in todo]  # the workers cannot reach the figure cache
        futures = {k: client.submit(compute, job, pure=False) for k, job in enumerate(plans) if isinstance(job, Job)}
        total = len(todo)
        for k, job in enumerate(plans):
            o = job if isinstance(job, Outcome) else finish(job, futures[k].result(), opts)
            outcomes.append(o)
            if progress:
                progress(k + 1, total, o)
