"""Warm start across geometry (issue 13, item 1): a closed loop of a new geometry (other lengths,
the same joints, drivers, point names and grid) starts a Newton-Raphson on all samples at once
from the motion of the nearest design solved before, instead of the sequential continuation.

It must give what a cold analysis of the same design gives (to 1e-10 of each kind's peak:
positions, efforts, reactions, shaking loads), and fall back to the continuation whenever the
warm solution is not on the branch of the design's own initial pose or does not converge.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import analyse, fastpath
from balpipe.model import Model, Prismatic, Revolute
from balpipe.study import gravity_vector
from test_engine_paths import CASES, _arrays, _scale, _stages


def _stretched(model: Model, body: str, factor: float) -> Model:
    """``model`` with the named points of ``body`` and the joints' points on it scaled by
    ``factor`` (a longer or shorter link; its mass properties and the initial poses unchanged:
    the assembly at t = 0 closes the loop from them)."""
    b = next(b for b in model.bodies if b.name == body)
    new = dataclasses.replace(b, points={k: (v[0] * factor, v[1] * factor) for k, v in b.points.items()})

    def scale(p):
        return (p[0] * factor, p[1] * factor)

    joints = []
    for j in model.joints:
        if isinstance(j, Revolute):
            j = dataclasses.replace(j, point_a=scale(j.point_a) if j.a == body else j.point_a,
                                    point_b=scale(j.point_b) if j.b == body else j.point_b)
        elif isinstance(j, Prismatic):
            j = dataclasses.replace(j, point_guide=scale(j.point_guide) if j.guide == body else j.point_guide,
                                    point_slider=scale(j.point_slider) if j.slider == body else j.point_slider)
        joints.append(j)
    return dataclasses.replace(model.replace_body(new), joints=tuple(joints))


def _setting(case: str):
    spec, stages = _stages(CASES[case][0])
    return stages, registry.time_grid(spec), gravity_vector(spec), tuple(spec.analysis.moment_point)


def _assert_same(an, ref, label: str) -> None:
    a, b = _arrays(an), _arrays(ref)
    scale = _scale(b)
    for k in b:
        err = float(np.abs(a[k] - b[k]).max())
        assert err <= 1e-10 * scale[k], f"{label}: {k} differs by {err:.3g} (scale {scale[k]:.3g})"


def _cold(model, t, g, mp):
    engine.clear_cache()
    return analyse(model, t, g, mp)


# crank factors: the spec's design, 1 % and a few % off, and seeded random ones (the
# Scott-Russell slider-crank has crank = coupler: only a shorter crank reaches every angle)
_RNG = np.random.default_rng(13)
FACTORS = {
    "slider-crank": [1.0, 0.99, 0.97, *_RNG.uniform(0.9, 1.0, 2), 0.995],
    "four-bar": [1.0, 1.01, 1.05, *_RNG.uniform(0.9, 1.1, 2), 0.95],
}


@pytest.mark.parametrize("samples", [None, 3])
@pytest.mark.parametrize("case", list(FACTORS))
def test_designs_analysed_in_turn_equal_cold_analyses(case, samples):
    """Each new crank length starts from the previous design (a warm start counted in
    ``fastpath.STATS``); every stage of every design equals its cold analysis."""
    stages, t, g, mp = _setting(case)
    if samples is not None:
        t = np.linspace(t[0], t[-1], samples)
    designs = [[_stretched(s.model, "crank", f) for s in stages] for f in FACTORS[case]]
    cold = [[_cold(m, t, g, mp) for m in models] for models in designs]
    engine.clear_cache()
    before = dict(fastpath.STATS)
    with fastpath.warm_designs():
        warm = [[analyse(m, t, g, mp) for m in models] for models in designs]
    counts = {k: fastpath.STATS[k] - before[k] for k in before}
    topologies = len({repr([type(j).__name__ for j in s.model.joints]) for s in stages})
    assert counts["continuation"] == topologies  # the first design only
    assert counts["warm_rejected"] == 0
    assert counts["warm"] == topologies * (len(designs) - 1)
    assert counts["reused"] == (len(stages) - topologies) * len(designs)
    for f, ws, cs, models in zip(FACTORS[case], warm, cold, designs):
        for stage, w, c in zip(stages, ws, cs):
            _assert_same(w, c, f"{case} x{f:.4f}/{stage.name}")


def _flipped(model: Model) -> Model:
    """The four-bar assembled on its other branch: coupler and rocker mirrored about the line
    through the crank pin and the rocker's pivot (the x axis at the spec's crank angle 0)."""
    initial = dict(model.initial)
    for name in ("coupler", "rocker"):
        x, y, th = initial[name]
        initial[name] = (x, -y, -th)
    return dataclasses.replace(model, initial=initial)


def test_a_design_on_the_other_branch_falls_back_to_the_continuation():
    """The new design's initial pose is on the other assembly branch: Newton-Raphson from the
    previous design's motion converges, but to the previous branch; the guard (first sample
    against the design's own assembled pose) rejects it and the continuation gives the cold
    result."""
    stages, t, g, mp = _setting("four-bar")
    base = stages[0].model
    other = _flipped(_stretched(base, "crank", 1.01))
    ref = _cold(other, t, g, mp)
    engine.clear_cache()
    with fastpath.warm_designs():
        first = analyse(base, t, g, mp)
    assert np.abs(ref.q[:, 2, 2] - first.q[:, 2, 2]).min() > 0.5  # really another branch
    # what an unguarded warm start would give: the previous branch
    c = engine.compiled(other)
    if c.fast is None:
        c.fast = fastpath.prepare(c)
    f = fastpath.law_table(c.fast.vz, t)[0]
    start = fastpath._place(fastpath._MOTIONS[fastpath._motion_key(engine.compiled(base), t)][1], c.com_local)
    unguarded = fastpath._block_newton(c.fast.vz, c.fast.dec, start, f)
    assert unguarded is not None and np.abs(unguarded[:, 8] - ref.q[:, 2, 2]).max() > 0.5
    before = dict(fastpath.STATS)
    with fastpath.warm_designs():
        an = analyse(other, t, g, mp)
    assert fastpath.STATS["warm_rejected"] == before["warm_rejected"] + 1
    assert fastpath.STATS["continuation"] == before["continuation"] + 1
    _assert_same(an, ref, "flipped four-bar")


def test_a_very_different_design_falls_back_to_the_continuation():
    """A crank 40 % shorter: the previous motion is too far off (angles beyond the
    continuation's 0.2 rad branch guard); the continuation gives the cold result."""
    stages, t, g, mp = _setting("slider-crank")
    other = _stretched(stages[0].model, "crank", 0.6)
    ref = _cold(other, t, g, mp)
    engine.clear_cache()
    before = dict(fastpath.STATS)
    with fastpath.warm_designs():
        analyse(stages[0].model, t, g, mp)
        an = analyse(other, t, g, mp)
    assert fastpath.STATS["warm"] == before["warm"]
    assert fastpath.STATS["warm_rejected"] == before["warm_rejected"] + 1
    assert fastpath.STATS["continuation"] == before["continuation"] + 2
    _assert_same(an, ref, "slider-crank x0.6")


def test_the_nearest_design_is_the_start():
    """Of the designs solved before with the same structure, the nearest in its numbers."""
    stages, t, g, mp = _setting("slider-crank")
    engine.clear_cache()
    with fastpath.warm_designs():
        for f in (0.8, 0.99, 0.9):
            analyse(_stretched(stages[0].model, "crank", f), t, g, mp)
    c = engine.compiled(_stretched(stages[0].model, "crank", 0.985))
    skey, numbers = fastpath._structure_key(c, t)
    designs = fastpath._WARM[skey]
    assert len(designs) == 3
    nearest = min(designs, key=lambda d: float(np.abs(d[0] - numbers).max()))
    assert nearest is designs[1]


def test_a_design_that_cannot_move_still_raises_the_located_error():
    """A crank longer than the coupler cannot follow the Scott-Russell motion: after a design
    that can, the warm start does not converge and the continuation raises its error."""
    stages, t, g, mp = _setting("slider-crank")
    other = _stretched(stages[0].model, "crank", 1.2)
    engine.clear_cache()
    with pytest.raises(engine.AnalysisError) as cold:
        analyse(other, t, g, mp)
    engine.clear_cache()
    with fastpath.warm_designs(), pytest.raises(engine.AnalysisError) as warm:
        analyse(stages[0].model, t, g, mp)
        analyse(_stretched(stages[0].model, "crank", 1.2), t, g, mp)
    assert str(warm.value) == str(cold.value)


def test_off_by_default_and_outside_the_block():
    """Without :func:`fastpath.warm_designs` a new geometry runs the continuation (a build's
    numbers do not depend on what ran before in its process), and nothing is kept for it."""
    stages, t, g, mp = _setting("slider-crank")
    engine.clear_cache()
    with fastpath.warm_designs():
        analyse(stages[0].model, t, g, mp)
    before = dict(fastpath.STATS)
    analyse(_stretched(stages[0].model, "crank", 0.99), t, g, mp)
    assert fastpath.STATS["warm"] == before["warm"]
    assert fastpath.STATS["continuation"] == before["continuation"] + 1
    assert sum(len(v) for v in fastpath._WARM.values()) == 1  # the design of the block only
