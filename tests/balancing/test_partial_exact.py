"""Unique optima exact: RMS objectives of partial_balance solved to the design, not only to the
solver's objective tolerance, against closed forms and independent least squares written here
(analytic kinematics, numpy's lstsq), never balpipe's engine."""

from __future__ import annotations

import math

import numpy as np
import pytest

from balpipe.balancing.partial import method as P
from balpipe.balancing.partial import polish as PP
from balpipe.balancing.partial.maps import time_weights
from balpipe.spec import Spec
from generic_specs import _circles, four_bar
from test_partial import method, setup

RMS_FORCE = [{"load": "shaking_force", "measure": "rms"}]


def slider_crank(rng, samples: int, budget: float = 50.0, cw=None) -> Spec:
    """An in-line slider-crank with random masses and lengths at a constant crank speed, one turn."""
    r, l = float(rng.uniform(0.03, 0.1)), float(rng.uniform(0.2, 0.4))
    cw = cw or {"body": "crank", "name": "cw", "segment": [[0, 0], [-r, 0]]}
    return Spec.model_validate({
        "name": "in-line slider-crank",
        "mechanism": {"template": "slider_crank", "offset": 0.0,
                      "crank": {"length": r, "mass": float(rng.uniform(0.2, 1)), "com": float(rng.uniform(0.2, 0.6)) * r,
                                "inertia": 1e-4},
                      "coupler": {"length": l, "mass": float(rng.uniform(0.3, 1.5)), "com": float(rng.uniform(0.2, 0.5)) * l,
                                  "inertia": 6e-3},
                      "slider": {"mass": float(rng.uniform(0.2, 2))}},
        "motion": {"cycles": 1, "drive": {"crank": {"law": "constant_speed", "from": 0.0,
                                                    "speed": f"{float(rng.uniform(200, 3000))} rpm"}}},
        "balancing": method([cw], objective=RMS_FORCE, budget=budget),
        "analysis": {"samples": samples},
        "validation": {"enabled": False},
    })


def slider_crank_lstsq(spec: Spec, n: int) -> np.ndarray:
    """The crank counterweight's first moment (crank axes) of least time-RMS shaking force by an
    independent least squares: the slider's position x = r cos th + sqrt(l^2 - r^2 sin^2 th) and
    its second derivative in th written out, the coupler's centre of mass on the line from crank pin
    to slider, n distinct crank angles of one turn (equal weights: a constant speed)."""
    m = spec.mechanism
    r, l = m.crank.length, m.coupler.length
    lam = m.coupler.com / l
    th = 2 * math.pi * np.arange(n) / n
    q = l * l - (r * np.sin(th)) ** 2
    dq, ddq = -r * r * np.sin(2 * th), -2 * r * r * np.cos(2 * th)
    xs_dd = -r * np.cos(th) - 0.25 * q ** -1.5 * dq ** 2 + 0.5 * q ** -0.5 * ddq  # d^2 x / d th^2
    e = np.stack([np.cos(th), np.sin(th)], axis=1)
    pin_dd, slider_dd = -r * e, np.stack([xs_dd, 0 * th], axis=1)
    # total m a at unit speed: crank's centre, coupler's (1 - lam) pin + lam slider, slider
    ma = (m.crank.mass * m.crank.com * -e + m.coupler.mass * ((1 - lam) * pin_dd + lam * slider_dd)
          + m.slider.mass * slider_dd)
    # a first moment s (crank axes) on the crank adds -R(th) s to m a; least |ma - R s|^2
    R = np.stack([np.stack([np.cos(th), -np.sin(th)], axis=1), np.stack([np.sin(th), np.cos(th)], axis=1)], axis=1)
    return np.linalg.lstsq(R.reshape(-1, 2), ma.reshape(-1), rcond=None)[0]


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_least_rms_crank_counterweight_is_rotating_plus_half_reciprocating_exactly(seed):
    """At a constant speed the in-line slider's acceleration is r w^2 (-cos th) plus even harmonics
    only (sqrt(l^2 - r^2 sin^2 th) is a function of cos 2 th), orthogonal over a turn to cos th and
    sin th. With the crank's first moment mu along it (the counterweight's included) the force is
    w^2 ((mu + m_rec r) cos th, mu sin th) + even harmonics, whose mean square
    ((mu + m_rec r)^2 + mu^2) / 2 + const is least at mu = -m_rec r / 2: the counterweight's first
    moment is m_rot r + m_rec r / 2 (m_rot r = m_crank c_crank + m_coupler (1 - lam) r, m_rec =
    m_slider + m_coupler lam). Exact, not only for r << l."""
    rng = np.random.default_rng(seed)
    samples = int(rng.integers(181, 722))
    spec = slider_crank(rng, samples)
    maps = setup(spec)
    _, out, *_ = P.solve(maps, spec.balancing)
    m = spec.mechanism
    r, lam = m.crank.length, m.coupler.com / m.coupler.length
    first = m.crank.mass * m.crank.com + m.coupler.mass * (1 - lam) * r + (m.slider.mass + m.coupler.mass * lam) * r / 2
    s = out.z[1:3]
    assert abs(-s[0] - first) <= 1e-9 * first
    assert abs(s[1]) <= 1e-9 * first
    ref = slider_crank_lstsq(spec, samples - 1)
    assert np.max(np.abs(s - ref)) <= 1e-9 * first
    # the budget is not spent: the lightest optimal design puts the whole mass at the segment's end
    assert out.z[0] == pytest.approx(first / r, rel=1e-9)
    assert out.precision is not None and out.precision <= 1e-9


