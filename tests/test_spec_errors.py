"""Bad input: a short located message (file:line:column: field path: what), never a traceback."""

import pytest

from balpipe import units
from balpipe.loader import SpecErrors, load_text, schema
from _edits import replaced

GOOD = """\
name: test
mechanism:
  template: slider_crank
  crank: {length: 0.2 m, mass: 1 kg, com: 0.1 m, inertia: 0.003 kg m^2}
  coupler: {length: 0.3 m, mass: 1 kg, com: 0.15 m, inertia: 0.007 kg m^2}
  slider: {mass: 500 g}
motion:
  duration: 0.5 s
  drive: {crank: {from: 0 deg, to: 90 deg}}
"""


def at(text: str, line: int, token: str) -> str:
    """file:line:column of the first ``token`` on ``line`` (1-based)."""
    return f"s.yaml:{line}:{text.splitlines()[line - 1].index(token) + 1}"


def errors(text: str) -> list[str]:
    with pytest.raises(SpecErrors) as exc:
        load_text(text, "s.yaml")
    return [str(e) for e in exc.value.errors]


def test_good_spec_loads_with_units():
    spec, _ = load_text(GOOD, "s.yaml")
    assert spec.mechanism.slider.mass == pytest.approx(0.5)
    assert spec.motion.drive["crank"].end == "90 deg"


def test_malformed_yaml():
    (e,) = errors(replaced(GOOD, "drive: {crank", "drive: [crank"))
    assert e.startswith("s.yaml:9:") and "malformed YAML" in e


def test_unknown_key_points_at_the_key():
    text = replaced(GOOD, "slider: {mass: 500 g}", "slider: {mass: 500 g, colour: red}")
    (e,) = errors(text)
    assert e == at(text, 6, "colour") + ": mechanism.slider.colour: unknown key (not part of the spec schema; check the spelling)"


def test_wrong_type():
    (e,) = errors(replaced(GOOD, "duration: 0.5 s", "duration: [1, 2]"))
    assert e.startswith("s.yaml:8:13: motion.duration:") and "time" in e


@pytest.mark.parametrize("old,new,line,token,where", [
    ("mass: 1 kg, com: 0.1 m", "mass: -1 kg, com: 0.1 m", 4, "-1 kg", "mechanism.crank.mass: must be >= 0"),
    ("length: 0.3 m", "length: -0.3 m", 5, "-0.3 m", "mechanism.coupler.length: must be > 0"),
    ("duration: 0.5 s", "duration: 0 s", 8, "0 s", "motion.duration: must be > 0"),
])
def test_negative_or_zero_values(old, new, line, token, where):
    text = replaced(GOOD, old, new)
    (e,) = errors(text)
    assert e.startswith(f"{at(text, line, token)}: {where}")


def test_wrong_unit_dimension():
    (e,) = errors(replaced(GOOD, "length: 0.2 m", "length: 0.2 deg"))
    assert "mechanism.crank.length: unit 'deg' is not a length unit" in e


def test_unknown_template_and_duplicate_key():
    (e,) = errors(replaced(GOOD, "template: slider_crank", "template: slider_crunk"))
    assert e.startswith("s.yaml:3:13: mechanism.template: unknown value 'slider_crunk'")
    (e,) = errors(GOOD + "name: again\n")
    assert e.startswith("s.yaml:10:1: name: duplicate key")


def test_several_errors_are_all_reported_in_line_order():
    text = replaced(replaced(GOOD, "mass: 1 kg, com: 0.1 m", "mass: -1 kg, com: 0.1 m"), "duration: 0.5 s", "duration: 0")
    es = errors(text)
    assert [e.split(":")[1] for e in es] == ["4", "8"]


def test_units_parse_and_reject():
    assert units.parse("30 deg", "angle") == pytest.approx(0.5235987755982988)
    assert units.parse("12 g", "mass") == pytest.approx(0.012)
    assert units.parse("0.5 kg m^2", "inertia") == 0.5
    assert units.parse("2 kg·cm²", "inertia") == pytest.approx(2e-4)
    assert units.parse(3, "length") == 3.0
    for bad in ("3 parsecs", "fast", True):
        with pytest.raises(ValueError):
            units.parse(bad, "length")


def test_schema_documents_every_field():
    s = schema()
    assert s["title"] == "balpipe spec"
    missing = []

    def walk(node, path):
        if isinstance(node, dict):
            for name, prop in node.get("properties", {}).items():
                target = prop
                if "$ref" in prop and "description" not in prop:
                    target = s["$defs"][prop["$ref"].split("/")[-1]]
                if "description" not in prop and "description" not in target and name not in ("template", "method", "type", "name", "a", "b"):
                    missing.append(f"{path}.{name}")
            for k, v in node.items():
                walk(v, f"{path}.{k}")
        elif isinstance(node, list):
            for v in node:
                walk(v, path)

    walk(s, "")
    assert not missing, missing
