"""The continuation's solves on the block path (engine/newton_blocks.py) against the general
path's (positions.DenseOps): the same motion of every closed loop of the specs, by either of
its linear solvers (dense scattered Jacobian for few samples, block substitution for many)."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import compile_model, fastpath, newton_blocks
from balpipe.engine.newton_blocks import BlockOps
from balpipe.engine.positions import DenseOps, follow_motion
from balpipe.loader import load

SPECS = ["specs/scott_russell.yaml", "specs/custom_four_bar_balancing.yaml", "specs/paper000_rpr3_idler_loop.yaml",
         "specs/paper004_five_bar.yaml", "specs/offset_slider_crank.yaml"]


def _closed_loops():
    for path in SPECS:
        spec = load(path).spec
        t = registry.time_grid(spec)
        for stage in registry.balance(spec).stages[:2]:
            yield f"{path}:{stage.name}", stage.model, t


@pytest.mark.parametrize("name,model,t", list(_closed_loops()))
@pytest.mark.parametrize("dense_entries", [0, 10**12])
def test_block_continuation_follows_the_same_motion(name, model, t, dense_entries, monkeypatch):
    monkeypatch.setattr(newton_blocks, "_DENSE_ENTRIES", dense_entries)
    c = compile_model(model)
    p = fastpath.prepare(c)
    assert p.dec is not None and not p.dec.explicit  # a closed loop on the block path
    ref = follow_motion(c, t, DenseOps(c))
    got = follow_motion(c, t, BlockOps(c, p.vz, p.dec, t))
    scale = max(1.0, float(np.abs(ref).max()))
    assert np.abs(got - ref).max() <= 1e-10 * scale
    # velocities and accelerations at the same positions, both solvers
    ops, dense = BlockOps(c, p.vz, p.dec, t), DenseOps(c)
    k = np.linspace(0, len(t) - 1, 7).round().astype(int)
    for got_x, ref_x in zip(ops.vel_acc(ref[k], t[k]), dense.vel_acc(ref[k], t[k])):
        assert np.abs(got_x - ref_x).max() <= 1e-10 * max(1.0, float(np.abs(ref_x).max()))


def test_default_continuation_uses_the_block_solves_once_decomposed():
    spec = load("specs/scott_russell.yaml").spec
    model = registry.balance(spec).stages[0].model
    engine.clear_cache()
    c = engine.compiled(model)
    from balpipe.engine.positions import _ops

    t = registry.time_grid(spec)
    assert isinstance(_ops(c, t), DenseOps)  # not decomposed yet
    c.fast = fastpath.prepare(c)
    assert isinstance(_ops(c, t), BlockOps)


def test_a_singular_step_takes_the_general_step(monkeypatch):
    """Where the block step is not finite (a singular block), the general path's solve (least
    squares) gives the step: Newton-Raphson still converges from a start whose block Jacobian
    has a zero pivot if the general step exists."""
    spec = load("specs/scott_russell.yaml").spec
    model = registry.balance(spec).stages[0].model
    c = compile_model(model)
    p = fastpath.prepare(c)
    t = registry.time_grid(spec)
    ops = BlockOps(c, p.vz, p.dec, t)
    q = follow_motion(c, t[:5], DenseOps(c))
    calls = []
    real = ops._general

    def spy(qq, phi):
        calls.append(qq.shape)
        return real(qq, phi)

    monkeypatch.setattr(ops, "_general", spy)
    monkeypatch.setattr(newton_blocks, "_DENSE_ENTRIES", 0)  # block substitution
    monkeypatch.setattr(newton_blocks, "invert_blocks", lambda dec, vals: {b: np.full(d.shape + (vals.shape[1],), np.nan)
                                                                             for b, d in dec.square_blocks})
    start = q + 1e-3
    sol, ok, _ = ops.newton(start, t[:5])
    assert calls and ok.all()
    assert np.abs(sol - q).max() < 1e-9
