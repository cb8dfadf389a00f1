"""Physics checks on a built spec, independent of the figures balpipe reports: every number is
recomputed here from the stage's model (its bodies' masses, centres of mass and inertias) and
the engine's motion (centre-of-mass accelerations), never read from the study's verdicts.

* a stage that claims to cancel the shaking force (moment) keeps its inertial peak within its
  stated tolerance of the reference load: max_t |dP/dt| <= tol F_ref, max_t |dH_P/dt| <= tol M_ref;
* the joint reactions on the frame equal the momentum rates: F = m g - dP/dt and
  M_P = sum (r_i - P) x m_i g - dH_P/dt, with P = sum m_i r_i' and
  H_P = sum (r_i - P) x m_i r_i' + I_i theta_i' (the reactions route of the engine against
  Newton-Euler on the whole mechanism), to 1e-9 of the reference load;
* every mass and inertia times k scales the shaking force and moment by k (and, without force
  elements or applied loads, every actuator effort and joint reaction), to 1e-9 of the scaled
  loads.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from ..engine import Analysis, analyse
from ..mechanics.planar import cross
from ..model import Model
from ..study import StageResult

#: relative agreement of two routes to the same load, of the reference load
ROUTE_TOLERANCE = 1e-9
#: the factor of the mass-scaling check (not a round number: a bug that doubles would not hide)
MASS_FACTOR = 2.7


class PhysicsError(AssertionError):
    """A physical invariant that a stage's analysis breaks; the message names the stage."""


def _mass_arrays(model: Model, names: list[str]) -> tuple[np.ndarray, np.ndarray]:
    props = [model.body(n).mass_properties() for n in names]
    return np.array([p[0] for p in props]), np.array([p[2] for p in props])


def momentum_rates(model: Model, an: Analysis) -> tuple[np.ndarray, np.ndarray]:
    """dP/dt (N, 2) and dH_P/dt (N,) about the analysis' moment point, from the bodies' masses
    and centroidal inertias (attachments included) and the centre-of-mass accelerations."""
    m, inertia = _mass_arrays(model, an.names)
    P = np.asarray(an.moment_point, dtype=float)
    r, a = an.q[:, :, :2] - P, an.a[:, :, :2]
    dP = np.einsum("k,nkd->nd", m, a)
    dH = np.einsum("k,nk->n", m, cross(r, a)) + an.a[:, :, 2] @ inertia
    return dP, dH


def weight_loads(model: Model, an: Analysis) -> tuple[np.ndarray, np.ndarray]:
    """The weight m g (2,) of the moving bodies and its moment (N,) about the moment point."""
    m, _ = _mass_arrays(model, an.names)
    g = np.asarray(an.gravity, dtype=float)
    r = an.q[:, :, :2] - np.asarray(an.moment_point, dtype=float)
    return m.sum() * g, np.einsum("k,nk->n", m, cross(r, np.broadcast_to(g, r.shape)))


def check_claims(sr: StageResult) -> None:
    """A stage that claims a balance ("force", "force+moment") meets the tolerance its metrics
    state (:mod:`balpipe.mechanics.claim_precision`), on peaks recomputed from momentum."""
    claims = [w for w in ("force", "moment") if w in sr.stage.balances]
    if not claims:
        return
    dP, dH = momentum_rates(sr.stage.model, sr.analysis)
    metrics = sr.metrics
    ref = metrics.reference_loads
    peaks = {"force": float(np.max(np.linalg.norm(dP, axis=1))), "moment": float(np.max(np.abs(dH)))}
    for what in claims:
        tol = metrics.force_tolerance if what == "force" else metrics.moment_tolerance
        scale = ref.force if what == "force" else ref.moment
        if not peaks[what] <= tol * scale * (1 + 1e-9):
            raise PhysicsError(f"stage {sr.stage.name!r} claims to cancel the shaking {what} but keeps "
                               f"{peaks[what]:.6g} (tolerance {tol:.3g} of the reference {scale:.6g})")


