"""The actuators' cost table in wide form: a row per stage, a group of columns per driver."""

from balpipe.report.effort_table import effort_table


def _row(stage, driver, peak, unit="N m"):
    return {"stage": stage, "label": stage.upper(), "driver": driver, "unit": unit, "peak": peak,
            "rms": peak / 2, "power": peak * 3}


def test_stages_are_rows_and_drivers_are_column_groups():
    rows = [_row(s, d, 10 * k + j) for k, s in enumerate(("u", "cw", "cr", "full")) for j, d in enumerate(("q1", "q2", "s"))]
    rows[-1]["unit"] = "N"
    t = effort_table(rows)
    assert [r["label"] for r in t["rows"]] == ["U", "CW", "CR", "FULL"]
    assert t["drivers"] == [("q1", "N m"), ("q2", "N m"), ("s", "N m")]  # the first row's unit of each driver
    for k, r in enumerate(t["rows"]):
        assert [c["peak"] for c in r["cells"]] == [10 * k, 10 * k + 1, 10 * k + 2]


def test_a_stage_without_a_drivers_row_has_a_gap():
    t = effort_table([_row("u", "q1", 1.0), _row("u", "q2", 2.0), _row("b:x", "q1", 3.0)])
    assert [[c and c["peak"] for c in r["cells"]] for r in t["rows"]] == [[1.0, 2.0], [3.0, None]]
