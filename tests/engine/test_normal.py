"""The redundant systems' solves by the normal equations (:mod:`balpipe.engine.normal`) against the
QR solves they replace: the same solutions to round-off where the Jacobians are well conditioned,
and the QR solves themselves (None from the normal equations) where they are not."""

from __future__ import annotations

import numpy as np
import pytest

from balpipe.engine import normal
from balpipe.engine.kinematics import Consistent, _solve_rect
from balpipe.engine.dynamics import solve_multipliers


class _Drivers:
    """The part of a compiled model that :func:`solve_multipliers` reads: its driver rows."""

    def __init__(self, rows: dict[str, int]):
        self.driver_rows = rows


def _consistent(seed: int, N: int = 40, m: int = 10, n: int = 8, spread: float = 1.0):
    """Random stacks J (N, m, n) with condition numbers up to ``spread`` and consistent
    right-hand sides b = J x."""
    rng = np.random.default_rng(seed)
    U = np.linalg.qr(rng.standard_normal((N, m, m)))[0][:, :, :n]
    V = np.linalg.qr(rng.standard_normal((N, n, n)))[0]
    s = np.geomspace(1.0, 1.0 / spread, n)
    J = (U * s[None, None, :]) @ V.transpose(0, 2, 1)
    x = rng.standard_normal((N, n))
    return J, np.einsum("nij,nj->ni", J, x), x


@pytest.mark.parametrize("seed", range(4))
def test_refined_solution_equals_qr_to_round_off(seed):
    J, b, x = _consistent(seed, spread=300.0)
    F = normal.factor(J)
    assert F is not None
    mine = F.solve(b)
    assert mine is not None
    ref = _solve_rect(J, b)
    assert np.abs(mine - ref).max() <= 1e-13 * np.abs(ref).max()
    assert np.abs(mine - x).max() <= 1e-12 * np.abs(x).max()


def test_ill_conditioned_solves_by_qr():
    """cond(J) = 1e7: the refinement's correction is far above 1e-8 of the solution, so the
    normal equations give None and :class:`Consistent` takes QR, the same floats as before."""
    J, b, _ = _consistent(7, spread=1e7)
    F = normal.factor(J)
    assert F is None or F.solve(b) is None
    solver = Consistent(J)
    assert np.array_equal(solver.solve(b), _solve_rect(J, b))


def test_square_jacobians_keep_lu():
    J, b, _ = _consistent(3, m=8, n=8)
    assert normal.factor(J) is None
    assert np.array_equal(Consistent(J).solve(b), _solve_rect(J, b))


@pytest.mark.parametrize("k", [None, 3])
@pytest.mark.parametrize("m", [11, 12])
def test_least_effort_multipliers_equal_qr(k, m):
    """The multipliers with the least driver efforts (one or two redundant drivers among the
    driver rows 8 to m - 1: the one-vector null space's own formula, and the eigenvectors'):
    the normal equations' solution equals the complete QR's to round-off, for one right-hand
    side and for several."""
    J, _, _ = _consistent(11, N=30, m=m, n=10, spread=50.0)
    c = _Drivers({f"d{i}": i for i in range(8, m)})
    rng = np.random.default_rng(5)
    rhs = rng.standard_normal((30, 10) if k is None else (30, 10, k))
    F = normal.factor(J)
    assert F is not None
    mine = solve_multipliers(c, J, rhs, F)
    # the QR path: no factorisation where the normal equations do not hold
    ref = solve_multipliers(c, J, rhs, _Refusing(J, F))
    assert np.abs(mine - ref).max() <= 1e-12 * np.abs(ref).max()
    # a solution, with efforts no larger than any other solution's
    lam = mine if k is None else mine[..., 0]
    r0 = rhs if k is None else rhs[..., 0]
    assert np.abs(np.einsum("nmi,nm->ni", J, lam) - r0).max() <= 1e-12 * np.abs(r0).max()
    null = np.linalg.svd(J, full_matrices=True)[0][:, :, 10:]
    shifted = lam + (null @ rng.standard_normal((30, m - 10, 1)))[..., 0]
    assert np.all(np.linalg.norm(lam[:, 8:], axis=1) <= np.linalg.norm(shifted[:, 8:], axis=1) * (1 + 1e-12))


class _Refusing(normal.Normal):
    """Normal equations that never hold: :func:`solve_multipliers` takes its QR path."""

    def __init__(self, J: np.ndarray, F: normal.Normal):
        super().__init__(J, normal.gram(J))

    def null_space(self, rows, r):
        return None


def test_newton_steps_converge_as_qr():
    """A redundant 4-RRR's positions: Newton-Raphson with the normal equations' steps converges
    to the positions of QR's steps (within the iteration's tolerance, 1e-12 of the residual)."""
    import balpipe
    from balpipe.engine import compiled, positions
    from balpipe.engine.constraints import residual, with_frame

    s = balpipe.run(balpipe.load("specs/paper001_4rrr.yaml"))
    an = s.engine_study.stages[0].analysis
    c = compiled(s.engine_study.stages[0].stage.model)
    t = an.t[::10]
    q = an.q.reshape(len(an.t), -1)[::10]
    guess = q + 1e-4 * np.sin(np.arange(q.size)).reshape(q.shape)
    mine, ok, _ = positions.newton_raphson(c, guess, t)
    ref, ok_ref, _ = positions.newton_raphson(c, guess, t, normal=False)
    assert ok.all() and ok_ref.all()
    assert np.abs(mine - ref).max() <= 1e-11
    assert np.abs(residual(c, with_frame(mine), t)).max() < 1e-12


def test_newton_repeats_by_qr_what_the_normal_steps_do_not_converge(monkeypatch):
    """Samples whose normal-equation steps do not converge are iterated again from the guess by
    QR alone: the same positions, bit for bit, as QR's iteration (here every step is spoiled)."""
    import balpipe
    from balpipe.engine import compiled, positions

    s = balpipe.run(balpipe.load("specs/paper001_4rrr.yaml"))
    an = s.engine_study.stages[0].analysis
    c = compiled(s.engine_study.stages[0].stage.model)
    t = an.t[::20]
    guess = an.q.reshape(len(an.t), -1)[::20] + 1e-4

    class Spoiled:
        def step(self, b):
            return np.zeros((len(b), guess.shape[1]))

    monkeypatch.setattr(positions, "factor", lambda J: Spoiled())
    mine, ok, norms = positions.newton_raphson(c, guess, t)
    ref, ok_ref, norms_ref = positions.newton_raphson(c, guess, t, normal=False)
    assert ok.all() and np.array_equal(mine, ref) and np.array_equal(norms, norms_ref)
