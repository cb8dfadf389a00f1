"""Issue 14, item 5: a fuzz suite over the loader and the command line.

Random YAML documents and mutations of every spec in ``specs/`` (dropped, renamed and duplicated
keys, swapped types, NaN, inf, 1e308, -0, negatives, zeros, empty and enormous lists, deep
nesting, unicode and control characters, aliases), and mutated CSV table files read by a motion
and by a path's timing. Every case must end with a located message (exit 2) or a valid result,
never a traceback or a hang.

The default run takes a small fixed-seed sample (hypothesis ``derandomize``); ``--long`` (or
``BALPIPE_LONG_TESTS=1``) a larger one, still fixed. A long random run by hand:

    BALPIPE_FUZZ=long python -m pytest -q tests/test_fuzz.py -s

(``BALPIPE_FUZZ_EXAMPLES=N`` sets the examples per test; the run prints the number of cases.)
"""

from __future__ import annotations

import copy
import math
import os
import re
from pathlib import Path

import pytest
import yaml
from hypothesis import HealthCheck, example, given, settings
from hypothesis import strategies as st

from balpipe.cli import main
from balpipe.loader import SpecError, SpecErrors, load_text
from _long import sample
from test_motion_specs import FOUR_BAR, TWO_R_TIP

ROOT = Path(__file__).resolve().parents[1]
SPEC_FILES = sorted((ROOT / "specs").glob("*.yaml"))
LONG = os.environ.get("BALPIPE_FUZZ") == "long"
N = int(os.environ.get("BALPIPE_FUZZ_EXAMPLES", "0"))
COUNT = {"loader": 0, "mutations": 0, "cli": 0, "tables": 0}


def fuzz_settings(ci: int, long: int, short: int | None = None):
    """``short`` fixed-seed examples by default (``ci`` when not given), ``ci`` with ``--long``,
    ``long`` random ones with BALPIPE_FUZZ=long."""
    return settings(
        max_examples=N or (long if LONG else sample(ci if short is None else short, ci)),
        derandomize=not LONG,  # CI: fixed seed, the same cases every run
        deadline=None,
        database=None,
        suppress_health_check=list(HealthCheck),
    )


def _base(path: Path) -> dict:
    data = yaml.safe_load(path.read_text())
    data.setdefault("analysis", {})["samples"] = 21  # a small grid: the fuzz looks for crashes
    data.setdefault("validation", {})["enabled"] = False
    return data


BASES = [_base(p) for p in SPEC_FILES]

# --- strategies -------------------------------------------------------------------------------

CONTROL = "".join(map(chr, [0, 1, 7, 8, 0x0B, 0x0C, 0x1B, 0x7F, 0x85, 0x9B]))
text_st = st.text(alphabet=st.characters(codec="utf-8") | st.sampled_from(list(CONTROL) + list("$\\{}<>&'\"")),
                  max_size=30)
weird_numbers = st.sampled_from([math.nan, math.inf, -math.inf, 1e308, -1e308, -0.0, 0, -1, 1e-300, 10**30,
                                 2**63, 3, 0.5, -2.5])
scalars = (weird_numbers | st.floats(allow_nan=True, allow_infinity=True) | st.integers(-10**20, 10**20)
           | st.booleans() | st.none() | text_st
           | st.sampled_from(["0.2 m", "30 deg", "12 g", "9.81 m/s^2", "1 kg m^2", "nan m", "0.2", "x m", "-0 s"]))
documents = st.recursive(
    scalars,
    lambda kids: st.lists(kids, max_size=6) | st.dictionaries(text_st | st.sampled_from(
        ["name", "mechanism", "motion", "template", "drive", "from", "to", "method", "mass", "length"]), kids,
        max_size=6),
    max_leaves=40,
)


def _paths(data, prefix=()):
    """Every (container, key) in a spec document."""
    out = []
    if isinstance(data, dict):
        for k in list(data):
            out.append((data, k))
            out += _paths(data[k], prefix + (k,))
    elif isinstance(data, list):
        for i in range(len(data)):
            out.append((data, i))
            out += _paths(data[i], prefix + (i,))
    return out


replacement = st.one_of(
    scalars,
    st.just([]), st.just({}),
    st.builds(lambda n: [0.1] * n, st.sampled_from([0, 1, 3, 5000])),
    st.integers(1, 70).map(lambda d: _nest(d)),
)


def _nest(depth: int):
    v: object = 1.0
    for _ in range(depth):
        v = [v]
    return v


NUMBER_WITH_UNIT = re.compile(r"^\s*([-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?)(\s*.*)$")


def _scale(value, factor):
    """``value`` (a number or 'number unit') multiplied by ``factor``, unit kept."""
    if isinstance(value, bool):
        return value
    if isinstance(value, (int, float)):
        return value * factor
    m = NUMBER_WITH_UNIT.match(value)
    return f"{float(m.group(1)) * factor:.6g}{m.group(2)}"


def _numeric_leaves(data):
    return [(c, k) for c, k in _paths(data)
            if (isinstance(c[k], (int, float)) and not isinstance(c[k], bool))
            or (isinstance(c[k], str) and NUMBER_WITH_UNIT.match(c[k]))]


