"""The engine's general (dense) path places every model of one geometry in the frame motion of
that geometry, solved once on the frame model (:mod:`balpipe.engine.shared`, issue 23): the
stages and mass designs of a redundantly actuated 4-RRR share one continuation, each stage's
numbers agree with its own continuation to the Newton tolerance, and they depend only on the
geometry and the stage's masses, never on which stage ran first."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import analyse, compiled, shared
from balpipe.engine.positions import solve_positions
from balpipe.loader import load
from balpipe.mechanics.sampling import time_grid
from balpipe.study import gravity_vector

RRR4 = "specs/paper001_4rrr.yaml"  # redundant actuation: the general (dense) path


@pytest.fixture(scope="module")
def rrr4():
    spec = load(RRR4).spec
    return spec, registry.balance(spec).stages, time_grid(spec)


def _offsets(model) -> bool:
    return bool(np.any(compiled(model).com_local))


def test_stages_share_one_frame_motion_and_agree_with_their_own_continuation(rrr4):
    spec, stages, t = rrr4
    g, mp = gravity_vector(spec), tuple(spec.analysis.moment_point)
    engine.clear_cache()
    before = dict(shared.STATS)
    mine = [analyse(s.model, t, g, mp) for s in stages]
    placed = sum(_offsets(s.model) for s in stages)
    assert placed >= 3
    assert shared.STATS["solved"] - before["solved"] == 1  # one continuation, on the frame model
    assert shared.STATS["shared"] - before["shared"] == placed
    assert shared.STATS["rejected"] == before["rejected"]
    ref = np.abs(mine[0].force).max()
    for s, a in zip(stages, mine):
        own = solve_positions(engine.compile_model(s.model), t)  # the stage's own continuation
        assert np.abs(a.q.reshape(len(t), -1) - own).max() <= 1e-10 * np.abs(own).max(), s.name
    engine.clear_cache()
    with pytest.MonkeyPatch.context() as m:  # every stage by its own continuation
        m.setattr(shared, "_frame_entry", lambda c, t: shared._Shared([], None, None))
        alone = [analyse(s.model, t, g, mp) for s in stages]
    for s, a, b in zip(stages, mine, alone):
        assert np.abs(a.force - b.force).max() <= 1e-9 * ref, s.name
        assert np.abs(a.moment - b.moment).max() <= 1e-9 * np.abs(b.moment).max(), s.name
        for name in b.efforts:
            assert np.abs(a.efforts[name] - b.efforts[name]).max() <= 1e-9 * np.abs(b.efforts[name]).max()
        assert a.condition == pytest.approx(b.condition, rel=1e-6)


def test_a_stage_gets_the_same_bits_whatever_ran_before(rrr4):
    spec, stages, t = rrr4
    last = stages[-1].model
    engine.clear_cache()
    first = analyse(last, t)
    engine.clear_cache()
    for s in stages[:-1]:
        analyse(s.model, t)
    after = analyse(last, t)
    for name in ("q", "v", "a", "force", "moment"):
        assert getattr(first, name).tobytes() == getattr(after, name).tobytes(), name


def test_a_model_with_its_masses_at_the_frames_is_its_own_continuation(rrr4):
    """Its own frame model: no placement, the continuation's bits."""
    _, stages, t = rrr4
    model = engine.fastpath.frame_model(stages[0].model)
    engine.clear_cache()
    assert not _offsets(model)
    before = dict(shared.STATS)
    q = analyse(model, t).q.reshape(len(t), -1)
    assert shared.STATS == before
    assert q.tobytes() == solve_positions(engine.compile_model(model), t).tobytes()


def test_a_frame_motion_that_does_not_solve_the_model_is_rejected(rrr4, monkeypatch):
    """A motion that is not the model's (here: shifted by 0.5 rad) fails the branch guard; the
    model's own continuation runs."""
    _, stages, t = rrr4
    model = stages[1].model
    engine.clear_cache()
    own = solve_positions(engine.compile_model(model), t)
    real = shared._from_shared

    def shifted(c, t, frame):
        bad = frame.copy()
        bad[:, 2::3] += 0.5
        return real(c, t, bad)

    monkeypatch.setattr(shared, "_from_shared", shifted)
    before = dict(shared.STATS)
    q = analyse(model, t).q.reshape(len(t), -1)
    assert shared.STATS["rejected"] - before["rejected"] == 1
    assert q.tobytes() == own.tobytes()


def test_other_laws_are_another_motion(rrr4):
    """The key holds the drivers' laws by identity: a stage given another law object (here an equal
    copy) solves its own frame motion."""
    _, stages, t = rrr4
    model = stages[1].model
    engine.clear_cache()
    before = dict(shared.STATS)
    analyse(model, t)
    law = model.drivers[0].law
    other = dataclasses.replace(model, drivers=(dataclasses.replace(model.drivers[0], law=dataclasses.replace(law)),
                                                 *model.drivers[1:]))
    analyse(other, t)
    assert shared.STATS["solved"] - before["solved"] == 2


