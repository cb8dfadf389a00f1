"""``balpipe diff OLD NEW``: what changed between two designs, and what it did to the results.

Each side is a spec file, or ``REV:PATH`` for the spec as it was at a git revision (e.g.
``HEAD~1:specs/scott_russell.yaml``). Both are run through the same study as ``build`` (and,
unless ``--no-sim``, the same pymunk validation); the comparison covers the inputs (every
field of the validated spec, in SI units), the computed parameters, every stage's peaks,
ratios, added mass and actuator effort, the references and the validation residuals. Every
output says first whether each side is still balanced, in the words of the pages' verdict
(:func:`balpipe.report.verdict.verdict`: "force balanced as designed", "the paper's claim fails:
moment × 6.74", the costs), then which inputs changed, then what they did. Stages are named by
their label, as on the pages. Output as text, Markdown, JSON or a self-contained HTML page linking
to both designs' pages on the report site, with both designs' curves overlaid in interactive
plots (the pages' uPlot plots: :mod:`balpipe.draw.live`).
"""

from __future__ import annotations

import json
import math
import re
import subprocess
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from . import runner
from .display.numbers import num, num_at
from .loader import LoadedSpec, SpecError, SpecErrors, load, load_text
from .report.results import json_safe
from .study import Study

ROUND_OFF = 1e-9  # ratios to the unbalanced peak below this are cancelled loads
# readable names and units of the stage results (the JSON keeps the keys)
STAGE_NAMES = {
    "max_shaking_force": "peak |F| (N)", "max_shaking_moment": "peak |M| (N m)",
    "force_ratio": "|F| vs unbalanced", "moment_ratio": "|M| vs unbalanced",
    "max_actuator_effort": "peak actuator effort (N m or N, largest driver)", "added_mass": "added mass (kg)",
    "added_inertia": "added inertia (kg m²)",
}
STAGE_KEYS = ("max_shaking_force", "max_shaking_moment", "force_ratio", "moment_ratio",
              "max_actuator_effort", "added_mass", "added_inertia")


@dataclass
class Side:
    ref: str
    loaded: LoadedSpec
    study: Study


def shown_ref(ref: str) -> str:
    """How the outputs name a side: a file or the PATH of REV:PATH as
    :func:`balpipe.site_files.spec_files.published_names` does (never a path of the machine)."""
    from .site_files.spec_files import published_names

    p = Path(ref)
    if p.exists() or ":" not in ref:
        return published_names([ref], [p])[p]
    rev, path = ref.split(":", 1)
    return f"{rev}:{published_names([path], [Path(path)])[Path(path)]}"


def read_side(ref: str) -> LoadedSpec:
    """A spec file, or REV:PATH read with ``git show REV:./PATH`` (PATH relative to the current
    folder, or absolute). REV is verified as a commit first (``git rev-parse --verify
    --end-of-options``) and only its hash reaches ``git show``: a REV that starts with ``-`` is
    refused, never read as an option."""
    p = Path(ref)
    name_shown = shown_ref(ref)
    if p.exists() or ":" not in ref:
        return load(p, name_shown)
    rev, path = ref.split(":", 1)
    target = Path(path)
    cwd = target.parent if target.is_absolute() else Path(".")
    name = target.name if target.is_absolute() else target.as_posix()

    def refused(why: str) -> SpecErrors:
        return SpecErrors([SpecError(name_shown, None, None, "", why)])

    if not rev or rev.startswith("-"):
        raise refused(f"not a git revision: {rev!r} (a revision cannot start with '-')")
    try:
        commit = subprocess.run(["git", "rev-parse", "--verify", "--quiet", "--end-of-options", f"{rev}^{{commit}}"],
                                cwd=cwd, capture_output=True, text=True, check=True).stdout.strip()
    except (subprocess.CalledProcessError, OSError):
        raise refused(f"cannot read it from git: {rev!r} is not a commit of the repository here") from None
    if not re.fullmatch(r"[0-9a-f]{40,64}", commit):
        raise refused(f"cannot read it from git: {rev!r} is not a commit of the repository here")
    try:
        text = subprocess.run(["git", "show", f"{commit}:./{name}"], cwd=cwd, capture_output=True,
                              text=True, check=True).stdout
    except (subprocess.CalledProcessError, OSError) as exc:
        detail = (getattr(exc, "stderr", "") or str(exc)).strip().splitlines()
        raise refused("cannot read it from git: " + (detail[0] if detail else "?")) from None
    spec, node = load_text(text, name_shown, Path(ref).parent)
    return LoadedSpec(Path(ref), text, spec, node, name_shown)


