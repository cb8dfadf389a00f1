"""Facets of the site index (verdict, paper, template, method, status) for its search and filter bar.

Each index entry gets the values it is filtered by and a lower-case text that the search box
matches word by word; :func:`options` lists the values present, sorted, for the drop-downs.
The filtering itself is a few lines of inline JavaScript in ``templates/index.html``.
"""

from __future__ import annotations

from pathlib import Path

from .history_page import index_link

FACETS = ("verdict", "paper", "template", "method", "status")
NO_PAPER = "(no paper)"
# the index's status labels -> short filter values (also the labels of the status drop-down)
STATUS = {"invalid spec": "invalid", "internal error": "internal-error"}
# the verdict's kinds (balpipe.report.verdict.KINDS) as the drop-down names them, in that order
VERDICTS = {"holds": "claim holds (as claimed, as designed)", "fails": "a claim fails",
            "objective": "optimised (judged by its objective)", "unclaimed": "no claim (loads reduced or not)",
            "unconfirmed": "unconfirmed by the simulation"}


def facets(entry: dict, results: dict | None, out: Path, slug: str) -> dict:
    """Filter values of one index entry; ``results`` may be a stale page's results.json."""
    r = results or {}
    paper = r.get("paper") or NO_PAPER
    v = r.get("verdict") if results is not None and not entry.get("stale") else None
    f = {
        "verdict": (v or {}).get("verdict", ""),
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
        if k == "verdict":  # best first, in words
            out[k] = [(v, VERDICTS.get(v, v)) for v in sorted(values, key=lambda v: list(VERDICTS).index(v) if v in VERDICTS else len(VERDICTS))]
            continue
        out[k] = [(v, _label(v)) for v in values]
    return out
