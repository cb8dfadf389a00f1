"""Issue 8: random 3-RPR legs (paper 000's topologies: the idler loop E-F-P of Sec. 2 and the
Scott-Russell legs of Sec. 3, random geometry, masses, inertias and motion) balanced by the
generic methods instead of the paper's closed forms: ``force_balance`` keeps the shaking force at
most 1e-9 of the unbalanced peak, ``moment_balance`` (the paper's chained counter-rotations as
discs; for the Scott-Russell legs a disc on each cylinder geared to its coupler in place of eq.
30e) the moment too, with the total centre of mass fixed and the angular momentum constant, and
pymunk agrees (``validate``)."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe import registry
from balpipe.balancing import force_balance as FB
from balpipe.balancing import moment_balance as MB
from balpipe.balancing.context import BalanceContext
from balpipe.engine import analyse
from balpipe.model import Model
from balpipe.validate import validate
from test_rpr3 import random_idler, random_scott_russell, valid

TOL = 1e-9


def segments(model: Model) -> list[dict]:
    """A counterweight region on every moving link but the platform: the link's axis, 2.5 link
    lengths either side of its frame origin (the paper's counterweights lie on it)."""
    out = []
    for b in model.bodies:
        if b.name == "platform":
            continue
        L = max(abs(p[0]) for p in b.points.values())
        out.append({"body": b.name, "name": f"cw_{b.name}", "segment": [[-2.5 * L, 0.0], [2.5 * L, 0.0]]})
    return out


def linkage(kind: str, seed: int):
    """The paper's topology without its counterweights (the stage the generic method balances)."""
    if kind == "idler":
        spec, res = valid(random_idler, np.random.default_rng(seed))
    else:
        spec, res = valid(random_scott_russell, np.random.default_rng(seed), "coupler_inertia")
    return spec, res.stages[1].model


# the paper's chained counter-rotations (PAPERS.md, Sec. 2): Icr1 on the base at each A_i geared to
# the cylinder, Icr2 carried by link 6 geared to the platform, Icr3 carried by link 5 geared to
# link 6, Icr4 on the base at E geared to link 5
IDLER_DISCS = [{"name": f"cr1.{i}", "carrier": "frame", "at": f"A{i}", "geared_to": f"cyl{i}", "ratio": -1} for i in (1, 2, 3)] + [
    {"name": "cr2", "carrier": "link6", "at": "P", "geared_to": "platform", "ratio": -1},
    {"name": "cr3", "carrier": "link5", "at": "F", "geared_to": "link6", "ratio": -1},
    {"name": "cr4", "carrier": "frame", "at": "E", "geared_to": "link5", "ratio": -1},
]


@pytest.mark.parametrize("kind,seed", [("idler", 500), ("idler", 501), ("idler", 502),
                                       ("scott_russell", 600), ("scott_russell", 601)])
def test_random_3rpr_legs_force_balanced_by_the_generic_method(kind, seed):
    spec, model = linkage(kind, seed)
    t = registry.time_grid(spec)
    method = FB.ForceBalance.model_validate({"method": "force_balance", "counterweights": segments(model)})
    res = FB.balance(registry.context(spec, method, model=model))
    assert [s.name for s in res.stages] == ["unbalanced", "counterweights"]
    an0, an = analyse(model, t), analyse(res.stages[1].model, t)
    assert an0.max_force > 0
    assert an.max_force <= TOL * an0.max_force
    assert np.max(np.linalg.norm(an.com - an.com[0], axis=1)) <= TOL * float(np.ptp(an0.com, axis=0).max())


def assert_stage_balanced(model: Model, an0, t: np.ndarray, expect: tuple[str, ...], pymunk: bool = True) -> None:
    """A stage that claims ``expect`` ("force", "moment") against the unbalanced analysis
    ``an0``: shaking force (moment) at most 1e-9 of the unbalanced peak, the invariants behind
    it (total centre of mass fixed, linear momentum zero; angular momentum constant) and, with
    ``pymunk``, the same claim checked by simulation (:func:`balpipe.validate.validate`)."""
    an = analyse(model, t)
    peaks = (an0.max_force, float(np.max(np.abs(an0.moment))))
    assert an.max_force <= TOL * peaks[0]
    assert np.max(np.linalg.norm(an.com - an.com[0], axis=1)) <= TOL * float(np.ptp(an0.com, axis=0).max())
    assert np.max(np.linalg.norm(an.momentum, axis=1)) <= TOL * float(np.max(np.linalg.norm(an0.momentum, axis=1)))
    if "moment" in expect:
        assert float(np.max(np.abs(an.moment))) <= TOL * peaks[1]
        h = an.angular_momentum
        assert float(np.max(np.abs(h - h[0]))) <= TOL * float(np.max(np.abs(an0.angular_momentum)))
    if pymunk:
        v = validate(model, an, peaks, expect=expect)
        assert v.passed, v.reasons


def moment_balanced(model: Model, t: np.ndarray, discs: list[dict]):
    method = MB.MomentBalance.model_validate({"method": "moment_balance", "counterweights": segments(model),
                                             "counter_rotations": discs})
    return MB.balance(BalanceContext(method, model, t))


def test_random_3rpr_idler_loop_moment_balanced_and_validated_in_pymunk():
    spec, model = linkage("idler", 503)
    t = registry.time_grid(spec)
    res = moment_balanced(model, t, IDLER_DISCS)
    assert [s.name for s in res.stages] == ["unbalanced", "counterweights", "counter_rotations"]
    assert res.stages[2].balances == "force+moment"
    p = {x.name: x.value for x in res.parameters}
    assert all(p[f"{d['name']}.inertia"] > 0 for d in IDLER_DISCS)
    an0 = analyse(model, t)
    assert_stage_balanced(res.stages[1].model, an0, t, ("force",))
    assert_stage_balanced(res.stages[2].model, an0, t, ("force", "moment"))
    # the unbalanced linkage fails the same claim in pymunk (the check can fail)
    peaks = (an0.max_force, float(np.max(np.abs(an0.moment))))
    v0 = validate(model, an0, peaks, expect=("force",))
    assert not v0.passed


# the Scott-Russell legs' counter-rotations: the paper's one per leg on the base at A_i geared to the
# cylinder (eq. 30f), and, in place of eq. 30e's choice of a link inertia, a disc on the cylinder at
# A_i geared to the coupler (ratio -1: it turns with theta_cyl - (theta_coupler - theta_cyl)), which
# carries the angular momentum of the crank and coupler turning relative to the leg axis
SCOTT_RUSSELL_DISCS = [{"name": f"cr{i}", "carrier": "frame", "at": f"A{i}", "geared_to": f"cyl{i}", "ratio": -1}
                       for i in (1, 2, 3)] + [
    {"name": f"cc{i}", "carrier": f"cyl{i}", "at": [0.0, 0.0], "geared_to": f"coupler{i}", "ratio": -1} for i in (1, 2, 3)]


@pytest.mark.parametrize("kind,seed,discs,pymunk", [
    # 504 and 506 were left force-only before the finder's pivots kept above the row space's
    # accuracy and the least-mass programme worked on independent equations
    ("idler", 504, IDLER_DISCS, True), ("idler", 505, IDLER_DISCS, False), ("idler", 506, IDLER_DISCS, False),
    ("scott_russell", 600, SCOTT_RUSSELL_DISCS, True), ("scott_russell", 602, SCOTT_RUSSELL_DISCS, False),
])
def test_random_3rpr_legs_force_then_moment_balanced(kind, seed, discs, pymunk):
    """Random legs of both of paper 000's styles: ``force_balance`` alone, then
    ``moment_balance`` (its counterweights and the discs), each stage's claim and invariants, the
    fully balanced one in pymunk for one seed of each style (a simulation is most of a case's
    time)."""
    spec, model = linkage(kind, seed)
    t = registry.time_grid(spec)
    an0 = analyse(model, t)
    fb = FB.balance(BalanceContext(FB.ForceBalance.model_validate({"method": "force_balance",
                                                                  "counterweights": segments(model)}), model, t))
    assert_stage_balanced(fb.stages[1].model, an0, t, ("force",), pymunk=False)
    res = moment_balanced(model, t, discs)
    assert res.stages[2].balances == "force+moment", res.notes
    assert_stage_balanced(res.stages[2].model, an0, t, ("force", "moment"), pymunk=pymunk)
