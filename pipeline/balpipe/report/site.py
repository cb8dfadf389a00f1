"""The site index: every spec of the build with its status and headline numbers."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Sequence

from ..runtime.fsutil import write_file_atomic  # replaced in one step, never through a planted symlink
from . import citations, site_filter, verdict
from .verdict import LEVELS
from .costs import drivers_text, factor_text
from ..display.numbers import num_at
from .mechanism_key import describe
from .render import environment, num, printable, ratio
from .render import tol as tol_fmt


def _entry(out: Path, o) -> dict:
    page = out / o.slug / "index.html"
    results = o.results
    stale = False
    if results is None and page.exists():
        stale = True  # the spec failed now; its earlier page is still there
        try:
            results = json.loads((out / o.slug / "results.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            results = None
    if getattr(o, "kept_previous", False):
        # failed its checks after a good build: the good page stays, the failed one is in failed/
        stale = True
        try:
            results = json.loads((out / o.slug / "results.json").read_text(encoding="utf-8"))
        except (OSError, ValueError):
            results = None
    e = {
        "title": printable((results or {}).get("spec") or Path(o.source).name),
        "source": printable(o.source),
        "link": f"{o.slug}/index.html" if page.exists() else None,
        "status": {"ok": "ok", "failed": "failed", "error": "invalid spec", "crash": "internal error"}.get(o.status, o.status),
        "stale": stale,
        "results": results if not stale else None,
        "errors": printable(o.message) if o.status in ("error", "crash", "failed") else "",
        "error_short": printable((o.message.splitlines() or [""])[0]),
        "failed_link": f"{o.slug}/failed/index.html" if getattr(o, "kept_previous", False) else None,
        "error_rest": printable("\n".join(o.message.splitlines()[1:])) if o.status in ("error", "crash", "failed") else "",
        "not_realisable": [],
        "slug": o.slug,
        "verdict": None,
        "citation": citations.cite((results or {}).get("paper")),  # once, in "The papers"; a row links to it
        "paper_id": citations.paper_id((results or {}).get("paper") or "") if (results or {}).get("paper") else "",
        "built": "",
        "stale_text": "page from an earlier build",
    }
    if e["results"]:
        st = results["stages"]
        first = st[0]
        v = results.get("verdict") or verdict.verdict(results)  # a results.json of an older build
        e["verdict"] = v
        e["not_realisable"] = [f"{s['label']}: {s['not_realisable']}" for s in st if s.get("realisable") is False]
        tol = results.get("checks", {}).get("balance_tolerance")
        e["headline"] = headline(v, tol, {a["driver"]: a.get("symbol") or a["driver"] for a in results.get("actuators") or []})
        # the main design's headline stage of its first motion (never a compared design's)
        last = next((s for s in st if v["motions"] and s["name"] == v["motions"][0]["final"]), st[-1])
        e["added_mass"] = f"{num_at(last['added_mass'], results.get('moving_mass'))} kg"
        e.update(_costs(results, first, last))
        e["refs"] = v["references"].get("badge") or "—"  # reproduced / explained / not reproduced, apart
        val = results.get("validation")
        if val is None:
            e["validation"] = '<span class="muted">skipped</span>'
        else:
            passed = all(v.get("passed") for v in val.values())
            e["validation"] = '<span class="badge ok">pass</span>' if passed else '<span class="badge bad">fail</span>'
    e.update(site_filter.facets(e, results, out, o.slug))  # search, filter and history link
    e["sort"] = sort_keys(e)
    return e


def headline(v: dict, tol: float | None, symbols: dict[str, str] | None = None) -> dict:
    """The index's headline numbers from the verdict's motions (the spec's main design only):
    inertial |F| and |M| peaks, reference -> final stage, and with gravity the weight apart; a
    spec with several motions shows the range over them. ``symbols`` names the drivers (the
    paper's symbol of each) in the costs, which say which driver is the worst and every other
    driver's factor."""
    ms = v.get("motions") or []
    if not ms:
        return {"force": "—", "moment": "—", "weight": "", "motions": 0, "rows": [], "costs": [], "realisable": True}

    zero = f"0 (< {tol_text(tol)})"

    def after(g: dict, key: str) -> str:
        out = v["stages"][g["final"]][key]
        return zero if out["outcome"] in ("cancelled", "zero") else num(g[key][1])

    def before(g: dict, key: str) -> str:
        return zero if v["stages"][g["final"]][key]["outcome"] == "zero" else num(g[key][0])

    def span(values: list[str]) -> str:
        return values[0] if len(set(values)) == 1 else f"{values[0]} … {values[-1]}"

    rows = [{"label": g["reference_label"], "final": g["final_label"],
             "force": f"{before(g, 'force')} → {after(g, 'force')}",
             "moment": f"{before(g, 'moment')} → {after(g, 'moment')}",
             "costs": g["costs"]} for g in ms]
    if len(ms) == 1:
        force, moment = rows[0]["force"], rows[0]["moment"]
    else:
        f0 = sorted(g["force"][0] for g in ms)
        m0 = sorted(g["moment"][0] for g in ms)
        f1 = sorted(g["force"][1] for g in ms)
        m1 = sorted(g["moment"][1] for g in ms)
        force = f"{span([num(f0[0]), num(f0[-1])])} → {span([num(f1[0]), num(f1[-1])])}"
        moment = f"{span([num(m0[0]), num(m0[-1])])} → {span([num(m1[0]), num(m1[-1])])}"
    w = ms[0].get("weight")
    weight = f"{num(w[0])} → {num(w[1])}" if w and w[0] is not None else ""
    c = ms[0]["costs"]
    def per_driver(name: str) -> str:  # the factor, which driver (the worst) and every other driver's
        who = drivers_text(c, name, lambda d: (symbols or {}).get(d, d))
        return factor_text(c[name]) + (f" ({who})" if who else "")

    costs = [("moving mass", factor_text(c["moving_mass"])), ("peak effort", per_driver("effort")),
             ("RMS effort", per_driver("rms")), ("peak power", per_driver("power")),
             ("largest joint load", factor_text(c["joint_load"]))]
    return {"force": force, "moment": moment, "weight": weight, "motions": len(ms), "rows": rows,
            "costs": costs, "realisable": c["realisable"]}


def tol_text(tol: float | None) -> str:
    """'< tolerance' text of a cancelled load: the balance tolerance of the reference."""
    return f"{tol_fmt(tol)} of unbalanced" if tol is not None else "tolerance"


def _costs(results: dict, first: dict, last: dict) -> dict:
    """What each stage claims and whether it holds (a warning mark where a stage makes the
    moment worse than its reference), and what balancing costs: added mass relative to the
    moving mass, peak/RMS actuator effort and peak power per driver (unbalanced -> last stage),
    the largest joint-load increase over the stages."""
    tol = (results.get("checks") or {}).get("balance_tolerance")
    claims = []
    for s in results["stages"][1:]:
        parts = [p for p in ("force", "moment") if p in (s.get("balances") or "")]
        holds = all(s.get(f"{p}_balanced") for p in parts)
        claims.append({
            "name": s["name"], "label": s["label"], "claims": " and ".join(parts) or "—", "holds": holds if parts else None,
            "realisable": s.get("realisable", True) is not False,
            "worse": (s.get("moment_ratio") or 0.0) > 1.0 + 1e-9,
            "moment": ratio(s.get("moment_ratio"), tol), "force": ratio(s.get("force_ratio"), tol),
        })
    mm = results.get("moving_mass") or 0.0
    # relative to the moving mass: the "moving mass ×" factor beside it (one format per column)
    added = f"{num(last['added_mass'])} kg" + (f" on {num(mm)} kg" if mm else "")
    acts = results.get("actuators") or []
    efforts = []
    for a0 in [a for a in acts if a["stage"] == first["name"]]:
        a1 = next((a for a in acts if a["stage"] == last["name"] and a["driver"] == a0["driver"]), None)
        if a1 is None:
            continue
        u = a0["unit"]
        sym = a0.get("symbol") or a0["driver"]  # the paper's symbol, the spec's name beside it
        who = sym if sym == a0["driver"] else f"{sym} [{a0['driver']}]"
        efforts.append(f"{who}: peak {num(a0['peak'])} → {num(a1['peak'])} {u}, RMS {num(a0['rms'])} → "
                       f"{num(a1['rms'])} {u}, power {num(a0['power'])} → {num(a1['power'])} W")
    rows = (results.get("comparison") or {}).get("rows") or []
    base = next((r for r in rows if r["stage"] == first["name"]), None)
    joint = ""
    if base is not None:
        incs = [(r["max_joint_load"] - base["max_joint_load"], r) for r in rows if r["design"] == base["design"]]
        inc, r = max(incs, key=lambda x: x[0]) if incs else (0.0, base)
        if inc > 0:
            joint = (f"+{num(inc)} N ({r['label']}, joint {r['max_joint_load_joint']}; "
                     f"{ratio(inc / base['max_joint_load']) if base['max_joint_load'] else '—'} of {num(base['max_joint_load'])} N)")
        else:
            joint = "none"
    return {"claims": claims, "added_mass": added, "efforts": efforts, "joint_increase": joint}


def write_site(out: Path, outcomes: list, earlier: Sequence[Any] = (), site_key: str = "") -> None:
    """The site's index (and its navigation script): this build's ``outcomes`` and the pages of
    ``earlier`` builds still in ``out`` (:func:`balpipe.site_files.site_earlier.earlier_pages`). ``site_key``
    (:func:`balpipe.build.site_key`) is written into the index's head, so that a build with
    nothing changed can leave the index as it is."""
    entries = [_entry(out, o) for o in sorted(outcomes, key=lambda o: o.source)]
    for old in earlier:
        e = _entry(out, old)
        e["built"] = "in an earlier build"
        if old.stale_reason:
            e["stale"], e["stale_text"] = True, f"stale: {old.stale_reason}"
        entries.append(e)
    entries.sort(key=lambda e: e["source"])
    now = [e for e in entries if not e["built"]]  # this build's specs: the command line's counts
    n_ok = sum(e["status"] == "ok" for e in now)
    n_flagged = sum(e["status"] == "ok" and bool(e["not_realisable"]) for e in now)
    n_invalid = sum(e["status"] == "invalid spec" for e in now)
    html = environment().get_template("index.html").render(
        entries=entries, n_earlier=len(entries) - len(now), n_ok=n_ok - n_flagged, n_failed=len(now) - n_ok - n_invalid, n_flagged=n_flagged,
        n_invalid=n_invalid, n_ok_cli=n_ok,
        filters=site_filter.options(entries),
        papers=site_papers(entries),
        comparisons=comparisons(entries),
        site_key=site_key,
    )
    write_file_atomic(out / "site_nav.js", site_nav_script(entries))
    write_file_atomic(out / "index.html", html)  # last: a failure before it leaves the previous index


def comparisons(entries: list[dict]) -> list[dict]:
    """The designs of one mechanism side by side: the specs whose unbalanced linkage is the same
    (``mechanism_key`` of results.json, :mod:`balpipe.report.mechanism_key`), two or more of them,
    one row per spec (its main design's headline stage): verdict, added mass (kg and relative to
    the moving mass), added inertia, counter-rotations, residual |F| and |M| as the verdict words
    them, and the cost factors; each cell carries its value for sorting."""
    by: dict[str, list[dict]] = {}
    for e in entries:
        r = e.get("results")
        if r and r.get("mechanism_key") and e.get("verdict") and e["verdict"].get("motions"):
            by.setdefault(r["mechanism_key"], []).append(e)
    out = []
    for key, group in by.items():
        if len(group) < 2:
            continue
        rows = []
        for e in group:
            r, v = e["results"], e["verdict"]
            g = v["motions"][0]
            comp: dict[str, Any] = next((c for c in (r.get("comparison") or {}).get("rows") or [] if c["stage"] == g["final"]), {})
            c = g["costs"]
            mm = r.get("moving_mass") or 0.0
            rel = c["added_mass"] / mm if mm and c["added_mass"] is not None else None
            rows.append({
                "title": e["title"], "link": e["link"], "method": r.get("method"), "level": v["level"],
                "rank": LEVELS.index(v["level"]),
                "words": v["words"], "added_mass": num_at(c["added_mass"], r.get("moving_mass")), "added_mass_value": c["added_mass"] or 0.0,
                "added_relative": factor_text(rel), "added_relative_value": rel if rel is not None else 0.0,
                "added_inertia": (num_at(c["added_inertia"], r.get("inertia_scale")) if c["added_inertia"] is not None
                                  else "cannot be built"),
                "added_inertia_value": c["added_inertia"] if c["added_inertia"] is not None else "",
                "counter_rotations": comp.get("counter_rotations", "—"),
                "force": v["stages"][g["final"]]["force"]["text"], "force_value": g["force"][1],
                "moment": v["stages"][g["final"]]["moment"]["text"], "moment_value": g["moment"][1],
                "effort": factor_text(c["effort"]), "effort_value": c["effort"] if c["effort"] is not None else "",
                "joint_load": factor_text(c["joint_load"]),
                "joint_load_value": c["joint_load"] if c["joint_load"] is not None else "",
            })
        first = group[0]["results"]
        bodies = first.get("moving_bodies") or []
        out.append({"key": key, "template": first.get("mechanism") or "",
                    "bodies": describe(bodies), "moving_mass": num(first.get("moving_mass")),
                    "methods": len({row["method"] for row in rows}),
                    "rows": sorted(rows, key=lambda row: (row["rank"], row["added_relative_value"], row["title"]))})
    return sorted(out, key=lambda c: (-len(c["rows"]), c["template"], c["bodies"], c["key"]))


def sort_keys(e: dict) -> dict:
    """What each column of the index sorts by: the title, the verdict (best first), the
    headline stage's |F| and |M| peaks (the largest over the motions), the added mass relative
    to the moving mass, and the build's status."""
    v = e.get("verdict") or {}
    ms = v.get("motions") or []
    mm = (e.get("results") or {}).get("moving_mass") or 0.0
    added = ms[0]["costs"]["added_mass"] if ms else None
    return {
        "title": e["title"].lower(),
        "verdict": LEVELS.index(v["level"]) if v.get("level") in LEVELS else len(LEVELS),
        "force": max((g["force"][1] for g in ms), default=""),
        "moment": max((g["moment"][1] for g in ms), default=""),
        "cost": added / mm if mm and added is not None else "",
        "built": site_filter.STATUS.get(e["status"], e["status"]),  # the status filter's short value
    }


def site_papers(entries: list[dict]) -> list[dict]:
    """The papers the listed specs reproduce, each cited once, by id."""
    seen: dict[str, str] = {}
    for e in entries:
        paper = (e.get("facets") or {}).get("paper") or ""
        pid = citations.paper_id(paper)
        if pid and paper != site_filter.NO_PAPER and pid not in seen:
            seen[pid] = citations.cite(paper)
    return [{"id": k, "text": seen[k]} for k in sorted(seen)]


def site_nav_script(entries: list[dict]) -> str:
    """``site_nav.js``: previous/next links between the study pages in the index's order, and a
    spec's file name in a page's description (``other_spec.yaml``, ``specs/other_spec.yaml``)
    made a link to that spec's page when this site has it (titled with its study's title);
    written once per build so that a cached page needs no rebuild when another spec changes,
    and no link points at a page the site does not hold."""
    pages = [[e["link"].split("/")[0], e["title"]] for e in entries if e.get("link")]
    data = json.dumps(pages, separators=(",", ":"), sort_keys=True, ensure_ascii=False)
    return f"""// previous/next between the studies of this site (written by balpipe build)
(function() {{
const P = {data};
const here = location.pathname.split("/").slice(-2)[0];
const k = P.findIndex(p => p[0] === here);
if (k < 0) return;
function link(p, rel, text) {{ const a = document.createElement("a"); a.href = "../" + p[0] + "/index.html";
  a.rel = rel; a.textContent = text + p[1]; return a; }}
document.querySelectorAll(".sitenav").forEach(el => {{
  if (k > 0) el.append(" · ", link(P[k - 1], "prev", "\u2190 previous: "));
  if (k < P.length - 1) el.append(" · ", link(P[k + 1], "next", "next: "));
  if (k < P.length - 1) el.lastChild.textContent += " \u2192";
}});
const bySlug = new Map(P.map(p => [p[0], p]));
document.querySelectorAll("p.description").forEach(el => {{
  const walker = document.createTreeWalker(el, NodeFilter.SHOW_TEXT), texts = [];
  while (walker.nextNode()) texts.push(walker.currentNode);
  texts.forEach(t => {{
    const re = /(?:specs\\/)?([A-Za-z0-9_.-]+)\\.yaml\\b/g, frag = document.createDocumentFragment();
    let m, last = 0;
    while ((m = re.exec(t.data))) {{
      const p = bySlug.get(m[1]);
      if (!p || p[0] === here) continue;
      const a = document.createElement("a");
      a.href = "../" + p[0] + "/index.html"; a.title = p[1]; a.textContent = m[0];
      frag.append(t.data.slice(last, m.index), a);
      last = m.index + m[0].length;
    }}
    if (last) {{ frag.append(t.data.slice(last)); t.replaceWith(frag); }}
  }});
}});
}})();
"""
