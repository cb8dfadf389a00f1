"""The papers' symbols for the inputs of a spec: small declarative tables, one per template and
balancing method, that the report's inputs table reads (:mod:`balpipe.report.inputs`).

A table maps a *path pattern* to a :class:`Sym`. A pattern is a spec field path
(``mechanism.links.proximal.mass``) in which ``<name>`` matches one key or list index and
captures it: ``mechanism.legs.<i>.proximal.mass`` matches ``mechanism.legs.3.proximal.mass``
with ``i = 3``; the capture is substituted into the symbol and the text. A symbol is written
in a small markup, rendered by :func:`symbol_html`: letters are variables (italic), ``_1`` or
``_{cw1}`` a subscript, ``^*`` or ``^{*}`` a superscript, ``'`` a prime; anything else is
copied. ``m_1 = m_2`` gives *m*\\ :sub:`1` = *m*\\ :sub:`2`.

The notation of a study is the method's table, then the template's, then :data:`COMMON`; the
first pattern that matches wins, so a method can rename the template's parts (the 3-RPR's
cylinder is link 1 of the idler loop's paper section and link 4 of the Scott-Russell legs').
A table may also be a function of the spec section (``custom`` names its symbols after the
spec's own bodies).
"""

from __future__ import annotations

import html
import re
from dataclasses import dataclass
from functools import lru_cache
from typing import Any, Callable, Mapping, Union


@dataclass(frozen=True)
class Sym:
    """One input's symbol (markup, see the module docstring), its meaning in words, and whether
    the symbol is the paper's (``paper=False``: a name of ours, marked "not in the paper"; a
    ``setting`` of balpipe's, such as the number of samples, is neither and is not marked)."""

    symbol: str
    text: str
    paper: bool = True
    unit: str | None = None  # for a plain number whose unit the spec's type does not carry
    setting: bool = False

    def filled(self, captures: Mapping[str, str]) -> "Sym":
        s, t = self.symbol, self.text
        for k, v in captures.items():
            s = s.replace(f"<{k}>", v)
            t = t.replace(f"<{k}>", v)
        return Sym(s, t, self.paper, self.unit, self.setting)


def ours(symbol: str, text: str, unit: str | None = None) -> Sym:
    """A symbol the paper does not use (a name of balpipe's, or a quantity the paper leaves out)."""
    return Sym(symbol, text, paper=False, unit=unit)


def setting(symbol: str, text: str, unit: str | None = None) -> Sym:
    """A setting of balpipe's (samples, tolerances, which designs to build): no paper quantity."""
    return Sym(symbol, text, paper=False, unit=unit, setting=True)


Table = Mapping[str, Sym]
TableSource = Union[Table, Callable[[Any], Table], None]


@lru_cache(maxsize=512)
def _pattern(key: str) -> re.Pattern:
    out, pos = [], 0
    for m in re.finditer(r"<(\w+)>", key):
        out.append(re.escape(key[pos:m.start()]))
        out.append(rf"(?P<{m.group(1)}>[^.\[\]]+)")
        pos = m.end()
    out.append(re.escape(key[pos:]))
    return re.compile("".join(out) + r"\Z")


def lookup(tables: list[Table], path: str) -> Sym | None:
    """The symbol of ``path`` from the first table with a matching pattern (exact keys first)."""
    for table in tables:
        if path in table:
            return table[path].filled({})
        for key, sym in table.items():
            if "<" in key:
                m = _pattern(key).match(path)
                if m:
                    return sym.filled(m.groupdict())
    return None


def table_of(source: TableSource, section: Any) -> Table:
    """A template's or method's table for this spec section (a mapping, a function of the
    section, or nothing)."""
    if source is None:
        return {}
    if callable(source):
        return source(section)
    return source


