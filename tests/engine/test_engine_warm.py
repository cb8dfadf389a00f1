"""Warm start across geometry (issue 13, item 1; :mod:`balpipe.engine.warmstart`).

A closed loop of a new geometry (other lengths, the same joints, drivers, point names and number
of samples) is solved by Newton-Raphson on all samples at once from a fixed **anchor** (the base
design's motion, recorded with ``engine.record_anchors()``), instead of the sequential
continuation. It must give what a cold analysis of the same design gives (to 1e-10 of each
kind's peak), fall back to the continuation whenever the result is not on the branch of the
design's own initial pose or does not converge, and give the same bits whatever ran before in
the process (a sweep's table may not depend on its chunking, a build's bytes on the other specs).
"""

from __future__ import annotations

import dataclasses
import pickle

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import analyse, fastpath, warmstart
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


def _assert_close(an, ref, label: str) -> None:
    a, b = _arrays(an), _arrays(ref)
    scale = _scale(b)
    for k in b:
        err = float(np.abs(a[k] - b[k]).max())
        assert err <= 1e-10 * scale[k], f"{label}: {k} differs by {err:.3g} (scale {scale[k]:.3g})"


def _assert_identical(an, ref, label: str) -> None:
    a, b = _arrays(an), _arrays(ref)
    for k in b:
        assert np.array_equal(a[k], b[k]), f"{label}: {k} differs by {float(np.abs(a[k] - b[k]).max()):.3g}"


def _cold(model, t, g, mp):
    engine.clear_cache()
    return analyse(model, t, g, mp)


def _anchors(stages, t, g, mp) -> engine.Anchors:
    engine.clear_cache()
    with engine.record_anchors() as anchors:
        for s in stages:
            analyse(s.model, t, g, mp)
    return anchors


def _counts(before: dict) -> dict:
    return {k: warmstart.STATS[k] - before[k] for k in before}


# crank factors: a few % off and seeded random ones (the Scott-Russell slider-crank has crank =
# coupler: only a shorter crank reaches every angle)
_RNG = np.random.default_rng(13)
FACTORS = {
    "slider-crank": [0.99, 0.97, *_RNG.uniform(0.9, 1.0, 2), 0.995],
    "four-bar": [1.01, 1.05, *_RNG.uniform(0.9, 1.1, 2), 0.95],
    "3-RPR with idler loop": [1.01, 0.98, *_RNG.uniform(0.97, 1.03, 2)],  # prismatic legs, gears
    "five-bar with meshes": [1.01, 0.98, *_RNG.uniform(0.97, 1.03, 2)],  # gear meshes
}
STRETCHED = {"slider-crank": "crank", "four-bar": "crank", "3-RPR with idler loop": "platform",
             "five-bar with meshes": "link3"}


@pytest.mark.parametrize("samples", [None, 3])
@pytest.mark.parametrize("case", list(FACTORS))
def test_designs_started_from_the_anchors_equal_cold_analyses(case, samples):
    """Every stage of every design (a link longer or shorter) equals its cold analysis; each
    design's geometry is solved once (a warm start per topology; its other stages reuse the
    motion), with no continuation."""
    stages, t, g, mp = _setting(case)
    if samples is not None:
        t = np.linspace(t[0], t[-1], samples)
    designs = [[_stretched(s.model, STRETCHED[case], f) for s in stages] for f in FACTORS[case]]
    cold = [[_cold(m, t, g, mp) for m in models] for models in designs]
    anchors = _anchors(stages, t, g, mp)
    topologies = len({repr([type(j).__name__ for j in s.model.joints]) for s in stages})
    assert len(anchors) == topologies
    before = dict(warmstart.STATS)
    with engine.warm_start(anchors):
        warm = [[analyse(m, t, g, mp) for m in models] for models in designs]
    counts = _counts(before)
    assert counts["continuation"] == counts["warm_rejected"] == 0
    assert counts["warm"] == topologies * len(designs)
    assert counts["reused"] == (len(stages) - topologies) * len(designs)
    for f, ws, cs in zip(FACTORS[case], warm, cold):
        for stage, w, c in zip(stages, ws, cs):
            _assert_close(w, c, f"{case} x{f:.4f}/{stage.name}")


