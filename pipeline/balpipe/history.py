"""``balpipe history``: every spec's headline figures along its git history.

For each spec, ``git log --follow`` lists the commits that changed the file (renames followed;
merge commits, which change nothing of their own, are left out). The spec as it was at each
commit runs through the same study as ``balpipe build`` (and, unless ``--no-sim``, the same
pymunk validation), and the commit's *headline figures* are kept: the computed balancing
parameters, every stage's peak shaking force and moment, added mass and inertia, and the
validation status. They are taken from the study's ``results.json`` dictionary, so a history
point and a build of the same revision hold the same numbers to the last digit.

Cache: a commit's figures are stored under the build's input hash (spec text, simulation on or
off, balpipe's code: :func:`balpipe.build.input_hash`), one JSON file per hash in the cache
folder. A spec text already seen, in any commit of any spec, is never recomputed; a new balpipe
version recomputes everything, as ``build`` does. When ``<out>/<slug>/results.json`` was built
from the same text and options (same input hash), its figures are taken from there.

Output, per spec: ``<out>/<slug>/history.json`` (documented in docs/history.md, deterministic: sorted
keys, commits oldest first, no time of the run) and ``<out>/<slug>/history.html``, a page of
plots against the commits. ``balpipe build`` reads ``history.json`` and puts the same section
in the study page (see :mod:`balpipe.report.history_page`).
"""

from __future__ import annotations

import json
import os
import subprocess
import tempfile
import traceback
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

SCHEMA_VERSION = 1
STAGE_KEYS = ("max_shaking_force", "max_shaking_moment", "max_inertial_force", "max_inertial_moment",
              "force_ratio", "moment_ratio", "added_mass", "added_inertia")


class HistoryError(Exception):
    """A spec whose history cannot be read (not in a git repository, git missing)."""


@dataclass(frozen=True)
class Commit:
    """One commit that changed a spec: its hash, committer date (ISO 8601), subject line and the
    spec's path in the repository at that commit."""

    hash: str
    date: str
    subject: str
    path: str


@dataclass
class SpecHistory:
    """What ``history`` did for one spec."""

    source: str
    slug: str
    commits: int = 0
    computed: int = 0
    cached: int = 0
    reused: int = 0  # taken from the build's results.json
    status: str = "ok"  # "ok", "untracked" (no commit yet), "error" (cannot read the history)
    message: str = ""
    files: list[str] = field(default_factory=list)


# --------------------------------------------------------------------------------------- git

def _git(root: Path, *args: str) -> str:
    try:
        r = subprocess.run(["git", "-c", "core.quotepath=off", "-C", str(root), *args],
                           capture_output=True, text=True, check=False)
    except OSError as exc:
        raise HistoryError(f"cannot run git: {exc}") from None
    if r.returncode != 0:
        first = (r.stderr.strip().splitlines() or ["?"])[0]
        raise HistoryError(f"git {args[0]}: {first}")
    return r.stdout


def repository_root(path: Path) -> Path:
    """The top folder of the git work tree holding ``path``."""
    folder = path.parent if not path.is_dir() else path
    try:
        return Path(_git(folder.resolve(), "rev-parse", "--show-toplevel").strip())
    except HistoryError:
        raise HistoryError(f"{path}: not in a git repository (balpipe history reads the spec's git log)") from None


def spec_commits(path: Path, max_commits: int | None = None) -> tuple[Path, list[Commit]]:
    """The repository root and the commits that changed ``path``, oldest first
    (``git log --follow``: the spec's earlier names are followed through renames)."""
    root = repository_root(path)
    rel = path.resolve().relative_to(root.resolve()).as_posix()
    args = ["log", "--follow", "--no-merges", "--format=%x1e%H%x1f%cI%x1f%s", "--name-only"]
    if max_commits:
        args.append(f"--max-count={max_commits}")
    try:
        out = _git(root, *args, "--", rel)
    except HistoryError as exc:
        if "does not have any commits" in str(exc):
            return root, []
        raise
    commits = []
    for block in out.split("\x1e")[1:]:
        head, _, rest = block.partition("\n")
        h, date, subject = (head.split("\x1f") + ["", ""])[:3]
        names = [n for n in rest.splitlines() if n.strip()]
        if not names:  # no file listed: nothing of this spec changed in it
            continue
        commits.append(Commit(h, date, subject, names[-1]))
    return root, commits[::-1]


