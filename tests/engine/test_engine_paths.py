"""The engine's block-triangular path (issue 13) against its general dense path, and the caches.

`analyse(..., method="dense")` is the general path (continuation, batched Newton-Raphson, dense
batched solves on every sample's full Jacobian); the default takes the block path where it
applies. At the same positions the two give the same velocities, accelerations and multipliers
to 1e-12 of the largest value of each kind. The whole Analysis agrees to the dense path's
Newton tolerance: its Newton-Raphson stops at a residual of 1e-12, where the block path solves
open chains exactly, so positions differ by up to ~1e-12 and what is computed from them
(accelerations of closed loops, moments of the momenta) by a few 1e-12 of their scale.
"""

from __future__ import annotations

import math
import pickle

import numpy as np
import pytest

from balpipe import engine, registry
from balpipe.engine import analyse, compiled, fastpath, jacobian
from balpipe.engine.constraints import with_frame
from balpipe.engine.dynamics import solve_multipliers
from balpipe.engine.kinematics import _vel_acc
from balpipe.engine.structure import decompose
from balpipe.engine import AnalysisError
from balpipe.loader import load
from balpipe.model import FRAME, Body, Driver, Model, Prismatic, Revolute
from balpipe.motion import PROFILES, PointToPoint
from balpipe.study import gravity_vector

# (spec, expected structure): explicit = every block 1 x 1 and linear (no Newton), blocks = the
# closed loops' Newton blocks, dense = the general path (redundant actuation)
CASES = {
    "slider-crank": ("specs/scott_russell.yaml", "blocks"),
    "four-bar": ("specs/custom_four_bar_balancing.yaml", "blocks"),
    "3R arm": ("specs/paper003_com_planning.yaml", "explicit"),
    "3-RPR with idler loop": ("specs/paper000_rpr3_idler_loop.yaml", "blocks"),
    "five-bar with meshes": ("specs/paper004_five_bar.yaml", "blocks"),
    "redundant 4-RRR": ("specs/paper001_4rrr.yaml", "dense"),
}


def _stages(path: str):
    spec = load(path).spec
    return spec, registry.balance(spec).stages


@pytest.fixture
def balanced(shared):
    """``balanced(path)``: what :func:`_stages` gives, the balancing done once per run (the
    tests/conftest.py ``shared`` fixture: paper 003's planner takes seconds, and two tests of each
    case need it); a fresh copy of the stages for each test."""
    from pathlib import Path

    def get(path: str):
        text = Path(path).read_text(encoding="utf-8")
        return load(path).spec, shared.get(f"balanced stages\n{path}\n{text}", lambda: _stages(path)[1])

    return get


def _arrays(an) -> dict[str, np.ndarray]:
    out = {k: getattr(an, k) for k in ("q", "v", "a", "force", "moment", "force_momentum", "moment_momentum",
                                        "com", "momentum", "angular_momentum")}
    out.update({f"effort {k}": v for k, v in an.efforts.items()})
    out.update({f"reaction {j}.{k}": v for j, d in an.reactions.items() for k, v in d.items()})
    out["frame_pose"] = an.frame_pose
    return out


def _scale(arrays: dict[str, np.ndarray]) -> dict[str, float]:
    """The largest value of each kind: kinematics, loads (forces, moments, efforts, momenta)."""
    kin = max(float(np.abs(arrays[k]).max()) for k in ("q", "v", "a", "com", "frame_pose"))
    loads = max(float(np.abs(v).max()) for k, v in arrays.items() if k not in ("q", "v", "a", "com", "frame_pose"))
    return {k: kin if k in ("q", "v", "a", "com", "frame_pose") else loads for k in arrays}