def test_placed_rates_are_the_models_own_solves_to_round_off(rrr4):
    """The velocities and accelerations placed from the frame motion's satisfy the stage's own
    velocity and acceleration equations and agree with its own solves (one QR per sample)."""
    from balpipe.engine.constraints import acceleration_rhs, jacobian, velocity_rhs, with_frame
    from balpipe.engine.kinematics import _vel_acc

    spec, stages, t = rrr4
    engine.clear_cache()
    for s in stages:
        if not _offsets(s.model):
            continue
        an = analyse(s.model, t)
        c = compiled(s.model)
        q, v, a = (x.reshape(len(t), -1) for x in (an.q, an.v, an.a))
        own_v, own_a = _vel_acc(c, q, t)
        assert np.abs(v - own_v).max() <= 1e-10 * np.abs(own_v).max(), s.name
        assert np.abs(a - own_a).max() <= 1e-10 * np.abs(own_a).max(), s.name
        J = jacobian(c, with_frame(q))[:, :, 3:]
        nu, gamma = velocity_rhs(c, t), acceleration_rhs(c, with_frame(q), with_frame(v), t)
        assert np.abs(np.einsum("nij,nj->ni", J, v) - nu).max() <= 1e-10 * np.abs(nu).max(), s.name
        assert np.abs(np.einsum("nij,nj->ni", J, a) - gamma).max() <= 1e-9 * np.abs(gamma).max(), s.name


def test_placed_models_multipliers_by_their_geometrys_map(rrr4):
    """A placed stage's multipliers come from the frame model's map with the generalised forces
    moved to the frames' origins: they solve the stage's own Phi_q^T lambda = rhs and equal its
    own least-norm-efforts solution to 1e-9 of their peak; joint reactions and efforts follow."""
    from balpipe.engine.constraints import jacobian, with_frame
    from balpipe.engine.dynamics import solve_multipliers

    spec, stages, t = rrr4
    engine.clear_cache()
    used = 0
    for s in stages:
        c = compiled(s.model)
        q, v, a, placed = shared.kinematics(c, t)
        rhs = -np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(1, -1) * a
        got = shared.multipliers(c, placed, rhs)
        if not _offsets(s.model):
            assert placed is None and got is None
            continue
        used += 1
        lam, J0 = got
        J = jacobian(c, with_frame(q))
        own = solve_multipliers(c, J[:, :, 3:], rhs)
        peak = np.abs(own).max()
        assert np.abs(lam - own).max() <= 1e-9 * peak, s.name
        residual = np.einsum("nmk,nm->nk", J[:, :, 3:], lam) - rhs
        assert np.abs(residual).max() <= 1e-9 * np.abs(rhs).max(), s.name
        assert np.array_equal(J0, J[:, :, :3])  # the frame's columns do not see the masses
    assert used >= 3


def test_placed_models_regular_by_the_frame_motions_proof(rrr4, monkeypatch):
    """A placed stage is shown regular by its geometry's frame motion, screened once
    (shared._shown_regular): its own screen does not run, its condition numbers are computed
    when read and are its own Jacobian's; with centres of mass too far from their frames for the
    bound (cond(T)^2 above shared._TRANSFER) its own screen runs, as before."""
    from balpipe.engine import positions

    _, stages, t = rrr4
    placed = [s.model for s in stages if _offsets(s.model)]
    engine.clear_cache()
    screens = []
    real = shared._check_regular
    monkeypatch.setattr(shared, "_check_regular", lambda *a, **k: screens.append(1) or real(*a, **k))
    mine = [analyse(m, t) for m in placed]
    assert screens == []
    for m, a in zip(placed, mine):
        own = positions.condition_numbers(compiled(m), a.q.reshape(len(t), -1))
        assert np.array_equal(a.condition, own)
    monkeypatch.setattr(shared, "_TRANSFER", 1.0)  # no arm passes: every stage screens its own
    engine.clear_cache()
    again = [analyse(m, t) for m in placed]
    assert len(screens) == len(placed)
    for a, b in zip(mine, again):
        assert a.force.tobytes() == b.force.tobytes() and np.array_equal(a.condition, b.condition)


def test_a_singular_placed_model_fails_with_its_own_error(rrr4, monkeypatch):
    """Where the frame motion is not shown regular (here: its screen refuses), the placed model's
    own check runs and raises its own located error (here: the screens refuse and the condition
    limit is lowered below every condition number)."""
    from balpipe.engine import positions

    _, stages, t = rrr4
    model = [s.model for s in stages if _offsets(s.model)][0]
    engine.clear_cache()
    monkeypatch.setattr(shared, "_proven_regular", lambda J, G=None: False)
    monkeypatch.setattr(positions, "_proven_regular", lambda J, G=None: False)  # its own screen too
    monkeypatch.setattr(positions, "_COND_LIMIT", 1.0)
    with pytest.raises(engine.AnalysisError, match="singular configuration"):
        analyse(model, t)


def test_positions_moved_from_the_placed_ones_screen_their_own(rrr4, monkeypatch):
    """The frame motion's proof holds at the placed positions: a model whose refined positions
    moved from them by more than shared._PLACED (here: the refinement made to move them) screens
    its own Jacobian."""
    _, stages, t = rrr4
    model = [s.model for s in stages if _offsets(s.model)][0]
    engine.clear_cache()
    real = shared._from_shared
    monkeypatch.setattr(shared, "_from_shared", lambda c, t, frame: None if (q := real(c, t, frame)) is None else q + 1e-6)
    screens = []
    own = shared._check_regular
    monkeypatch.setattr(shared, "_check_regular", lambda *a, **k: screens.append(1) or own(*a, **k))
    analyse(model, t)
    assert screens == [1]
