"""A tabulated law: time and value columns of a CSV file, through a spline.

The CSV's header names the columns with their units in brackets or parentheses, e.g.
``t [s], crank [deg]`` (a column without a unit is in SI). Rows are numbers, times strictly
increasing. The law is a cubic spline through the rows (scipy's ``CubicSpline``, ends
``not-a-knot``, ``clamped`` (at rest), ``natural`` or ``periodic``) or a smoothing spline
(``make_smoothing_spline`` with the given penalty); q' and q'' are the spline's own derivatives,
so they are consistent with q to round-off. scipy is imported here only, when a table is built.

Errors are :class:`TableError` with the CSV row (1-based, the header is row 1): a row that is not
numbers, times not increasing, a table too coarse for a spline. A message quotes the column
names (at most 40 characters each) and numbers it parsed, never a row's text: a table's content
does not reach a message or a published page.
"""

from __future__ import annotations

import csv
import io
import re
from dataclasses import dataclass, field

import numpy as np

from .. import units
from ..model import Law

Triple = tuple[np.ndarray, np.ndarray, np.ndarray]

#: fewest rows of a table (a cubic spline through fewer cannot give a meaningful q'')
MIN_ROWS = 8
#: largest gap between two rows, as a multiple of the median spacing
MAX_GAP = 10.0

_HEADER = re.compile(r"^\s*(.*?)\s*(?:[\[(]\s*(.*?)\s*[\])])?\s*$", re.S)  # a quoted cell may hold line breaks


class TableError(ValueError):
    """A problem in a CSV table; ``row`` is the 1-based line of the file (None: the whole file)."""

    def __init__(self, message: str, row: int | None = None):
        super().__init__(message)
        self.row = row


@dataclass(frozen=True, eq=False)
class Table:
    """Parsed columns in SI: times (s) and values (the coordinate's SI unit)."""

    t: np.ndarray = field(repr=False)
    q: np.ndarray = field(repr=False)
    rows: tuple[int, ...] = field(repr=False)  # the file line of each sample


def _column(header: list[str], want: str | None, default: int, what: str) -> tuple[int, str]:
    names = [(_HEADER.match(h).group(1), _HEADER.match(h).group(2) or "") for h in header]
    if want is None:
        if default >= len(names):
            raise TableError(f"the header has {len(names)} column(s); the {what} column is missing", 1)
        return default, names[default][1]
    for k, (n, u) in enumerate(names):
        if n == want:
            return k, u
    raise TableError(f"no column {want!r} in the header (columns: {', '.join(_name(n) for n, _ in names)})", 1)


def _name(cell: str) -> str:
    """A column name as a message quotes it: stripped, at most 40 characters."""
    cell = " ".join("".join(c if c.isprintable() else " " for c in cell).split())  # one line, printable
    return cell if len(cell) <= 40 else cell[:39] + "…"