@pytest.mark.parametrize("case", list(CASES))
def test_block_path_equals_dense_path(case, balanced):
    path, kind = CASES[case]
    spec, stages = balanced(path)
    t = registry.time_grid(spec)
    g, mp = gravity_vector(spec), tuple(spec.analysis.moment_point)
    for stage in stages:
        engine.clear_cache()  # no motion reused from another stage (see the test below)
        fast = analyse(stage.model, t, g, mp)
        dense = analyse(stage.model, t, g, mp, method="dense")
        c = compiled(stage.model)
        dec = c.fast.dec
        if kind == "dense":
            assert dec is None
        else:
            assert dec is not None and dec.explicit == (kind == "explicit")
        a, b = _arrays(fast), _arrays(dense)
        assert a.keys() == b.keys()
        scale = _scale(b)
        for k in b:
            err = float(np.abs(a[k] - b[k]).max())
            assert err <= 1e-10 * scale[k], f"{case}/{stage.name}: {k} differs by {err:.3g} (scale {scale[k]:.3g})"
        cond_a, cond_b = fast.condition, dense.condition
        assert np.allclose(cond_a, cond_b, rtol=1e-6), f"{case}/{stage.name}: condition numbers differ"
        assert fast.redundant_actuators == dense.redundant_actuators


@pytest.mark.parametrize("case", [k for k, (_, kind) in CASES.items() if kind != "dense"])
def test_block_substitution_equals_dense_solves_at_the_same_positions(case, balanced):
    """Velocities, accelerations (Phi_q x = b by forward substitution) and multipliers
    (Phi_q^T lambda = Q - M q'' by backward substitution) against the dense batched solves of
    the general path, at the block path's positions: to 1e-12 of each quantity's peak."""
    path, _ = CASES[case]
    spec, stages = balanced(path)
    t = registry.time_grid(spec)
    g = np.asarray(gravity_vector(spec))
    for stage in stages:
        c = compiled(stage.model)
        if c.fast is None:
            c.fast = fastpath.prepare(c)
        kin = fastpath.kinematics(c, c.fast, t)
        q = kin.X[3:-1].T
        v, a = _vel_acc(c, q, t)
        for mine, ref in ((kin.V[3:-1].T, v), (kin.A[3:-1].T, a)):
            assert np.abs(mine - ref).max() <= 1e-12 * np.abs(ref).max()
        if c.meshes:
            continue  # meshes: the multipliers are the dense path's (tooth rows)
        Mdiag = np.stack([c.mass, c.mass, c.inertia], axis=1).reshape(1, -1)
        rhs = -Mdiag * a
        rhs[:, 0::3] += c.mass * g[0]
        rhs[:, 1::3] += c.mass * g[1]
        lam = solve_multipliers(c, jacobian(c, with_frame(q))[:, :, 3:], rhs)
        mine = fastpath.multipliers(c.fast, kin, np.ascontiguousarray(rhs.T)).T
        assert np.abs(mine - lam).max() <= 1e-12 * np.abs(lam).max(), f"{case}/{stage.name}"


@pytest.mark.parametrize("case", ["slider-crank", "four-bar", "five-bar with meshes"])
def test_motion_reused_across_stages_equals_a_fresh_solution(case):
    """A closed loop's motion, once solved, is reused by the other stages (same joints, drivers
    and grid; other mass properties): the centres of mass are placed in the bodies' frames. It
    equals a fresh continuation to the Newton tolerance (residual 1e-12)."""
    path, _ = CASES[case]
    spec, stages = _stages(path)
    t = registry.time_grid(spec)
    g, mp = gravity_vector(spec), tuple(spec.analysis.moment_point)
    engine.clear_cache()
    analyse(stages[0].model, t, g, mp)
    reused = [analyse(s.model, t, g, mp) for s in stages[1:]]
    topologies = {(repr(s.model.joints), repr(s.model.bodies and [b.name for b in s.model.bodies])) for s in stages}
    assert len(engine.fastpath._MOTIONS) == len(topologies) < len(stages)  # solved once per topology
    for stage, an in zip(stages[1:], reused):
        engine.clear_cache()
        fresh = _arrays(analyse(stage.model, t, g, mp))
        scale = _scale(fresh)
        for k, v in _arrays(an).items():
            assert float(np.abs(v - fresh[k]).max()) <= 1e-9 * scale[k], f"{case}/{stage.name}: {k}"


