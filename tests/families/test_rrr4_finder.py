"""Issue 8's 4-RRR acceptance: the generic condition finder against paper 001's printed
conditions (eq. 17; eqs. 19, 21 with a translating platform), the leg-by-leg solution in its space,
and the least-mass design beside the leg-by-leg one."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe import registry, study
from balpipe.balancing import conditions as C
from balpipe.balancing import least_mass as LM
from balpipe.balancing import regressor as R
from balpipe.families.rrr4 import counter_masses as recipe
from balpipe.families.rrr4 import conditions as cond
from balpipe.families.rrr4 import finder as G
from balpipe.engine import analyse
from balpipe.families.rrr4.template import mass_parameters
from balpipe.balancing.parts import add_counterweight
from test_rrr4 import paper_data, regular_random, spec_of, special_data

TOL = 1e-9


def test_finder_parameters_are_the_papers():
    """Body frames match the paper's p, q: the finder's parameter vector is mass_parameters mapped."""
    model = registry.unbalanced_model(spec_of(paper_data()))
    names = R.param_names(model)
    p = R.parameters(model)
    mp = mass_parameters(model)
    assert len(mp) == len(names) == 27
    for k, v in mp.items():
        assert p[names.index(G.finder_name(k))] == pytest.approx(v, abs=1e-15), k
    assert G.finder_name("m12p12") == "mx[link12]" and G.finder_name("m41q41") == "my[link41]"
    assert G.finder_name("m5") == "m[platform]" and G.finder_name("m5q5") == "my[platform]"


def _case(seed: int | None, base: int):
    """The paper's manipulator (``seed`` None) or a regular random one (seed ``base + seed``):
    its spec and unbalanced model."""
    if seed is None:
        spec = spec_of(paper_data())
        return spec, registry.unbalanced_model(spec)
    _, spec, model = regular_random(base + seed)
    return spec, model


@pytest.mark.parametrize("seed", [None, 0, 1, 2])
def test_twelve_general_conditions_and_eq17_lies_in_their_space(seed):
    """12 conditions; each printed row of eq. 17 within 1e-9 of their space; a misprinted row is not."""
    spec, model = _case(seed, 300)
    t = registry.time_grid(spec)
    found = G.check(model, t, cond.eq17(recipe.geometry(spec.mechanism)))
    assert found.general.count == 12
    assert found.general.gap > 1e6
    assert found.eq17.shape == (12,) and found.eq17.max() <= TOL
    # spans exactly: the twelve printed rows are independent, so both spaces coincide
    rows = G.to_finder(cond.eq17(recipe.geometry(spec.mechanism)), found.general.names)
    assert np.linalg.matrix_rank(rows * found.scale) == 12
    assert G.span_residuals(rows, found.general.matrix, found.scale).max() <= TOL
    # the check can fail: eq. 16's misprint carried into a row, or a coefficient off by 1 %
    bad = rows.copy()
    bad[0, found.general.names.index("m[link12]")] *= 1.01
    assert G.span_residuals(found.general.matrix, bad, found.scale)[0] > 1e-4


@pytest.mark.parametrize("seed", [None, 0, 1])
def test_leg_by_leg_solution_lies_in_the_computed_space(seed):
    spec, model = _case(seed, 310)
    found = G.check(model, registry.time_grid(spec), cond.eq17(recipe.geometry(spec.mechanism)))
    lbl, _ = recipe.leg_by_leg(spec.mechanism, spec.balancing, model)
    assert found.design_residual(lbl) <= TOL
    assert found.design_residual(model) > 1e-3  # the design as given does not


@pytest.mark.parametrize("kind,eq", [("fig5a", "eq. 19"), ("fig5b", "eq. 21")])
def test_special_kinematics_translating_platform_has_six_conditions(kind, eq):
    """PAPERS.md: 6, not the paper's 8; the eight are sufficient, and eliminating m5 p5, m5 q5
    (the split of m5 into point masses) from them leaves the six."""
    spec = spec_of(special_data(kind))
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    g = recipe.geometry(spec.mechanism)
    printed = cond.special(g, kind)
    found = G.check(model, t, cond.eq17(g), printed)
    assert found.general.count == 12  # every motion (the platform may turn)
    tr = found.translating
    assert tr.count == 6 and tr.gap > 1e6
    assert len(printed) == 8 and cond.SPECIAL_EQ[kind] == eq
    P = G.to_finder(printed, tr.names)
    assert np.linalg.matrix_rank(P * found.scale) == 8
    assert found.special_in_printed.max() <= TOL  # the printed eight imply the six
    assert np.sum(found.printed_in_translating > 1e-6) >= 2  # but are not all in their space
    assert found.reduced_count == 6 and found.reduced_in_translating.max() <= TOL
    # the translating conditions ignore the platform's first moments
    for n in ("mx[platform]", "my[platform]"):
        assert np.abs(tr.matrix[:, tr.names.index(n)]).max() <= TOL  # coefficients of order 1


@pytest.mark.parametrize("kind", ["fig5a", "fig5b"])
def test_six_conditions_suffice_for_a_translating_platform(kind):
    """A design meeting the six computed conditions but not the eight printed ones: no shaking
    force for the translating motion (engine), some but not all of it when the platform turns."""
    spec = spec_of(special_data(kind))
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    g = recipe.geometry(spec.mechanism)
    found = G.check(model, t, cond.eq17(g), cond.special(g, kind))
    regions = [LM.Region(f"cw{b.name}", b.name, "disc", ((0.0, 0.0),), 0.1) for b in model.bodies if b.name != "platform"]
    regions.append(LM.Region("cwp", "platform", "disc", ((0.0, 0.0),), 0.05))
    sol = LM.solve(model, found.translating, regions)
    out = model
    for cw in sol.counterweights:
        if cw.mass > 0:
            out = add_counterweight(out, cw.region.body, cw.region.name, cw.mass, cw.position, radius=None)
    an0, an = analyse(model, t), analyse(out, t)
    assert an.max_force <= TOL * an0.max_force
    p = mass_parameters(out)
    assert max(abs(r.residual(p)) / r.scale(p) for r in cond.special(g, kind)) > 1e-6
    assert found.general.contains(R.parameters(out), C.scale_of(out)) > 1e-6  # not balanced for every motion


@pytest.mark.parametrize("seed", [None, 0, 1, 2])
def test_least_mass_adds_no_more_than_leg_by_leg_and_balances(seed):
    spec, model = _case(seed, 320)
    res = recipe.balance(registry.context(spec, model=model))
    stages = {s.name: s for s in res.stages}
    lbl, lm = stages["leg_by_leg"].model, stages["least_mass"].model
    base = model.total_mass()
    assert lm.total_mass() - base <= (lbl.total_mass() - base) * (1 + 1e-9)
    p = {x.name: x.value for x in res.parameters}
    assert p["added_mass_least_mass"] == pytest.approx(lm.total_mass() - base, rel=1e-12)
    # every counter-mass within its allowed disc about the link's proximal joint
    for b in lm.bodies:
        for a in b.attachments:
            r = spec.balancing.counterweights.proximal if b.name.endswith("1") else spec.balancing.counterweights.distal
            assert np.hypot(*a.position) <= r * (1 + 1e-12)
    t = registry.time_grid(spec)
    an0, an = analyse(model, t), analyse(lm, t)
    assert an.max_force <= TOL * an0.max_force
    assert np.ptp(an.com, axis=0).max() <= 1e-12


def test_least_mass_can_be_switched_off():
    data = paper_data()
    data["balancing"]["least_mass"] = False
    res = registry.balance(spec_of(data))
    assert "least_mass" not in [s.name for s in res.stages]
    assert any(p.name == "finder_conditions" for p in res.parameters)  # the finder still runs (four legs)


def test_special_page_reports_the_count_and_explains_it():
    st = study.run(spec_of(special_data("fig5a")))
    assert st.ok, st.problems
    p = {x.name: x.value for x in st.balance.parameters}
    assert p["finder_conditions"] == 12 and p["translating_conditions"] == 6
    assert p["printed_reduced_conditions"] == 6
    extra = st.extra_figures()  # drawn once for both checks
    title, table, caption = next(f for f in extra if f[0].startswith("Generic condition finder"))
    assert "8 (eq. 19)" in table and "<td class=\"num\">6</td>" in table
    note = next(n for n in st.balance.notes if n.startswith("Special kinematics"))
    assert "finds 6 independent conditions where the paper prints 8" in note and "split" in note
    assert "least mass" in next(f for f in extra if f[0].startswith("Balance topologies"))[0]