def run_side(ref: str, simulate: bool) -> Side:
    loaded = read_side(ref)
    st = runner.run(loaded, simulate)  # the checks and limits of check and build, errors located
    return Side(shown_ref(ref), loaded, st)


def side_verdict(side: Side) -> dict:
    """The side's verdict as its page gives it (:func:`balpipe.report.verdict.verdict` of its
    stages' rows, references, status and paper; the main design's stages): ``verdict``, ``words``,
    ``level``, ``costs``, ``text``."""
    from .report.verdict import verdict

    st = side.study
    rows = {"stages": [s.metrics.to_json() for s in st.stages], "references": st.references,
            "status": "ok" if st.ok else "failed", "problems": list(st.problems),
            "paper": side.loaded.spec.paper}
    v = verdict(rows, main={s.stage.name for s in st.stages if s.stage.design is None})
    return {k: v[k] for k in ("verdict", "words", "level", "costs", "text")}


def still(old: dict, new: dict) -> str:
    """One sentence: is the new design still what the old one was? ('still force balanced as
    designed', 'no longer balanced: the paper's claim fails: moment × 6.74 (was: balanced as
    claimed)', 'now balanced as designed (was: ...)')."""
    if old["words"] == new["words"]:
        lead = "still" if new["verdict"] in ("holds", "unconfirmed") else "both"
        costs = ("; costs " + ", ".join(old["costs"]) + " → " + ", ".join(new["costs"])
                 if old["costs"] != new["costs"] else "")
        return f"{lead} {new['words']}{costs}"
    if old["verdict"] in ("holds", "unconfirmed") and new["verdict"] not in ("holds", "unconfirmed"):
        return f"no longer balanced: {new['words']} (was: {old['words']})"
    if new["verdict"] in ("holds", "unconfirmed") and old["verdict"] not in ("holds", "unconfirmed"):
        return f"now {new['words']} (was: {old['words']})"
    return f"{old['words']} → {new['words']}"


