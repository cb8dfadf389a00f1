"""The general path's continuation with its constraints evaluated by primitive type
(:class:`balpipe.engine.positions.DenseOps` ``by_type``, the frame motions of :mod:`balpipe.engine.shared`)
against the loop over the primitives: paper 001's 4-RRR the same floats, bit for bit; a model
with gear rows (whose sums run in another order) the same motion to round-off."""

from __future__ import annotations

import numpy as np
import pytest

import balpipe
from balpipe.engine import positions
from balpipe.engine.compile import compile_model
from balpipe.engine.fastpath import frame_model


@pytest.mark.parametrize("path, exact", [("specs/paper001_4rrr.yaml", True), ("specs/paper004_five_bar.yaml", False)])
def test_by_type_follows_the_same_motion(path, exact):
    s = balpipe.run(balpipe.load(path))
    stage = s.engine_study.stages[-1]
    fc = compile_model(frame_model(stage.stage.model))
    t = np.linspace(stage.analysis.t[0], stage.analysis.t[-1], 301)
    ref = positions.follow_motion(fc, t, positions.DenseOps(fc, t))
    mine = positions.follow_motion(fc, t, positions.DenseOps(fc, t, by_type=True))
    ops, ops_ref = positions.DenseOps(fc, t, by_type=True), positions.DenseOps(fc, t)
    rates, rates_ref = ops.vel_acc(ref, t), ops_ref.vel_acc(ref, t)
    if exact:
        assert np.array_equal(mine, ref)
        assert all(np.array_equal(x, y) for x, y in zip(rates, rates_ref))
    else:
        assert np.abs(mine - ref).max() <= 1e-12 * np.abs(ref).max()
        for x, y in zip(rates, rates_ref):
            assert np.abs(x - y).max() <= 1e-12 * np.abs(y).max()
