"""The spec files of a command line and their page folders: which files a build or a check reads
(named files, and the *.yaml / *.yml found in named folders) and the folder name of each page,
with the files whose pages would clash. Light on purpose: ``balpipe check`` needs nothing of the
report to find its specs."""

from __future__ import annotations

import hashlib
import os
from pathlib import Path


def find_specs(paths: list[str], problems: list[str] | None = None) -> list[Path]:
    """Spec files named on the command line or found (*.yaml, *.yml) in named folders, sorted.
    Folders that cannot be read are appended to ``problems`` (not silently skipped)."""
    found: list[Path] = []
    for p in map(Path, paths):
        if p.is_dir():
            def unreadable(exc: OSError) -> None:
                if problems is not None:
                    where = Path(exc.filename)
                    shown = published_names([str(p)], [where]).get(where, where.name)
                    problems.append(f"{shown}: cannot read the folder: {exc.strerror or exc}")
            files = []
            for root, dirs, names in os.walk(p, onerror=unreadable):
                dirs.sort()
                files += [Path(root) / n for n in names if Path(n).suffix in (".yaml", ".yml")]
            found += sorted(q for q in files if q.is_file())
        else:
            found.append(p)
    seen, unique = set(), []
    for f in found:
        key = f.resolve()
        if key not in seen:
            seen.add(key)
            unique.append(f)
    return unique


def published_names(paths: list[str], specs: list[Path]) -> dict[Path, str]:
    """The name under which each of ``specs`` (found from the command line's ``paths``) appears
    in published files (index, pages, results.json, messages): never a path of the machine.

    A path given relative and without ``..`` is kept as given (``specs/x.yaml``). Any other is
    made relative to the first of: the working folder (unless it is ``/``), the git repository holding it, the folder
    holding the command line's folder or file that found it (``/abs/specs`` gives
    ``specs/x.yaml``). So a build from absolute paths publishes what the same build from
    relative paths does."""
    cwd = Path(os.getcwd())
    named = [Path(os.path.normpath(os.path.abspath(p))) for p in paths]
    out = {}
    for spec in specs:
        if not spec.is_absolute() and ".." not in spec.parts:
            out[spec] = spec.as_posix()
            continue
        a = Path(os.path.normpath(os.path.abspath(spec)))
        root = next((n for n in named if a == n or n in a.parents), a)
        bases = [*([cwd] if cwd.parent != cwd else []), *(q for q in a.parents if (q / ".git").exists())][:2]
        bases.append(root.parent)
        out[spec] = next(a.relative_to(b).as_posix() for b in bases if b == a.parent or b in a.parents)
    return out


MAX_SLUG = 80  # characters of a page folder's name (file systems allow 255 bytes)


def slug_for(path: Path) -> str:
    """The page folder of a spec: its file name's stem with other characters than letters,
    digits, '-' and '_' replaced by '-'; long names are cut and end in a hash of the stem."""
    stem = path.stem
    slug = "".join(c if (c.isalnum() and c.isascii()) or c in "-_" else "-" for c in stem)
    if len(slug) > MAX_SLUG or not slug.strip("-_"):
        digest = hashlib.sha256(stem.encode("utf-8", "surrogateescape")).hexdigest()[:10]
        slug = slug[: MAX_SLUG - 11] + "-" + digest
    return slug


def clash_groups(specs: list[Path]) -> list[list[Path]]:
    """Specs whose page folders would be the same (x.yaml and x.yml, 'a b' and 'a-b', names that
    differ only in case), each group in sorted order."""
    groups: dict[str, list[Path]] = {}
    for p in specs:
        groups.setdefault(slug_for(p).lower(), []).append(p)
    return [sorted(g, key=str) for g in groups.values() if len(g) > 1]


def clashes(specs: list[Path], name=str) -> dict[Path, str]:
    """The specs refused for a page-name clash: every one after the first of its group in sorted
    order (the first is built), each with a message naming the others (``name``: a path's
    name in messages)."""
    out = {}
    for first, *rest in clash_groups(specs):
        for p in rest:
            others = ", ".join(name(q) for q in [first, *rest] if q is not p)
            out[p] = (f"{name(p)}: its page {slug_for(p)}/ would be the same as that of {others}; "
                      f"{name(first)} (the first in sorted order) is built, not this file; rename one of these files")
    return out


def clash_notes(specs: list[Path], name=str) -> dict[Path, str]:
    """For the spec built from each clashing group: a note naming the files refused beside it."""
    out = {}
    for first, *rest in clash_groups(specs):
        others = ", ".join(map(name, rest))
        out[first] = (f"{name(first)}: its page {slug_for(first)}/ would be the same as that of {others}; "
                      f"built from this file, the first in sorted order ({others} refused); rename one of these files")
    return out
