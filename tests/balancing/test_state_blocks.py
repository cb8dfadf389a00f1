"""The state sampler by blocks (balpipe.balancing.state_blocks) against the dense route: the same
states, the same force-balance conditions, on random ladders of four-bar loops and on every spec;
and the block inverses batched by size equal to each block's own."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry
from balpipe.balancing import conditions as C
from balpipe.balancing import regressor as R
from balpipe.engine.structure import decompose, inverse, invert_blocks
from balpipe.engine.vectorised import State, jacobian_values, vectorise
from balpipe.engine import compile_model
from balpipe.loader import load
from balpipe.spec_parts import SpecFieldError

ROOT = Path(__file__).resolve().parents[2]
SPECS = sorted((ROOT / "specs").glob("*.yaml"))


def _ladder():
    spec = importlib.util.spec_from_file_location("ladder", ROOT / "benchmarks" / "ladder.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _model_and_grid(path: Path):
    spec = load(path).spec
    return registry.unbalanced_model(spec), registry.time_grid(spec)


def _same(model, t, rel: float) -> tuple[R.States, R.States]:
    """Both routes' states and conditions; states equal to round-off (velocities up to each
    sample's sign: the null vector's sign is the SVD's choice), conditions equal to ``rel`` of
    the largest coefficient, singular values above the rank to ``rel`` each."""
    blocks = R.sample_states(model, t, blocks=True)
    dense = R.sample_states(model, t, blocks=False)
    assert (blocks.count, blocks.dof) == (dense.count, dense.dof)
    size = R.model_size(model)
    assert np.max(np.abs(blocks.pose[..., :2] - dense.pose[..., :2])) <= 1e-12 * size
    assert np.max(np.abs(blocks.pose[..., 2] - dense.pose[..., 2])) <= 1e-12
    sign = np.sign(np.sum(blocks.rate * dense.rate, axis=(1, 2)))
    assert np.all(sign != 0)
    assert np.max(np.abs(blocks.rate * sign[:, None, None] - dense.rate)) <= 1e-12 * np.max(np.abs(dense.rate))
    cb, cd = C.find(model, t, states=blocks), C.find(model, t, states=dense)
    assert cb.count == cd.count and cb.pivots == cd.pivots
    assert np.max(np.abs(cb.matrix - cd.matrix)) <= rel * np.max(np.abs(cd.matrix))
    r = cd.count
    assert np.all(np.abs(cb.singular[:r] - cd.singular[:r]) <= rel * cd.singular[:r])
    return cb, cd


@pytest.mark.parametrize("loops", [1, 3, 8])
def test_regular_ladders_give_the_dense_conditions_to_1e_12(tmp_path, loops):
    f = tmp_path / "ladder.yaml"
    f.write_text(_ladder().ladder_spec(loops, 0, samples=41))
    model, t = _model_and_grid(f)
    cb, _ = _same(model, t, 1e-12)
    assert cb.dof == 1


@pytest.mark.parametrize("loops,seed", [(2, 1), (3, 2), (4, 3), (6, 4), (8, 5)])
def test_random_ladders_give_the_dense_conditions(tmp_path, loops, seed):
    """Random (nearly parallelogram) loops make nearly dependent conditions: the finder states
    its own accuracy as 1 / gap (the singular-value gap), and the two routes agree within it
    (and to 1e-12 wherever the gap allows it)."""
    f = tmp_path / "ladder.yaml"
    f.write_text(_ladder().ladder_spec(loops, seed, samples=41))
    model, t = _model_and_grid(f)
    dense = C.find(model, t, states=R.sample_states(model, t, blocks=False))
    _same(model, t, max(1e-12, 10.0 / dense.gap))


@pytest.mark.parametrize("path", SPECS, ids=[p.stem for p in SPECS])
def test_every_spec_gives_the_dense_conditions(path):
    """Every spec's unbalanced model: the block route (where it applies: one degree of freedom;
    else it is the dense route itself) samples the same states and finds the same conditions."""
    try:
        model, t = _model_and_grid(path)
    except SpecFieldError:  # pragma: no cover - every spec loads
        pytest.fail(f"{path.name} does not load")
    try:
        R.sample_states(model, t, blocks=False)
    except Exception as exc:  # a model the sampler cannot take (no drivers): the block route refuses it alike
        with pytest.raises(type(exc)):
            R.sample_states(model, t, blocks=True)
        return
    _same(model, t, 1e-12)


def test_default_route_is_dense_for_small_machines_and_blocks_for_large(tmp_path, monkeypatch):
    """Below BLOCK_COORDINATES the states are the dense route's bit for bit (the specs' results
    do not move); from it on the block route runs (the dense round is never called)."""
    f = tmp_path / "ladder.yaml"
    lad = _ladder()
    f.write_text(lad.ladder_spec(2, 0, samples=41))
    model, t = _model_and_grid(f)
    a, b = R.sample_states(model, t), R.sample_states(model, t, blocks=False)
    assert np.array_equal(a.pose, b.pose) and np.array_equal(a.rate, b.rate)
    loops = R.BLOCK_COORDINATES // 6 + 1  # 2 N + 1 bodies, 3 coordinates each
    f.write_text(lad.ladder_spec(loops, 0, samples=41))
    model, t = _model_and_grid(f)
    assert 3 * len(model.bodies) >= R.BLOCK_COORDINATES

    def refuse(*args, **kwargs):
        raise AssertionError("the dense round ran")

    monkeypatch.setattr(R, "_dense_round", refuse)
    st = R.sample_states(model, t)
    assert st.dof == 1 and st.count == 2 * 4 * len(model.bodies) + 12


def test_singular_states_are_not_certified(tmp_path):
    """A state whose joint Jacobian is singular (every angle zero: the x rows of the four
    revolutes involve the three bodies' x alone) is never certified, the SVD decides it as on the
    dense route; a regular one (the initial pose) is."""
    from balpipe.balancing.state_blocks import BlockRound
    from balpipe.engine import jacobian
    from balpipe.engine.constraints import with_frame

    f = tmp_path / "ladder.yaml"
    f.write_text(_ladder().ladder_spec(1, 0, samples=41))
    model, _ = _model_and_grid(f)
    c = compile_model(model)
    m = len(c.row_owner) - 1  # the joints' rows; the driver's last
    block = BlockRound.of(c, m)
    assert block is not None
    q = np.repeat(c.q0[None, :], 2, axis=0)
    q[1, 2::3] = 0.0
    s = np.linalg.svd(jacobian(c, with_frame(q))[:, :m, 3:], compute_uv=False)
    assert s[0, -1] > 1e-3 * s[0, 0] and s[1, -1] <= R.MIN_CONDITION * s[1, 0]
    sure, null = block.certify(q, R.MIN_CONDITION)
    assert sure.tolist() == [True, False]
    J0 = jacobian(c, with_frame(q[:1]))[0, :m, 3:]
    assert np.max(np.abs(J0 @ null[0])) <= 1e-12 * np.max(np.abs(J0)) and abs(np.linalg.norm(null[0]) - 1) < 1e-14


def test_batched_block_inverses_equal_each_blocks_own(tmp_path):
    f = tmp_path / "ladder.yaml"
    f.write_text(_ladder().ladder_spec(5, 3, samples=41))
    model, t = _model_and_grid(f)
    c = compile_model(model)
    vz = vectorise(c)
    dec = decompose(vz)
    assert dec is not None and len(dec.square_blocks) >= 5
    rng = np.random.default_rng(0)
    for N in (7, 400):  # LAPACK per matrix, and the vectorised Gauss-Jordan
        X = np.zeros((vz.ncol, N))
        X[3:] = (c.q0[:, None] + 0.05 * rng.standard_normal((len(c.q0), N)))
        vals = jacobian_values(vz, State(vz, X))
        got = invert_blocks(dec, vals)
        for b, diag in dec.square_blocks:
            assert np.array_equal(got[b], inverse(vals[diag]))