def symbol_html(markup: str) -> str:
    """HTML of a symbol: ``m_{CW1}`` -> ``<var>m</var><sub>CW1</sub>``; runs of one or two
    letters are ``<var>``, longer words and subscripts upright, a `name` in backticks is copied
    as it is (spec names with underscores); everything is escaped."""
    out: list[str] = []
    pos = 0
    while pos < len(markup):
        c = markup[pos]
        if c in "_^" and pos + 1 < len(markup):
            nxt = markup[pos + 1]
            if nxt == "{":
                end = markup.find("}", pos + 2)
                end = len(markup) if end < 0 else end
                body, pos = markup[pos + 2:end], end + 1
            else:
                body, pos = nxt, pos + 2
            tag = "sub" if c == "_" else "sup"
            out.append(f"<{tag}>{html.escape(body)}</{tag}>")
        elif c == "`":
            end = markup.find("`", pos + 1)
            end = len(markup) if end < 0 else end
            out.append(f'<span class="name">{html.escape(markup[pos + 1:end])}</span>')
            pos = end + 1
        elif c.isalpha():
            end = pos + 1
            while end < len(markup) and (markup[end].isalpha() or "\u0300" <= markup[end] <= "\u036f"):
                end += 1
            word = html.escape(markup[pos:end])
            # one- or two-letter runs are variables (italic); longer ones are words (law, method)
            out.append(f"<var>{word}</var>" if len(markup[pos:end].rstrip("\u0307\u0308")) <= 2 else word)
            pos = end
        else:
            out.append(html.escape(c))
            pos += 1
    return "".join(out)


_TEXT = re.compile(r"`([^`]*)`|([^\W\d_])_(\{[^}]*\}|\d+'?|[^\W\d_]'?)")


def text_html(text: str) -> str:
    """HTML of a description: ``A_jB_j`` -> A<sub>j</sub>B<sub>j</sub>, ``S_{1i}`` -> S<sub>1i</sub>
    (one digit run, one letter or a braced group), a `name` in backticks copied as it is."""
    out, pos = [], 0
    for m in _TEXT.finditer(text):
        out.append(html.escape(text[pos:m.start()]))
        if m.group(1) is not None:
            out.append(f'<span class="name">{html.escape(m.group(1))}</span>')
        else:
            sub = m.group(3)[1:-1] if m.group(3).startswith("{") else m.group(3)
            out.append(f"{html.escape(m.group(2))}<sub>{html.escape(sub)}</sub>")
        pos = m.end()
    out.append(html.escape(text[pos:]))
    return "".join(out)


def dotted(symbol: str, dots: int) -> str:
    """``θ_1`` -> ``θ̇_1`` (one dot) or ``θ̈_1`` (two): a time derivative over the base letter."""
    mark = {1: "\u0307", 2: "\u0308"}[dots]
    m = re.match(r"[^\W\d_]", symbol)
    if not m:
        return f"d{'^' + str(dots) if dots > 1 else ''}({symbol})/dt{'^' + str(dots) if dots > 1 else ''}"
    return symbol[:1] + mark + symbol[1:]


def drive_table(drives: Mapping[str, Sym], end_time: str = "t_f") -> Table:
    """Rows of ``motion.drive.<name>.*`` from the drives' coordinate symbols: start and end values
    q(0), q(t_f), and the polynomial law's end velocities and accelerations."""
    out: dict[str, Sym] = {}
    for name, s in drives.items():
        base = f"motion.drive.{name}"
        mk = Sym if s.paper else ours
        out[f"{base}.start"] = mk(f"{s.symbol}(0)", f"{s.text}: at the start")
        out[f"{base}.end"] = mk(f"{s.symbol}({end_time})", f"{s.text}: at the end")
        for i in ("start", "end"):
            at = "0" if i == "start" else end_time
            out[f"{base}.{i}[<k>]"] = mk(f"{s.symbol}({at})_<k>", f"{s.text}: component <k> at the {i}")
            out[f"{base}.{i}_velocity"] = ours(f"{dotted(s.symbol, 1)}({at})", f"{s.text}: rate at the {i} (polynomial law)")
            out[f"{base}.{i}_acceleration"] = ours(f"{dotted(s.symbol, 2)}({at})", f"{s.text}: second derivative at the {i} (polynomial law)")
        out[f"{base}.law"] = ours(f"law({s.symbol})", f"{s.text}: its own motion law")
        out[f"{base}.accel_fraction"] = ours(f"κ({s.symbol})", f"{s.text}: acceleration fraction of its trapezoidal law")
    return out