def test_a_designs_numbers_do_not_depend_on_what_ran_before():
    """The same designs in another order, each alone after the caches are emptied, or with the
    anchors shipped to another process (pickled): the same bits."""
    stages, t, g, mp = _setting("slider-crank")
    anchors = _anchors(stages, t, g, mp)
    designs = [_stretched(stages[-1].model, "crank", f) for f in FACTORS["slider-crank"]]
    with engine.warm_start(anchors):
        forward = [analyse(m, t, g, mp) for m in designs]
    engine.clear_cache()
    with engine.warm_start(anchors):
        backward = [analyse(m, t, g, mp) for m in designs[::-1]][::-1]
    shipped = pickle.loads(pickle.dumps(anchors))
    assert not shipped.solved and len(shipped) == len(anchors)
    alone = []
    for m in designs:
        engine.clear_cache()
        with engine.warm_start(shipped):
            alone.append(analyse(m, t, g, mp))
    for f, a, b, c in zip(FACTORS["slider-crank"], forward, backward, alone):
        _assert_identical(b, a, f"x{f:.4f} backward")
        _assert_identical(c, a, f"x{f:.4f} alone")


@pytest.mark.parametrize("case", ["slider-crank", "four-bar", "3-RPR with idler loop"])
def test_stages_share_a_motion_whatever_ran_first(case):
    """The motion of a closed loop is solved on its frame model (centres of mass at the frames'
    origins), so a stage's numbers are the same bits whether it is analysed first or after
    another stage of the same geometry (other centres of mass) solved the motion."""
    stages, t, g, mp = _setting(case)
    last = stages[-1].model
    first = _cold(last, t, g, mp)
    engine.clear_cache()
    for s in stages[:-1]:
        analyse(s.model, t, g, mp)
    _assert_identical(analyse(last, t, g, mp), first, f"{case}/{stages[-1].name}")


def test_another_duration_starts_from_the_anchor():
    """A design with another duration (its laws and grid scaled in time, the same number of
    samples) starts from the anchor's motion sample by sample and equals its cold analysis."""
    import yaml

    from balpipe.spec import Spec

    data = yaml.safe_load(open(CASES["slider-crank"][0]).read())
    spec = Spec.model_validate(data)
    base, t = registry.unbalanced_model(spec), registry.time_grid(spec)
    data["motion"]["duration"] = spec.motion.duration * 0.8
    spec2 = Spec.model_validate(data)
    other, t2 = registry.unbalanced_model(spec2), registry.time_grid(spec2)
    assert len(t2) == len(t) and not np.array_equal(t2, t)
    g, mp = gravity_vector(spec), tuple(spec.analysis.moment_point)
    ref = _cold(other, t2, g, mp)
    engine.clear_cache()
    with engine.record_anchors() as anchors:
        analyse(base, t, g, mp)
    before = dict(warmstart.STATS)
    with engine.warm_start(anchors):
        an = analyse(other, t2, g, mp)
    assert _counts(before)["warm"] == 1
    _assert_close(an, ref, "duration x0.8")
    assert an.max_force == pytest.approx(analyse(base, t, g, mp).max_force / 0.8**2, rel=1e-9)


