"""The generic joint laws of pose-driven templates (balpipe.mechanics.joint_laws): a body point's motion
from the pose laws, and the per-grid solution shared by a template's joint laws."""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from balpipe.mechanics.joint_laws import KEEP, PoseJointLaw, body_point
from balpipe.families.rpr3 import template as rpr3
from balpipe.families.rrr4 import template as rrr4
from balpipe.families.serial_arm import template as serial_arm
from balpipe.motion import PointToPoint, quintic


def test_body_point_derivatives_are_those_of_its_position(rng):
    """C' and C'' are the time derivatives of C (central differences), for random poses and points."""
    for _ in range(5):
        a, b = rng.uniform(-1, 1, 3), rng.uniform(-1, 1, 3) * 3
        laws = [PointToPoint(a[k], b[k], 1.0, quintic) for k in range(3)]
        c = rng.uniform(-0.5, 0.5, 2)
        t, h = np.linspace(0.05, 0.95, 37), 1e-5
        C, Cd, Cdd = body_point(tuple(law(t) for law in laws), c)
        Cp = body_point(tuple(law(t + h) for law in laws), c)[0]
        Cm = body_point(tuple(law(t - h) for law in laws), c)[0]
        assert np.allclose(Cd, (Cp - Cm) / (2 * h), atol=1e-7)
        Cdp = body_point(tuple(law(t + h) for law in laws), c)[1]
        Cdm = body_point(tuple(law(t - h) for law in laws), c)[1]
        assert np.allclose(Cdd, (Cdp - Cdm) / (2 * h), atol=1e-5)
        # |C - P| is the point's distance from the frame's origin, whatever the pose
        P = np.stack([laws[0](t)[0], laws[1](t)[0]], axis=1)
        assert np.allclose(np.hypot(*(C - P).T), np.hypot(*c))


@dataclass(frozen=True)
class Toy(PoseJointLaw):
    """q_k = k t^2 for k = 1, 2; counts how often it solves."""

    coordinate: int
    calls: list

    def solve(self, t):
        self.calls.append(len(t))
        return {k: (k * t**2, 2 * k * t, 2.0 * k * np.ones_like(t)) for k in (1, 2)}


def test_a_grid_is_solved_once_and_the_values_are_copies():
    calls: list = []
    law = Toy(2, calls)
    t = np.linspace(0, 1, 5)
    q, qd, qdd = law(t)
    assert np.array_equal(q, 2 * t**2) and np.array_equal(qd, 4 * t) and np.array_equal(qdd, 4 * np.ones(5))
    q[:] = -1.0  # a caller writing to the values does not change the next call's
    assert np.array_equal(law(t)[0], 2 * t**2) and calls == [5]
    assert law(0.5)[0].shape == (1,) and calls == [5, 1]
    for n in range(KEEP + 2):  # an old grid falls out after KEEP others
        law(np.linspace(0, 1, 10 + n))
    law(t)
    assert calls[-1] == 5
    moved = replace(law, coordinate=1)  # a copy starts with its own, empty store
    assert np.array_equal(moved(t)[0], t**2) and calls[-1] == 5 and len(calls) == KEEP + 6


def test_the_templates_laws_are_pose_joint_laws():
    """The 3-RPR, the n-RRR and the serial arm take their joint laws from the same helper."""
    assert issubclass(rpr3.LegLaw, PoseJointLaw)
    assert issubclass(rrr4.JointLaw, PoseJointLaw)
    assert issubclass(serial_arm.JointLaw, PoseJointLaw)


def test_serial_arm_joints_share_one_solution_per_grid(monkeypatch):
    chain = serial_arm.Chain((0.0, 0.0), ((0.5, 0.0), (0.3, 0.0), (0.1, 0.0)))
    laws = tuple(PointToPoint(a, b, 1.0, quintic) for a, b in ((0.3, 0.5), (0.2, 0.4), (0.0, 1.0)))
    joint = serial_arm.joint_laws(chain, serial_arm.TaskMotion(laws, "tip"), 1)
    solved = []
    real = serial_arm.JointSolution

    def counting(*a, **k):
        solved.append(1)
        return real(*a, **k)

    monkeypatch.setattr(serial_arm, "JointSolution", counting)
    t = np.linspace(0, 1, 11)
    q = np.stack([law(t)[0] for law in joint], axis=1)
    assert len(solved) == 1
    assert np.allclose(chain.point(q), np.stack([laws[0](t)[0], laws[1](t)[0]], axis=1), atol=1e-12)
    assert np.allclose(q.sum(axis=1), laws[2](t)[0], atol=1e-12)  # phi = q1 + q2 + q3


def test_dyad_rates_recover_the_link_rates(rng):
    """Two links at angles alpha_k(t) (random quadratics): from the end point's velocity and
    acceleration the dyad's rates and accelerations are the alpha_k' and alpha_k''; a stretched
    dyad gives non-finite values, no exception (the templates check the configuration)."""
    from balpipe.mechanics.joint_laws import dyad_rates

    t = np.linspace(0, 1, 50)
    for _ in range(5):
        a, b = rng.uniform(0.2, 1.0, 2)
        p, q, r = rng.uniform(-2, 2, (3, 2))
        al = [p[k] + q[k] * t + r[k] * t**2 for k in (0, 1)]
        w = [q[k] + 2 * r[k] * t for k in (0, 1)]
        acc = [2 * r[k] * np.ones_like(t) for k in (0, 1)]
        if np.min(np.abs(np.sin(al[1] - al[0]))) < 1e-2:
            continue
        e = [(np.cos(x), np.sin(x)) for x in al]
        L = (a, b)
        Cd = [sum(L[k] * w[k] * (-e[k][1], e[k][0])[i] for k in (0, 1)) for i in (0, 1)]
        Cdd = [sum(L[k] * (acc[k] * (-e[k][1], e[k][0])[i] - w[k] ** 2 * e[k][i]) for k in (0, 1)) for i in (0, 1)]
        det = a * b * np.sin(al[1] - al[0])
        w1, w2, a1, a2 = dyad_rates(a, *e[0], b, *e[1], det, Cd, Cdd)
        for got, want in ((w1, w[0]), (w2, w[1]), (a1, acc[0]), (a2, acc[1])):
            assert np.allclose(got, want, rtol=1e-9, atol=1e-9)
    one = np.ones(1)
    w1, *_ = dyad_rates(1.0, one, 0 * one, 1.0, one, 0 * one, 0 * one, (one, one), (one, one))
    assert not np.all(np.isfinite(w1))


def test_body_point_by_components_is_body_point(rng):
    """:func:`body_point_xy` gives body_point's columns, bit for bit."""
    from balpipe.mechanics.joint_laws import body_point_xy

    for _ in range(5):
        pose = tuple(tuple(rng.normal(size=50) * 10.0 ** rng.integers(-3, 3) for _ in range(3)) for _ in range(3))
        c = rng.normal(size=2)
        for whole, (x, y) in zip(body_point(pose, c), body_point_xy(pose, c), strict=True):
            assert whole[:, 0].tobytes() == x.tobytes() and whole[:, 1].tobytes() == y.tobytes()