#: Inputs every spec has: the motion law, the analysis and the validation settings.
COMMON: dict[str, Sym] = {
    "mechanism.template": setting("template", "mechanism template"),
    "motion.law": setting("law", "motion law of the driven coordinates (quintic: the 3-4-5 polynomial)"),
    "motion.duration": ours("T", "duration of the motion"),
    "motion.accel_fraction": setting("κ", "trapezoidal law: fraction of the duration spent accelerating (and decelerating)"),
    "motion.drive.<d>.start": ours("<d>(0)", "driven coordinate <d> at the start"),
    "motion.drive.<d>.end": ours("<d>(T)", "driven coordinate <d> at the end"),
    "motion.drive.<d>.start[<k>]": ours("<d>(0)_<k>", "driven coordinate <d>, component <k>, at the start"),
    "motion.drive.<d>.end[<k>]": ours("<d>(T)_<k>", "driven coordinate <d>, component <k>, at the end"),
    "motion.drive.<d>.start_velocity": ours("<d>'(0)", "rate of <d> at the start (polynomial law)"),
    "motion.drive.<d>.end_velocity": ours("<d>'(T)", "rate of <d> at the end (polynomial law)"),
    "motion.drive.<d>.start_acceleration": ours("<d>''(0)", "second derivative of <d> at the start (polynomial law)"),
    "motion.drive.<d>.end_acceleration": ours("<d>''(T)", "second derivative of <d> at the end (polynomial law)"),
    "motion.drive.<d>.law": setting("law(<d>)", "the drive's own motion law"),
    "motion.drive.<d>.accel_fraction": setting("κ(<d>)", "the drive's acceleration fraction (trapezoidal law)"),
    # the laws of real machines (balpipe.laws, docs/motion.md)
    "motion.cycles": ours("n_c", "number of cycles of the periodic drives (sets the duration)"),
    "motion.drive.<d>.speed": ours("ω(<d>)", "constant speed of <d>"),
    "motion.drive.<d>.ramp": ours("T_r(<d>)", "time to reach the speed from rest (0: steady state)"),
    "motion.drive.<d>.period": ours("P(<d>)", "period of the law of <d>"),
    "motion.drive.<d>.profile": setting("profile(<d>)", "cam profile of <d>"),
    "motion.drive.<d>.rise": ours("β_r(<d>)", "fraction of the period rising"),
    "motion.drive.<d>.dwell": ours("β_d(<d>)", "fraction of the period dwelling at the high value"),
    "motion.drive.<d>.ret": ours("β_b(<d>)", "fraction of the period returning (return:)"),
    "motion.drive.<d>.mean": ours("a_0(<d>)", "constant term of the Fourier series of <d>"),
    "motion.drive.<d>.terms[<k>]": ours("(a, b)_<k>(<d>)", "Fourier coefficients of <d>, term <k> (from 0)"),
    "motion.drive.<d>.terms[<k>][<i>]": ours("(a, b)_<k>(<d>)", "Fourier coefficient <i> (0: cosine, 1: sine) of term <k>"),
    "motion.drive.<d>.file": setting("file(<d>)", "CSV table of <d>"),
    "motion.drive.<d>.time": setting("t column", "the table's time column"),
    "motion.drive.<d>.value": setting("q column", "the table's value column"),
    "motion.drive.<d>.ends": setting("ends(<d>)", "end conditions of the table's spline"),
    "motion.drive.<d>.smoothing": ours("λ(<d>)", "smoothing penalty of the table's spline"),
    "motion.drive.<d>.segments[<k>].law": setting("law_<k>(<d>)", "law of segment <k> of <d>'s cycle"),
    "motion.drive.<d>.segments[<k>].duration": ours("T_<k>(<d>)", "duration of segment <k> of <d>'s cycle"),
    "motion.drive.<d>.segments[<k>].to": ours("<d>_<k>", "value of <d> at the end of segment <k>"),
    "motion.drive.<d>.segments[<k>].by": ours("Δ<d>_<k>", "displacement of <d> over segment <k>"),
    "motion.drive.<d>.segments[<k>].speed": ours("ω_<k>(<d>)", "speed of <d> over segment <k>"),
    "motion.drive.<d>.segments[<k>].accel_fraction": setting("κ_<k>(<d>)", "acceleration fraction of segment <k>"),
    "motion.drive.<d>.segments[<k>].end_velocity": ours("<d>'_<k>", "velocity of <d> at the end of segment <k>"),
    "motion.drive.<d>.segments[<k>].end_acceleration": ours("<d>''_<k>", "acceleration of <d> at the end of segment <k>"),
    "motion.drive.<d>.components[<k>]": setting("component <k>", "the drive that component <k> of the path feeds"),
    "motion.drive.<d>.heading": setting("heading(<d>)", "the pose's angle follows the path's tangent"),
    "motion.drive.<d>.angle": ours("φ_0(<d>)", "the pose's angle (or its offset from the tangent)"),
    "motion.drive.<d>.path.type": setting("path(<d>)", "kind of path of <d>"),
    "motion.drive.<d>.path.<f>": ours("`<f>`(<d>)", "<f> of the path of <d>"),
    "motion.drive.<d>.path.<f>[<k>]": ours("`<f>`_<k>(<d>)", "<f> of the path of <d>, component <k>"),
    "motion.drive.<d>.path.<f>[<k>][<i>]": ours("`<f>`_<k>(<d>)", "<f> of the path of <d>: point <k>, component <i>"),
    "motion.drive.<d>.timing.<f>": ours("`<f>`(s)", "timing law of the arc length s of <d>: <f>"),
    "motion.drive.<d>.timing.segments[<k>].<f>": ours("`<f>`_<k>(s)", "segment <k> of the arc length's cycle: <f>"),
    "balancing.method": setting("method", "balancing method"),
    "compare[<k>].balancing.method": setting("method", "balancing method of a compared design"),
    "analysis.samples": setting("N", "time samples over the motion"),
    "analysis.gravity": setting("gravity", "gravity along −y"),
    "analysis.g": Sym("g", "gravitational acceleration"),
    "analysis.moment_point": setting("O", "point about which the shaking moment is taken"),
    "analysis.balance_tolerance": setting("ε", "a stage counts as balanced when its peak is at most this fraction of its reference"),
    "validation.enabled": setting("simulate", "simulate every stage in pymunk"),
    "validation.dt": setting("Δt", "pymunk time step"),
    "validation.stage_dt.<s>": setting("Δt(`<s>`)", "pymunk time step of stage <s>"),
    "validation.iterations": setting("iterations", "pymunk solver iterations per step"),
    "validation.tolerance": setting("ε_{sim}", "pymunk residuals pass below this fraction of the reference loads"),
    "validation.reactionless": setting("free frame", "free-floating frame demonstration"),
    "validation.max_refinement": setting("refinement", "a run that cannot resolve its error is rerun at steps down to the first divided by this, then unconfirmed"),
    # the generic finder's settings, shared by force_balance and moment_balance
    "balancing.rank_tolerance": setting("ε_{rank}", "finding the conditions numerically: a direction smaller than this fraction of the largest counts as round-off"),
    "balancing.samples": setting("N_{states}", "states the mechanism can reach at which its momentum is evaluated to find the conditions (0: automatic)"),
    "balancing.seed": setting("seed", "picks those states at random, the same ones at every build"),
    "balancing.polygon_sides": setting("n_{sides}", "sides of the polygon inscribed in each disc region"),
    # the frame on its mounts (docs/mounts.md): our names, no paper gives them
    "frame.mass": ours("m_f", "frame: mass"),
    "frame.inertia": ours("J_f", "frame: moment of inertia about its centre of mass"),
    "frame.com": ours("G_f", "frame: centre of mass"),
    "frame.mounts[<k>].at": ours("p_<k>", "mount <k> (from 0): where it holds the frame"),
    "frame.mounts[<k>].kx": ours("k_{x,<k>}", "mount <k>: stiffness along x"),
    "frame.mounts[<k>].ky": ours("k_{y,<k>}", "mount <k>: stiffness along y"),
    "frame.mounts[<k>].cx": ours("c_{x,<k>}", "mount <k>: viscous damping along x"),
    "frame.mounts[<k>].cy": ours("c_{y,<k>}", "mount <k>: viscous damping along y"),
    "frame.points[<k>].at": ours("r_<k>", "point <k> of the frame whose vibration velocity is reported"),
    "frame.limits.velocity_rms": ours("v_{lim}", "limit of the RMS vibration velocity (along x or y)"),
    "frame.limits.force_peak": ours("F_{lim}", "limit of the peak force of a mount on the floor"),
    "frame.resonance_band": setting("β_{res}", "an excitation order within this fraction of a natural frequency is near resonance"),
    # external loads (docs/loads.md): the usual quantities by name, any other field by its own
    "loads[<k>].type": setting("load <k>", "kind of external load <k> (from 0)"),
    "loads[<k>].stiffness": ours("k_<k>", "load <k>: spring stiffness"),
    "loads[<k>].preload": ours("F_{0,<k>}", "load <k>: spring preload"),
    "loads[<k>].damping": ours("c_<k>", "load <k>: viscous damping"),
    "loads[<k>].coefficient": ours("μ_<k>", "load <k>: Coulomb friction coefficient"),
    "loads[<k>].viscous": ours("c_{v,<k>}", "load <k>: viscous friction coefficient"),
    "loads[<k>].pin_radius": ours("r_{p,<k>}", "load <k>: pin radius of the bearing's friction"),
    "loads[<k>].area": ours("A_<k>", "load <k>: piston area"),
    "loads[<k>].<f>": ours("`<f>`_<k>", "load <k>: <f>"),
    "loads[<k>].<f>.<g>": ours("`<f>.<g>`_<k>", "load <k>: <f>, <g>"),
    "loads[<k>].<f>.<g>.<h>": ours("`<f>.<g>.<h>`_<k>", "load <k>: <f>, <g>, <h>"),
    "loads[<k>].<f>.<g>.<h>.<i>": ours("`<f>.<g>.<h>.<i>`_<k>", "load <k>: <f>, <g>, <h>, <i>"),
}


