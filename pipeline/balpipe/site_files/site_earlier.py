"""Pages of earlier builds in the same output folder: building some specs into an existing site
keeps the others listed on the index.

A folder of the site with an ``index.html`` and a ``results.json`` that this build did not
touch is an earlier page. It stays on the index, marked as built earlier, and *stale* when its
spec changed since (its input hash, recomputed from the spec file named in ``results.json``, no
longer matches: the spec's text, the simulation option, balpipe's code or the spec's history
changed) or when the spec file is gone.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

from typing import Any, Callable

PageHash = Callable[[Any, Path, bool], str]  # (the spec, a balpipe.loader.LoadedSpec; its page folder; simulated?) -> the build's input hash


@dataclass
class Earlier:
    """An earlier page, shaped as a build outcome for the index (:func:`balpipe.report.site._entry`)."""

    source: str
    slug: str
    status: str
    results: dict
    message: str = ""
    stale_reason: str = ""


def spec_changed(folder: Path, results: dict, page_hash: PageHash) -> str:
    """Why an earlier page no longer shows its spec ('' when it still does): ``page_hash`` is the
    hash a build would give the spec now (:func:`balpipe.build.page_hash`)."""
    from ..loader import SpecErrors, load

    source = Path(results.get("source") or "")
    if not source.is_file():
        return f"spec {source} no longer found"
    try:
        loaded = load(source)
    except (SpecErrors, OSError, ValueError):
        return "its spec has changed and is now invalid"
    simulated = results.get("validation") is not None
    h = page_hash(loaded, folder, simulated)
    return "" if h == results.get("input_hash") else "its spec or balpipe changed since this page was built"


def earlier_pages(out: Path, built: set[str], page_hash: PageHash) -> list[Earlier]:
    """The site's study pages outside ``built`` (the slugs of this build), sorted by folder."""
    found = []
    for folder in sorted(p for p in out.iterdir() if p.is_dir() and not p.is_symlink()):
        if folder.name in built or folder.name.startswith("."):
            continue
        page, data = folder / "index.html", folder / "results.json"
        if not (page.is_file() and data.is_file()):
            continue
        try:
            results = json.loads(data.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            continue
        if not isinstance(results, dict) or not results.get("stages"):
            continue
        found.append(Earlier(str(results.get("source") or folder.name), folder.name,
                             results.get("status") or "ok", results, stale_reason=spec_changed(folder, results, page_hash)))
    return found
