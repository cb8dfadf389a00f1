"""Inverses of stacks of small blocks (the engine's k x k diagonal blocks of Phi_q, one per time
sample): LAPACK per matrix (numpy.linalg.inv) against the Gauss-Jordan elimination vectorised over
the samples (balpipe.engine.structure._gauss_jordan), to place the crossing used by
balpipe.engine.structure.inverse. Run by hand: ``python benchmarks/bench_inverse.py``; prints
microseconds (best of repeats) and the ratio; asserts nothing about speed."""

from __future__ import annotations

import numpy as np

from balpipe.engine.structure import _LAPACK_SAMPLES, _gauss_jordan, inverse
from bench import best_of


def best(fn) -> float:
    """Microseconds, best of 30 calls."""
    return best_of(fn, 30) * 1e6


def main() -> None:
    rng = np.random.default_rng(0)
    print(f"chosen by balpipe.engine.structure.inverse: LAPACK up to {_LAPACK_SAMPLES} samples or from k = 7")
    print(f"{'k':>3} {'samples':>8} {'LAPACK us':>10} {'Gauss-Jordan us':>16} {'GJ / LAPACK':>12}")
    for k in (2, 3, 5, 8):
        for n in (3, 100, 300, 1000, 10000):
            A = rng.normal(size=(k, k, n)) + 3 * np.eye(k)[:, :, None]
            la = best(lambda: np.linalg.inv(A.transpose(2, 0, 1)))
            gj = best(lambda: _gauss_jordan(A))
            assert np.allclose(inverse(A), _gauss_jordan(A))
            print(f"{k:>3} {n:>8} {la:>10.1f} {gj:>16.1f} {gj / la:>12.2f}")


if __name__ == "__main__":
    main()