def flatten(obj: Any, prefix: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.update(flatten(v, f"{prefix}.{k}" if prefix else str(k)))
    elif isinstance(obj, list) and obj and all(isinstance(v, dict) for v in obj):
        for i, v in enumerate(obj):
            out.update(flatten(v, f"{prefix}[{i}]"))
    else:
        out[prefix] = obj
    return out


def same(old: Any, new: Any) -> bool:
    """Equal, or two numbers that differ by round-off only (1e-9 relative, 1e-12 absolute in SI):
    round-off never counts as a change."""
    if old == new:
        return True
    if isinstance(old, bool) or isinstance(new, bool):
        return False
    if isinstance(old, (int, float)) and isinstance(new, (int, float)) and math.isfinite(old) and math.isfinite(new):
        return abs(new - old) <= max(1e-12, ROUND_OFF * max(abs(old), abs(new)))
    return False


def _change(old: float | None, new: float | None) -> dict:
    d: dict[str, Any] = {"old": old, "new": new}
    if isinstance(old, (int, float)) and isinstance(new, (int, float)):
        d["delta"] = new - old
        d["relative"] = (new - old) / abs(old) if old else (0.0 if new == old else math.inf)
    return d


def _input_units(side: Side) -> dict[str, str]:
    """SI unit of every input field with a declared dimension (as on the study page)."""
    from .report.inputs import input_rows

    return {r["path"]: r["unit"].replace("^2", "²") for r in input_rows(side.loaded.spec) if r["unit"]}


def site_link(site: str, out: str | None) -> str:
    """The link back to the report site: ``site`` if given, else an ``index.html`` of a balpipe
    site beside or above the output file (relative), else none."""
    if site:
        return site
    if out:
        folder = Path(out).resolve().parent
        for rel, cand in (("index.html", folder / "index.html"), ("../index.html", folder.parent / "index.html")):
            try:
                if cand.exists() and "balpipe" in cand.read_text(encoding="utf-8")[:2000]:
                    return rel
            except OSError:
                continue
    return ""


def _input_symbol(side: Side, path: str) -> str:
    """The paper's symbol of an input (plain text, as the page's inputs table has it:
    :mod:`balpipe.notation`), '' for a setting of balpipe's or a field without one; a compared
    design's field by that design's method's table."""
    from . import notation as N
    from .report.notation_table import tables_for

    spec = side.loaded.spec
    balancing = spec.balancing
    m = re.fullmatch(r"compare\[(\d+)\]\.(.*)", path)
    if m:
        designs = getattr(spec, "compare", None) or []
        if int(m.group(1)) >= len(designs):
            return ""
        balancing, path = designs[int(m.group(1))].balancing, m.group(2)
    sym = N.lookup(tables_for(spec.mechanism, balancing), path)
    return "" if sym is None or sym.setting else N.symbol_text(sym.symbol)


def compare(a: Side, b: Side) -> dict:
    """The differences between two studies, as plain data (the JSON output)."""
    ia = flatten(a.loaded.spec.model_dump(mode="json", by_alias=True))
    ib = flatten(b.loaded.spec.model_dump(mode="json", by_alias=True))
    units = _input_units(a) | _input_units(b)
    inputs = [
        {"field": k, "symbol": _input_symbol(b, k) or _input_symbol(a, k), "old": ia.get(k), "new": ib.get(k),
         "unit": units.get(k, "")}
        for k in sorted(set(ia) | set(ib)) if not same(ia.get(k), ib.get(k))
    ]
    pa = {p.name: p for p in a.study.balance.parameters}
    pb = {p.name: p for p in b.study.balance.parameters}
    params = []
    for name in list(pa) + [n for n in pb if n not in pa]:
        x, y = pa.get(name), pb.get(name)
        row = _change(x.value if x else None, y.value if y else None)
        row.update({"name": name, "unit": (x or y).unit, "source": (x or y).source})
        params.append(row)
    ma = {s.stage.name: s.metrics for s in a.study.stages}
    mb = {s.stage.name: s.metrics for s in b.study.stages}
    stages = []
    for name in list(ma) + [n for n in mb if n not in ma]:
        row: dict[str, Any] = {"name": name, "label": (mb.get(name) or ma[name]).label}
        for key in STAGE_KEYS:
            row[key] = _change(*(getattr(m[name], key) if name in m else None for m in (ma, mb)))
        va = next((s.validation for s in a.study.stages if s.stage.name == name), None)
        vb = next((s.validation for s in b.study.stages if s.stage.name == name), None)
        if va is not None or vb is not None:
            row["validation"] = {
                "force_residual": _change(getattr(va, "force_residual", None), getattr(vb, "force_residual", None)),
                "moment_residual": _change(getattr(va, "moment_residual", None), getattr(vb, "moment_residual", None)),
                "passed": {"old": getattr(va, "passed", None), "new": getattr(vb, "passed", None)},
            }
        stages.append(row)
    ra = {r["name"]: r for r in a.study.references}
    rb = {r["name"]: r for r in b.study.references}
    refs = [
        {"name": n, "published": (ra.get(n) or rb.get(n))["published"],
         "old": ra.get(n, {}).get("computed"), "new": rb.get(n, {}).get("computed"),
         "old_status": ra.get(n, {}).get("status"), "new_status": rb.get(n, {}).get("status")}
        for n in list(ra) + [n for n in rb if n not in ra]
        if not same(ra.get(n, {}).get("computed"), rb.get(n, {}).get("computed"))
        or ra.get(n, {}).get("status") != rb.get(n, {}).get("status")
    ]
    va, vb = side_verdict(a), side_verdict(b)
    return json_safe({
        "mounts": mounts_changes(a, b),
        "old": a.ref, "new": b.ref,
        "verdict": {"old": va, "new": vb, "still": still(va, vb)},
        "old_spec": a.loaded.spec.name, "new_spec": b.loaded.spec.name,
        "status": {"old": "ok" if a.study.ok else "failed", "new": "ok" if b.study.ok else "failed"},
        "inputs": inputs,
        "parameters": [p for p in params if not same(p["old"], p["new"])],
        "stages": stages,
        "references": refs,
    })


def _fmt(x: Any) -> str:
    if x is None:
        return "—"
    if isinstance(x, bool):
        return str(x).lower()
    if isinstance(x, float):
        return num(x, 6)  # the pages' numbers: 1500000, never 1.5e+06
    return str(x)


ROUND_OFF_TEXT = "0 (< tolerance)"
LONG_TEXT = 60  # an input longer than this (a description) is shown by its start and its length


def _short(x: Any) -> str:
    """An input's value for a row: a long text by its first words and its length."""
    t = _fmt(x)
    return t if len(t) <= LONG_TEXT else f"{t[:LONG_TEXT - 20].rstrip()}… ({len(t)} characters)"


def _cancelled(stage: dict) -> dict[tuple[str, str], bool]:
    """(load, side) -> whether a stage row's force or moment is round-off on that side: its
    ratio to the unbalanced peak at most :data:`ROUND_OFF`."""
    return {(w, side): isinstance(stage[f"{w}_ratio"][side], float) and stage[f"{w}_ratio"][side] <= ROUND_OFF
            for w in ("force", "moment") for side in ("old", "new")}


def _side_fmt(value: Any, cancelled: bool) -> str:
    """A load of one side: round-off (its ratio to the unbalanced peak at most :data:`ROUND_OFF`)
    reads ``0 (< tolerance)``, not as a number."""
    return ROUND_OFF_TEXT if cancelled and isinstance(value, float) else _fmt(value)


def _rel(d: dict) -> str:
    r = d.get("relative")
    if r is None:
        return ""
    if r == 0:
        return "="
    if not math.isfinite(r):
        return "new"
    return f"{'+' if r > 0 else ''}{num(100 * r, 3)} %"


def _frame_summary(side: Side) -> dict[str, dict]:
    """Per stage, what the frame on its mounts feels (none without a ``frame``): the largest peak
    floor force of any mount (N), the largest RMS vibration velocity along x or y of any point
    (m/s), and the verdicts against the spec's limits."""
    from .report.frame_mounts import mounts_json

    mounts = mounts_json(side.study)
    if mounts is None:
        return {}
    return {name: {"floor_force_peak": max(m["peak"] for m in st["mounts"]),
                   "velocity_rms": max(max(p["rms_x"], p["rms_y"]) for p in st["velocity"]),
                   "limits": "; ".join(f"{c['quantity']} at {c['where']}: {c['verdict']}" for c in st["limits"])}
            for name, st in mounts["stages"].items()}


def mounts_changes(a: Side, b: Side) -> list[dict]:
    """The frame on its mounts in both designs (:mod:`balpipe.report.frame_mounts`), per stage
    either side has: the largest floor force and RMS vibration velocity, old and new, and the
    limits' verdicts; empty when neither spec has a ``frame``."""
    fa, fb = _frame_summary(a), _frame_summary(b)
    rows = []
    for name in list(fa) + [n for n in fb if n not in fa]:
        x, y = fa.get(name, {}), fb.get(name, {})
        rows.append({"name": name, **{k: _change(x.get(k), y.get(k)) for k in ("floor_force_peak", "velocity_rms")},
                     "limits": {"old": x.get("limits"), "new": y.get("limits")}})
    return rows


def _rows(data: dict) -> list[tuple[str, list[list[str]], list[str]]]:
    """Sections as (title, rows, header) for the text and Markdown renderers: the verdict of each
    side first (is it still balanced?), the inputs that changed next, then what they did (stages,
    references, computed parameters). A stage is named by its label, as on the pages."""
    sections = []
    v = data.get("verdict")
    if v:
        sections.append(("Verdict", [["old", v["old"]["words"], "; ".join(v["old"]["costs"]) or "—"],
                                     ["new", v["new"]["words"], "; ".join(v["new"]["costs"]) or "—"]],
                         ["design", "verdict", "costs"]))
    sections.append(("Inputs", [[d.get("symbol") or "—", d["field"], _short(d["old"]), _short(d["new"]), d.get("unit", "")]
                                for d in data["inputs"]],
                     ["symbol (paper)", "field", "old", "new", "unit (SI)"]))
    rows: list[list[str]] = []
    sim: list[list[str]] = []
    for s in data["stages"]:
        # per side: a load cancelled to round-off reads 0 (< tolerance); cancelled in both designs,
        # it is not a change worth a row
        cancelled = _cancelled(s)
        quiet = {w: cancelled[w, "old"] and cancelled[w, "new"] for w in ("force", "moment")}
        for key in STAGE_KEYS:
            d = s[key]
            if same(d["old"], d["new"]) or any(quiet[w] and w in key for w in quiet):
                continue
            load = next((w for w in quiet if w in key), None)
            old_text, new_text = (_side_fmt(d[side], load is not None and cancelled[load, side]) for side in ("old", "new"))
            change = "cancelled" if new_text == ROUND_OFF_TEXT and old_text not in (ROUND_OFF_TEXT, "—") else _rel(d)
            rows.append([s.get("label") or s["name"], STAGE_NAMES.get(key, key), old_text, new_text, change])
        v = s.get("validation")
        if v:
            # the simulation's residuals are numerical noise, not a design change: their own section
            for key in ("force_residual", "moment_residual"):
                d = v[key]
                if not same(d["old"], d["new"]):
                    sim.append([s.get("label") or s["name"], f"pymunk {key.replace('_', ' ')} (vs reference load)", _fmt(d["old"]),
                                _fmt(d["new"]), _rel(d)])
            if v["passed"]["old"] != v["passed"]["new"]:
                rows.append([s.get("label") or s["name"], "pymunk validation passed", _fmt(v["passed"]["old"]), _fmt(v["passed"]["new"]), ""])
    sections.append(("Stages", rows, ["stage", "result", "old", "new", "change"]))
    if sim:
        sections.append(("Simulation residuals (numerical, not a design change)", sim,
                         ["stage", "residual", "old", "new", "change"]))
    labels = {s["name"]: s.get("label") or s["name"] for s in data["stages"]}
    frame: list[list[str]] = []
    mounts = data.get("mounts", [])
    # round-off of a side's largest value (its unbalanced stage's) reads 0; 0 on both sides is no change
    scale = {(key, w): max((abs(m[key][w]) for m in mounts if m[key][w] is not None), default=0.0)
             for key in ("floor_force_peak", "velocity_rms") for w in ("old", "new")}
    for m in mounts:
        label = labels.get(m["name"], m["name"])
        for key, what, k in (("floor_force_peak", "largest peak floor force (N)", 1.0),
                             ("velocity_rms", "largest RMS vibration velocity (mm/s)", 1000.0)):
            d = m[key]
            old, new = ("—" if d[w] is None else num_at(k * d[w], k * scale[key, w]) for w in ("old", "new"))
            if old != new:
                frame.append([label, what, old, new, _rel(d) if "0" not in (old, new) else ""])
        if m["limits"]["old"] != m["limits"]["new"]:
            frame.append([label, "against the limits", _fmt(m["limits"]["old"]), _fmt(m["limits"]["new"]), ""])
    if frame:
        sections.append(("The frame on its mounts", frame, ["stage", "result", "old", "new", "change"]))
    sections.append(("References", [[r["name"], _fmt(r["published"]), _fmt(r["old"]), _fmt(r["new"]), f"{_fmt(r['old_status'])} -> {_fmt(r['new_status'])}"] for r in data["references"]],
                     ["reference", "published", "old", "new", "status"]))
    sections.append(("Computed parameters", [[p["name"], _fmt(p["old"]), _fmt(p["new"]), _rel(p), p["unit"]] for p in data["parameters"]],
                     ["parameter", "old", "new", "change", "unit"]))
    return sections


def headline(sections: list) -> list[list[str]]:
    """The headline changes: the peak |F| and |M| rows of the stages, last stage first (the
    balanced design's before the unbalanced one's); only those of stages both designs have, where any."""
    rows = next((r for title, r, _ in sections if title == "Stages"), [])
    keys = (STAGE_NAMES["max_shaking_force"], STAGE_NAMES["max_shaking_moment"])
    peaks = [r for r in reversed(rows) if r[1] in keys]
    both = [r for r in peaks if "—" not in (r[2], r[3])]  # a stage of both designs before one that one lacks
    return (both or peaks)[:4]


def to_text(data: dict) -> str:
    out = [f"balpipe diff: {data['old']} ({data['status']['old']}) -> {data['new']} ({data['status']['new']})"]
    if data.get("verdict"):
        out.append(f"Verdict: {data['verdict']['still']}")
    for title, rows, header in _rows(data):
        out.append("")
        out.append(f"{title}:" if rows else f"{title}: no change")
        if rows:
            widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(header)]
            out.append("  " + "  ".join(h.ljust(w) for h, w in zip(header, widths)).rstrip())
            for r in rows:
                out.append("  " + "  ".join(c.ljust(w) for c, w in zip(r, widths)).rstrip())
    return "\n".join(out) + "\n"