def test_least_rms_counterweight_at_a_point_and_its_page_precision():
    """A counterweight of free mass at a fixed point: its mass is the closed form's first moment
    over its distance; the stage's parameters and notes state the design's precision."""
    rng = np.random.default_rng(7)
    spec0 = slider_crank(rng, 361)
    r = spec0.mechanism.crank.length
    spec = slider_crank(np.random.default_rng(7), 361, cw={"body": "crank", "name": "cw", "at": [-0.8 * r, 0]})
    maps = setup(spec)
    _, out, *_ = P.solve(maps, spec.balancing)
    m = spec.mechanism
    lam = m.coupler.com / m.coupler.length
    first = m.crank.mass * m.crank.com + m.coupler.mass * (1 - lam) * r + (m.slider.mass + m.coupler.mass * lam) * r / 2
    assert out.z[0] == pytest.approx(first / (0.8 * r), rel=1e-9)
    from balpipe import registry
    res = P.balance(registry.context(spec))
    d = res.details["partial_balance"]
    assert d["relative_error"] is not None and d["relative_error"] <= 1e-9
    assert "exact to" in d["precision"] and "exact to" in res.notes[0]
    assert all("exact to" in p.source for p in res.parameters if p.name.startswith("cw."))


def _four_bar_kinematics(spec: dict, th: np.ndarray, w: float):
    """Each body's angle, angular velocity and acceleration and its origin's acceleration at crank
    angles ``th`` and constant crank speed ``w``, from the loop a e(th) + b e(phi) = d e_x + c e(psi)
    differentiated twice (two 2x2 solves per sample); the assembly branch of the spec's pose."""
    fp = spec["mechanism"]["frame_points"]
    a, b, c = (bd["points"][k][0] for bd, k in zip(spec["mechanism"]["bodies"], ("A", "B", "B")))
    d = fp["O4"][0]
    out = {k: [] for k in ("crank", "coupler", "rocker")}
    for t in th:
        A = a * np.array([math.cos(t), math.sin(t)])
        B = _circles(A, b, (d, 0.0), c)
        phi, psi = math.atan2(*(B - A)[::-1]), math.atan2(B[1], B[0] - d)
        perp = lambda x: np.array([-math.sin(x), math.cos(x)])  # noqa: E731
        along = lambda x: np.array([math.cos(x), math.sin(x)])  # noqa: E731
        M = np.stack([b * perp(phi), -c * perp(psi)], axis=1)
        dphi, dpsi = np.linalg.solve(M, -a * w * perp(t))
        ddphi, ddpsi = np.linalg.solve(M, a * w * w * along(t) + b * dphi ** 2 * along(phi) - c * dpsi ** 2 * along(psi))
        out["crank"].append((t, w, 0.0, np.zeros(2)))
        out["coupler"].append((phi, dphi, ddphi, -a * w * w * along(t)))
        out["rocker"].append((psi, dpsi, ddpsi, np.zeros(2)))
    return out


