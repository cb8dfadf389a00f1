"""The frame on elastic mounts: a rigid planar body (mass m, centroidal inertia J, centre of mass
c) held by linear spring-dampers at points p_j (stiffness kx, ky and damping cx, cy along the
frame's axes), moved by the loads the mechanism puts on it.

Small motions of the frame's centre of mass, q = (x, y, theta), obey

    M q'' + C q' + K q = Q(t),      M = diag(m, m, J),
    K = sum_j G_j^T diag(kx_j, ky_j) G_j,   C = sum_j G_j^T diag(cx_j, cy_j) G_j,
    G(p) = [[1, 0, -(p_y - c_y)], [0, 1, p_x - c_x]],

G(p) q being the displacement of the frame's point p (and G(p) q' its velocity). Q = (F_x, F_y,
M_c) is the load on the frame, its moment taken about c. Mount j pushes on the floor with
f_j = diag(kx_j, ky_j) G_j q + diag(cx_j, cy_j) G_j q' (and on the frame with -f_j), so that
M q'' = Q - sum_j G_j^T f_j: the frame's Newton-Euler equations.

Two ways to the motion, both exact for what they are given:

* :func:`periodic_response`, the steady state of a periodic load sampled on whole cycles: each
  order k of the load (its exact DFT, :func:`balpipe.mechanics.orders.complex_amplitudes`, every
  order below the Nyquist order) is solved with the complex dynamic stiffness,
  q_k = (K - (k w)^2 M + i k w C)^{-1} Q_k. The result is the exact steady state of the
  trigonometric polynomial through the samples; the constant (order 0) is a static deflection
  and is left out, so forces and velocities are what the load's variation adds.
* :func:`transient_response`, any load sampled in time: the frame starts at rest in
  equilibrium under the first sample's load, and the load varies linearly between samples (a
  first-order hold); the state-transition over each step is the exact solution of the linear
  system for that load (the matrix exponential of the augmented system, Van Loan's method), so
  the samples of q and q' are exact for the piecewise-linear load, with no integration error.
  What is reported is the change from the initial static state.

:func:`modes` gives the undamped natural frequencies and mode shapes (the generalized
eigenproblem K phi = w^2 M phi). Pure numpy and scipy; nothing here reads a spec.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .orders import complex_amplitudes, nyquist_order, whole_cycle_samples


@dataclass(frozen=True)
class Mount:
    """One mount: its point on the frame (m, frame axes), stiffness (N/m) and damping (N s/m)
    along x and y."""

    name: str
    at: tuple[float, float]
    kx: float
    ky: float
    cx: float = 0.0
    cy: float = 0.0


@dataclass(frozen=True)
class Frame:
    """A rigid frame (mass in kg, centroidal inertia in kg m^2, centre of mass in m) on mounts."""

    mass: float
    inertia: float
    com: tuple[float, float]
    mounts: tuple[Mount, ...]

    def jacobian(self, point: tuple[float, float]) -> np.ndarray:
        """G(p) (2, 3): the displacement of the frame's point p per unit (x, y, theta)."""
        rx, ry = point[0] - self.com[0], point[1] - self.com[1]
        return np.array([[1.0, 0.0, -ry], [0.0, 1.0, rx]])

    def mass_matrix(self) -> np.ndarray:
        return np.diag([self.mass, self.mass, self.inertia])

    def stiffness_matrix(self) -> np.ndarray:
        return sum((self.jacobian(m.at).T @ np.diag([m.kx, m.ky]) @ self.jacobian(m.at) for m in self.mounts),
                   np.zeros((3, 3)))

    def damping_matrix(self) -> np.ndarray:
        return sum((self.jacobian(m.at).T @ np.diag([m.cx, m.cy]) @ self.jacobian(m.at) for m in self.mounts),
                   np.zeros((3, 3)))

    def held(self) -> str:
        """"" when the mounts hold the frame in x, y and rotation (K positive definite), else
        what moves freely."""
        K = self.stiffness_matrix()
        scale = max(float(np.max(np.abs(K))), 1e-300)
        w, v = np.linalg.eigh(K / scale)
        if w[0] > 1e-12:
            return ""
        free = v[:, 0]
        names = ("x", "y", "rotation")
        return "the mounts leave the frame free to move along " + \
            ", ".join(n for n, c in zip(names, free) if abs(c) > 1e-6) + " (no stiffness resists it)"

    def load_about_com(self, force: np.ndarray, moment: np.ndarray, point: tuple[float, float]) -> np.ndarray:
        """Q (N, 3): a load given as a force (N, 2) and its moment (N,) about ``point``, with the
        moment moved to the centre of mass: M_c = M_p + (p - c) x F."""
        f = np.asarray(force, float)
        dx, dy = point[0] - self.com[0], point[1] - self.com[1]
        return np.column_stack([f[:, 0], f[:, 1], np.asarray(moment, float) + dx * f[:, 1] - dy * f[:, 0]])