def check_reactions_equal_momentum(sr: StageResult) -> None:
    """The engine's shaking force and moment from the frame's joint reactions equal m g - dP/dt
    and the weight's moment - dH_P/dt, to :data:`ROUTE_TOLERANCE` of the reference load."""
    an, model = sr.analysis, sr.stage.model
    dP, dH = momentum_rates(model, an)
    W, MW = weight_loads(model, an)
    ref = sr.metrics.reference_loads
    df = float(np.max(np.linalg.norm(an.force - (W - dP), axis=1)))
    dm = float(np.max(np.abs(an.moment - (MW - dH))))
    fscale, mscale = max(ref.force, 1e-300), max(ref.moment, 1e-300)
    if not (df <= ROUTE_TOLERANCE * fscale and dm <= ROUTE_TOLERANCE * mscale):
        raise PhysicsError(f"stage {sr.stage.name!r}: the frame's reactions and the momentum rates disagree by "
                           f"{df:.3g} N ({df / fscale:.3g} of the reference) and {dm:.3g} N m ({dm / mscale:.3g})")


def scaled_masses(model: Model, k: float) -> Model:
    """The model with every body's and attachment's mass and inertia times k (same geometry)."""
    bodies = tuple(replace(b, mass=b.mass * k, inertia=b.inertia * k,
                           attachments=tuple(replace(a, mass=a.mass * k, inertia=a.inertia * k) for a in b.attachments))
                   for b in model.bodies)
    return replace(model, bodies=bodies)


def _scale_gaps(scaled: dict[str, np.ndarray], base: dict[str, np.ndarray], k: float) -> dict[str, float]:
    """max_t |scaled - k base| of each load, over the larger of its own peak and a thousandth of
    the largest peak of them all (a load that is zero but for round-off is judged against the
    loads whose round-off it carries)."""
    peaks = {n: float(np.max(np.abs(k * v), initial=0.0)) for n, v in base.items()}
    floor = 1e-3 * max(peaks.values(), default=0.0)
    return {n: float(np.max(np.abs(scaled[n] - k * v), initial=0.0)) / max(peaks[n], floor, 1e-300)
            for n, v in base.items()}


def check_mass_scaling(sr: StageResult, k: float = MASS_FACTOR) -> None:
    """Every mass and inertia times ``k`` gives k times the shaking force and moment (about the
    same point, gravity included) and, without force elements or applied loads, k times every
    actuator effort and joint reaction."""
    an, model = sr.analysis, sr.stage.model
    big = analyse(scaled_masses(model, k), an.t, an.gravity, an.moment_point)
    ref = sr.metrics.reference_loads
    gaps = {"shaking force": float(np.max(np.linalg.norm(big.force - k * an.force, axis=1))) / max(k * ref.force, 1e-300),
            "shaking moment": float(np.max(np.abs(big.moment - k * an.moment))) / max(k * ref.moment, 1e-300)}
    if not getattr(model, "loads", ()):
        base = {f"effort {n}": e for n, e in an.efforts.items()}
        base |= {f"reaction {j}.{c}": v for j, comps in an.reactions.items() for c, v in comps.items()}
        scaled = {f"effort {n}": e for n, e in big.efforts.items()}
        scaled |= {f"reaction {j}.{c}": v for j, comps in big.reactions.items() for c, v in comps.items()}
        gaps |= _scale_gaps(scaled, base, k)
    bad = {n: g for n, g in gaps.items() if not g <= ROUTE_TOLERANCE}
    if bad:
        worst = sorted(bad.items(), key=lambda kv: -kv[1])[:3]
        raise PhysicsError(f"stage {sr.stage.name!r}: masses x {k} do not scale the loads by {k}: "
                           + ", ".join(f"{n} off by {g:.3g}" for n, g in worst))


STAGE_CHECKS = (check_claims, check_reactions_equal_momentum, check_mass_scaling)