def show(root: Path, commit: Commit) -> str:
    """The spec's text at ``commit``."""
    return _git(root, "cat-file", "blob", f"{commit.hash}:{commit.path}")


def is_shallow(root: Path) -> bool:
    return _git(root, "rev-parse", "--is-shallow-repository").strip() == "true"


def has_uncommitted_changes(root: Path, path: Path) -> bool:
    rel = path.resolve().relative_to(root.resolve()).as_posix()
    return bool(_git(root, "status", "--porcelain", "--", rel).strip())


# ------------------------------------------------------------------------------ the figures

def _status(v: dict) -> str:
    """A stage's validation status: "pass", "fail" or "unconfirmed" (results written before
    that status have ``passed`` only)."""
    return v.get("status") or ("pass" if v.get("passed") else "fail")


def figures_from_results(results: dict) -> dict:
    """The headline figures of one revision, from its ``results.json`` dictionary (already
    rounded to 12 significant digits: a history point equals a build's numbers)."""
    val = results.get("validation")
    stages = []
    for s in results["stages"]:
        row = {"name": s["name"], "label": s["label"], **{k: s.get(k) for k in STAGE_KEYS}}
        v = (val or {}).get(s["name"])
        row["validation"] = None if v is None else _status(v)
        stages.append(row)
    if val is None:
        overall = "skipped"
    else:  # the worst of the stages' (an unconfirmed check is not a failure)
        kinds = {_status(v) for v in val.values()}
        overall = "fail" if not val or "fail" in kinds else "unconfirmed" if "unconfirmed" in kinds else "pass"
    return {
        "status": results["status"],
        "problems": list(results.get("problems") or []),
        "spec": results["spec"],
        "mechanism": results["mechanism"],
        "method": results["method"],
        "parameters": [{"name": p["name"], "value": p["value"], "unit": p["unit"], "source": p["source"]}
                       for p in results["parameters"]],
        "stages": stages,
        "validation": overall,
        "references": [{"name": r["name"], "status": r["status"], "expected": r.get("expected")}
                       for r in results.get("references") or []],
        # the page's verdict of that revision (balpipe.report.verdict): still balanced, at what cost?
        "verdict": {k: v.get(k) for k in ("verdict", "words", "level", "costs")}
        if (v := results.get("verdict")) else None,
    }


def compute(text: str, source: str, simulate: bool, input_hash: str) -> dict:
    """Run one revision of a spec (study, and the simulation when asked) and return its figures;
    an invalid revision gives ``status: invalid`` and the located errors."""
    from . import runner
    from .loader import LoadedSpec, SpecErrors, load_text
    from .report.results import results_dict

    try:
        spec, node = load_text(text, source)
        loaded = LoadedSpec(Path(source), text, spec, node)
        st = runner.run(loaded, simulate)  # the checks of build: a revision build rejects is invalid here too
    except SpecErrors as exc:
        return {"status": "invalid", "problems": str(exc).splitlines(), "parameters": [], "stages": [],
                "validation": "skipped", "references": []}
    results = results_dict(st, source, input_hash, simulated=st.stages[0].validation is not None)
    return figures_from_results(results)


def _compute_job(args: tuple[str, str, bool, str]) -> tuple[str, dict | None, str]:
    text, source, simulate, h = args
    try:
        return h, compute(text, source, simulate, h), ""
    except Exception as exc:  # a bug in balpipe: reported, not cached
        return h, None, f"{source}: internal error: {exc!r}\n{traceback.format_exc(limit=6)}"