GROUPS = ("Geometry", "Mass parameters", "Motion", "Balancing method", "Analysis and validation")

_MASS_LEAVES = {"mass", "inertia", "com", "com_offset", "payload", "platform_split"}


def group_of(path: str, unit: str) -> str:
    """The group of an input in the table: geometry and mass parameters of the mechanism, its
    motion, the balancing method (with compared designs), analysis and validation settings, the
    external loads and the frame on its mounts."""
    head = path.split(".", 1)[0].split("[", 1)[0]
    if head == "motion":
        return "Motion"
    if head == "loads":
        return "External loads"
    if head == "frame":
        return "The frame on its mounts"
    if head in ("balancing", "compare"):
        return "Balancing method"
    if head in ("analysis", "validation"):
        return "Analysis and validation"
    leaves = set(re.split(r"[.\[\]]+", path))
    if unit in ("kg", "kg m^2") or leaves & _MASS_LEAVES:
        return "Mass parameters"
    return "Geometry"


# --- the names a page shows: drivers, parts and joints -------------------------------------------
#
# Beside the inputs, a family's table may name the model's *drivers* (the ``motion.drive.<name>``
# keys and the actuated joints whose efforts the pages tabulate), its *parts* (links,
# counterweights, counter-rotations, added discs), its *joints* and the method's computed
# *parameters* (``results.json``'s ``parameters`` and ``references``) in the paper's symbols: keys
# ``driver:<name>``, ``part:<name>``, ``joint:<name>`` and ``param:<name>`` (patterns as above,
# made by :func:`names_table`), looked up in the same order as the inputs (method, template, common).
# A name without a symbol stays the model's own; ``custom`` declares none, so its pages keep the
# spec's names.

