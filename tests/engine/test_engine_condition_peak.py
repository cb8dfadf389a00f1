"""The largest condition number of a motion with SVDs only where it can be
(:func:`balpipe.engine.conditioning.peak`): the same sample and the same float as the argmax of
every sample's condition number, on random motions of every conditioning profile (flat, one sharp
peak between two first-pass samples, near-singular, ties) and on every spec's stages; and the
analysis's ``condition_peak`` is that of its ``condition`` array."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from balpipe import engine, loader, registry
from balpipe.engine import analyse, condition_peak, conditioning
from balpipe.engine.positions import _condition

SPECS = sorted((Path(__file__).resolve().parents[2] / "specs").glob("*.yaml"))


def _exact(J: np.ndarray) -> tuple[int, float]:
    cond = _condition(J)
    k = int(np.argmax(cond))
    return k, float(cond[k])


def _motion(rng, N: int, m: int, n: int, wobble: float, dip: tuple[int, float] | None = None) -> np.ndarray:
    """A smooth path of m x n matrices: a random start bent along the samples by ``wobble``, and
    with ``dip`` = (sample, depth) its smallest singular value pulled towards zero near that
    sample (a Gaussian dip two samples wide: a sharp singular passage)."""
    A, B, C = (rng.normal(size=(m, n)) for _ in range(3))
    s = np.linspace(0.0, 1.0, N)[:, None, None]
    J = A + wobble * (np.sin(3 * s) * B + s**2 * C)
    if dip is not None:
        k, depth = dip
        u, sv, vt = np.linalg.svd(J, full_matrices=False)
        g = depth * np.exp(-(((np.arange(N) - k) / 2.0) ** 2))
        sv[:, -1] *= 1.0 - g
        J = np.einsum("nik,nk,nkj->nij", u, sv, vt)
    return J


@pytest.mark.parametrize("seed", range(12))
def test_the_peak_is_the_argmax_of_every_sample(seed):
    rng = np.random.default_rng(seed)
    m = int(rng.integers(3, 30))
    n = m - int(rng.integers(0, 2))
    N = int(rng.integers(1, 700))
    for wobble in (0.0, 1e-3, 0.3, 3.0):
        for dip in (None, (int(rng.integers(0, N)), 0.999), (int(rng.integers(0, N)), 1 - 1e-9)):
            J = _motion(rng, N, m, n, wobble, dip)
            k, value = conditioning.peak(J)
            assert (k, value) == _exact(J)


def test_ties_give_the_first_sample_and_non_finite_motions_the_plain_argmax():
    rng = np.random.default_rng(5)
    J = np.repeat(rng.normal(size=(1, 9, 9)), 200, axis=0)  # every sample the same matrix
    assert conditioning.peak(J) == _exact(J) and conditioning.peak(J)[0] == 0
    J[150] *= np.inf
    with np.errstate(invalid="ignore"):
        assert conditioning.peak(J)[0] == _exact(J)[0]


def test_a_sharp_peak_off_the_first_pass_is_found_and_a_peaked_motion_skips_samples(monkeypatch):
    rng = np.random.default_rng(11)
    N = 501
    k0 = 3 * conditioning.STRIDE + 3  # between two first-pass samples
    J = _motion(rng, N, 12, 12, 0.3, (k0, 0.9999))
    calls = []
    original = conditioning._condition
    monkeypatch.setattr(conditioning, "_condition", lambda A: calls.append(len(A)) or original(A))
    k, value = conditioning.peak(J)
    assert (k, value) == _exact(J) and abs(k - k0) <= 1
    assert sum(calls) + len(range(0, N, conditioning.STRIDE)) + 1 < N / 2  # most samples never decomposed


@pytest.mark.parametrize("path", SPECS, ids=[p.stem for p in SPECS])
def test_every_spec_reports_the_largest_condition_number_of_its_stages(path, studies):
    """A study's max_condition_number (found by the peaks) is the largest of its stages' whole
    condition number arrays (computed when read, or when the shared study was pickled)."""
    st = studies(path.name)
    whole = max(float(np.max(s.analysis.condition)) for s in st.stages)
    assert st.checks["max_condition_number"] == whole


def test_an_analysis_peak_is_its_condition_numbers_argmax():
    """Before the condition numbers are read, condition_peak takes the peak search; after, the
    array; the two agree. Other keys: the plain argmax, None when absent."""
    spec = loader.load(Path(__file__).resolve().parents[2] / "specs" / "paper001_4rrr.yaml").spec
    model = registry.unbalanced_model(spec)
    engine.clear_cache()
    an = analyse(model, registry.time_grid(spec))
    assert an._condition is None  # not read yet
    found = condition_peak(an)
    cond = np.asarray(an.condition)
    assert found == (int(np.argmax(cond)), float(np.max(cond)))
    assert condition_peak(an) == found
    from dataclasses import replace

    assert condition_peak(replace(an, actuation_condition=np.array([1.0, 3.0, 3.0])), "actuation_condition") == (1, 3.0)
    assert condition_peak(an, "actuation_condition") is None


def test_chunked_jacobians_give_the_same_peak_and_numbers(monkeypatch):
    """motion_peak and condition_numbers form the Jacobians a chunk of samples at a time (the
    memory of a chunk, whatever the motion's length): the same sample and the same floats as the
    whole motion's Jacobians at once, for chunks that cut the motion anywhere."""
    from balpipe.engine.constraints import jacobian, with_frame
    from balpipe.engine.positions import condition_numbers

    spec = loader.load(Path(__file__).resolve().parents[2] / "specs" / "paper004_five_bar.yaml").spec
    model = registry.unbalanced_model(spec)
    engine.clear_cache()
    an = analyse(model, registry.time_grid(spec))
    c = engine.compiled(model)
    q = an.q.reshape(len(an.t), -1)
    whole = jacobian(c, with_frame(q))[:, :, 3:]
    expected = conditioning.peak(whole)
    numbers = _condition(whole)
    for chunk in (1, 7, 64, len(q) - 1, 10 * len(q)):
        monkeypatch.setattr(conditioning, "CHUNK", chunk)
        assert conditioning.motion_peak(c, q) == expected
        assert np.array_equal(condition_numbers(c, q, chunk=chunk), numbers)
