"""The general path's regularity screen (:func:`balpipe.engine.positions._proven_regular`): a
Cholesky factorisation that proves a whole motion far from singular, so that the condition
numbers (an SVD per sample) are computed only when read, and the same as before."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe import engine
from balpipe.engine import AnalysisError, analyse, compile_model
from balpipe.engine import positions
from balpipe.engine.constraints import jacobian, with_frame
from balpipe.engine.positions import _check_regular, _condition, _proven_regular


def _with_condition(rng, m: int, n: int, cond: float, scale_spread: float = 0.0) -> np.ndarray:
    """A random m x n matrix (m >= n) with condition number ``cond``, its rows and columns then
    scaled by up to 10^scale_spread (a Jacobian mixes lengths and angles)."""
    u, _ = np.linalg.qr(rng.normal(size=(m, m)))
    v, _ = np.linalg.qr(rng.normal(size=(n, n)))
    s = np.geomspace(1.0, 1.0 / cond, n)
    a = (u[:, :n] * s) @ v.T
    if scale_spread:
        a = a * 10.0 ** rng.uniform(-scale_spread, scale_spread, size=(m, 1))
        a = a * 10.0 ** rng.uniform(-scale_spread, scale_spread, size=(1, n))
    return a


@pytest.mark.parametrize("m,n", [(6, 6), (9, 9), (28, 27), (45, 45)])
def test_a_proven_sample_is_far_from_the_limit_and_a_well_conditioned_one_is_proven(m, n):
    """Over condition numbers 1 .. 1e14 (scaled rows and columns too): whatever the screen
    proves has an exact condition number below 1.1e5 (its bound), and every sample below 1e4
    is proven, so the SVD is skipped where it matters."""
    rng = np.random.default_rng(m * 100 + n)
    for cond in np.geomspace(1.0, 1e14, 29):
        for spread in (0.0, 1.0):
            a = _with_condition(rng, m, n, float(cond), spread)
            exact = float(_condition(a[None])[0])
            proven = _proven_regular(a[None])
            if proven:
                assert exact <= 1.1e5, f"proved regular at condition {exact:.3g}"
            if exact <= 1e4:
                assert proven, f"not proved at condition {exact:.3g}"


def test_one_bad_sample_or_non_finite_entries_leave_the_batch_unproven():
    rng = np.random.default_rng(3)
    good = np.stack([_with_condition(rng, 9, 9, 10.0) for _ in range(20)])
    assert _proven_regular(good)
    bad = good.copy()
    bad[7] = _with_condition(rng, 9, 9, 1e12)
    assert not _proven_regular(bad)
    bad = good.copy()
    bad[3, 2, 2] = np.nan
    assert not _proven_regular(bad)
    assert not _proven_regular(np.zeros((4, 9, 9)))
    assert not _proven_regular(good[:, :, :8].transpose(0, 2, 1))  # fewer rows than columns


def _crank_rocker():
    from test_engine import four_bar  # the crank-rocker of test_engine.py

    return four_bar(np.random.default_rng(0))


def test_dense_path_condition_numbers_are_computed_when_read_and_unchanged():
    """A regular motion on the general path: the screen proves it, the analysis carries no
    condition numbers until read, and then they are the SVD's, bit for bit."""
    model = _crank_rocker()
    t = np.linspace(0.0, 0.5, 301)
    engine.clear_cache()
    an = analyse(model, t, method="dense")
    c = compile_model(model)
    assert c.condition is None  # shown regular: no SVD yet
    assert an._condition is None  # computed when read
    exact = _condition(jacobian(c, with_frame(an.q.reshape(len(t), -1)))[:, :, 3:])
    assert an.condition.tobytes() == exact.tobytes()
    fast = analyse(model, t)  # the block path's, also computed when read
    assert np.allclose(fast.condition, exact, rtol=1e-6)


def test_a_singular_sample_is_reported_as_without_the_screen(monkeypatch):
    """A sample whose Jacobian loses rank: with and without the screen, the same error (time,
    joints), and the condition numbers returned where nothing is singular are the same."""
    model = _crank_rocker()
    t = np.linspace(0.0, 0.5, 101)
    engine.clear_cache()
    c = compile_model(model)
    q = positions.follow_motion(c, t, positions.DenseOps(c))
    assert _check_regular(c, q, t, screen=True) is None
    assert _check_regular(c, q, t).tobytes() == _condition(jacobian(c, with_frame(q))[:, :, 3:]).tobytes()
    real = positions.jacobian

    def rank_lost(cc, qx):
        J = real(cc, qx).copy()
        if len(qx) == len(t):
            J[63, :, 3 + 2] = 0.0  # body 1's angle drops out at t[63]
        return J

    monkeypatch.setattr(positions, "jacobian", rank_lost)
    errors = []
    for screen in (True, False):
        with pytest.raises(AnalysisError) as exc:
            _check_regular(c, q, t, screen=screen)
        errors.append((str(exc.value), exc.value.time, exc.value.joint))
    assert errors[0] == errors[1]
    assert "singular configuration at t = " in errors[0][0] and errors[0][1] == pytest.approx(t[63])
