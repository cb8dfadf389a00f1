"""The time-series CSV's number text (:func:`balpipe.report.results.csv_rows`,
:func:`balpipe.display.csv_numbers.rows`): the same text as one %.12g format per row."""

from __future__ import annotations

import numpy as np

from balpipe.report.results import csv_rows


def _per_row(columns: list[np.ndarray]) -> str:
    data = np.column_stack(columns) + 0.0
    row = ",".join(["%.12g"] * data.shape[1]) + "\n"
    return "".join(row % tuple(r) for r in data.tolist())


def test_same_text_as_a_format_per_row_with_repeated_and_awkward_columns(rng):
    n = 37
    base = [rng.normal(size=n) * 10.0 ** rng.integers(-15, 15, size=n) for _ in range(6)]
    awkward = np.array([0.0, -0.0, np.nan, np.inf, -np.inf, 1e-300, -5e-324, 123456789012345.0, 1 / 3] * 5)[:n]
    ints = np.arange(n)  # an integer column is written as its float values
    columns = [base[0], base[1], base[0].copy(), awkward, base[2], ints, awkward.copy(), -base[1], base[3]]
    text = csv_rows(columns)
    assert text == _per_row(columns)
    assert "-0," not in text and ",-0\n" not in text  # no negative zero
    assert text.count("\n") == n and all(line.count(",") == len(columns) - 1 for line in text.splitlines())


def test_a_figures_cells_leave_what_is_not_finite_empty(rng):
    """csv_numbers.rows with ``missing``: NaN, inf and -inf as that text (a figure's CSV leaves
    them empty), every other value as one %.12g format per value writes it."""
    from balpipe.display.csv_numbers import rows

    n = 23
    a = rng.normal(size=n) * 10.0 ** rng.integers(-12, 12, size=n)
    b = np.array([np.nan, -0.0, np.inf, -np.inf, 1e-300, 5e-324, 1 / 3, -2.5] * 3)[:n]
    expected = "".join(",".join("" if not np.isfinite(v) else "%.12g" % (v + 0.0) for v in r) + "\n"
                       for r in zip(a.tolist(), b.tolist(), a.tolist()))
    assert rows([a, b, a], missing="") == expected
    assert rows([a, b], missing="") != rows([a, b])  # without it, as %.12g writes them
    assert rows([a, b]) == _per_row([a, b])
    assert rows([a], missing="") == _per_row([a])  # all finite: the same text


def test_one_row_one_column_and_no_rows():
    assert csv_rows([np.array([2.5])]) == "2.5\n"
    assert csv_rows([np.array([]), np.array([])]) == ""
    assert csv_rows([]) == ""


def test_the_file_written_by_pieces_is_the_whole_text(rng, tmp_path, monkeypatch):
    """The time-series file is written ROWS rows at a time (never whole in memory): the same
    bytes as the whole text, for pieces that cut the rows anywhere, through the build's writer."""
    from balpipe.report.results import CsvFile
    from balpipe.runtime.fsutil import write_new

    n = 53
    a, b = rng.normal(size=n), rng.normal(size=n) * 1e-9
    columns = [np.arange(n) * 0.01, a, b, a.copy(), -b]
    whole = "t,a,b,a2,mb\n" + csv_rows(columns)
    for rows in (1, 7, 52, 53, 1000):
        monkeypatch.setattr(CsvFile, "ROWS", rows)
        f = CsvFile("t,a,b,a2,mb", columns)
        assert f.text() == whole
        path = tmp_path / f"ts{rows}.csv"
        write_new(path, f)
        assert path.read_bytes() == whole.encode("utf-8")


#: the unit tags timeseries.csv's column names end with (SI)
UNIT_TAGS = ("_s", "_N", "_Nm", "_m", "_rad", "_m_s", "_rad_s", "_W")


def test_every_timeseries_column_names_its_unit(studies):
    """Every column of timeseries.csv ends in its SI unit: the efforts (N m or N by their
    driver), the joint reactions (forces N, moments and gear torques N m), the loads' series
    (a friction's rate in rad/s at a revolute), the frame load and the motion's columns; on a
    spec with gears, one with loads and friction, and a slider-driven one (an effort in N)."""
    from balpipe.report.results import timeseries_columns

    seen = set()
    for name in ("paper004_five_bar.yaml", "custom_four_bar_loaded.yaml", "custom_slider_driven_slider_crank_gravity.yaml"):
        cols = [c for c, _ in timeseries_columns(studies(name))]
        missing = [c for c in cols if not c.endswith(UNIT_TAGS)]
        assert not missing, (name, missing[:10])
        seen |= {c.rsplit(".", 1)[0].split(".", 1)[-1] + "." + c.rsplit("_", 1)[-1] for c in cols if ".effort." in c}
        if name == "paper004_five_bar.yaml":
            assert any(".reaction." in c and c.endswith(".Ft_N") for c in cols)
            assert any(".reaction." in c and c.endswith(".T_Nm") or c.endswith(".M_Nm") for c in cols)
        if name == "custom_four_bar_loaded.yaml":
            assert any(".load." in c for c in cols)
    assert any(s.endswith(".Nm") for s in seen) and any(s.endswith(".N") for s in seen), seen