def test_compiled_model_and_structure_are_cached():
    spec, stages = _stages(CASES["slider-crank"][0])
    t = registry.time_grid(spec)
    engine.clear_cache()
    first = stages[0].model
    analyse(first, t)
    c = compiled(first)
    assert compiled(first) is c  # the same model object: compiled once
    analyse(first, t)
    assert compiled(first) is c
    # another stage (same topology, other masses): its own compiled model, the same structure
    other = stages[-1].model
    analyse(other, t)
    assert compiled(other) is not c
    assert compiled(other).fast.dec is c.fast.dec
    assert decompose(c.fast.vz) is c.fast.dec
    engine.clear_cache()
    assert compiled(first) is not c


def test_the_condition_numbers_are_computed_when_read_and_pickled():
    spec, stages = _stages(CASES["slider-crank"][0])
    t = registry.time_grid(spec)
    an = analyse(stages[0].model, t)
    assert an.condition is not None
    again = pickle.loads(pickle.dumps(an))
    assert again._motion is None and again._condition is not None  # pickled with them, without the compiled model
    assert np.array_equal(again.condition, an.condition)


def test_unknown_method_is_refused():
    spec, stages = _stages(CASES["slider-crank"][0])
    with pytest.raises(ValueError, match="method"):
        analyse(stages[0].model, registry.time_grid(spec), method="fast")


def _slider_crank_pushed_too_far() -> Model:
    """Crank 0.1, coupler 0.3, the slider driven from x = 0.3 past the dead point x = 0.4
    (crank and coupler aligned) to 0.45, out of reach."""
    r, L, x0 = 0.1, 0.3, 0.3
    th = math.acos((x0 * x0 + r * r - L * L) / (2 * x0 * r))
    tip = (r * math.cos(th), r * math.sin(th))
    phi = math.atan2(-tip[1], x0 - tip[0])
    bodies = (Body("crank", 1.0, (0.05, 0.0), 0.001, {"P": (0.0, 0.0), "Q": (r, 0.0)}),
              Body("coupler", 2.0, (0.15, 0.0), 0.02, {"P": (0.0, 0.0), "Q": (L, 0.0)}),
              Body("slider", 1.0, (0.0, 0.0), 0.001))
    joints = (Revolute("A", FRAME, "crank", (0.0, 0.0), (0.0, 0.0)),
              Revolute("B", "crank", "coupler", (r, 0.0), (0.0, 0.0)),
              Revolute("C", "coupler", "slider", (L, 0.0), (0.0, 0.0)),
              Prismatic("guide", FRAME, "slider", (0.0, 0.0), (1.0, 0.0)))
    drive = Driver("push", ("joint", "guide"), PointToPoint(x0, r + L + 0.05, 0.2, PROFILES["quintic"]))
    return Model("dead point", bodies, joints, (drive,),
                 {"crank": (0.0, 0.0, th), "coupler": (tip[0], tip[1], phi), "slider": (x0, 0.0, 0.0)})


def _rocker_driven_four_bar() -> Model:
    from test_engine import four_bar  # the crank-rocker of test_engine.py

    m = four_bar(np.random.default_rng(0))
    phi = m.initial["rocker"][2]
    return Model(m.name, m.bodies, m.joints,
                 (Driver("rocker", ("joint", "D"), PointToPoint(phi, phi + 3.0, 0.4, PROFILES["quintic"])),), m.initial)


@pytest.mark.parametrize("build,T", [(_slider_crank_pushed_too_far, 0.2), (_rocker_driven_four_bar, 0.4)])
def test_both_paths_raise_the_same_located_error(build, T):
    """A motion the mechanism cannot follow: the same message, time and joint from both paths."""
    errors = []
    for method in ("auto", "dense"):
        engine.clear_cache()
        with pytest.raises(AnalysisError) as exc:
            analyse(build(), np.linspace(0.0, T, 201), method=method)
        errors.append((str(exc.value), exc.value.time, exc.value.joint))
    assert errors[0] == errors[1]
    assert "t = " in errors[0][0] and errors[0][1] is not None