@st.composite
def mutated_spec(draw) -> str:
    """A spec of specs/ with a few mutations, as YAML text: half of them only rescale numbers
    (so that many stay valid and reach the analysis and the page), the others break the
    structure and the types."""
    data = copy.deepcopy(draw(st.sampled_from(BASES)))
    if draw(st.booleans()):
        for _ in range(draw(st.integers(1, 3))):
            parent, key = draw(st.sampled_from(_numeric_leaves(data)))
            parent[key] = _scale(parent[key], draw(st.sampled_from([-1, 0, 0.5, 0.9, 1.1, 2, 10, 1e3, 1e-3, -0.0])))
        return yaml.safe_dump(data, allow_unicode=True, sort_keys=False, width=10**6)
    for _ in range(draw(st.integers(1, 3))):
        places = _paths(data)
        if not places:
            break
        parent, key = draw(st.sampled_from(places))
        op = draw(st.sampled_from(["drop", "rename", "replace", "replace", "replace", "scale"]))
        if op == "drop":
            del parent[key]
        elif op == "rename" and isinstance(parent, dict):
            parent[draw(text_st)] = parent.pop(key)
        elif op == "scale" and isinstance(parent[key], (int, float)) and not isinstance(parent[key], bool):
            parent[key] = parent[key] * draw(st.sampled_from([-1, 0, 1e-12, 1e6, 1e300]))
        else:
            parent[key] = draw(replacement)
    text = yaml.safe_dump(data, allow_unicode=True, sort_keys=False, width=10**6)
    extra = draw(st.sampled_from(["none", "none", "duplicate", "alias", "bomb", "control", "garbage"]))
    lines = text.splitlines(keepends=True)
    if extra == "duplicate" and lines:
        i = draw(st.integers(0, len(lines) - 1))
        lines.insert(i, lines[i])
    elif extra == "alias":
        lines.append("extra: &x [1, 2, *x]\n" if draw(st.booleans()) else "x: &y {a: 1}\nz: *y\n")
    elif extra == "bomb":
        lines.append("bomb: &b0 [1, 1, 1, 1, 1, 1, 1, 1]\n")
        for k in range(1, 9):
            lines.append(f"b{k}: &b{k} [" + ", ".join([f"*b{k - 1}"] * 8) + "]\n")
    elif extra == "control" and lines:
        i = draw(st.integers(0, len(lines) - 1))
        lines[i] = lines[i].rstrip("\n") + draw(st.sampled_from(list(CONTROL))) + "\n"
    elif extra == "garbage" and lines:
        i = draw(st.integers(0, len(lines) - 1))
        lines[i] = draw(st.sampled_from(["{", "]", ": :", "- - -", "\t", "%YAML 9.9\n", "!!python/object:os.system x"])) + lines[i]
    return "".join(lines)


LOCATED = re.compile(r"^s\.yaml(:\d+:\d+)?: .+")


def _assert_located(exc: SpecErrors) -> None:
    assert exc.errors, "an empty error list"
    for e in exc.errors:
        assert isinstance(e, SpecError) and e.message
        assert LOCATED.match(str(e)), str(e)
        assert "Traceback" not in e.message and "Input should be" not in e.message, e.message


def _load_or_fail_located(text: str) -> None:
    """The loader takes ``text`` or refuses it with located errors only, never another exception."""
    try:
        load_text(text, "s.yaml")
    except SpecErrors as exc:
        _assert_located(exc)


# --- the suite --------------------------------------------------------------------------------

@fuzz_settings(ci=150, long=20000)
@given(documents)
@example({"\x85\x85": None})  # found by the long run: a key of line breaks made a two-line message
@example({"": 1, " a": 2})
def test_random_documents_load_or_fail_located(doc):
    COUNT["loader"] += 1
    _load_or_fail_located(yaml.safe_dump(doc, allow_unicode=True) if not isinstance(doc, str) else doc)


@fuzz_settings(ci=60, long=8000)
@given(mutated_spec())
# found by the long run: a key containing '[' was taken for a pydantic validator name (IndexError)
@example("name: x\n'[': 1\n")
@example("name: x\n'function-after[x]': 1\n")
def test_mutated_specs_load_or_fail_located(text):
    COUNT["mutations"] += 1
    _load_or_fail_located(text)


@fuzz_settings(ci=10, long=1500, short=3)  # each case a build: 3 by default
@given(mutated_spec())
def test_cli_check_and_build_on_mutated_specs(tmp_path_factory, text):
    """The whole pipeline on mutated specs: check, then build when check passes; exit 0, 1 or 2
    with messages, never an exception."""
    COUNT["cli"] += 1
    d = tmp_path_factory.mktemp("fuzz")
    (d / "s.yaml").write_text(text, encoding="utf-8")
    rc = main(["check", str(d / "s.yaml")])
    assert rc in (0, 2)
    COUNT["cli_valid"] = COUNT.get("cli_valid", 0) + (rc == 0)
    if rc == 0:
        rb = main(["build", str(d / "s.yaml"), "-o", str(d / "out"), "--no-sim", "-q"])
        assert rb in (0, 1), "check passed but build refused the spec"