KINDS = ("driver", "part", "joint", "param")

_SUBSCRIPT = dict(zip("0123456789+-=()aehijklmnoprstuvx", "₀₁₂₃₄₅₆₇₈₉₊₋₌₍₎ₐₑₕᵢⱼₖₗₘₙₒₚᵣₛₜᵤᵥₓ"))
_SUPERSCRIPT = {"*": "*", "'": "'", "2": "²", "3": "³"}


def names_table(drivers: Mapping[str, Sym] | None = None, parts: Mapping[str, Sym] | None = None,
                joints: Mapping[str, Sym] | None = None, params: Mapping[str, Sym] | None = None) -> Table:
    """Rows ``driver:<name>``, ``part:<name>``, ``joint:<name>``, ``param:<name>`` for a family's
    notation table: the paper's symbol of each model or parameter name (patterns such as
    ``theta<i>`` allowed)."""
    out: dict[str, Sym] = {}
    for kind, rows in zip(KINDS, (drivers, parts, joints, params)):
        out.update({f"{kind}:{name}": s for name, s in (rows or {}).items()})
    return out


def symbol_text(markup: str) -> str:
    """Plain text of a symbol, for plots and tooltips: ``θ_1`` -> ``θ₁``, ``θ_{11}`` -> ``θ₁₁``,
    ``m_1^*`` -> ``m₁*``; a subscript with a character that has no subscript form keeps an
    underscore (``m_{cp1}`` -> ``m_cp1``); backticks dropped."""
    out: list[str] = []
    pos = 0
    while pos < len(markup):
        c = markup[pos]
        if c in "_^" and pos + 1 < len(markup):
            if markup[pos + 1] == "{":
                end = markup.find("}", pos + 2)
                end = len(markup) if end < 0 else end
                body, pos = markup[pos + 2:end], end + 1
            else:
                body, pos = markup[pos + 1], pos + 2
            table = _SUBSCRIPT if c == "_" else _SUPERSCRIPT
            out.append("".join(table[ch] for ch in body) if all(ch in table for ch in body) else c + body)
        elif c == "`":
            pos += 1
        else:
            out.append(c)
            pos += 1
    return "".join(out)


