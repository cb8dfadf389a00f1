"""The history section of a study page, the standalone ``history.html``, and how ``build``
takes them in.

``balpipe history`` writes ``<out>/<slug>/history.json``. When ``balpipe build`` rebuilds that
spec's folder it keeps the file (:func:`build_files`), re-renders ``history.html`` and puts the
same section into the study page (:func:`section`); the file's content is part of the build's
input hash (:func:`balpipe.report.history_file.mix_hash`), so a new history re-renders the page even if the spec did not
change. Both pages render the section from ``history.json`` alone: the same bytes whichever
command ran last.
"""

from __future__ import annotations

from pathlib import Path

from .history_file import HISTORY_FILE, HISTORY_PAGE, load
from .render import environment, num
from .render import load as peak_text


def _date(iso: str) -> str:
    """'2026-11-22T00:22:26+00:00' -> '2026-11-22 00:22'."""
    return iso[:16].replace("T", " ") if iso else ""


def _peaks(c: dict, key: str) -> str:
    st = c.get("stages") or []
    if not st:
        return "—"
    a, b = st[0].get(key), st[-1].get(key)
    # a last stage's round-off (at most 1e-9 of the unbalanced peak) reads as 0, as on the stage table
    return num(a) if len(st) == 1 else f"{num(a)} → {peak_text(b, a, 1e-9, of='unbalanced')}"


def _value(x) -> str:
    """An input's value in a row of changes: a number as the pages write it, a long text by its
    start."""
    if isinstance(x, bool) or x is None:
        return "—" if x is None else str(x).lower()
    if isinstance(x, (int, float)):
        return num(x)
    t = str(x)
    return t if len(t) <= 40 else t[:30].rstrip() + "…"


def changes(c: dict) -> dict:
    """Which inputs a commit changed (``inputs_changed`` of history.json), in words: the spec's
    fields ('mechanism.slider.mass 0.6 → 0.7'), or that it is the spec's first commit; and the
    other files the commit changed."""
    ch = c.get("inputs_changed")
    if ch is None:  # a history.json written before the field
        return {"fields": [], "first": False, "none": False, "files": [], "known": False}
    fields = ch.get("fields")
    rows = [f"{f['field']}: {_value(f['old'])} → {_value(f['new'])}" for f in fields or []]
    if ch.get("more"):
        rows.append(f"and {ch['more']} more")
    files = list(ch.get("files") or []) + ([f"and {ch['more_files']} more"] if ch.get("more_files") else [])
    return {"fields": rows, "first": fields is None, "none": fields == [], "files": files, "known": True}


def view(history: dict, prefix: str = "hist") -> dict:
    """What the templates need: figures (title, interactive plot, caption) and one row per commit."""
    from ..draw import live
    from .history_figures import (added_history_figure, changing_parameters, flagged, loads_history_figure,
                                  parameters_history_figure)

    numbers = 'its numbers are in the table below and in <a href="history.json">history.json</a>'

    commits = history.get("commits") or []
    changing, constant = changing_parameters(commits)
    shown = {name for name, _ in changing}
    rows = []
    for i, c in enumerate(commits):
        st = c.get("stages") or []
        rows.append({
            "index": i + 1,
            "hash": c["hash"],
            "short": c["short"],
            "date": _date(c.get("date", "")),
            "iso_date": c.get("date", ""),
            "subject": c.get("subject", ""),
            "path": c.get("path", ""),
            "status": c.get("status"),
            "validation": c.get("validation"),
            "flagged": flagged(c),
            "peak_f": _peaks(c, "max_shaking_force"),
            "peak_m": _peaks(c, "max_shaking_moment"),
            "added_mass": num(st[-1].get("added_mass")) if st else "—",
            "last_stage": st[-1]["label"] if st else "",
            "problems": c.get("problems") or [],
            "parameters": ", ".join(f"{p['name']} = {num(p['value'])}" for p in c.get("parameters") or []
                                    if p["name"] in shown),
            "changes": changes(c),
            "verdict": c.get("verdict"),
        })
    figures = []
    if commits:
        figures.append(("Peak shaking loads per commit", live.html(f"{prefix}-loads", loads_history_figure(commits), numbers),
                        "Peak over the motion of the shaking force |F| (N) and moment |M| (N m) on the frame, "
                        "each balancing stage as on the stage table, for the spec as it was at each commit."))
        figures.append(("Added mass and inertia per commit",
                        live.html(f"{prefix}-added", added_history_figure(commits), numbers),
                        "Mass (kg) and declared rotating inertia (kg m²) each balancing stage adds to the "
                        "unbalanced mechanism."))
        params = parameters_history_figure(commits)
        if params is not None:
            figures.append(("Computed balancing parameters per commit", live.html(f"{prefix}-params", params, numbers),
                            "Each computed parameter that changes along the history, in its own unit, as in the "
                            "parameter table of the study page."))
    last = commits[-1] if commits else {}
    return {
        "source": history.get("source", ""),
        "spec": last.get("spec") or history.get("source", ""),
        "n": len(commits),
        "rows": rows,
        "figures": figures,
        "constant": [f"{name} = {num(value, 6)}{' ' + unit.replace('^2', '²') if unit else ''}"
                     for name, unit, value in constant],
        "simulated": bool(history.get("simulated")),
        "shallow": bool(history.get("shallow")),
        "uncommitted": bool(history.get("uncommitted_changes")),
    }


def render_history_page(history: dict, has_study_page: bool) -> str:
    """The standalone ``history.html`` of one spec."""
    return environment().get_template("history.html").render(
        h=view(history, "hist"), has_study_page=has_study_page)


def section(folder: Path) -> dict | None:
    """The history section of the study page in ``folder``, if a history was recorded."""
    got = load(folder)
    return view(got[1], "hist") if got is not None else None


def build_files(folder: Path) -> dict[str, str]:
    """Files that ``build`` writes beside a study page: the history kept and its page re-rendered."""
    got = load(folder)
    if got is None:
        return {}
    return {HISTORY_FILE: got[0], HISTORY_PAGE: render_history_page(got[1], has_study_page=True)}


def index_link(out: Path, slug: str) -> dict | None:
    """For the site index: the history page of a spec and its number of commits, if any."""
    folder = out / slug
    if not (folder / HISTORY_PAGE).exists():
        return None
    got = load(folder)
    n = len(got[1].get("commits") or []) if got else 0
    return {"link": f"{slug}/{HISTORY_PAGE}", "commits": n}
