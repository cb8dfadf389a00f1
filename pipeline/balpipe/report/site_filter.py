"""Facets of the site index (paper, template, method, status) for its search and filter bar.

Each index entry gets the values it is filtered by and a lower-case text that the search box
matches word by word; :func:`options` lists the values present, sorted, for the drop-downs.
The filtering itself is a few lines of inline JavaScript in ``templates/index.html``.
"""

from __future__ import annotations

from pathlib import Path

from .history_page import index_link

FACETS = ("paper", "template", "method", "status")
NO_PAPER = "(no paper)"
# the index's status labels -> short filter values (also the labels of the status drop-down)
STATUS = {"invalid spec": "invalid", "internal error": "internal-error"}


def facets(entry: dict, results: dict | None, out: Path, slug: str) -> dict:
    """Filter values of one index entry; ``results`` may be a stale page's results.json."""
    r = results or {}
    paper = r.get("paper") or NO_PAPER
    f = {
        "paper": paper,
        "template": r.get("mechanism") or "",
        "method": r.get("method") or "",
        "status": STATUS.get(entry["status"], entry["status"]),
    }
    words = [entry["title"], entry["source"], f["paper"], f["template"], f["method"]]
    return {"facets": f, "search_text": " ".join(w for w in words if w).lower(),
            "history": index_link(out, slug)}


def _label(value: str, width: int = 60) -> str:
    return value if len(value) <= width else value[: width - 1].rstrip() + "…"


def options(entries: list[dict]) -> dict[str, list[tuple[str, str]]]:
    """For each facet, the (value, label) pairs present in the index, sorted."""
    out: dict[str, list[tuple[str, str]]] = {}
    for k in FACETS:
        values = sorted({e["facets"][k] for e in entries if e["facets"][k]})
        out[k] = [(v, _label(v)) for v in values]
    return out
