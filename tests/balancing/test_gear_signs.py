"""Counter-rotations found, not guessed: where the spec's gear signs cannot cancel the shaking
moment, moment_balance names the combination that does, every disc at once, and that combination
balances force and moment."""

from __future__ import annotations

import re

import pytest
import yaml

from balpipe import registry
from balpipe.balancing import gear_signs as GS
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError
from generic_specs import watt_six_bar
from test_generic_balancing import SPECS


def _named(message: str) -> list[float]:
    m = re.search(r"the ratios (.*) cancel the moment: set them", message)
    assert m, message
    return [float(part.split(":")[1]) for part in m.group(1).split(", ")]


def _balanced(d: dict, ratios: list[float]):
    for disc, r in zip(d["balancing"]["counter_rotations"], ratios):
        disc["ratio"] = r
    return registry.balance(Spec.model_validate(d))


def test_watt_six_bar_gear_signs_named_in_one_step():
    """Every disc turning with its gear (+1): one error names all five signs, and they work."""
    d = watt_six_bar([1, 1, 1, 1, 1])
    with pytest.raises(SpecFieldError) as err:
        registry.balance(Spec.model_validate(d))
    assert err.value.path == ("balancing", "counter_rotations")
    assert "would need a negative inertia" in err.value.message
    ratios = _named(err.value.message)
    assert len(ratios) == 5 and all(abs(r) == 1 for r in ratios)
    res = _balanced(d, ratios)
    assert res.stages[-1].balances == "force+moment"
    residual = next(p.value for p in res.parameters if p.name == "moment_residual")
    assert residual <= 1e-9
    assert all(p.value >= 0 for p in res.parameters if p.name.startswith("d_") and p.name.endswith(".inertia"))


def test_four_bar_every_wrong_combination_names_a_working_one():
    d = yaml.safe_load((SPECS / "custom_four_bar_balancing.yaml").read_text())
    d["balancing"].pop("fronts", None)
    with pytest.raises(SpecFieldError) as err:
        _balanced(d, [1, 1, 1])
    assert _balanced(d, _named(err.value.message)).stages[-1].balances == "force+moment"


def test_sign_combinations_fewest_reversals_first():
    combos = GS.sign_combinations([-1.0, 2.0])
    assert combos == [(1.0, 2.0), (-1.0, -2.0), (1.0, -2.0)]
    assert GS.working_ratios([1.0] * (GS.MAX_DISCS + 1), lambda r: True) is None
    assert GS.named(["a", "b"], [-1, 2.5]) == "a: -1, b: +2.5"


def test_gear_signs_find_balances_with_the_signs_it_found():
    """gear_signs: find: the Watt-II with every disc at +1 builds, force and moment cancelled, and
    the notes and parameters name the signs used."""
    d = watt_six_bar([1, 1, 1, 1, 1])
    d["balancing"]["gear_signs"] = "find"
    res = registry.balance(Spec.model_validate(d))
    assert res.stages[-1].balances == "force+moment"
    assert res.notes[0].startswith("Gear signs found (gear_signs: find): d_crank: -1, d_c1: -1, d_r4: +1, d_c2: +1, d_r6: -1")
    discs = res.details["moment_balance"]["discs"]
    assert [x["ratio"] for x in discs] == [-1, -1, 1, 1, -1] and all(x["inertia"] >= 0 for x in discs)
