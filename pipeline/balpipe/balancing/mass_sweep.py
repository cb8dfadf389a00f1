"""Mass-parameter sweeps without re-analysis: every load is linear in the mass parameters, so one
kinematic analysis serves every mass.

At fixed geometry (joint points, initial poses, drivers, time grid) the kinematics of every
body's *frame* do not depend on the masses. Every load the engine computes is linear in each
body's parameters p = (m, mx, my, J) (mass, first moments in the body frame, inertia about the
frame origin; :func:`balpipe.balancing.regressor.parameters` with ``angular=True``):

* shaking force and moment, from the momentum rates (:func:`regressor.shaking_regressor`);
* the Lagrange multipliers, hence the actuator efforts and the joint reactions, from
  Phi_q^T lambda = -Y_D p in body-frame-origin coordinates (:func:`regressor.dynamics_regressor`),
  where Phi_q is the engine's Jacobian transformed from centre-of-mass to frame-origin
  coordinates (dr_c/dtheta = perp(A c)); the multipliers are unique and coordinate-free, and
  with redundant actuation the engine's least-norm choice (:func:`engine.solve_multipliers`) is
  linear too.

So one engine analysis of a base design gives matrices from which every design's loads are a
matrix product. A model's loads (springs, dampers, applied loads, viscous friction:
:mod:`balpipe.mechanics.loads`) depend on the motion alone, not on the masses: they add the same
multipliers ``Lam0`` (and efforts ``G0``) to every design, so the efforts and reactions are
affine in p; the shaking loads, inertial, keep no such term. Coulomb friction is not affine (its
magnitude follows the reactions): a model with it has no mass sweep (ValueError). The radial tooth forces of gear meshes with pitch radii (|F_t| tan alpha) are
not linear; they change only the bearings' reactions (and a fixed sun's frame load, which the
momentum route already contains), and :meth:`MassSweep.multipliers` adds them per design.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .regressor import dynamics_regressor, parameters, shaking_regressor, states_from_analysis
from ..engine import analyse, compile_model, jacobian
from ..engine.constraints import with_frame
from ..engine.dynamics import joint_reactions, solve_multipliers, radial_tooth_loads, tooth_rows
from ..engine.loads import terms as load_terms
from ..mechanics.planar import rotate
from ..model import Model

CHUNK = 512  # designs per block of the batched products (bounds the memory: CHUNK x N x rows)


def geometry_key(model: Model, t: np.ndarray, gravity=(0.0, 0.0), moment_point=(0.0, 0.0)) -> tuple:
    """Everything the kinematics depend on, and nothing else: two models with equal keys differ
    only in their bodies' mass parameters (masses, centres of mass, inertias, attachments), so
    one :class:`MassSweep` serves both."""
    t = np.asarray(t, dtype=float)
    bodies = tuple((b.name, tuple(sorted(b.points.items()))) for b in model.bodies)
    drivers = tuple((d.name, d.target, tuple(np.asarray(x, dtype=float).tobytes() for x in d.law(t)))
                    for d in model.drivers)
    return (bodies, model.joints, tuple(sorted(model.initial.items())), tuple(sorted(model.frame_points.items())),
            drivers, model.loads, t.tobytes(), tuple(map(float, gravity)), tuple(map(float, moment_point)))


def check_parameters(names: list[str], P: np.ndarray) -> list[str | None]:
    """Per design: None, or why it cannot be built (a negative mass or centroidal inertia), in the
    words of :func:`balpipe.engine.compile_model`."""
    D = P.shape[0]
    X = P.reshape(D, len(names), 4)
    m, mx, my, J = X[..., 0], X[..., 1], X[..., 2], X[..., 3]
    with np.errstate(divide="ignore", invalid="ignore"):
        Ic = np.where(m > 0, J - (mx**2 + my**2) / np.where(m > 0, m, 1.0), J)
    scale = np.maximum(np.abs(J), 1e-300)
    bad = (m < 0) | (Ic < -1e-12 * scale)
    out: list[str | None] = [None] * D
    for d in np.flatnonzero(bad.any(axis=1)):
        out[d] = f"body {names[int(np.argmax(bad[d]))]!r} has a negative mass or inertia"
    return out


@dataclass
class MassSweep:
    """The mass-independent matrices of one geometry (see the module docstring).

    ``YF`` (N, 2, np), ``YM`` (N, np): shaking force and moment about ``moment_point``;
    ``Lam`` (N, m, np): multipliers without radial tooth forces; ``G`` (N, ndrv, np): efforts
    (``drivers`` order); ``np`` = 4 x bodies, columns as in ``parameters(model, angular=True)``."""

    model: Model
    t: np.ndarray
    key: tuple
    YF: np.ndarray
    YM: np.ndarray
    Lam: np.ndarray
    G: np.ndarray
    drivers: list[str]
    compiled: object
    mesh_geo: list
    Lam0: np.ndarray | float = 0.0  # (N, m): the multipliers of the loads, the same for every design
    G0: np.ndarray | float = 0.0  # (N, ndrv): their efforts

    @classmethod
    def build(cls, model: Model, t: np.ndarray, gravity=(0.0, 0.0), moment_point=(0.0, 0.0),
              analysis=None, samples: np.ndarray | None = None) -> "MassSweep":
        """One engine analysis of ``model`` (``analysis``, when given, is taken as that analysis:
        the engine's of ``model`` on ``t`` with this gravity and moment point, already at hand);
        raises :class:`balpipe.engine.AnalysisError` like it.

        ``samples``: the matrices at these indices of ``t`` only (the sweep's ``t`` is then
        ``t[samples]``), from the analysis of the whole of ``t``: every sample's matrices are
        computed alone, so they are the same numbers as in the sweep of every sample, and the
        sweep holds (samples, rows, 4 x bodies) arrays instead of (N, ...) ones."""
        t = np.asarray(t, dtype=float)
        an = analysis if analysis is not None else analyse(model, t, gravity, moment_point)
        at = slice(None) if samples is None else np.asarray(samples, dtype=int)
        t = t[at]
        q, v = an.q[at], an.v[at]
        states = states_from_analysis(model, an, samples=samples)
        YF, YM = shaking_regressor(states, gravity, moment_point)
        YD = dynamics_regressor(states, gravity)
        base = compile_model(model)
        c = base.dynamics or base  # with actuators: their rows, not the drivers' (engine.compile._actuated)
        N = len(t)
        qx = with_frame(q.reshape(N, -1))
        J = jacobian(c, qx)
        geo = tooth_rows(c, qx, J)
        Lam0: np.ndarray | float = 0.0
        if model.loads:  # in centre-of-mass coordinates, before the change below
            lt = load_terms(model, base, t, q.reshape(N, -1), v.reshape(N, -1))
            if lt.coulomb:
                raise ValueError("Coulomb friction is not linear in the masses: no mass sweep of this model")
            Lam0 = solve_multipliers(c, J[:, :, 3:].copy(), lt.Q)
        for k, b in enumerate(model.bodies):  # centre-of-mass -> frame-origin coordinates
            _, com, _ = b.mass_properties()
            s = rotate(q[:, k, 2], np.asarray(com, dtype=float))
            col = 3 * (k + 1)
            J[:, :, col + 2] += -J[:, :, col] * s[:, 1, None] + J[:, :, col + 1] * s[:, 0, None]
        Jf = J[:, :, 3:]
        Lam = solve_multipliers(c, Jf, -YD)  # every parameter's column at once
        drivers = list(c.driver_rows)
        G = -Lam[:, [c.driver_rows[d] for d in drivers], :]
        key = geometry_key(model, t, gravity, moment_point)
        G0 = -Lam0[:, [c.driver_rows[d] for d in drivers]] if model.loads else 0.0
        return cls(model, t, key, YF, YM, Lam, G, drivers, c, geo, Lam0, G0)

    @property
    def names(self) -> list[str]:
        return [b.name for b in self.model.bodies]

    def parameters(self, model: Model) -> np.ndarray:
        """p of a design with this geometry (raises ValueError if its geometry differs)."""
        if [b.name for b in model.bodies] != self.names or geometry_key(
            model, self.t, *self.key[-2:]
        ) != self.key:
            raise ValueError(f"model {model.name!r} does not have the geometry of this sweep")
        return parameters(model, angular=True)

    def loads(self, p: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Shaking force (N, 2), moment (N,) and efforts (N, ndrv) of one design."""
        return self.YF @ p, self.YM @ p, self.G @ p + self.G0

    def multipliers(self, p: np.ndarray) -> np.ndarray:
        """All multipliers (N, m) of one design, radial tooth forces included."""
        lam = self.Lam @ p + self.Lam0
        if self.compiled.meshes:
            lam, _ = radial_tooth_loads(self.compiled, self.mesh_geo, lam)
        return lam

    def reactions(self, p: np.ndarray) -> dict[str, dict[str, np.ndarray]]:
        """Joint reactions of one design, as :attr:`balpipe.engine.Analysis.reactions`."""
        return joint_reactions(self.model, self.compiled, self.multipliers(p), self.mesh_geo)

    def peaks(self, P: np.ndarray, chunk: int = CHUNK) -> dict[str, np.ndarray]:
        """Peak |F|, |M| and |effort| of every design (rows of P, (D, np)) by blocks of matrix
        products: the sweep's fast path. One product per block with the stacked regressor
        [Fx; Fy; M; efforts]^T, designs as rows; peaks as max and min (no temporaries of |x|)."""
        P = np.atleast_2d(np.asarray(P, dtype=float))
        D, n = P.shape
        N = len(self.t)
        nd = self.G.shape[1]
        Y = np.concatenate([self.YF[:, 0, :], self.YF[:, 1, :], self.YM,
                            np.transpose(self.G, (1, 0, 2)).reshape(nd * N, n)]).T.copy()  # (np, rows)
        out = {"max_shaking_force": np.empty(D), "max_shaking_moment": np.empty(D), "max_actuator_effort": np.zeros(D)}
        for s in range(0, D, chunk):
            R = P[s : s + chunk] @ Y  # (d, rows)
            fx, fy, m = R[:, :N], R[:, N : 2 * N], R[:, 2 * N : 3 * N]
            out["max_shaking_force"][s : s + chunk] = np.sqrt(np.max(fx * fx + fy * fy, axis=1))
            out["max_shaking_moment"][s : s + chunk] = np.maximum(m.max(axis=1), -m.min(axis=1))
            if nd:
                e = R[:, 3 * N :]
                if self.model.loads:
                    e = e + np.asarray(self.G0).T.reshape(1, nd * N)
                out["max_actuator_effort"][s : s + chunk] = np.maximum(e.max(axis=1), -e.min(axis=1))
        return out