@dataclass(frozen=True)
class Mode:
    """A natural mode: frequency (Hz), mass-normalised shape phi (x, y in m, theta in rad per
    sqrt(kg)), and its modal damping ratio phi^T C phi / (2 w) (exact when the damping is
    proportional; an estimate otherwise)."""

    frequency: float
    shape: tuple[float, float, float]
    damping_ratio: float

    def direction(self, frame: Frame) -> tuple[float, float, float]:
        """The shape as a unit vector of (x, y, rho theta), rho = sqrt(J / m) the frame's radius
        of gyration: the share of each motion in the mode's kinetic energy, signed."""
        rho = np.sqrt(frame.inertia / frame.mass)
        v = np.array([self.shape[0], self.shape[1], rho * self.shape[2]])
        return tuple(float(c) for c in v / np.linalg.norm(v))  # type: ignore[return-value]


def modes(frame: Frame) -> list[Mode]:
    """The undamped natural modes, lowest first: K phi = w^2 M phi (scipy's generalized symmetric
    eigensolver), phi^T M phi = 1, each shape's largest (x, y, rho theta) component positive and
    components below 1e-12 of it (round-off of a motion the mode does not involve) set to 0."""
    from scipy.linalg import eigh

    M, K, C = frame.mass_matrix(), frame.stiffness_matrix(), frame.damping_matrix()
    w2, phi = eigh(K, M)
    rho = np.sqrt(frame.inertia / frame.mass)
    out = []
    for i in range(3):
        v = phi[:, i]
        scaled = v * np.array([1.0, 1.0, rho])
        v = np.where(np.abs(scaled) <= 1e-12 * np.max(np.abs(scaled)), 0.0, v)  # round-off of a decoupled motion
        if scaled[int(np.argmax(np.abs(scaled)))] < 0:
            v = -v
        w = float(np.sqrt(max(w2[i], 0.0)))
        out.append(Mode(w / (2 * np.pi), (float(v[0]), float(v[1]), float(v[2])),
                        float(v @ C @ v / (2 * w)) if w > 0 else 0.0))
    return out


def dynamic_stiffness(frame: Frame, omega: float) -> np.ndarray:
    """K - w^2 M + i w C (3, 3), complex: the load amplitude per unit displacement amplitude at
    angular frequency w (rad/s)."""
    return frame.stiffness_matrix() - omega**2 * frame.mass_matrix() + 1j * omega * frame.damping_matrix()


def harmonic_response(frame: Frame, omega: float, load: np.ndarray) -> np.ndarray:
    """The complex amplitude of q (3,) under a load Re(Q e^{i w t}), Q (3,) complex."""
    return np.linalg.solve(dynamic_stiffness(frame, omega), np.asarray(load, complex))


@dataclass(frozen=True)
class Response:
    """The frame's motion on samples: q, q', q'' (N, 3) at times ``t`` (N,), and the weights
    (N,) of a time average over them (sum 1): uniform over whole cycles for a periodic steady
    state (exact for its band-limited content), the trapezoidal rule over the motion otherwise.
    ``method`` is "orders" or "time"; ``orders`` the number of orders solved (0 in the time
    domain)."""

    t: np.ndarray
    q: np.ndarray
    v: np.ndarray
    a: np.ndarray
    weights: np.ndarray
    method: str
    orders: int = 0

    def point_velocity(self, frame: Frame, point: tuple[float, float]) -> np.ndarray:
        """The velocity (N, 2) of the frame's point p: G(p) q'."""
        return self.v @ frame.jacobian(point).T

    def mount_forces(self, frame: Frame) -> np.ndarray:
        """The force (n_mounts, N, 2) each mount puts on the floor: k G q + c G q'."""
        out = []
        for m in frame.mounts:
            G = frame.jacobian(m.at)
            out.append((self.q @ G.T) * np.array([m.kx, m.ky]) + (self.v @ G.T) * np.array([m.cx, m.cy]))
        return np.array(out)

    def rms(self, values: np.ndarray) -> float:
        """The RMS of a signal (N,) or of a vector's magnitude (N, d) over the response."""
        v = np.asarray(values, float)
        sq = v**2 if v.ndim == 1 else np.sum(v**2, axis=1)
        return float(np.sqrt(max(float(self.weights @ sq), 0.0)))