@dataclass(frozen=True)
class Names:
    """The names a study's pages show for its drivers, parts and joints (``kind`` one of
    :data:`KINDS`), from its notation tables (:func:`names_table`). A joint named
    ``<body>-<body>`` without a row of its own (the bearing of a gear on its carrier, a mesh) is
    named after its two bodies when both have a symbol or are the frame."""

    tables: tuple[Table, ...] = ()

    def sym(self, kind: str, name: str) -> Sym | None:
        found = lookup(list(self.tables), f"{kind}:{name}")
        if found is not None or kind != "joint" or "-" not in name:
            return found
        ends = name.split("-")
        syms = [Sym("frame", "the frame") if e == "frame" else self.sym("part", e) for e in ends]
        if len(ends) != 2 or any(s is None for s in syms) or all(s.symbol == "frame" for s in syms):
            return None
        return Sym(f"{syms[0].symbol} – {syms[1].symbol}",
                   f"joint between {symbol_text(syms[0].symbol)} and {symbol_text(syms[1].symbol)}",
                   paper=all(s.paper for s in syms))

    def text(self, kind: str, name: str, spec_name: bool = False) -> str:
        """Plain text of ``name``'s symbol (``θ₁``), or ``name`` itself; ``spec_name``: followed
        by the model's name in brackets when they differ (``θ₁ [theta1]``), for plots."""
        s = self.sym(kind, name)
        if s is None:
            return name
        t = symbol_text(s.symbol)
        return f"{t} [{name}]" if spec_name and t != name else t

    def html(self, kind: str, name: str) -> str:
        """HTML of ``name``: the symbol (:func:`symbol_html`) with its meaning as a tooltip and the
        model's name after it, small and muted, so that it can be found in the spec, ``results.json``
        and ``timeseries.csv``; a symbol not in the paper says so; ``name`` escaped without one."""
        s = self.sym(kind, name)
        if s is None:
            return html.escape(name)
        tip = _TEXT.sub(lambda m: m.group(1) if m.group(1) is not None else symbol_text(m.group(2) + "_" + m.group(3)),
                        s.text) + ("" if s.paper else " (balpipe's name, not the paper's)")
        out = f'<span class="sym" title="{html.escape(tip)}">{symbol_html(s.symbol)}</span>'
        if not s.paper:
            out += ' <span class="muted">(ours)</span>'
        if symbol_text(s.symbol) == name:
            return out
        return out + f' <span class="spec-name" title="the name in the spec and the result files">{html.escape(name)}</span>'
