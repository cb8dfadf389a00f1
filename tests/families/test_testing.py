"""balpipe.testing, the families' public conformance checks: each check passes on sound input
and fails, naming what is wrong, on input broken on purpose (a template without a label, a
family without examples, a stage that claims a balance it does not have, reactions that
disagree with the momentum rates, a mass scaling that forgets a part), and the physics checks
pass on slider-cranks of random dimensions, masses and gravity."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from balpipe import plugins, registry
from balpipe.testing import (Check, ConformanceError, FamilyCheckError, PhysicsError, check_example_physics,
                             check_family, family_cases, family_checks, physics)
from balpipe.testing.conformance import check_template, example_name, is_text, load_example
from balpipe.study import run

SLIDER_CRANK = next(f for f in plugins.discover() if f.name == "slider_crank")


def _text(rng: np.random.Generator, gravity: bool) -> str:
    L1 = rng.uniform(0.05, 0.3)
    L2 = rng.uniform(1.3, 3.0) * L1
    m1, m2, m3 = rng.uniform(0.2, 3.0, 3)
    return f"""\
name: random slider-crank
mechanism:
  template: slider_crank
  offset: {rng.uniform(-0.3, 0.3) * L1:.6f} m
  crank: {{length: {L1:.6f} m, mass: {m1:.5f} kg, com: {rng.uniform(0.1, 0.9) * L1:.6f} m, inertia: {m1 * L1 ** 2 / 12:.8f} kg m^2}}
  coupler: {{length: {L2:.6f} m, mass: {m2:.5f} kg, com: {rng.uniform(0.1, 0.9) * L2:.6f} m, inertia: {m2 * L2 ** 2 / 12:.8f} kg m^2}}
  slider: {{mass: {m3:.5f} kg}}
motion:
  law: quintic
  duration: {rng.uniform(0.1, 2.0):.4f} s
  drive:
    crank: {{from: 0 deg, to: {rng.uniform(90, 720):.3f} deg}}
balancing:
  method: slider_crank_counterweights
  crank_counterweight: {-rng.uniform(0.2, 1.0) * L1:.6f} m
  coupler_counterweight: {-rng.uniform(0.2, 1.0) * L2:.6f} m
analysis:
  samples: 151
  gravity: {str(gravity).lower()}
  moment_point: [{rng.uniform(-0.2, 0.2):.4f} m, {rng.uniform(-0.2, 0.2):.4f} m]
"""


@pytest.mark.parametrize("seed", range(6))
def test_physics_checks_pass_on_random_slider_cranks(seed):
    rng = np.random.default_rng(seed)
    text = _text(rng, gravity=bool(seed % 2))
    assert is_text(text) and example_name(text) == "random slider-crank"
    check_family(SLIDER_CRANK, examples=[text])


def test_checks_are_named_and_parametrisable():
    checks = family_checks(SLIDER_CRANK)
    names = [c.name for c in checks]
    assert names == ["discovered[slider_crank]", "template[slider_crank]", "method[slider_crank_counterweights]",
                     "examples_cover[slider_crank]", "example_model[offset_slider_crank]",
                     "example_physics[offset_slider_crank]"]
    assert all(isinstance(c, Check) for c in checks)
    cases = family_cases(SLIDER_CRANK)
    assert [c.id for c in cases] == names == [c.values[0].name for c in cases]


def test_a_template_without_a_label_fails():
    broken = replace(SLIDER_CRANK.templates[0], label=" ")
    with pytest.raises(ConformanceError, match="template 'slider_crank': empty label"):
        check_template(broken)
    family = replace(SLIDER_CRANK, templates=(broken,))
    with pytest.raises(FamilyCheckError) as err:
        check_family(family)
    text = str(err.value)
    assert "template[slider_crank]: ConformanceError" in text and "empty label" in text
    assert "discovered[slider_crank]: ConformanceError" in text  # not the registry's object either


def test_a_family_without_examples_fails():
    with pytest.raises(FamilyCheckError, match="has no examples"):
        check_family(replace(SLIDER_CRANK, examples=()))


def test_an_example_of_another_family_fails():
    other = next(f for f in plugins.discover() if f.name == "five_bar")
    with pytest.raises(FamilyCheckError) as err:
        check_family(SLIDER_CRANK, examples=other.examples)
    assert "no example uses slider_crank, slider_crank_counterweights" in str(err.value)
    assert "uses the template 'five_bar', not one of family 'slider_crank'" in str(err.value)


@pytest.fixture(scope="module")
def study():
    return run(load_example(SLIDER_CRANK.examples[0]).spec, page=False)


def test_a_claim_that_is_not_met_fails(study):
    unbalanced, balanced = study.stages
    physics.check_claims(balanced)
    liar = replace(unbalanced, stage=replace(unbalanced.stage, balances="force"))
    with pytest.raises(PhysicsError, match="claims to cancel the shaking force but keeps"):
        physics.check_claims(liar)
    liar = replace(balanced, stage=replace(balanced.stage, balances="force+moment"))
    with pytest.raises(PhysicsError, match="claims to cancel the shaking moment"):
        physics.check_claims(liar)


def test_reactions_that_disagree_with_the_momentum_fail(study):
    sr = study.stages[1]
    physics.check_reactions_equal_momentum(sr)
    ref = sr.metrics.reference_loads
    an = replace(sr.analysis, force=sr.analysis.force + np.array([1e-6 * ref.force, 0.0]))
    with pytest.raises(PhysicsError, match="reactions and the momentum rates disagree"):
        physics.check_reactions_equal_momentum(replace(sr, analysis=an))
    an = replace(sr.analysis, moment=sr.analysis.moment * (1 + 1e-6))
    with pytest.raises(PhysicsError, match="disagree"):
        physics.check_reactions_equal_momentum(replace(sr, analysis=an))


def test_a_mass_scaling_that_forgets_a_part_fails(study, monkeypatch):
    sr = study.stages[1]
    physics.check_mass_scaling(sr)
    honest = physics.scaled_masses

    def forgets_attachments(model, k):
        scaled = honest(model, k)
        return replace(scaled, bodies=tuple(replace(b, attachments=o.attachments)
                                            for b, o in zip(scaled.bodies, model.bodies)))

    monkeypatch.setattr(physics, "scaled_masses", forgets_attachments)
    with pytest.raises(PhysicsError, match="do not scale the loads"):
        physics.check_mass_scaling(sr)


def test_scaled_masses_scale_every_part():
    model = registry.unbalanced_model(load_example(SLIDER_CRANK.examples[0]).spec)
    big = physics.scaled_masses(model, 3.0)
    assert big.total_mass() == pytest.approx(3.0 * model.total_mass(), rel=1e-15)
    for b, o in zip(big.bodies, model.bodies):
        assert (b.points, b.com, b.outline) == (o.points, o.com, o.outline)
        assert b.mass_properties()[2] == pytest.approx(3.0 * o.mass_properties()[2], rel=1e-14)


def test_example_physics_runs_every_stage():
    check_example_physics(SLIDER_CRANK.examples[0])
