"""Issue 7, item 8 and issue 14, item 1: every numeric spec field accepts units of its kind and
refuses booleans, NaN, infinities, unit-less strings and magnitudes beyond the stated limits."""

from __future__ import annotations

import math
import typing
from pathlib import Path

import pytest
from pydantic import BaseModel, BeforeValidator

from balpipe import registry, units
from balpipe.loader import SpecErrors, load_text
from balpipe.spec import Deferred, Spec
from balpipe.spec_parts import SpecFieldError
from _edits import replaced

ROOT = Path(__file__).resolve().parents[1]
SCOTT = (ROOT / "specs" / "scott_russell.yaml").read_text()
OFFSET = (ROOT / "specs" / "offset_slider_crank.yaml").read_text()
FIVE = (ROOT / "specs" / "paper004_five_bar.yaml").read_text()


def _with(text: str, old: str, new: str) -> str:
    return replaced(text, old, new)


def _errors(text: str) -> str:
    with pytest.raises(SpecErrors) as e:
        load_text(text, "s.yaml")
    msg = str(e.value)
    assert "Input should be" not in msg, msg  # no raw pydantic wording
    return msg


def test_g_accepts_an_acceleration_with_its_unit():
    text = _with(SCOTT, "  samples: 501", "  samples: 501\n  gravity: true\n  g: 9.81 m/s^2")
    spec, _ = load_text(text, "s.yaml")
    assert spec.analysis.g == 9.81
    spec, _ = load_text(_with(SCOTT, "  samples: 501", "  samples: 501\n  g: 1 g0"), "s.yaml")
    assert spec.analysis.g == pytest.approx(9.80665)


def test_g_with_a_length_unit_is_a_located_error():
    msg = _errors(_with(SCOTT, "  samples: 501", "  samples: 501\n  g: 9.81 m"))
    assert "analysis.g" in msg and "not a acceleration" not in msg and "acceleration unit" in msg


@pytest.mark.parametrize("field,value,expect", [
    ("  g: {}", "9.81 m/s^2", 9.81),
    ("  balance_tolerance: {}", "1e-8", 1e-8),
])
def test_analysis_fields(field, value, expect):
    spec, _ = load_text(_with(SCOTT, "  samples: 501", "  samples: 501\n" + field.format(value)), "s.yaml")
    assert math.isclose(getattr(spec.analysis, field.split(":")[0].strip()), expect)


def test_validation_dt_accepts_a_time_unit():
    spec, _ = load_text(SCOTT + "validation:\n  dt: 0.5 ms\n", "s.yaml")
    assert spec.validation.dt == pytest.approx(5e-4)


def test_drive_velocities_accept_units_of_their_coordinate():
    text = _with(SCOTT, "law: quintic", "law: polynomial")
    text = _with(text, "crank: {from: -80 deg, to: 80 deg}",
                 "crank: {from: -80 deg, to: 80 deg, start_velocity: 60 rpm, end_acceleration: 90 deg/s^2}")
    spec, _ = load_text(text, "s.yaml")
    d = spec.motion.drive["crank"]
    assert d.start_velocity == pytest.approx(2 * math.pi) and d.end_acceleration == pytest.approx(math.pi / 2)
    registry.balance(spec)
    bad = _with(text, "start_velocity: 60 rpm", "start_velocity: 2 m/s")
    spec, _ = load_text(bad, "s.yaml")
    with pytest.raises(SpecFieldError) as e:
        registry.balance(spec)
    assert e.value.path == ("motion", "drive", "crank", "start_velocity") and "linear unit" in e.value.message


@pytest.mark.parametrize("value,words", [
    (".nan", "finite"), (".inf", "finite"), ("-.inf", "finite"), ("true", "boolean"), ("'0.2'", "no unit"),
    ("1.0e+300", "out of range"), ("1e300", "no unit"), ("[1, 2]", "a list"),
])
def test_lengths_refuse_nonsense(value, words):
    msg = _errors(_with(OFFSET, "offset: 30 mm", f"offset: {value}"))
    assert "mechanism.offset" in msg and words in msg