# --- table files ------------------------------------------------------------------------------

TABLE_SPEC = (FOUR_BAR.replace("analysis: {samples: 201}", "analysis: {samples: 21}")
              + "motion:\n  duration: 1 s\n  drive:\n    crank: {law: table, file: crank.csv, ends: periodic}\n")
TIMING_SPEC = TWO_R_TIP.replace("analysis: {samples: 201}", "analysis: {samples: 21}").replace(
    "timing: {law: quintic}", "timing: {law: table, file: crank.csv, ends: clamped}")
GOOD_ROWS = [(k / 20, 30 * (1 - math.cos(2 * math.pi * k / 20))) for k in range(21)]
#: the timing's arc length s (m) along TWO_R_TIP's polyline (0.15 m + 0.15 m, a fillet cut), at rest at both ends
TIMING_ROWS = [(k / 20, 0.28 * (k / 20 - math.sin(2 * math.pi * k / 20) / (2 * math.pi))) for k in range(21)]
cells = st.sampled_from(["nan", "inf", "-inf", "1e308", "-1e308", "1e400", "0", "-0", "", " ", "x", "1,5", '"1"',
                         "1e5", "1e7", "\x00", "\ufeff0", "0x10", "1_000", "٣"]) | st.floats(allow_nan=True) | text_st
headers = st.sampled_from(["t [s], crank [deg]", "t [ms], crank [rad]", "t, crank", "t [s]", "t [s], crank [mm]",
                           "\ufefft [s], crank [deg]", "t (s); crank (deg)", "", "# comment", "t [s], crank [deg], x",
                           "t [xyz], crank [deg]", "t [s], crank [kg]"]) | text_st


@st.composite
def table_file(draw, good: list, good_header: str) -> bytes:
    """A CSV table: the good one, then a few of its rows and cells replaced, rows dropped,
    duplicated or shuffled, the header changed, line endings and encodings changed, bytes added."""
    rows = [[repr(t), repr(q)] for t, q in good]
    for _ in range(draw(st.integers(0, 4))):
        kind = draw(st.sampled_from(["cell", "drop", "dup", "swap", "extra", "short", "many"]))
        if not rows:
            break
        i = draw(st.integers(0, len(rows) - 1))
        if kind == "cell":
            rows[i][draw(st.integers(0, len(rows[i]) - 1))] = str(draw(cells))
        elif kind == "drop":
            rows.pop(i)
        elif kind == "dup":
            rows.insert(i, list(rows[i]))
        elif kind == "swap":
            j = draw(st.integers(0, len(rows) - 1))
            rows[i], rows[j] = rows[j], rows[i]
        elif kind == "extra":
            rows[i].append(str(draw(cells)))
        elif kind == "short":
            rows[i] = rows[i][:1]
        else:
            rows = rows * draw(st.integers(2, 50))
    header = draw(st.just(good_header) | headers)
    sep = draw(st.sampled_from(["\n", "\r\n", "\r"]))
    text = sep.join([header] + [", ".join(r) for r in rows]) + sep
    enc = draw(st.sampled_from(["utf-8", "utf-8-sig", "utf-16", "latin-1"]))
    data = text.encode(enc, errors="replace")
    if draw(st.booleans()):
        data += draw(st.binary(max_size=40))
    return data


@fuzz_settings(ci=40, long=5000, short=12)  # each case a check of a small spec
@example((False, b'"\n0.0, 0.0\n' + b"".join(f"{t!r}, {q!r}\n".encode() for t, q in GOOD_ROWS[1:])))  # found by the long run
@example((False, b"t [s], crank [deg]\r" + b"".join(f"{t!r}, {q!r}\r".encode() for t, q in GOOD_ROWS)))  # CR line ends
@given(st.booleans().flatmap(lambda timing: st.tuples(st.just(timing), table_file(
    TIMING_ROWS if timing else GOOD_ROWS, "t [s], s [m]" if timing else "t [s], crank [deg]"))))
def test_table_files_check_or_fail_located(tmp_path_factory, case):
    """A table file of any content, read by a motion or a path's timing: ``check`` passes or
    refuses it with located lines (exit 2) that quote no row of it; never an exception."""
    import contextlib
    import io

    timing, data = case
    COUNT["tables"] += 1
    COUNT["tables_valid"] = COUNT.get("tables_valid", 0)
    d = tmp_path_factory.mktemp("table")
    (d / "crank.csv").write_bytes(data)
    spec = d / "s.yaml"
    spec.write_text(TIMING_SPEC if timing else TABLE_SPEC)
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        rc = main(["check", str(spec)])
    assert rc in (0, 2), err.getvalue()
    COUNT["tables_valid"] += rc == 0
    for line in err.getvalue().splitlines()[:-1]:  # the last is the summary
        assert re.match(rf"{re.escape(str(spec))}:\d+:\d+: \S", line) and "Traceback" not in line, line
        assert "internal error" not in line and "computation failed" not in line, line


def test_fuzz_report():
    """Prints the number of cases run (for the long run's record)."""
    print(f"\nfuzz cases: {COUNT} (long={LONG})")
    assert True