def to_markdown(data: dict) -> str:
    out = [f"## balpipe diff: `{data['old']}` → `{data['new']}`", "",
           f"Status: {data['status']['old']} → {data['status']['new']}"]
    if data.get("verdict"):
        out += ["", f"**Verdict:** {data['verdict']['still']}"]
    for title, rows, header in _rows(data):
        out += ["", f"### {title}", ""]
        if not rows:
            out.append("No change.")
            continue
        out.append("| " + " | ".join(header) + " |")
        out.append("|" + "---|" * len(header))
        out += ["| " + " | ".join(c.replace("|", "\\|") for c in r) + " |" for r in rows]
    return "\n".join(out) + "\n"


def to_json(data: dict) -> str:
    return json.dumps(data, indent=2, sort_keys=True, ensure_ascii=False) + "\n"


def page_links(site: str, out: str | None, paths: tuple[str, str]) -> tuple[str, str]:
    """Each side's page on the report site (``site``: the site's index, as :func:`site_link`
    finds or is given it), '' where there is none: the page of the spec's file name
    (:func:`balpipe.site_files.spec_files.slug_for`); of a local site, only a page that exists.
    ``paths``: each side's file (the PATH of REV:PATH)."""
    from .site_files.spec_files import slug_for

    if not site:
        return "", ""
    base = site[: -len("index.html")] if site.endswith("index.html") else site.rstrip("/") + "/"
    local = Path(out).resolve().parent if out and "://" not in site else None
    links = []
    for path in paths:
        href = f"{base}{slug_for(Path(path))}/index.html"
        links.append(href if local is None or (local / href).exists() else "")
    return links[0], links[1]


