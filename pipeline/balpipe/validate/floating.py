"""The reactionless demonstration: the mechanism on a free-floating frame, without gravity.

Simulated in pymunk when it holds together, and always compared with the exact conservation
solution (constant total momentum and angular momentum along the analysed relative motion).

Massless bodies (the paper-004 five-bar's gears) cannot be simulated: pymunk needs a mass, and
a floor mass as large as the position-driven validation's (0.1 of the heaviest) would move the
free base. They get a physically small mass instead, ``small_mass`` (default 1 %) of the
mechanism's total mass, and, if they have no moment of inertia either, that of a disc of their
drawn radius (or of a tenth of the mechanism's reach). The simulated design is then that of the
model with those parts; its own conservation solution checks the simulation
(``reference_difference``), and the massless model's conservation solution
(``massless_max_drift``/``..._rotation``, ``massless_difference``) shows what the small masses
change. ``method`` says per stage which it is.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field, replace

import numpy as np

from ..display import numbers
from ..engine import Analysis
from ..mechanics.planar import cross, rotate
from ..model import Attachment, Model
from .run import model_scale, _run_adaptive
from .settings import ValidationSettings, _step_grid, default_settings

#: the small masses tried in turn, times ``small_mass``: the smallest that pymunk holds together
SMALL_MASS_STEPS = (1.0, 10.0, 100.0)
#: the demonstration's step, as a multiple of the checks' default (:func:`default_settings`: T/1000
#: and 0.01 rad a step of the fastest body), placed on the analysis grid like every run's. It has no
#: residual limit, and its accuracy is on the page beside it: its difference from the exact
#: conservation solution. Measured on specs/ against the checks' step: the same method for every
#: stage (pymunk or the conservation solution), drifts and rotations the same to 3 digits, the
#: differences from the conservation solution at most 6e-6 m and 8e-6 rad (2.6e-2 m and 6e-3 rad of
#: drift and rotation unbalanced), and the free-frame runs 4.1 -> 2.3 s of CPU
DEMONSTRATION_STEP = 2.0

#: the demonstration's solver effort from its first step: the checks' start-up (their first steps,
#: and those after a law's jump, at 5000 iterations) serves their residual limits, and a
#: demonstration has none. Measured on specs/ without it: the same method, solver iterations and
#: small masses for every stage, drifts and rotations the same to 3 digits, the differences from the
#: conservation solution of the same order (at most 5.8e-6 -> 4.7e-6 m, 7.7e-6 rad), and the
#: demonstrations' runs 2.89 -> 2.25 s of CPU in the simulated build (a run that comes apart in its
#: first steps, 15 of them on each of paper 000's idler-loop counter-rotation stages, mostly paid
#: the start-up)
DEMONSTRATION_STARTUP = False

@dataclass
class FreeFloating:
    """The mechanism on a free base without gravity (reactionless demonstration).

    ``t`` (N,) analysis grid; ``base`` (N, 3): pose (x, y, angle) of the frame's origin, so a
    frame point p is drawn at base[:2] + R(base[2]) p; ``drift`` (N, 2): displacement of the
    base's centre of gravity; ``rotation`` (N,) = base[:, 2] (rad); ``poses`` (N, nb, 3):
    global pose of each body's own frame (for drawing, like ``Analysis.pose``).
    ``method``: "pymunk" (the simulation) or "momentum" (the exact solution from the
    conservation of the total momentum and angular momentum along the analysed relative
    motion, used when the simulation did not hold together; ``notes`` says why). The
    conservation solution is always computed: ``reference_max_drift``/``..._rotation`` and
    ``reference_difference`` (largest |drift| and |rotation| difference) compare the two.
    ``momentum_drift``: change of the simulated total linear (N s) and angular (N m s) momentum
    of base + mechanism, zero in physics (a check of the simulation; zeros for "momentum").
    """

    t: np.ndarray
    names: list[str]
    base: np.ndarray
    drift: np.ndarray
    rotation: np.ndarray
    poses: np.ndarray
    base_mass: float
    base_inertia: float
    base_centre: tuple[float, float]
    method: str
    max_drift: float
    max_rotation: float
    reference_max_drift: float
    reference_max_rotation: float
    reference_difference: tuple[float, float]
    momentum_drift: tuple[float, float]
    dt: float
    iterations: int
    notes: list[str] = field(default_factory=list)
    timing: dict[str, float] = field(default_factory=dict)
    small_masses: dict[str, tuple[float, float]] = field(default_factory=dict)
    massless_max_drift: float = math.nan
    massless_max_rotation: float = math.nan
    massless_difference: tuple[float, float] = (math.nan, math.nan)
    small_mass_fraction: float = math.nan

    @property
    def method_label(self) -> str:
        """What the page shows: a simulation or the conservation solution."""
        if self.method == "pymunk":
            return "simulation (pymunk)" + (
                f", each massless part given {100 * self.small_mass_fraction:g} % of the mechanism's mass "
                "(pymunk cannot move a body without mass)" if self.small_masses else "")
        return "conservation solution (not simulated)"

    def to_json(self) -> dict:
        return {
            "method": self.method,
            "base_mass": float(self.base_mass),
            "base_inertia": float(self.base_inertia),
            "max_drift": float(self.max_drift),
            "max_rotation": float(self.max_rotation),
            "max_rotation_deg": float(math.degrees(self.max_rotation)),
            "final_drift": float(np.linalg.norm(self.drift[-1])),
            "final_rotation": float(self.rotation[-1]),
            "reference_max_drift": float(self.reference_max_drift),
            "reference_max_rotation": float(self.reference_max_rotation),
            "reference_difference_drift": float(self.reference_difference[0]),
            "reference_difference_rotation": float(self.reference_difference[1]),
            "linear_momentum_drift": float(self.momentum_drift[0]),
            "angular_momentum_drift": float(self.momentum_drift[1]),
            "dt": float(self.dt),
            "iterations": int(self.iterations),
            "notes": "; ".join(self.notes),
            "method_label": self.method_label,
            "small_masses": {k: {"mass": float(m), "inertia": float(i)} for k, (m, i) in sorted(self.small_masses.items())},
            "massless_max_drift": float(self.massless_max_drift),
            "massless_max_rotation": float(self.massless_max_rotation),
            "massless_difference_drift": float(self.massless_difference[0]),
            "massless_difference_rotation": float(self.massless_difference[1]),
            "small_mass_fraction": float(self.small_mass_fraction),
        }



def _conservation_solution(model: Model, analysis: Analysis, mb: float, ib: float, centre: np.ndarray):
    """Base motion from the conservation of momentum along the analysed relative motion.

    The analysis gives every body's centre of mass rho_k, angle theta_k and their rates in the
    frame's coordinates. With the base at angle phi and the total centre of mass r_G (moving
    uniformly with the initial momentum), r_k = r_G + R(phi) d_k, d_k = rho_k - s,
    s = (m_B c_B + sum m_k rho_k) / M; the angular momentum about r_G is
    sum m_k d_k x d_k' + phi' (sum m_k |d_k|^2 + sum I_k + I_B) + sum I_k theta_k' (base
    included in the sums of m), constant, which gives phi' (integrated by trapezoids).
    Returns (phi (N,), base origin (N, 2))."""
    t = np.asarray(analysis.t, dtype=float)
    q, v = analysis.q, analysis.v
    props = [b.mass_properties() for b in model.bodies]
    m = np.array([p[0] for p in props])
    inertia = np.array([p[2] for p in props])
    M = mb + m.sum()
    s = (mb * centre + np.einsum("k,nkd->nd", m, q[:, :, :2])) / M
    sd = np.einsum("k,nkd->nd", m, v[:, :, :2]) / M
    d = q[:, :, :2] - s[:, None, :]
    dd = v[:, :, :2] - sd[:, None, :]
    dB = centre[None, :] - s
    num = np.einsum("k,nk->n", m, cross(d, dd)) + mb * cross(dB, -sd) + v[:, :, 2] @ inertia
    den = np.einsum("k,nk->n", m, np.sum(d**2, axis=-1)) + mb * np.sum(dB**2, axis=-1) + inertia.sum() + ib
    phid = (num[0] - num) / den
    phi = np.concatenate([[0.0], np.cumsum(0.5 * (phid[1:] + phid[:-1]) * np.diff(t))])
    p0 = np.einsum("k,kd->d", m, v[0, :, :2])
    rG = s[0][None, :] + np.outer(t - t[0], p0 / M)
    origin = rG - rotate(phi, s)
    return phi, origin


def motion_only(analysis: Analysis) -> Analysis:
    """``analysis`` with only what :func:`free_floating` reads: the time grid, the centres of
    mass' poses, velocities and accelerations, the momenta that follow from them and the moment
    point. The loads, efforts and reactions, which depend on gravity and the external loads
    (a free-floating run has neither), are left out (NaN, empty), and gravity is zero. Two
    analyses of the same model and motion under other gravity or loads give the same view, so
    the simulation cache (:mod:`balpipe.cache.simulation`, keyed by the arguments) runs their
    demonstration once: paper 002's vertical and horizontal specs share all three of theirs.
    ``free_floating(model, motion_only(a))`` is ``free_floating(model, a)``, bit for bit
    (tests/validate/test_floating.py)."""
    nan = np.full_like(np.asarray(analysis.force, dtype=float), np.nan)
    return replace(
        analysis, force=nan, moment=np.full_like(np.asarray(analysis.moment, dtype=float), np.nan),
        force_momentum=nan, moment_momentum=np.full_like(np.asarray(analysis.moment, dtype=float), np.nan),
        efforts={}, reactions={}, gravity=(0.0, 0.0), actuation_condition=None, actuator_rates=None,
        frame_force=None, frame_moment=None, loads={},
    )


def with_small_masses(model: Model, fraction: float, reach: float) -> tuple[Model, dict[str, tuple[float, float]]]:
    """``model`` with every massless body given ``fraction`` of the total mass (a part at its
    centre of mass); one without a moment of inertia also gets that of a disc of its radius
    (or of reach / 10). Returns the model and {body: (added mass, added inertia)}."""
    total = model.total_mass()
    out, added = model, {}
    for b in model.bodies:
        m, com, inertia = b.mass_properties()
        if m > 0.0:
            continue
        dm = fraction * total
        r = b.radius or 0.1 * reach
        di = 0.5 * dm * r * r if inertia <= 0.0 else 0.0
        out = out.replace_body(b.with_attachments(Attachment("small mass", dm, tuple(com), di, kind="part")))
        added[b.name] = (dm, di)
    return out, added


def free_floating(
    model: Model,
    analysis: Analysis,
    base_mass: float = 10.0,
    base_inertia: float | None = None,
    settings: ValidationSettings | None = None,
    simulate_pymunk: bool = True,
    small_mass: float | None = 0.01,
) -> FreeFloating:
    """The mechanism moving on a free base, without gravity.

    The frame becomes a body of mass ``base_mass`` (default 10 kg) whose centre of gravity is
    the analysis' moment point, with moment of inertia ``base_inertia`` (default
    (2/3) base_mass reach^2, a square plate of side 2 reach; reach = the largest distance of a
    centre of mass from that point during the motion). Every driver and frame joint acts on the
    base; gear pairs carried by the frame mesh on it (``gear_model="mesh"``, which conserves
    angular momentum). The base starts at rest. A reactionless stage leaves it where it is.
    The step is :data:`DEMONSTRATION_STEP` times the motion's own default (:func:`default_settings`),
    whatever ``settings.dt``, every step at the run's solver iterations (no start-up boost:
    :data:`DEMONSTRATION_STARTUP`).
    When the simulation does not hold together (a mesh between gears of large inertia and
    small mass or radius converges slowly in pymunk's solver), or ``simulate_pymunk`` is False,
    the exact conservation solution is returned instead (``method = "momentum"``).
    ``small_mass``: massless bodies are simulated with this fraction of the total mass (see the
    module's docstring); None keeps today's fallback, the conservation solution.
    """
    settings = settings or ValidationSettings()
    wall0 = time.perf_counter()
    reach = model_scale(analysis)
    bi = float(base_inertia) if base_inertia is not None else (2.0 / 3.0) * base_mass * reach**2
    centre = np.asarray(analysis.moment_point, dtype=float)
    names = [b.name for b in model.bodies]
    t = np.asarray(analysis.t, dtype=float)
    notes: list[str] = []
    run = None
    dt, it = 0.0, 0
    massless = [b.name for b in model.bodies if b.mass_properties()[0] <= 0.0]
    massless_ref = None
    small: dict[str, tuple[float, float]] = {}
    sim_model = model
    idx = None
    attempts: list[float | None] = [None]
    if massless and small_mass and simulate_pymunk:
        massless_ref = _conservation_solution(model, analysis, float(base_mass), bi, centre)
        attempts = [float(small_mass) * k for k in SMALL_MASS_STEPS]
    elif simulate_pymunk and massless:
        simulate_pymunk = False
        notes.append(
            "massless bodies (" + ", ".join(massless) + "): pymunk needs a mass, which would move "
            "the free base; conservation solution used"
        )
    phi_ref, origin_ref = _conservation_solution(model, analysis, float(base_mass), bi, centre)
    drift_ref = origin_ref + rotate(phi_ref, np.broadcast_to(centre, origin_ref.shape)) - centre
    if simulate_pymunk:
        dt_default, it_default = default_settings(model, analysis)
        # from the motion's own step (:func:`default_settings`), not ``settings.dt``: a spec's step
        # is chosen for the checks' residual limits, a demonstration has none (paper 000's 0.125 ms,
        # a residual limit of its counterweights stages, doubled the demonstration's cost, and its
        # unbalanced stage came apart there at every solver effort: it holds together at 0.25 ms)
        dt, nsteps, idx = _step_grid(t, DEMONSTRATION_STEP * dt_default)
        # every step at the run's own solver effort: no start-up boost (:data:`DEMONSTRATION_STARTUP`)
        if not DEMONSTRATION_STARTUP:
            settings = replace(settings, startup_iterations=0)
        it = settings.iterations or it_default
        failed: list[str] = []
        for fraction in attempts:
            sim_model, small = (model, {}) if fraction is None else with_small_masses(model, fraction, reach)
            run, run_notes, _ = _run_adaptive(
                sim_model, analysis, dt, it, settings, reach, idx, max_iterations=max(4 * it, 1600),
                floating_base=(float(base_mass), bi, (float(centre[0]), float(centre[1]))),
            )
            if run is not None:
                mom = run.momentum - run.momentum[0]
                dp = float(np.max(np.linalg.norm(mom[:, :2], axis=1)))
                dh = float(np.max(np.abs(mom[:, 2])))
                # gross momenta of the mechanism (sums of magnitudes: a balanced stage nets zero)
                mk = np.array([b.mass_properties()[0] for b in sim_model.bodies])
                ik = np.array([b.mass_properties()[2] for b in sim_model.bodies])
                speed = np.linalg.norm(analysis.v[:, :, :2], axis=2)
                arm = np.linalg.norm(analysis.q[:, :, :2] - centre, axis=2)
                p_scale = float(np.max(speed @ mk)) or 1.0
                h_scale = float(np.max((arm * speed) @ mk + np.abs(analysis.v[:, :, 2]) @ ik)) or 1.0
                if dh > 1e-3 * h_scale or dp > 1e-3 * p_scale:
                    run_notes.append(f"the simulation lost {numbers.num(dh, 3)} N m s of angular momentum")
                    run = None
            if run is not None:
                if fraction is not None:
                    notes.append(
                        "massless parts simulated with a mass of their own, as pymunk needs one (" + ", ".join(
                            f"{k} {numbers.num(1000 * m, 3)} g" + (f" and {numbers.num(i, 3)} kg m^2" if i > 0 else "")
                            for k, (m, i) in small.items()
                        ) + f": each {numbers.num(100 * fraction)} % of the mechanism's mass)"
                        + (f"; with {', '.join(failed)} of the mechanism's mass pymunk did not hold together" if failed else "")
                    )
                    phi_ref, origin_ref = _conservation_solution(sim_model, analysis, float(base_mass), bi, centre)
                    drift_ref = origin_ref + rotate(phi_ref, np.broadcast_to(centre, origin_ref.shape)) - centre
                else:
                    notes += run_notes
                break
            if fraction is None:
                notes += run_notes
            else:
                failed.append(f"{100 * fraction:g} %")
        if run is None:
            sim_model, small, massless_ref = model, {}, None
            notes.append("pymunk did not hold the mechanism together" + (
                f" (with the massless parts given {', '.join(failed)} of the mechanism's mass each)" if failed else "")
                + ": conservation solution used")
    if run is not None:
        if idx is None:
            idx = np.searchsorted(run.t, t).clip(0, len(run.t) - 1)
        base = run.base[idx]
        poses = run.poses[idx].copy()
        method = "pymunk"
        momentum_drift = (dp, dh)
        it = run.iterations
    else:
        base = np.column_stack([origin_ref, phi_ref])
        poses = analysis.q.copy()
        poses[:, :, :2] = origin_ref[:, None, :] + rotate(phi_ref[:, None], analysis.q[:, :, :2])
        poses[:, :, 2] = analysis.q[:, :, 2] + phi_ref[:, None]
        method = "momentum"
        momentum_drift = (0.0, 0.0)
    for k, b in enumerate(sim_model.bodies):  # centre-of-mass poses -> body frame poses
        cl = np.asarray(b.mass_properties()[1])
        poses[:, k, :2] -= rotate(poses[:, k, 2], cl)
    drift = base[:, :2] + rotate(base[:, 2], np.broadcast_to(centre, base[:, :2].shape)) - centre
    rotation = base[:, 2].copy()
    extra = {}
    if massless_ref is not None:
        phi0, origin0 = massless_ref
        drift0 = origin0 + rotate(phi0, np.broadcast_to(centre, origin0.shape)) - centre
        extra = {
            "small_masses": small,
            "small_mass_fraction": fraction,
            "massless_max_drift": float(np.max(np.linalg.norm(drift0, axis=1))),
            "massless_max_rotation": float(np.max(np.abs(phi0))),
            "massless_difference": (float(np.max(np.linalg.norm(drift - drift0, axis=1))),
                                    float(np.max(np.abs(rotation - phi0)))),
        }
    return FreeFloating(
        t=t, names=names, base=base, drift=drift, rotation=rotation, poses=poses,
        base_mass=float(base_mass), base_inertia=bi, base_centre=(float(centre[0]), float(centre[1])),
        method=method, max_drift=float(np.max(np.linalg.norm(drift, axis=1))),
        max_rotation=float(np.max(np.abs(rotation))),
        reference_max_drift=float(np.max(np.linalg.norm(drift_ref, axis=1))),
        reference_max_rotation=float(np.max(np.abs(phi_ref))),
        reference_difference=(
            float(np.max(np.linalg.norm(drift - drift_ref, axis=1))), float(np.max(np.abs(rotation - phi_ref)))
        ),
        momentum_drift=momentum_drift, dt=dt, iterations=it, notes=notes,
        timing={"total_s": time.perf_counter() - wall0, **({"simulation_s": run.wall} if run is not None else {})},
        **extra,
    )