class Cache:
    """Figures by input hash, one small JSON file each; written atomically."""

    def __init__(self, folder: Path):
        self.folder = folder

    def _file(self, h: str) -> Path:
        return self.folder / f"{h}.json"

    def get(self, h: str) -> dict | None:
        try:
            return json.loads(self._file(h).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            return None

    def put(self, h: str, figures: dict) -> None:
        self.folder.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{h}.", dir=self.folder)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(json.dumps(figures, sort_keys=True) + "\n")
        os.chmod(tmp, 0o644)
        os.replace(tmp, self._file(h))


def dumps(history: dict) -> str:
    return json.dumps(history, indent=1, sort_keys=True, ensure_ascii=False) + "\n"


# ------------------------------------------------------------------------------------ driver

@dataclass
class _Work:
    path: Path
    slug: str
    name: str = ""  # the published name of ``path`` (never a path of the machine)
    root: Path | None = None
    commits: list[Commit] = field(default_factory=list)
    hashes: list[str] = field(default_factory=list)
    texts: list[str] = field(default_factory=list)
    outcome: SpecHistory | None = None


def run(paths: list[str], out: Path, cache_dir: Path, simulate: bool = True, jobs: int = 1,
        max_commits: int | None = None, progress=None) -> list[SpecHistory]:
    """Walk, compute (only what no cache holds) and write the history of every spec."""
    from .build import Options, find_specs, input_hash, slug_for
    from .site_files.spec_files import published_names

    opts = Options(out=out, simulate=simulate)
    cache = Cache(cache_dir)
    works: list[_Work] = []
    seen_slugs: dict[str, Path] = {}
    specs = find_specs(paths)
    names = published_names(paths, specs)
    for p in specs:
        w = _Work(p, slug_for(p), name=names[p])
        w.outcome = SpecHistory(names[p], w.slug)
        works.append(w)
        if w.slug in seen_slugs:
            w.outcome.status, w.outcome.message = "error", f"{w.name}: same page name as {names[seen_slugs[w.slug]]}; rename one"
            continue
        seen_slugs[w.slug] = p
        try:
            w.root, w.commits = spec_commits(p, max_commits)
            w.texts = [show(w.root, c) for c in w.commits]
        except HistoryError as exc:
            w.outcome.status, w.outcome.message = "error", str(exc)
            continue
        w.hashes = [input_hash(t, opts) for t in w.texts]
        if not w.commits:
            w.outcome.status, w.outcome.message = "untracked", f"{w.name}: no commit of this file yet"

    # what to compute: hashes in no cache and no results.json of the build
    known: dict[str, dict] = {}
    todo: dict[str, tuple[str, str, bool, str]] = {}
    for w in works:
        if w.outcome.status != "ok":
            continue
        built = _read_json(out / w.slug / "results.json")
        for c, h, text in zip(w.commits, w.hashes, w.texts):
            if h in known or h in todo:
                continue
            fig = cache.get(h)
            if fig is None and built is not None and built.get("input_hash") == h:
                fig = figures_from_results(built)
                cache.put(h, fig)
                w.outcome.reused += 1
                known[h] = fig
                continue
            if fig is not None:
                known[h] = fig
            else:
                todo[h] = (text, f"{c.hash[:10]}:{c.path}", simulate, h)
    failures: dict[str, str] = {}
    if todo:
        if jobs > 1 and len(todo) > 1:
            with ProcessPoolExecutor(max_workers=min(jobs, len(todo))) as pool:
                results = list(pool.map(_compute_job, todo.values()))
        else:
            results = [_compute_job(job) for job in todo.values()]
        for h, fig, err in results:
            if fig is None:
                failures[h] = err
            else:
                cache.put(h, fig)
                known[h] = fig

    outcomes = []
    for k, w in enumerate(works):
        o = w.outcome
        if o.status == "ok":
            o.commits = len(w.commits)
            counted: set[str] = set()
            for h in w.hashes:
                if h in todo and h not in counted:
                    o.computed += 1
                    counted.add(h)
            o.cached = o.commits - o.computed - o.reused
            bad = [failures[h] for h in w.hashes if h in failures]
            if bad:
                o.status, o.message = "crash", bad[0]
            o.files = write(w, known, out, failures, simulate)
        outcomes.append(o)
        if progress:
            progress(k + 1, len(works), o)
    return outcomes


def _read_json(p: Path) -> dict | None:
    try:
        return json.loads(p.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return None


#: at most this many changed fields and files are listed per commit (then "and k more")
MAX_CHANGES = 12


def spec_fields(text: str, source: str) -> dict[str, Any]:
    """Every input field of a spec text, flattened to dotted paths (``mechanism.crank.mass``):
    the validated spec's, in SI units with its defaults (as ``balpipe diff`` compares them), or
    for a text that does not validate the YAML as written (``{}`` when it does not parse)."""
    import yaml

    from .diff import flatten
    from .loader import SpecErrors, load_text

    try:
        spec, _ = load_text(text, source)
        return flatten(spec.model_dump(mode="json", by_alias=True))
    except SpecErrors:
        try:
            raw = yaml.safe_load(text)
        except yaml.YAMLError:
            return {}
        return flatten(raw) if isinstance(raw, dict) else {}


def changed_fields(before: dict[str, Any], after: dict[str, Any]) -> list[dict]:
    """The fields whose value differs (round-off is no change: :func:`balpipe.diff.same`),
    sorted: ``{field, old, new}`` (None where a side lacks the field)."""
    from .diff import same

    return [{"field": k, "old": before.get(k), "new": after.get(k)}
            for k in sorted(set(before) | set(after)) if not same(before.get(k), after.get(k))]


def commit_files(root: Path, commit: Commit) -> list[str]:
    """The files a commit changed besides the spec (``git show --name-only``), sorted."""
    out = _git(root, "show", "--no-renames", "--name-only", "--format=", commit.hash)
    return sorted(n for n in {line.strip() for line in out.splitlines()} if n and n != commit.path)


def inputs_changed(w: _Work) -> list[dict]:
    """Per commit, which inputs it changed: ``fields`` (the spec's fields against the previous
    commit's spec; None at the spec's first commit, where every field is new), ``more`` (fields
    beyond :data:`MAX_CHANGES`), ``files`` (the other files the commit changed: tables the spec
    reads, code) and ``more_files``."""
    out = []
    previous: dict[str, Any] | None = None
    for c, text in zip(w.commits, w.texts):
        now = spec_fields(text, f"{c.hash[:10]}:{c.path}")
        fields = None if previous is None else changed_fields(previous, now)
        files = commit_files(w.root, c) if w.root is not None else []
        out.append({"fields": None if fields is None else fields[:MAX_CHANGES],
                    "more": 0 if fields is None else max(0, len(fields) - MAX_CHANGES),
                    "files": files[:MAX_CHANGES], "more_files": max(0, len(files) - MAX_CHANGES)})
        previous = now
    return out


def history_dict(w: _Work, known: dict[str, dict], failures: dict[str, str], simulate: bool) -> dict:
    commits = []
    changes = inputs_changed(w)
    for c, h, changed in zip(w.commits, w.hashes, changes):
        fig = known.get(h)
        if fig is None:
            fig = {"status": "crash", "problems": failures.get(h, "not computed").splitlines()[:1],
                   "parameters": [], "stages": [], "validation": "skipped", "references": []}
        commits.append({"hash": c.hash, "short": c.hash[:7], "date": c.date, "subject": c.subject,
                        "path": c.path, "input_hash": h, "inputs_changed": changed, **fig})
    from .report.results import json_safe

    return json_safe({
        "schema_version": SCHEMA_VERSION,
        "source": w.name or w.path.as_posix(),
        "slug": w.slug,
        "shallow": is_shallow(w.root),
        "simulated": simulate,
        "uncommitted_changes": has_uncommitted_changes(w.root, w.path),
        "commits": commits,
    })


STUDY_LINK = '<a href="index.html">study page</a>'


def write(w: _Work, known: dict[str, dict], out: Path, failures: dict[str, str], simulate: bool) -> list[str]:
    """Write ``history.json`` and ``history.html`` into the spec's folder of the site (left as
    they are when nothing changed: a second run renders nothing)."""
    data = history_dict(w, known, failures, simulate)
    folder = out / w.slug
    folder.mkdir(parents=True, exist_ok=True)
    text = dumps(data)
    has_page = (folder / "index.html").exists()
    old_json = _read_text(folder / "history.json")
    old_page = _read_text(folder / "history.html")
    files = [folder / "history.json", folder / "history.html"]
    if old_json == text and old_page is not None and (STUDY_LINK in old_page) == has_page:
        return [str(f) for f in files]
    from .report.history_page import render_history_page

    page = render_history_page(data, has_study_page=has_page)
    for target, content in zip(files, (text, page)):
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", dir=folder)
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            f.write(content)
        os.chmod(tmp, 0o644)
        os.replace(tmp, target)
    return [str(f) for f in files]


def _read_text(p: Path) -> str | None:
    try:
        return p.read_text(encoding="utf-8")
    except OSError:
        return None