def _file_of(ref: str) -> str:
    """The spec file of a side: the file, or the PATH of REV:PATH."""
    return ref if Path(ref).exists() or ":" not in ref else ref.split(":", 1)[1]


def to_html(data: dict, a: Side, b: Side, site: str = "", out: str | None = None) -> str:
    """The HTML page: each side's verdict and its page on the site first, the inputs next, then
    the results; per stage both designs' shaking loads in one interactive plot
    (:func:`balpipe.report.diff_overlay.overlay`), a load round-off in both designs drawn as zero
    and said so, not plotted as a signal."""
    from .draw import live
    from .report.diff_overlay import DIFF_NUMBERS, overlay
    from .report.render import environment

    figs = []
    names_b = {s.stage.name: s for s in b.study.stages}
    quiet = {s["name"]: tuple(c[w, "old"] and c[w, "new"] for w in ("force", "moment"))
             for s in data["stages"] for c in [_cancelled(s)]}
    for k, sa in enumerate(a.study.stages):
        sb = names_b.get(sa.stage.name)
        if sb is not None:
            qf, qm = quiet.get(sa.stage.name, (False, False))
            note = " and ".join(w for w, q in (("force", qf), ("moment", qm)) if q)
            figs.append((sb.stage.label, live.html(f"diff{k}", overlay(sa.analysis, sb.analysis, (qf, qm)), DIFF_NUMBERS),
                         note))
    sections = _rows(data)
    pages = page_links(site, out, (_file_of(str(a.loaded.path)), _file_of(str(b.loaded.path))))
    return environment().get_template("diff.html").render(d=data, sections=sections, figures=figs, site=site,
                                                          round_off=ROUND_OFF, headline=headline(sections),
                                                          pages=pages)


RENDERERS = {"text": to_text, "markdown": to_markdown, "json": to_json}
