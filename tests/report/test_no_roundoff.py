"""No round-off on show, no scientific notation, one ratio convention: every text node (and every
title, tooltip and label) of every page of the site built from specs/, the inline SVG figures'
text included, and the formatting functions that write them (balpipe.display.numbers)."""

from __future__ import annotations

import math
import re
from html.parser import HTMLParser
from pathlib import Path

import pytest

from balpipe.display import numbers

#: a number in e-notation: 6.939e-18, 1.48e-14, 3.6e-12, 1.363e+05
E_NOTATION = re.compile(r"(?<![\w.])[-+−]?\d+(?:\.\d+)?[eE][-+−]?\d+(?![\w.])")
#: a stated threshold or setting, written as in a spec: 1e-9, 1e3 (a power of ten, nothing measured)
THRESHOLD = re.compile(r"^1e-?[1-9]\d*$")
_SUP = str.maketrans("⁻⁰¹²³⁴⁵⁶⁷⁸⁹", "-0123456789")
#: a number written out with a power of ten: 2.753×10⁻¹¹
POWER = re.compile(r"(-?\d+(?:\.\d+)?)×10([⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)")
#: a plain number and the unit after it: 0.0003283 N, -0.08 m, 51.2 %
WITH_UNIT = re.compile(r"(?<![\w.×⁰¹²³⁴⁵⁶⁷⁸⁹])(-?\d+(?:\.\d+)?)(×10[⁻⁰¹²³⁴⁵⁶⁷⁸⁹]+)? ?(N m|N|kg m²|kg|W|%)(?![\w²])")


class _Texts(HTMLParser):
    """Every text node outside scripts, styles and the spec's own text (a <pre>: the YAML as its
    author wrote it), and every title, aria-label and alt."""

    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.stack: list[str] = []
        self.texts: list[str] = []

    def handle_starttag(self, tag, attrs):
        if tag not in ("br", "img", "input", "meta", "link", "hr", "col", "source", "wbr"):
            self.stack.append(tag)
        self.texts += [v for k, v in attrs if k in ("title", "aria-label", "alt") and v]

    def handle_startendtag(self, tag, attrs):
        self.texts += [v for k, v in attrs if k in ("title", "aria-label", "alt") and v]

    def handle_endtag(self, tag):
        if tag in self.stack:
            while self.stack.pop() != tag:
                pass

    def handle_data(self, data):
        if data.strip() and not ({"script", "style", "pre"} & set(self.stack)):
            self.texts.append(data)


def texts_of(html: str) -> list[str]:
    p = _Texts()
    p.feed(html)
    return p.texts


def _value(mantissa: str, power: str | None) -> float:
    v = float(mantissa)
    return v * 10.0 ** int(power[3:].translate(_SUP)) if power else v


def problems(html: str) -> list[str]:
    """What a page shows that it must not: e-notation (but for a threshold such as 1e-9), a
    written-out power of ten below 1e-9 (no quantity of a machine in its units is that small but
    round-off), a ratio below 1e-9 as a percentage, and a number with a unit at most 1e-9 of
    the largest number in that unit on the page (round-off of its quantity's scale)."""
    out = []
    texts = texts_of(html)
    largest: dict[str, float] = {}
    found = []
    for t in texts:
        for m in E_NOTATION.finditer(t):
            if not THRESHOLD.match(m.group()):
                out.append(f"e-notation {m.group()!r} in {t.strip()[:120]!r}")
        for m in POWER.finditer(t):
            if float(m.group(1)) != 1 and int(m.group(2).translate(_SUP)) < -9:
                out.append(f"round-off {m.group()!r} in {t.strip()[:120]!r}")
        for m in WITH_UNIT.finditer(t):
            v = abs(_value(m.group(1), m.group(2)))
            unit = m.group(3)
            largest[unit] = max(largest.get(unit, 0.0), v)
            found.append((v, unit, m.group(), t))
    for v, unit, what, t in found:
        if unit == "%":
            if 0 < v <= 100 * numbers.FLOOR:
                out.append(f"round-off ratio {what!r} in {t.strip()[:120]!r}")
        elif 0 < v <= numbers.FLOOR * largest[unit]:
            out.append(f"round-off {what!r} (the page's largest {largest[unit]:.4g} {unit}) in {t.strip()[:120]!r}")
    return out