def parse_table(text: str, dimension: str, time_column: str | None = None,
                value_column: str | None = None, argument: str = "time", spline: bool = True) -> Table:
    """Parse the CSV ``text``: the time column and the value column of ``dimension`` (angle or
    length) converted to SI; raises :class:`TableError` with the row of the first problem.
    ``argument``: the dimension of the first column when it is not a time (a load's table
    against an angle or a stroke); ``spline`` False: a table interpolated linearly (a load's),
    which needs two rows, not a spline's eight and even spacing."""
    reader = csv.reader(io.StringIO(text, newline=None))  # universal newlines: \r, \r\n and \n end a row
    try:
        reader = list(reader)
    except csv.Error as exc:  # a NUL byte, a field too large: the message names no cell
        raise TableError(f"not a CSV table: {str(exc).split(' - ')[0]}", reader.line_num or None) from None
    lines = [(k + 1, r) for k, r in enumerate(reader) if r and any(c.strip() for c in r) and not r[0].lstrip().startswith("#")]
    if not lines:
        raise TableError("the file is empty (expected a header such as 't [s], angle [deg]' and rows of numbers)")
    head_row, header = lines[0]
    it, tu = _column(header, time_column, 0, "time")
    iv, vu = _column(header, value_column, 1, "value")
    factors = []
    for unit, dim, col in ((tu, argument, header[it]), (vu, dimension, header[iv])):
        if not unit:
            factors.append(1.0)
            continue
        try:
            factors.append(units.parse(f"1 {unit}", dim))
        except ValueError as exc:
            raise TableError(f"column {_name(col)!r}: {exc}", head_row) from None
    ts, qs, rows = [], [], []
    for row, cells in lines[1:]:
        try:
            tv, qv = float(cells[it]), float(cells[iv])
        except (ValueError, IndexError):
            # the cells are not quoted: a table's text is never echoed into a message (or a page)
            raise TableError(f"expected numbers in the columns {_name(header[it])!r} and {_name(header[iv])!r} "
                             f"(the row has {len(cells)} cell(s))", row) from None
        if not (np.isfinite(tv) and np.isfinite(qv)):
            raise TableError("not a finite number", row)
        for x, f, dim, col in ((tv, factors[0], "time", it), (qv, factors[1], dimension, iv)):
            if abs(x * f) > units.MAX_ABS[dim]:  # the spec's own limits (docs/limits.md), here not blamed on a joint
                raise TableError(f"column {_name(header[col])!r}: out of range: |{x * f:.4g}| {units.SI[dim]} exceeds "
                                 f"the limit {units.MAX_ABS[dim]:g} {units.SI[dim]}", row)
        if ts and not tv * factors[0] > ts[-1] and argument != "time":
            raise TableError(f"the {argument} column must increase: {tv:g} after {ts[-1] / factors[0]:g} on row {rows[-1]}", row)
        if ts and not tv * factors[0] > ts[-1]:
            raise TableError(f"times must increase: t = {tv:g} after {ts[-1] / factors[0]:g} on row {rows[-1]}", row)
        ts.append(tv * factors[0])
        qs.append(qv * factors[1])
        rows.append(row)
    if not spline:
        if len(ts) < 2:
            raise TableError("too coarse: a load table needs at least two rows of data")
        return Table(np.array(ts), np.array(qs), tuple(rows))
    if len(ts) < MIN_ROWS:
        raise TableError(f"too coarse: {len(ts)} rows of data; a spline with consistent accelerations needs at least {MIN_ROWS}")
    dt = np.diff(ts)
    med = float(np.median(dt))
    k = int(np.argmax(dt))
    if dt[k] > MAX_GAP * med:
        raise TableError(f"too coarse here: a gap of {dt[k]:.4g} s after row {rows[k]}, more than {MAX_GAP:g} times "
                         f"the median spacing {med:.4g} s; add rows", rows[k + 1])
    return Table(np.array(ts), np.array(qs), tuple(rows))


@dataclass(frozen=True, eq=False)
class Tabulated(Law):
    """The spline through (or near) a :class:`Table`'s samples, with its own first and second
    derivatives. ``ends``: not-a-knot, clamped (zero slope: starts and ends at rest), natural or
    periodic (the table then repeats with the period of its span); ``smoothing``: None for the
    interpolating spline, a penalty lambda >= 0 for ``make_smoothing_spline`` (ends natural)."""

    table: Table
    ends: str = "not-a-knot"
    smoothing: float | None = None

    def spline(self):
        cached = self.__dict__.get("_spline")
        if cached is None:
            from scipy.interpolate import CubicSpline, make_smoothing_spline

            t, q = self.table.t, self.table.q
            if self.smoothing is not None:
                cached = make_smoothing_spline(t, q, lam=self.smoothing)
            else:
                cached = CubicSpline(t, q, bc_type=self.ends)
            object.__setattr__(self, "_spline", cached)
        return cached

    @property
    def span(self) -> tuple[float, float]:
        return float(self.table.t[0]), float(self.table.t[-1])

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        s = self.spline()
        t0, t1 = self.span
        x = t0 + np.mod(t - t0, t1 - t0) if self.ends == "periodic" else t
        return s(x), s(x, 1), s(x, 2)