def _acc(kin, p) -> np.ndarray:
    """The acceleration of the body point p (body axes) at each sample."""
    p = np.asarray(p, dtype=float)
    rows = []
    for ang, om, al, o in kin:
        R = np.array([[math.cos(ang), -math.sin(ang)], [math.sin(ang), math.cos(ang)]])
        rows.append(o + al * (R @ np.array([-p[1], p[0]])) - om * om * (R @ p))
    return np.array(rows)


def test_four_bars_split_of_a_mass_budget_equals_an_independent_least_squares():
    """Point counterweights of free mass on the crank and the rocker, the least time-RMS shaking
    force with a budget below what the unconstrained optimum wants: the split m1 + m2 = budget
    solved here as a one-variable least squares on analytic kinematics, to 1e-9."""
    rng = np.random.default_rng(21)
    d = four_bar(rng)
    th0 = d["mechanism"]["bodies"][0]["pose"][2]
    w = 2 * math.pi * 1.5
    pts = {"crank": [-0.04, 0.01], "rocker": [-0.06, 0.0]}
    n = 400
    th = th0 + 2 * math.pi * np.arange(n) / n
    kin = _four_bar_kinematics(d, th, w)
    F0 = sum(bd["mass"] * _acc(kin[bd["name"]], bd["com"]) for bd in d["mechanism"]["bodies"])
    a1, a2 = _acc(kin["crank"], pts["crank"]), _acc(kin["rocker"], pts["rocker"])
    X = np.stack([a1.reshape(-1), a2.reshape(-1)], axis=1)
    free = np.linalg.lstsq(X, -F0.reshape(-1), rcond=None)[0]
    assert np.all(free > 0)  # the unconstrained optimum: both parts, more mass than the budget below
    budget = 0.6 * float(free.sum())
    g = (a1 - a2).reshape(-1)
    m1 = -float(g @ (F0 + budget * a2).reshape(-1)) / float(g @ g)
    assert 0 < m1 < budget
    d["motion"] = {"cycles": 1, "drive": {"crank": {"law": "constant_speed", "from": th0, "speed": f"{w!r} rad/s"}}}
    d["analysis"]["samples"] = n + 1
    d["balancing"] = method([{"body": k, "name": f"cw_{k}", "at": v} for k, v in pts.items()], objective=RMS_FORCE,
                            budget=budget)
    spec = Spec.model_validate(d)
    maps = setup(spec)
    _, out, *_ = P.solve(maps, spec.balancing)
    assert out.z[0] == pytest.approx(m1, rel=1e-9, abs=1e-9 * budget)
    assert out.z[4] == pytest.approx(budget - m1, rel=1e-9, abs=1e-9 * budget)


def test_time_weights_count_a_cycles_shared_instant_once():
    t = np.linspace(0, 2.0, 9)
    w = time_weights(t)
    assert w.sum() == pytest.approx(1.0)
    assert w[0] == pytest.approx(w[1] / 2) and w[-1] == pytest.approx(w[1] / 2)
    f = np.cos(2 * math.pi * t / 2.0) ** 2  # a periodic function: its time average 1/2 exactly
    assert f @ w == pytest.approx(0.5, abs=1e-15)


def test_polish_refuses_a_wrong_active_set():
    """min x s.t. x >= 1 (nonneg row 1 - ... ): a slack/dual pair that claims the bound inactive
    gives no polished answer rather than a wrong one; the right pair gives x = 1 exactly."""
    q = np.array([1.0])
    A = np.array([[-1.0]])  # b - A x = x - 1 >= 0
    b = np.array([-1.0])
    cones = [("nonneg", 1)]
    x, err = PP.polish(q, A, b, cones, np.array([1.0 + 3e-9]), np.array([3e-9]), np.array([1.0]))
    assert x[0] == 1.0 and err <= 1e-15
    assert PP.polish(q, A, b, cones, np.array([1.5]), np.array([0.5]), np.array([0.0])) is None
