"""``balpipe.spec.validate``: a spec validated by the narrower class that holds only the sections it
names gives what the whole schema gives (the same values, the same errors), and the result is a
``Spec`` wherever one is read: its class name, pickle, equality and content hash."""

from __future__ import annotations

import copy
import pickle
import subprocess
import sys
from pathlib import Path

import pytest
import yaml
from pydantic import ValidationError

from balpipe import spec as spec_module
from balpipe.cache.content import digest_of
from balpipe.spec import Spec, named_sections

ROOT = Path(__file__).resolve().parents[1]
SPECS = sorted((ROOT / "specs").glob("*.yaml"))


def variants(data: dict):
    """The spec, and edits that a narrower class must refuse as the whole schema does."""
    yield "as written", data
    mech = data["mechanism"]
    for key in [k for k in mech if k != "template"][:3]:
        d = copy.deepcopy(data)
        del d["mechanism"][key]
        yield f"mechanism.{key} missing", d
        d = copy.deepcopy(data)
        d["mechanism"][key] = "x"
        yield f"mechanism.{key} a string", d
    d = copy.deepcopy(data)
    d["mechanism"]["extra"] = 1
    yield "unknown key in mechanism", d
    balancing = data.get("balancing")
    if isinstance(balancing, dict):
        d = copy.deepcopy(data)
        d["balancing"]["extra"] = 1
        yield "unknown key in balancing", d
        for key in [k for k in balancing if k != "method"][:2]:
            d = copy.deepcopy(data)
            d["balancing"][key] = [1, {}]
            yield f"balancing.{key} a list", d
        d = copy.deepcopy(data)
        d["compare"] = [{"name": "a", "balancing": copy.deepcopy(balancing)},
                        {"name": "b", "balancing": {"method": "moment_balance", "extra": 2}}]
        yield "two compared designs", d
    d = copy.deepcopy(data)
    d["motion"] = {}
    yield "empty motion", d
    for key, value in (("frame", {}), ("loads", [{"type": "nope"}]), ("sweep", {"vary": 5})):
        d = copy.deepcopy(data)
        d[key] = value  # an optional section present, and wrong
        yield f"{key} wrong", d
        if key in data:
            d = copy.deepcopy(data)
            del d[key]
            yield f"{key} left out", d


def outcome(cls: type, data: dict):
    try:
        return "valid", cls.model_validate(data)
    except ValidationError as exc:
        return "invalid", [(e["type"], e["loc"], e["msg"]) for e in exc.errors()]


@pytest.mark.parametrize("path", SPECS, ids=[p.name for p in SPECS])
def test_a_narrower_class_validates_as_the_whole_schema(path):
    data = yaml.safe_load(path.read_text(encoding="utf-8"))
    for what, d in variants(data):
        names = named_sections(d)
        assert names is not None and names[0] == d["mechanism"]["template"], what
        narrow = spec_module._narrowed(*names)
        kind, got = outcome(narrow, d)
        expected = outcome(Spec, d)
        assert (kind, got) == expected, (path.name, what)
        if kind == "valid":
            full = expected[1]
            assert type(got) is narrow and type(full) is Spec
            assert type(got).__qualname__ == "Spec" and repr(got) == repr(full)
            assert got.model_dump_json() == full.model_dump_json()
            assert got == full and full == got
            assert digest_of(got) == digest_of(full)  # the content caches' keys
            back = pickle.loads(pickle.dumps(got))
            assert type(back) is Spec and back == full and pickle.dumps(got) == pickle.dumps(full)


NONE = ("loads", "frame", "sweep")  # the optional sections a spec leaves out


@pytest.mark.parametrize("data, names", [
    ({"mechanism": {"template": "slider_crank"}}, ("slider_crank", (), NONE)),
    ({"mechanism": {"template": "custom"}, "balancing": {"method": "none"}, "frame": None}, ("custom", (), ("loads", "sweep"))),
    ({"mechanism": {"template": "custom"}, "balancing": {"method": "stages"}, "loads": [], "sweep": {},
      "compare": [{"balancing": {"method": "force_balance"}}]}, ("custom", ("force_balance", "stages"), ("frame",))),
    ({"mechanism": {"template": "nope"}}, None),
    ({"mechanism": {"template": ["slider_crank"]}}, None),
    ({"mechanism": "slider_crank"}, None),
    ({"mechanism": {"template": "custom"}, "balancing": {"method": "nope"}}, None),
    ({"mechanism": {"template": "custom"}, "balancing": None}, None),
    ({"mechanism": {"template": "custom"}, "compare": [{"name": "a"}]}, None),
    ({"mechanism": {"template": "custom"}, "compare": {"a": 1}}, None),
    ([], None),
])
def test_only_known_names_narrow(data, names):
    """A spec names its sections by known names, or the whole schema validates it (and its
    messages list every choice); the optional sections it leaves out are left out of its class."""
    assert named_sections(data) == names


def test_check_validates_with_the_narrower_class_and_prepare_with_the_whole_schema():
    """In a fresh process ``validate`` narrows until the whole schema is built; once it is
    (``loader.prepare``, before a pool forks), every spec goes through it."""
    probe = ("import sys\nfrom balpipe import loader, spec\n"
             "a = loader.load('specs/offset_slider_crank.yaml').spec\n"
             "print(type(a) is spec.Spec, sorted(m for m in sys.modules if m.startswith('balpipe.families.')"
             " and m.count('.') == 3))\n"
             "loader.prepare()\nb = loader.load('specs/offset_slider_crank.yaml').spec\n"
             "print(type(b) is spec.Spec, a == b)")
    out = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120, cwd=ROOT)
    assert out.stdout.splitlines() == [
        "False ['balpipe.families.slider_crank.specs', 'balpipe.families.slider_crank.template']",
        "True True"], out.stderr