def periodic_response(frame: Frame, t: np.ndarray, load: np.ndarray, cycles: float) -> Response:
    """The steady state under a periodic load Q (N, 3) sampled on ``t`` (uniform, both ends of
    ``cycles`` whole periods included, as the engine samples), order by order: every order below
    the Nyquist order, each through the complex dynamic stiffness. The returned samples are those
    of the ``cycles`` periods without the end point (``t[:-1]`` on the engine's grid)."""
    m = whole_cycle_samples(t, cycles)
    c = int(round(cycles))
    n = nyquist_order(m, c)
    tau = np.asarray(t[:m], float) - float(t[0])
    w = 2 * np.pi * c / (float(t[m]) - float(t[0]))  # the cycle's angular frequency
    q = np.zeros((m, 3))
    v = np.zeros((m, 3))
    a = np.zeros((m, 3))
    if n >= 1:
        Q = complex_amplitudes(np.asarray(load, float)[:m], c, n)  # (n, 3)
        for k in range(1, n + 1):
            wk = k * w
            qk = harmonic_response(frame, wk, Q[k - 1])
            e = np.exp(1j * wk * tau)[:, None]
            q += np.real(qk[None, :] * e)
            v += np.real(1j * wk * qk[None, :] * e)
            a += np.real(-(wk**2) * qk[None, :] * e)
    return Response(np.asarray(t[:m], float), q, v, a, np.full(m, 1.0 / m), "orders", n)


def _transition(A: np.ndarray, B: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Phi, Gamma0, Gamma1 of z' = A z + B (u + s tau) over a step h: z(h) = Phi z(0) + Gamma0 u
    + Gamma1 s, exactly (expm of the augmented matrix [[A, B, 0], [0, 0, I], [0, 0, 0]] h)."""
    from scipy.linalg import expm

    n, p = B.shape
    E = np.zeros((n + 2 * p, n + 2 * p))
    E[:n, :n] = A
    E[:n, n:n + p] = B
    E[n:n + p, n + p:] = np.eye(p)
    X = expm(E * h)
    return X[:n, :n], X[:n, n:n + p], X[:n, n + p:]


def transient_response(frame: Frame, t: np.ndarray, load: np.ndarray) -> Response:
    """The motion under a load Q (N, 3) sampled on increasing ``t``, linear between samples, from
    rest in equilibrium under Q(t_0): q and q' exact at every sample for that load (the
    state-transition matrices, one per distinct step: steps equal to 12 digits share them),
    q'' from the equations of motion.
    Reported as the change from the initial static state (the response to Q - Q(t_0))."""
    t = np.asarray(t, float)
    Q = np.asarray(load, float) - np.asarray(load, float)[0]
    M, K, C = frame.mass_matrix(), frame.stiffness_matrix(), frame.damping_matrix()
    Minv = np.linalg.inv(M)
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Minv @ K, -Minv @ C]])
    B = np.vstack([np.zeros((3, 3)), Minv])
    N = len(t)
    z = np.zeros((N, 6))
    steps: dict[float, tuple[np.ndarray, np.ndarray, np.ndarray]] = {}
    for i in range(N - 1):
        h = float(t[i + 1] - t[i])
        key = float(f"{h:.12e}")
        if key not in steps:
            steps[key] = _transition(A, B, h)
        Phi, G0, G1 = steps[key]
        z[i + 1] = Phi @ z[i] + G0 @ Q[i] + G1 @ ((Q[i + 1] - Q[i]) / h)
    q, v = z[:, :3], z[:, 3:]
    a = (Q - v @ C.T - q @ K.T) @ Minv.T
    weights = np.zeros(N)
    if N > 1:
        dt = np.diff(t)
        weights[:-1] += dt / 2
        weights[1:] += dt / 2
        weights /= t[-1] - t[0]
    else:
        weights[:] = 1.0
    return Response(t, q, v, a, weights, "time", 0)
