import numpy as np
import pytest

from balpipe.motion import PROFILES, Polynomial, PointToPoint, trapezoidal


@pytest.mark.parametrize("profile", [*PROFILES.values(), trapezoidal(0.25), trapezoidal(0.5)])
def test_profiles_meet_their_ends_and_derivatives_agree(profile):
    law = PointToPoint(0.3, 1.7, 0.8, profile)
    t = np.linspace(0, 0.8, 20001)
    q, qd, qdd = law(t)
    assert q[0] == pytest.approx(0.3, abs=1e-12)
    assert q[-1] == pytest.approx(1.7, abs=1e-12)
    assert qd[0] == pytest.approx(0, abs=1e-9) or profile is PROFILES["bang_bang"]
    # derivatives are the derivatives of the position (central differences)
    h = t[1] - t[0]
    assert np.max(np.abs(np.gradient(q, h)[1:-1] - qd[1:-1])) < 1e-3 * np.max(np.abs(qd))
    smooth = np.abs(qdd[2:] - qdd[:-2]) < 0.1 * np.max(np.abs(qdd))  # skip bang-bang/trapezoid jumps
    dd = np.gradient(qd, h)[1:-1] - qdd[1:-1]
    assert np.max(np.abs(dd[smooth])) < 1e-2 * np.max(np.abs(qdd))


def test_polynomial_meets_boundary_conditions():
    law = Polynomial.from_boundary((0.0, 1.0, 0.0), (2.0, -0.5, 3.0), 1.5)
    q, qd, qdd = law(np.array([0.0, 1.5]))
    assert np.allclose(q, [0, 2]) and np.allclose(qd, [1, -0.5]) and np.allclose(qdd, [0, 3])


def test_halving_the_duration_quadruples_accelerations():
    a = PointToPoint(0, 1, 1.0, PROFILES["quintic"])
    b = PointToPoint(0, 1, 0.5, PROFILES["quintic"])
    assert np.allclose(b(np.linspace(0, 0.5, 11))[2], 4 * a(np.linspace(0, 1, 11))[2])