@pytest.mark.parametrize("old,new,path", [
    # the list: a drive's start velocity, analysis.g, validation.dt, a reference's
    # published value, the five-bar's counter-rotation ratio, a working mode
    ("crank: {from: -80 deg, to: 80 deg}", "crank: {from: -80 deg, to: 80 deg, start_velocity: .nan}",
     "motion.drive.crank.start_velocity"),
    ("  samples: 501", "  samples: 501\n  g: .nan", "analysis.g"),
    ("  samples: 501", "  samples: 501\n  g: true", "analysis.g"),
    ("  samples: 501", "  samples: 501\nvalidation:\n  dt: .inf", "validation.dt"),
    ("  samples: 501", "  samples: 501\nvalidation:\n  dt: true", "validation.dt"),
    ("  samples: 501", "  samples: 501\nvalidation:\n  iterations: true", "validation.iterations"),
    ("  samples: 501", "  samples: true", "analysis.samples"),
    ("  samples: 501", "  samples: 50.5", "analysis.samples"),
])
def test_scott_russell_fields_refuse_nan_inf_and_booleans(old, new, path):
    assert path in _errors(_with(SCOTT, old, new))


@pytest.mark.parametrize("old,new,path", [
    ("ratio: 1 ", "ratio: .nan ", "balancing.counter_rotation.ratio"),
    ("ratio: 1 ", "ratio: .inf ", "balancing.counter_rotation.ratio"),
    ("ratio: 1 ", "ratio: true ", "balancing.counter_rotation.ratio"),
    ("working_modes: [+1, -1]", "working_modes: [true, -1]", "mechanism.working_modes[0]"),
    ("working_modes: [+1, -1]", "working_modes: [1, 2]", "mechanism.working_modes[1]"),
    ("{name: U21, published: 0.768}", "{name: U21, published: .nan}", "references[4].published"),
    ("{name: U21, published: 0.768}", "{name: U21, published: false}", "references[4].published"),
])
def test_five_bar_fields_refuse_nan_inf_and_booleans(old, new, path):
    assert path in _errors(_with(FIVE, old, new))


def test_no_numeric_field_escapes_the_units_parsers():
    """Audit: every float or int field of every spec section (templates, methods, motion,
    analysis, validation, references) goes through a parser of balpipe.units (finite, no
    booleans, units of its kind)."""
    parsers = {units.parse.__code__, units._parse_count.__code__, units._parse_sign.__code__,
               units._rate_parser(1).__code__}
    seen: set[type] = set()
    unchecked: list[str] = []

    def guarded(meta) -> bool:
        for m in meta:
            if isinstance(m, BeforeValidator):
                code = getattr(m.func, "__code__", None)
                if code in parsers or (code is not None and code.co_filename == units.__file__):
                    return True
        return False

    def walk(tp, where: str, meta=()) -> None:
        origin = typing.get_origin(tp)
        if origin is typing.Annotated:
            args = typing.get_args(tp)
            walk(args[0], where, tuple(meta) + tuple(tp.__metadata__))
            return
        deferred = [m for m in meta if isinstance(m, Deferred)]  # a type resolved when the schema is built
        if deferred:
            walk(deferred[0].type(), where)
            return
        if tp in (float, int) or tp is typing.Any and meta:
            if not guarded(meta):
                unchecked.append(where)
            return
        if isinstance(tp, type) and issubclass(tp, BaseModel):
            if tp in seen:
                return
            seen.add(tp)
            for name, f in tp.model_fields.items():
                walk(f.annotation, f"{tp.__name__}.{name}", tuple(f.metadata))
            return
        if origin is typing.Literal:  # +1/-1 choices (units.Sign): a boolean equals 1, so they need a parser
            if set(typing.get_args(tp)) == {1, -1} and not guarded(meta):
                unchecked.append(where)
            return
        for a in typing.get_args(tp):
            walk(a, where, meta)

    walk(Spec, "Spec")
    assert len(seen) > 15
    assert not unchecked, "\n".join(unchecked)


def test_schema_says_numbers_or_strings_with_units():
    s = Spec.model_json_schema()
    g = s["$defs"]["AnalysisSettings"]["properties"]["g"]
    assert {"type": "number"} in g["anyOf"] and g["anyOf"][1]["type"] == "string"