def _assert_rejected(model, anchors, t, g, mp, ref, label: str) -> None:
    """Within the anchors' block the warm start of ``model`` is rejected, the continuation runs
    once and the result is the cold one, ``ref``."""
    before = dict(warmstart.STATS)
    with engine.warm_start(anchors):
        an = analyse(model, t, g, mp)
    assert _counts(before) == {"reused": 0, "warm": 0, "warm_rejected": 1, "continuation": 1}
    _assert_close(an, ref, label)


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
    anchor converges, but to the anchor's branch; the guard (first sample against the design's
    own assembled pose) rejects it and the continuation gives the cold result."""
    stages, t, g, mp = _setting("four-bar")
    base = stages[0].model
    other = _flipped(_stretched(base, "crank", 1.01))
    ref = _cold(other, t, g, mp)
    anchors = _anchors(stages[:1], t, g, mp)
    [(_, anchor)] = next(iter(anchors.designs.values()))
    assert np.abs(ref.frame_pose[:, 2, 2] - anchor[:, 8]).min() > 0.5  # really another branch
    # what an unguarded warm start would give: the anchor's branch
    fc = fastpath._frame_compiled(engine.compiled(other))
    f = fastpath.law_table(fc.fast.vz, t)[0]
    unguarded = warmstart.newton(fc, fc.fast.vz, fc.fast.dec, anchor, t, f)
    assert unguarded is not None and np.abs(unguarded[:, 8] - ref.frame_pose[:, 2, 2]).max() > 0.5
    _assert_rejected(other, anchors, t, g, mp, ref, "flipped four-bar")


def test_a_very_different_design_falls_back_to_the_continuation():
    """A crank 40 % shorter: the anchor's motion is too far off (angles beyond the
    continuation's 0.2 rad branch guard); the continuation gives the cold result."""
    stages, t, g, mp = _setting("slider-crank")
    other = _stretched(stages[0].model, "crank", 0.6)
    ref = _cold(other, t, g, mp)
    anchors = _anchors(stages[:1], t, g, mp)
    _assert_rejected(other, anchors, t, g, mp, ref, "slider-crank x0.6")


def test_a_design_that_cannot_move_still_raises_the_located_error():
    """A crank longer than the coupler cannot follow the Scott-Russell motion: the warm start
    does not converge and the continuation raises its located error, the cold one."""
    stages, t, g, mp = _setting("slider-crank")
    other = _stretched(stages[0].model, "crank", 1.2)
    with pytest.raises(engine.AnalysisError) as cold:
        _cold(other, t, g, mp)
    anchors = _anchors(stages[:1], t, g, mp)
    with engine.warm_start(anchors), pytest.raises(engine.AnalysisError) as warm:
        analyse(_stretched(stages[0].model, "crank", 1.2), t, g, mp)
    assert str(warm.value) == str(cold.value)


def test_nearest_anchor_is_the_start_and_nothing_happens_outside_the_block():
    """Of several anchors of one structure the nearest in its numbers is the start; outside
    :func:`engine.warm_start` (or with ``None``) a new geometry runs the continuation, and
    nothing is recorded outside :func:`engine.record_anchors`."""
    stages, t, g, mp = _setting("slider-crank")
    engine.clear_cache()
    with engine.record_anchors() as anchors:
        for f in (0.8, 0.99, 0.9):
            analyse(_stretched(stages[0].model, "crank", f), t, g, mp)
    analyse(_stretched(stages[0].model, "crank", 0.85), t, g, mp)  # not recorded
    [designs] = anchors.designs.values()
    assert len(designs) == 3
    c = engine.compiled(_stretched(stages[0].model, "crank", 0.985))
    skey, numbers = warmstart.structure_key(c, t)
    assert anchors.designs[skey] is designs
    nearest = min(designs, key=lambda d: float(np.abs(d[0] - numbers).max()))
    assert nearest is designs[1]
    for f, block in ((0.98, lambda: engine.warm_start(None)), (0.97, _nothing)):
        before = dict(warmstart.STATS)
        with block():
            analyse(_stretched(stages[0].model, "crank", f), t, g, mp)
        assert _counts(before)["continuation"] == 1 and _counts(before)["warm"] == 0


class _nothing:
    def __enter__(self):
        return self

    def __exit__(self, *exc):
        return False
