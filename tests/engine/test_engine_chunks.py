"""The block path chunk by chunk (:func:`balpipe.engine.fastpath.dynamics_by_chunks`): the same
values as the whole grid at once, bit for bit, on open chains (explicit positions, solved level
by level with :func:`balpipe.engine.vectorised.residual_rows`) and closed loops; a singular
configuration is reported by the chunk that holds it, the earlier ones being regular."""

from __future__ import annotations

import runpy
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry
from balpipe.engine import analyse, compiled, fastpath
from balpipe.engine.vectorised import State, law_table, residual, residual_rows
from balpipe.loader import load
from balpipe.model import Model
from balpipe.study import gravity_vector

ROOT = Path(__file__).resolve().parents[2]


def chain(n: int, seed: int = 0, sweep: float = 1.0) -> Model:
    """benchmarks/chains.py's planar nR chain: random links, every joint on the 3-4-5 law."""
    return runpy.run_path(str(ROOT / "benchmarks" / "chains.py"))["serial_chain"](n, seed, sweep)[0]


def _both(model: Model, t: np.ndarray, g: np.ndarray, chunk: int):
    c = compiled(model)
    if c.fast is None:
        c.fast = fastpath.prepare(c)
    Mdiag = np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(1, -1)
    whole = fastpath.dynamics_by_chunks(c, c.fast, t, Mdiag, g, chunk=len(t))
    parts = fastpath.dynamics_by_chunks(c, c.fast, t, Mdiag, g, chunk=chunk)
    return whole, parts


def test_analyse_takes_the_chunks_on_long_grids():
    """analyse() on more samples than a chunk: the same Analysis as on one chunk."""
    model = chain(5, seed=2)
    c = compiled(model)
    size = fastpath.chunk_size(fastpath.prepare(c).vz)
    assert 1024 <= size <= 16384
    t = np.linspace(0.0, 1.0, 3 * size + 5)
    a = analyse(model, t, (0.0, -9.81))
    saved = fastpath.CHUNK
    try:
        fastpath.CHUNK = len(t)
        b = analyse(model, t, (0.0, -9.81))
    finally:
        fastpath.CHUNK = saved
    for name in ("q", "v", "a", "force", "moment", "frame_pose"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    assert all(np.array_equal(a.efforts[k], b.efforts[k]) for k in a.efforts)


@pytest.mark.parametrize("n", [1, 3, 12])
def test_chain_chunks_bit_for_bit(n):
    t = np.linspace(0.0, 1.0, 101)
    whole, parts = _both(chain(n, seed=n), t, np.array([0.0, -9.81]), chunk=17)
    for name in ("X", "V", "A", "lamT", "frame"):
        assert np.array_equal(getattr(whole, name), getattr(parts, name)), name


def test_closed_loop_chunks_bit_for_bit():
    spec = load("specs/custom_four_bar_balancing.yaml").spec
    for stage in registry.balance(spec).stages:
        t = np.linspace(0.0, spec.motion.duration, 53)
        whole, parts = _both(stage.model, t, np.asarray(gravity_vector(spec)), chunk=8)
        for name in ("X", "V", "A", "lamT", "frame"):
            assert np.array_equal(getattr(whole, name), getattr(parts, name)), (stage.name, name)


def test_residual_rows_are_the_residuals_rows():
    c = compiled(chain(7, seed=3))
    if c.fast is None:
        c.fast = fastpath.prepare(c)
    vz = c.fast.vz
    t = np.linspace(0.0, 1.0, 11)
    f, _, _ = law_table(vz, t)
    rng = np.random.default_rng(1)
    X = rng.normal(size=(vz.ncol, len(t)))
    X[:3] = 0.0
    s = State(vz, X)
    full = residual(vz, s, f)
    for eq in (np.arange(vz.m), np.array([0, 5, 2]), np.array([vz.m - 1])):
        assert np.array_equal(residual_rows(vz, s, f, eq), full[eq])


@pytest.mark.parametrize("n", [2, 9])
def test_static_bound_holds_at_every_sample(n):
    """An open chain's screen bound, known before any sample: above every sample's own bound
    (max |entry| / min |pivot|); a closed loop has none."""
    from balpipe.engine.structure import block_sigma_min, invert_blocks
    from balpipe.engine.vectorised import jacobian_values

    c = compiled(chain(n, seed=5, sweep=6.0))
    p = fastpath.prepare(c)
    assert p.static_bound is not None
    t = np.linspace(0.0, 1.0, 400)
    f, _, _ = law_table(p.vz, t)
    assert p.dec is not None
    X, state = fastpath._explicit_positions(p.vz, p.dec, f, len(t))
    vals = jacobian_values(p.vz, state)
    bound = np.abs(vals[p.free_slots]).max(axis=0) / block_sigma_min(p.dec, vals, invert_blocks(p.dec, vals))
    assert bound.max() <= p.static_bound
    assert bound.max() > 0.5 * p.static_bound  # and close to it: the links turn through every angle
    spec = load("specs/custom_four_bar_balancing.yaml").spec
    assert fastpath.prepare(compiled(registry.unbalanced_model(spec))).static_bound is None