@pytest.fixture(scope="module")
def site(shared_build) -> Path:
    """``balpipe build specs -o site --no-sim`` of every spec (the build tests/test_api.py reads
    too: the same key, built once a run)."""
    from conftest import SPECS

    folder, r = shared_build(tuple(sorted(p.name for p in SPECS.iterdir() if p.is_file())), "specs", "-o", "site", "--no-sim")
    assert r.returncode in (0, 1), r.stderr
    return folder / "site"


@pytest.fixture(scope="module")
def simulated_site(shared_build) -> Path:
    """``balpipe build specs -o site`` of every spec with its pymunk validation: the validation's
    tables, notes, reasons and residual plots' titles are words and numbers of the pages too."""
    from conftest import SPECS

    folder, r = shared_build(tuple(sorted(p.name for p in SPECS.iterdir() if p.is_file())), "specs", "-o", "site")
    assert r.returncode in (0, 1), r.stderr
    return folder / "site"


@pytest.mark.parametrize("which", ["site", "simulated_site"])
def test_no_page_of_the_site_shows_round_off_or_scientific_notation(which, request):
    site = request.getfixturevalue(which)
    pages = sorted(site.rglob("*.html"))
    assert len(pages) >= 20, pages  # the index and a page per spec
    bad = {str(p.relative_to(site)): problems(p.read_text(encoding="utf-8")) for p in pages}
    bad = {k: v for k, v in bad.items() if v}
    assert not bad, "\n".join(f"{k}: {len(v)}: " + "; ".join(v[:4]) for k, v in bad.items())


def test_the_scan_finds_what_the_site_used_to_show():
    """The scanner itself: the round-off the pages showed before (a design card's 6.939e-18, a
    panel title's 3.6e-12, 1.48e-14 %, an inertia of 2.753e-11) is found, thresholds are not."""
    page = ("<p>at (-0.08, 6.939e-18) m</p><svg><text>peak |F| / reference 3.6e-12</text></svg>"
            "<td>1.48e-14 %</td><td title='1.363e+05'>x</td><p>2.753×10⁻¹¹ kg m²; 5 kg m²</p>"
            "<p>peak 21140 N, residual 0.00000000000064 N; ratio 0.0000001 %</p>")
    found = problems(page)
    for shown in ("6.939e-18", "3.6e-12", "1.48e-14", "1.363e+05", "2.753×10⁻¹¹", "0.00000000000064 N", "0.0000001 %"):
        assert any(shown in f for f in found), (shown, found)
    assert problems("<p>0 (&lt; 1e-9 of reference); above 1e3 the page warns; 1×10⁻⁹; 0.0003283 N of 21 N</p>") == []


@pytest.mark.parametrize("x, shown", [
    (0.0789, "0.0789"), (-0.08, "-0.08"), (54.62, "54.62"), (136300.4, "136300"), (0.0003283, "0.0003283"),
    (21140.0, "21140"), (2.753e-11, "2.753×10⁻¹¹"), (None, "—"), (0.0, "0"), (-1e-300, "-1×10⁻³⁰⁰"),
])
def test_num_writes_fixed_point_decimals_never_e_notation(x, shown):
    assert numbers.num(x) == shown


def test_round_off_of_a_quantity_scale_reads_zero():
    assert numbers.num_at(2.753e-11, 0.37) == "0" and numbers.num_at(2.753e-4, 0.37) == "0.0002753"
    assert numbers.point((-0.08, 9.797e-18)) == "(-0.08, 0)" and numbers.point((0.0, 0.0)) == "(0, 0)"
    assert numbers.num_at(1e-12, 0.0) == "1×10⁻¹²"  # no scale: never hidden


def test_one_ratio_convention_percent_below_ten_times_factor_from_there():
    assert numbers.ratio(0.352) == "35.2 %" and numbers.ratio(6.74) == "674 %"
    assert numbers.ratio(41.73) == "× 41.7" and numbers.ratio(10.0) == "× 10"
    assert numbers.ratio(1.48e-16) == "0 (< 1e-9)" and numbers.ratio(3e-6, 1e-5) == "0 (< 1e-5)"
    assert numbers.factor(14.2) == "× 14.2" and numbers.factor(0.5) == "× 0.5" and numbers.factor(None) == "—"
    assert numbers.tol(1e-9) == "1e-9" and numbers.tol(1.56e-5) == "0.0000156" and numbers.tol(1000.0) == "1000"


def test_large_numbers_and_margins_are_written_out():
    assert numbers.beyond(3.58e14) == "10¹⁴" and numbers.num(3.58e14) == "3.58×10¹⁴"
    assert all(not math.isnan(float(numbers.num(x))) for x in (1.0, 999999.0, 123456789.0))
