"""Shaking-force reduction by planning the motion of the total centre of mass (paper 003).

The shaking force of an arm is F = -m x_S'' (eq. 1, horizontal plane): over a fixed duration T
the straight line between the centre of mass' end positions on the bang-bang law (eqs. 3-6)
has the least peak acceleration, 4 d / T^2, hence the least peak force 4 m d / T^2. For a 3R arm
the centre of mass fixes two of the three joint angles' combinations: the third, the
end-effector orientation phi, is free between its end values and is used against the shaking
moment. The joint angles follow from (x_S, y_S, phi) by the inverse kinematics of eqs. 8-10
(the centre of mass as a chain of equivalent links, :func:`balpipe.mechanisms.serial_arm.com_chain`),
with exact derivatives by the chain rule, so every stage is an ordinary joint-driven arm for the
engine.

Cases (Sec. 3), per trajectory of the tip from P_i (phi0) to P_j (phif), duration T:

1. ``end-effector quintic``: the tip on the straight line and phi, both on the 3-4-5 law;
2. ``CoM bang-bang``: the centre of mass on the straight line between the same end
   configurations' centres of mass, bang-bang; phi on the 3-4-5 law;
   ``CoM bang-bang + phi optimised``: phi a polynomial of degree d (default 8) with its ends
   fixed in position, velocity and acceleration (d - 5 free coefficients), optimised to minimise
   the peak shaking moment (multi-start Nelder-Mead, fixed seed);
3. ``CoM trapezoidal``: the centre of mass on a trapezoidal acceleration profile (linear ramps
   of duration f T) with the shortest ramps for which no actuator torque changes faster than the
   limit (the paper's 3.10^4 N m/s), phi as optimised in case 2.

The optimiser evaluates the shaking moment with the explicit serial dynamics
(:func:`balpipe.mechanisms.serial_arm.shaking_loads`), vectorised over the analysis grid; the
engine analyses only the final stages (tests check that both agree to 1e-9).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from .template import (
    ArmGeometry,
    Chain,
    JointLaw,
    JointSolution,
    SerialArmMechanism,
    TaskMotion,
    absolute_motion,
    absolute_state,
    com_chain,
    joint_laws,
    torques_rows,
    moment_rows,
    shaking_loads,
    state_rows,
    tip_chain,
    with_joint_laws,
)
from ...balancing.context import BalanceContext, Memo, compute
from ...display import numbers
from ...model import Law, Model
from ...motion import PointToPoint, bang_bang, law_for, quintic
from ...spec_parts import SpecFieldError, paper_id
from ...balancing.base import BalanceResult, Parameter, Stage
from ...mechanics.sampling import gravity_vector, time_grid
from .simplex import minimise_together, nelder_mead
from .specs import ComMotionPlanning

ROOT = ("balancing",)
CASES = (
    ("ee_quintic", "case 1: end-effector quintic"),
    ("com_bang_bang", "CoM bang-bang, φ on the 3-4-5 law (not in the paper)"),
    ("com_bang_bang_phi_opt", "case 2: CoM bang-bang + φ optimised"),
    ("com_trapezoidal", "case 3: CoM trapezoidal"),
)
#: each case's line style on the page (:attr:`Stage.style`): Figs. 3-4 draw case 1 black full
#: (style 0), case 2 black dashed (style 1), case 3 grey full (style 2); the stage the paper does
#: not draw takes the next style (blue dash-dot)
STYLES = {"ee_quintic": 0, "com_bang_bang_phi_opt": 1, "com_trapezoidal": 2, "com_bang_bang": 3}
#: the case whose reductions the paper publishes (:attr:`Stage.headline`): "reduction of the
#: shaking forces from 48 % up to 62.2 %" and of the moment "from 37.2 % up to 61 %" are case 2
#: against case 1 (Sec. 3); case 3 trades some of it for bounded torque rates
HEADLINE = "com_bang_bang_phi_opt"

# --------------------------------------------------------------------------------------------
# Laws


@dataclass(frozen=True)
class PhiPolynomial(Law):
    """phi(t) of :class:`PhiOptimisation` (exact derivatives); held at the ends outside [0, T]."""

    start: float
    end: float
    duration: float
    coefficients: tuple[float, ...] = ()

    def __call__(self, t):
        t = np.asarray(t, dtype=float)
        T = self.duration
        tau = np.clip(t / T, 0.0, 1.0)
        s, ds, dds = quintic(tau)
        h = self.end - self.start
        p, dp, ddp = self.start + h * s, h * ds, h * dds
        if self.coefficients:
            # b_k = 64 w(tau) u^k, w = tau^3 (1 - tau)^3, u = 2 tau - 1
            w = tau**3 * (1 - tau) ** 3
            dw = 3 * tau**2 * (1 - tau) ** 2 * (1 - 2 * tau)
            ddw = 6 * tau * (1 - tau) * (1 - 5 * tau + 5 * tau**2)
            u = 2 * tau - 1
            for k, c in enumerate(self.coefficients):
                uk = u**k
                duk = 2 * k * u ** (k - 1) if k >= 1 else 0.0
                dduk = 4 * k * (k - 1) * u ** (k - 2) if k >= 2 else 0.0
                p = p + 64 * c * w * uk
                dp = dp + 64 * c * (dw * uk + w * duk)
                ddp = ddp + 64 * c * (ddw * uk + 2 * dw * duk + w * dduk)
        inside = (t >= 0) & (t <= T)
        return p, np.where(inside, dp / T, 0.0), np.where(inside, ddp / T**2, 0.0)


def trapezoidal_acceleration(f: float):
    """Normalised profile s(tau) whose acceleration is trapezoidal: ramps of length f, plateaus
    +A and -A, the sign change a ramp of length 2 f centred on tau = 1/2 (0 < f <= 1/4)."""
    if not 0 < f <= 0.25:
        raise ValueError("ramp fraction must be in (0, 1/4]")
    knots = np.array([0.0, f, 0.5 - f, 0.5 + f, 1.0 - f, 1.0])
    acc = np.array([0.0, 1.0, 1.0, -1.0, -1.0, 0.0])
    jerk = np.diff(acc) / np.maximum(np.diff(knots), 1e-300)
    v = np.zeros(6)
    s = np.zeros(6)
    for i in range(5):
        h = knots[i + 1] - knots[i]
        v[i + 1] = v[i] + acc[i] * h + jerk[i] * h * h / 2
        s[i + 1] = s[i] + v[i] * h + acc[i] * h * h / 2 + jerk[i] * h**3 / 6
    A = 1.0 / s[-1]

    def profile(tau):
        i = np.clip(np.searchsorted(knots, tau, side="right") - 1, 0, 4)
        h = tau - knots[i]
        a = acc[i] + jerk[i] * h
        vv = v[i] + acc[i] * h + jerk[i] * h * h / 2
        ss = s[i] + v[i] * h + acc[i] * h * h / 2 + jerk[i] * h**3 / 6
        return A * ss, A * vv, A * a

    return profile

# --------------------------------------------------------------------------------------------
# One trajectory


@dataclass
class Plan:
    """Everything computed for one trajectory."""

    name: str
    start: tuple[float, float, float]
    end: tuple[float, float, float]
    q_start: np.ndarray
    q_end: np.ndarray
    com_start: np.ndarray
    com_end: np.ndarray
    com_mode: int
    models: dict[str, Model] = field(default_factory=dict)
    phi_coefficients: tuple[float, ...] = ()
    phi_peak_start: float = 0.0
    phi_peak_best: float = 0.0
    evaluations: int = 0
    ramp_fraction: float = 0.0
    ramp_rate: float = 0.0
    ramp_feasible: bool = True

    @property
    def com_distance(self) -> float:
        return float(np.hypot(*(self.com_end - self.com_start)))


def _com_motion(plan: Plan, profile, T: float, phi: Law, path: tuple) -> TaskMotion:
    laws = (PointToPoint(float(plan.com_start[0]), float(plan.com_end[0]), T, profile),
            PointToPoint(float(plan.com_start[1]), float(plan.com_end[1]), T, profile), phi)
    return TaskMotion(laws, "com", path, plan.name)


def _elbow_sign(chain: Chain, q: np.ndarray) -> int:
    """Working mode of configuration q in ``chain``: +1 when the second equivalent link turns
    clockwise from the first (the '+' root of eq. 8)."""
    v = np.asarray(chain.vectors)
    a1 = q[0] + math.atan2(v[0, 1], v[0, 0])
    a2 = q[0] + q[1] + math.atan2(v[1, 1], v[1, 0])
    return 1 if math.sin(a2 - a1) < 0 else -1


class Planner:
    """The method's computations for one arm model, duration and analysis grid."""

    def __init__(self, model: Model, mech: SerialArmMechanism, method: ComMotionPlanning, T: float,
                 t: np.ndarray, gravity, moment_point):
        self.model, self.mech, self.method = model, mech, method
        self.arm = ArmGeometry.of(model)
        self.tip, self.com = tip_chain(self.arm), com_chain(self.arm)
        self.T, self.t = T, np.asarray(t, dtype=float)
        self.gravity, self.point = tuple(gravity), tuple(moment_point)
        self.calls = 0

    # -- fast path ---------------------------------------------------------------------------
    def loads(self, motion: TaskMotion, mode: int, t: np.ndarray | None = None, check: bool = False):
        """Shaking force (N, 2), moment (N,) and the joint solution along a centre-of-mass motion."""
        sol, st = self.state(motion, mode, t, check)
        F, M = shaking_loads(self.arm, st, self.gravity, self.point)
        return F, M, sol, st

    def state(self, motion: TaskMotion, mode: int, t: np.ndarray | None = None, check: bool = False):
        """The joint solution and the links' state along a centre-of-mass motion (:meth:`loads`
        without the shaking loads: what the ramp's torque rates need)."""
        sol = JointSolution(self.com, motion, mode, self.t if t is None else t, check=check)
        return sol, absolute_state(self.arm, sol.th, sol.thd, sol.thdd, sol.trig)

    def torques(self, motion: TaskMotion, mode: int, t: np.ndarray) -> np.ndarray:
        """The joint torques (N, n) along a centre-of-mass motion on the grid ``t`` (what the
        ramp's torque rates differentiate): :meth:`state` and :func:`joint_torques`, the same
        values, on (links, samples) rows."""
        x, xd, xdd = motion.values(np.asarray(t, dtype=float).reshape(-1))
        th, thd, thdd, _, _, trig = absolute_motion(self.com, x, xd, xdd, mode, rows=True)
        rows = state_rows(self.arm, th if trig is None else None, thd, thdd, trig)
        return torques_rows(self.arm, rows, np.ascontiguousarray(thdd.T), self.gravity)

    def objective(self, plan: Plan, path: tuple):
        """The optimiser's objective c -> max |M| over the analysis grid with the CoM on the
        bang-bang law and phi(c) (a penalty outside the workspace or at a singular
        configuration): :meth:`peaks` of one point."""
        peaks = self.peaks([(plan, path)])
        return lambda c: peaks(np.asarray(c, dtype=float)[None, :], [0])[0]

    def peaks(self, plans: Sequence[tuple[Plan, tuple]]):
        """The objectives of ``plans`` ((plan, spec path) pairs), of several points at once:
        ``values(points, owners)``, points (k, free coefficients) and the index of each one's
        plan, -> their k values. The CoM laws and phi's basis are evaluated once; each call is a
        few vectorised array operations (explicit serial kinematics and dynamics, on (links,
        samples) rows) on the k points' grids one after the other, every sample computed as for
        one point alone (the same values, bit for bit, whatever the points evaluated with it: the
        kinematics and the state are sample by sample, :func:`moment_rows` keeps the grids
        apart), so that a call of 24 points costs 11 times a call of one."""
        t, T = self.t, self.T
        nfree = self.method.phi.degree - 5
        laws = [_com_motion(plan, bang_bang, T, PhiPolynomial(plan.start[2], plan.end[2], T), path).values(t)
                for plan, path in plans]
        rows = [tuple(np.ascontiguousarray(a.T) for a in law) for law in laws]  # x, y, phi rows and derivatives
        modes = [plan.com_mode for plan, _ in plans]
        basis = [PhiPolynomial(0.0, 0.0, T, tuple(1.0 if j == k else 0.0 for j in range(k + 1)))(t) for k in range(nfree)]
        B = [np.stack([b[d] for b in basis], axis=1) if nfree else np.zeros((len(t), 0)) for d in range(3)]
        n = len(t)

        def values(C: np.ndarray, owners: Sequence[int]) -> list[float]:
            k = len(C)
            # the task-space motions as rows (x, y, phi; the k grids one after the other), read as (k n, 3)
            X, Xd, Xdd = (np.concatenate([rows[o][d] for o in owners], axis=1) for d in range(3))
            for i, (c, o) in enumerate(zip(C, owners)):
                grid = slice(i * n, (i + 1) * n)
                x0, xd0, xdd0 = laws[o]
                X[2, grid], Xd[2, grid], Xdd[2, grid] = x0[:, 2] + B[0] @ c, xd0[:, 2] + B[1] @ c, xdd0[:, 2] + B[2] @ c
            mode = modes[owners[0]] if len({modes[o] for o in owners}) == 1 else np.repeat([modes[o] for o in owners], n)
            th, thd, thdd, margin, sg, trig = absolute_motion(self.com, X.T, Xd.T, Xdd.T, mode, rows=True)
            out = [0.0] * k
            good = []
            for i in range(k):
                grid = slice(i * n, (i + 1) * n)
                bad = max(0.0, float(-margin[grid].min())) + max(0.0, 1e-6 - float(np.abs(sg[grid]).min()))
                if bad > 0:
                    out[i] = 1e6 * (1.0 + bad)
                else:
                    good.append(i)
            if len(good) < k:  # the state of the points in the workspace only
                if not good:
                    return out
                keep = np.concatenate([np.arange(i * n, (i + 1) * n) for i in good])
                th, thd, thdd = th[:, keep], thd[:, keep], thdd[:, keep]
                trig = None if trig is None else (trig[0][:, keep], trig[1][:, keep])
            rx, ry, ax, ay, _, _ = state_rows(self.arm, th if trig is None else None, thd, thdd, trig)
            M = moment_rows(self.arm, rx, ry, ax, ay, np.ascontiguousarray(thdd.T), self.gravity, self.point,
                            grids=len(good))
            for j, i in enumerate(good):
                peak = float(np.max(np.abs(M[j * n:(j + 1) * n])))
                out[i] = peak if math.isfinite(peak) else 1e6
            return out

        return values

    def peak_moment(self, plan: Plan, coeffs, path: tuple) -> float:
        """max |M| of one phi (see :meth:`objective`)."""
        return self.objective(plan, path)(coeffs)

    # -- planning ----------------------------------------------------------------------------
    def plan(self, name: str, start, end, path: tuple) -> Plan:
        """End configurations by the tip's inverse kinematics, their centres of mass and the
        working mode of the centre-of-mass chain (the same configurations, checked)."""
        mode = self.mech.working_mode
        q0 = self.tip.inverse(np.array([start[:2]]), np.array([start[2]]), mode)
        q1 = self.tip.inverse(np.array([end[:2]]), np.array([end[2]]), mode)
        for (q, margin), pose, key in ((q0, start, "from"), (q1, end, "to")):
            if not margin[0] > 1e-9:
                raise SpecFieldError(path + (key,), f"trajectory {name}: the tip pose ({pose[0]:.4g}, {pose[1]:.4g}) m, "
                                     f"phi = {math.degrees(pose[2]):.4g} deg is out of reach")
        qa, qb = q0[0][0], q1[0][0]
        cmode = _elbow_sign(self.com, qa)
        if _elbow_sign(self.com, qb) != cmode:
            raise SpecFieldError(path, f"trajectory {name}: the end configurations are in different working "
                                 "modes of the centre-of-mass chain; no motion of the centre of mass joins them")
        return Plan(name, tuple(start), tuple(end), qa, qb, self.com.point(qa[None])[0], self.com.point(qb[None])[0], cmode)

    def optimise_phi(self, plans: Sequence[tuple[Plan, tuple]]) -> None:
        """phi's coefficients of each of ``plans`` ((plan, spec path) pairs, updated): Nelder-Mead
        from ``starts`` points (the 3-4-5 law and random ones), every plan's searches side by side
        (:func:`.simplex.minimise_together`: one call of :meth:`peaks` evaluates a point of each
        unfinished search). Each plan gets what it gets optimised alone, bit for bit."""
        if not plans:
            return
        opt = self.method.phi
        nfree = opt.degree - 5
        peaks = self.peaks(plans)
        start = peaks(np.zeros((len(plans), nfree)), range(len(plans)))
        searches, owner = [], []
        for i, (plan, _) in enumerate(plans):
            plan.phi_peak_start = plan.phi_peak_best = start[i]
            if nfree == 0:
                continue
            plan.phi_coefficients, plan.evaluations = (0.0,) * nfree, 1  # the start's evaluation
            rng = np.random.default_rng(opt.seed)
            starts = [np.zeros(nfree)] + [rng.normal(0.0, opt.spread, nfree) for _ in range(opt.starts - 1)]
            for x0 in starts:
                searches.append(nelder_mead(_simplex(x0, 0.2), opt.max_evaluations, opt.tolerance, opt.tolerance * start[i]))
                owner.append(i)

        def values(asking: list[int], points: np.ndarray) -> list[float]:
            owners = [owner[j] for j in asking]
            for o in owners:
                plans[o][0].evaluations += 1
            return peaks(points, owners)

        for o, (x, fun) in zip(owner, minimise_together(values, searches)):  # each plan's starts in order
            plan = plans[o][0]
            if fun < plan.phi_peak_best:
                plan.phi_coefficients, plan.phi_peak_best = tuple(float(c) for c in np.asarray(x, dtype=float)), float(fun)

    def ramp(self, plan: Plan, phi: Law, path: tuple) -> None:
        """Case 3: the shortest ramp fraction f whose torque rates stay within the limit
        (bisection; rates by central differences on ``rate_samples`` uniform samples plus 64 in
        each ramp, so that the shortest ramps are resolved)."""
        limit = self.method.torque_rate_limit
        uniform = np.linspace(0.0, self.T, self.method.rate_samples)

        def rate(f: float) -> float:
            ramps = [np.linspace(a, b, 64) for a, b in ((0.0, f), (0.5 - f, 0.5 + f), (1.0 - f, 1.0))]
            tt = _sorted_unique(np.concatenate([uniform, self.T * np.concatenate(ramps)]))
            motion = _com_motion(plan, trapezoidal_acceleration(f), self.T, phi, path)
            tau = self.torques(motion, plan.com_mode, tt)
            return float(np.max(np.abs(np.gradient(tau, tt, axis=0))))

        lo, hi = 1e-4, 0.25
        r_hi = rate(hi)
        if r_hi > limit:
            plan.ramp_fraction, plan.ramp_rate, plan.ramp_feasible = hi, r_hi, False
            return
        r_lo = rate(lo)
        if r_lo <= limit:
            plan.ramp_fraction, plan.ramp_rate = lo, r_lo
            return
        for _ in range(30):
            mid = 0.5 * (lo + hi)
            r_mid = rate(mid)
            if r_mid <= limit:
                hi, r_hi = mid, r_mid  # hi's rate kept: the result needs it, not computed again
            else:
                lo = mid
            if hi - lo < 1e-5:
                break
        plan.ramp_fraction, plan.ramp_rate = hi, r_hi

    def stages(self, plan: Plan, law_name: str, path: tuple) -> dict[str, Model]:
        """The four stage models of one trajectory (case 1 on the spec's law)."""
        T, mode = self.T, self.mech.working_mode
        tip_laws = tuple(law_for(_Motion(law_name, T), a, b) for a, b in zip(plan.start, plan.end))
        tip_motion = TaskMotion(tip_laws, "tip", path, plan.name)
        JointSolution(self.tip, tip_motion, mode, self.t)  # located errors on the tip path
        out = {"ee_quintic": with_joint_laws(self.model, joint_laws(self.tip, tip_motion, mode))}
        phi5 = PhiPolynomial(plan.start[2], plan.end[2], T)
        phio = PhiPolynomial(plan.start[2], plan.end[2], T, plan.phi_coefficients)
        for key, profile, phi in (("com_bang_bang", bang_bang, phi5), ("com_bang_bang_phi_opt", bang_bang, phio),
                                  ("com_trapezoidal", trapezoidal_acceleration(plan.ramp_fraction), phio)):
            m = _com_motion(plan, profile, T, phi, path)
            JointSolution(self.com, m, plan.com_mode, self.t)  # located errors on the centre-of-mass path
            out[key] = with_joint_laws(self.model, joint_laws(self.com, m, plan.com_mode))
        return out


@dataclass(frozen=True)
class _Motion:
    """The two fields of the spec's motion that :func:`law_for` reads."""

    law: str
    duration: float
    accel_fraction: float = 1 / 3


def _sorted_unique(x: np.ndarray) -> np.ndarray:
    """np.unique(x) (sorted, each value once), sorting by merges: the ramp's grid is four sorted
    runs (the uniform samples and the three ramps'), which a stable sort merges in linear time
    (0.01 ms against np.unique's 0.1 ms on 4,193 samples; the same array)."""
    s = np.sort(x, kind="stable")
    keep = np.empty(len(s), dtype=bool)
    keep[:1] = True
    np.not_equal(s[1:], s[:-1], out=keep[1:])
    return s[keep]


def _simplex(x0: np.ndarray, step: float) -> np.ndarray:
    n = len(x0)
    return np.vstack([x0] + [x0 + step * np.eye(n)[k] for k in range(n)])

# --------------------------------------------------------------------------------------------
# The method


def _point(square_points: dict, raw, path: tuple) -> tuple[float, float]:
    if isinstance(raw, str):
        if raw not in square_points:
            raise SpecFieldError(path, f"unknown point {raw!r}" + (f" (the test square has P1..P{len(square_points)})" if square_points else " (no test_square)"))
        return square_points[raw]
    return (float(raw[0]), float(raw[1]))


def trajectories_of(method: ComMotionPlanning, model: Model) -> list[tuple[str, tuple, tuple, tuple]]:
    """(name, start pose, end pose, spec path) of every trajectory."""
    pts = method.test_square.points() if method.test_square is not None else {}
    if not method.trajectories:
        for d in model.drivers:
            if isinstance(d.law, JointLaw) and d.law.motion.point == "tip":
                x0 = d.law.motion.values(np.array([0.0]))[0][0]
                x1 = d.law.motion.values(np.array([np.inf]))[0][0]
                return [("", tuple(map(float, x0)), tuple(map(float, x1)), ("motion", "drive", "tip"))]
        raise SpecFieldError(ROOT + ("trajectories",), "give the trajectories, or drive the tip (motion.drive.tip)")
    if model.drivers:
        raise SpecFieldError(("motion", "drive"), "with balancing.trajectories the method plans every motion: leave motion.drive empty ({})")
    if method.orientation is None:
        raise SpecFieldError(ROOT + ("orientation",), "give phi at both ends of the trajectories: orientation: {from, to}")
    o = method.orientation
    out = []
    for k, tr in enumerate(method.trajectories):
        path = ROOT + ("trajectories", k)
        if isinstance(tr, str):
            names = [p for p in tr.split("P") if p]
            if len(names) != 2 or not all(n.isdigit() for n in names):
                raise SpecFieldError(path, f"expected 'PiPj' (two test-square points), got {tr!r}")
            a, b = _point(pts, f"P{names[0]}", path), _point(pts, f"P{names[1]}", path)
            name = tr
        else:
            a, b = _point(pts, tr.start, path + ("from",)), _point(pts, tr.end, path + ("to",))
            name = tr.name
        out.append((name, (a[0], a[1], o.start), (b[0], b[1], o.end), path))
    names = [n for n, *_ in out]
    if len(set(names)) != len(names):
        raise SpecFieldError(ROOT + ("trajectories",), "trajectory names must be unique")
    return out


def balance(ctx: BalanceContext) -> BalanceResult:
    """Paper 003's cases per trajectory, phi optimised through ``ctx.memo`` (:func:`phi_search`)."""
    mech: SerialArmMechanism = ctx.mechanism
    method: ComMotionPlanning = ctx.balancing
    model, spec = ctx.model, ctx.spec
    if len(mech.links) != 3:
        raise SpecFieldError(("mechanism", "links"), f"com_motion_planning plans a 3R arm (eqs. 8-10); got {len(mech.links)} links")
    T = spec.motion.duration
    t = ctx.t
    planner = Planner(model, mech, method, T, t, ctx.gravity, ctx.moment_point)
    law_name = spec.motion.law if spec.motion.law != "polynomial" else "quintic"
    plans: list[Plan] = []
    stages: list[Stage] = []
    params: list[Parameter] = []
    P = lambda *a: params.append(Parameter(*a))  # noqa: E731
    m_total = planner.arm.total_mass
    trajectories = trajectories_of(method, model)
    main = main_trajectory(method, trajectories)
    prepared: list[tuple[str, tuple, tuple, tuple, Plan]] = []
    failure: SpecFieldError | None = None
    for name, start, end, path in trajectories:
        try:
            plan = planner.plan(name, start, end, path)
            # located errors on every path before optimising (case 1 and the bang-bang line)
            tip_laws = tuple(law_for(_Motion(law_name, T), a, b) for a, b in zip(plan.start, plan.end))
            JointSolution(planner.tip, TaskMotion(tip_laws, "tip", path, name), mech.working_mode, t)
            JointSolution(planner.com, _com_motion(plan, bang_bang, T, PhiPolynomial(start[2], end[2], T), path),
                          plan.com_mode, t)
        except SpecFieldError as exc:  # raised once the trajectories before it are done: the error one by one gives
            failure = exc
            break
        prepared.append((name, start, end, path, plan))
    searched = phi_searches(ctx.memo, model, mech, method, T, t, planner, [(plan, path) for *_, path, plan in prepared])
    for (name, start, end, path, plan), found in zip(prepared, searched):
        plan.phi_coefficients, plan.phi_peak_start, plan.phi_peak_best, plan.evaluations = found
        planner.ramp(plan, PhiPolynomial(start[2], end[2], T, plan.phi_coefficients), path)
        plan.models = planner.stages(plan, law_name, path)
        plans.append(plan)
        prefix = f"{name}_" if name else ""
        for key, label in CASES:
            if key == "ee_quintic" and law_name != "quintic":
                label = f"end-effector {law_name}"
            if paper_id(spec.paper) != "003":  # an arm of one's own: no paper to be absent from
                label = label.replace(" (not in the paper)", "")
            stages.append(Stage(
                prefix + key, f"{name} · {label}" if name else label, plan.models[key],
                _description(key, plan, method), reference=prefix + "ee_quintic", group=name, style=STYLES[key],
                headline=key == HEADLINE,
            ))
        sfx = f"_{name}" if name else ""
        P(f"com_distance{sfx}", plan.com_distance, "m", "eq. 7", f"{name or 'the'} centre of mass displacement d (straight line)")
        P(f"bang_bang_peak_force{sfx}", 4 * m_total * plan.com_distance / T**2, "N", "eqs. 1, 3-6: 4 m d / T^2",
          "predicted peak shaking force of the bang-bang law on the centre of mass")
        for k, c in enumerate(plan.phi_coefficients):
            P(f"phi_c{k}{sfx}", c, "rad", "phi optimisation", f"coefficient of 64 tau^3 (1 - tau)^3 (2 tau - 1)^{k} in phi")
        P(f"phi_peak_moment_start{sfx}", plan.phi_peak_start, "N m", "fast path", "peak |M| with phi on the 3-4-5 law (the optimisation's start)")
        P(f"phi_peak_moment_best{sfx}", plan.phi_peak_best, "N m", "fast path", "peak |M| with the optimised phi")
        P(f"phi_evaluations{sfx}", plan.evaluations, "", "phi optimisation", "objective evaluations, all starts")
        P(f"ramp_fraction{sfx}", plan.ramp_fraction, "", "case 3", "ramp duration of the trapezoidal acceleration / T")
        P(f"ramp_torque_rate{sfx}", plan.ramp_rate, "N m/s", "case 3", "largest actuator torque rate with that ramp")
    if failure is not None:
        raise failure
    notes = [_method_note(method, planner, plans, law_name)]
    for p in plans:
        if not p.ramp_feasible:
            notes.append(f"Trajectory {p.name or ''}: even the longest ramps (f = 1/4) need a torque rate of "
                         f"{p.ramp_rate:.4g} N m/s, above the limit {method.torque_rate_limit:.4g} N m/s: case 3 uses f = 1/4.")
    # the main trajectory's stages first: the page's headline, design card and stage figures show it
    stages.sort(key=lambda s: s.group != main)
    return BalanceResult(params, stages, notes, derived=lambda results: derived(results, plans, T, m_total))


def phi_searches(memo: Memo, model: Model, mech: SerialArmMechanism, method: ComMotionPlanning, T: float,
                 t: np.ndarray, planner: Planner, plans: list[tuple[Plan, tuple]]) -> list[tuple]:
    """phi's search of each of ``plans`` ((plan, spec path) pairs, as :meth:`Planner.plan` made
    them; not changed), as :func:`phi_search` returns it: one search per trajectory through
    ``memo``, which the build's balancing cache keeps one by one; side by side in one
    :meth:`Planner.optimise_phi` when ``memo`` keeps nothing (``balpipe check``: one objective call
    evaluates a point of up to 24 searches, the same results)."""
    if memo is not compute:
        return [memo(phi_search, model, mech, method, T, t, planner.gravity, planner.point, replace(plan), path)
                for plan, path in plans]
    copies = [(replace(plan), path) for plan, path in plans]
    planner.optimise_phi(copies)
    return [(p.phi_coefficients, p.phi_peak_start, p.phi_peak_best, p.evaluations) for p, _ in copies]


def phi_search(model: Model, mech: SerialArmMechanism, method: ComMotionPlanning, T: float, t: np.ndarray,
               gravity: tuple, point: tuple, plan: Plan, path: tuple) -> tuple[tuple[float, ...], float, float, int]:
    """:meth:`Planner.optimise_phi` of one trajectory (``plan`` as :meth:`Planner.plan` made it,
    updated here) as a function of plain data: what the build's balancing cache keys and keeps
    (:mod:`balpipe.cache.balance`; about 2 s of paper 003's balancing). Returns phi's
    coefficients, the peak moments at the start and at the optimum, and the evaluations."""
    Planner(model, mech, method, T, t, gravity, point).optimise_phi([(plan, path)])
    return plan.phi_coefficients, plan.phi_peak_start, plan.phi_peak_best, plan.evaluations


def main_trajectory(method: ComMotionPlanning, trajectories: list) -> str:
    """The name of the trajectory shown first (``main_trajectory``, default the first)."""
    names = [n for n, *_ in trajectories]
    if method.main_trajectory is None:
        return names[0]
    if method.main_trajectory not in names:
        raise SpecFieldError(ROOT + ("main_trajectory",), f"no trajectory {method.main_trajectory!r} "
                             f"(the trajectories: {', '.join(names)})")
    return method.main_trajectory


def replan(spec, parameters: dict) -> tuple[Planner, list[Plan]]:
    """The plans of a finished balancing, rebuilt from the spec and its computed parameters
    (end configurations and centres of mass by the inverse kinematics, phi's coefficients and
    the ramps as the balancing found them; nothing optimised again): what the figures draw."""
    from ... import registry

    method: ComMotionPlanning = spec.balancing
    model = registry.unbalanced_model(spec)
    planner = Planner(model, spec.mechanism, method, spec.motion.duration, time_grid(spec), gravity_vector(spec),
                      spec.analysis.moment_point)
    plans = []
    for name, start, end, path in trajectories_of(method, model):
        plan = planner.plan(name, start, end, path)
        sfx = f"_{name}" if name else ""
        plan.phi_coefficients = tuple(parameters[f"phi_c{k}{sfx}"] for k in range(method.phi.degree - 5))
        plan.ramp_fraction, plan.ramp_rate = parameters[f"ramp_fraction{sfx}"], parameters[f"ramp_torque_rate{sfx}"]
        plans.append(plan)
    return planner, plans


def _description(key: str, plan: Plan, method: ComMotionPlanning) -> str:
    deg = method.phi.degree
    return {
        "ee_quintic": "tip on the straight line and φ on the 3-4-5 law (case 1)",
        "com_bang_bang": "centre of mass on the straight line, bang-bang; φ on the 3-4-5 law",
        "com_bang_bang_phi_opt": f"centre of mass bang-bang; φ a degree-{deg} polynomial minimising the peak moment (case 2)",
        "com_trapezoidal": f"centre of mass on a trapezoidal acceleration, ramps {numbers.num(plan.ramp_fraction, 3)} T "
                           f"(torque rate <= {numbers.num(method.torque_rate_limit, 3)} N m/s); φ as optimised (case 3)",
    }[key]


def _method_note(method: ComMotionPlanning, planner: Planner, plans: list[Plan], law: str) -> str:
    o = method.phi
    return (
        f"phi optimisation: degree-{o.degree} polynomial, ends fixed in phi, phi', phi'' ({o.degree - 5} free "
        f"coefficients); objective the peak |M| on the analysis grid ({len(planner.t)} samples), by the explicit "
        f"serial dynamics; the Nelder-Mead simplex from {o.starts} starts (the 3-4-5 law and "
        f"{o.starts - 1} normal random points, sd {o.spread} rad, numpy default_rng({o.seed})), at most "
        f"{o.max_evaluations} evaluations per start, xatol {o.tolerance}; {sum(p.evaluations for p in plans)} objective evaluations in "
        f"all for {len(plans)} trajectories. Case 3: the shortest ramps (bisection on "
        f"f) for which every joint's torque rate, by central differences on {method.rate_samples} samples and 64 "
        f"in each ramp, stays "
        f"within {numbers.num(method.torque_rate_limit)} N m/s."
    )


def derived(results, plans: list[Plan], T: float, m_total: float) -> list[Parameter]:
    """Reductions per trajectory from the engine's analyses, and their ranges."""
    by = {r.stage.name: r.analysis for r in results}
    out: list[Parameter] = []
    red = {"force": [], "moment": [], "force3": [], "moment3": []}
    worst = 0.0
    for p in plans:
        pre, sfx = (f"{p.name}_", f"_{p.name}") if p.name else ("", "")
        a1, a2, a3 = by[pre + "ee_quintic"], by[pre + "com_bang_bang_phi_opt"], by[pre + "com_trapezoidal"]
        fr = 1 - a2.max_inertial_force / a1.max_inertial_force
        mr = 1 - a2.max_inertial_moment / a1.max_inertial_moment
        fr3 = 1 - a3.max_inertial_force / a1.max_inertial_force
        mr3 = 1 - a3.max_inertial_moment / a1.max_inertial_moment
        red["force"].append(fr), red["moment"].append(mr), red["force3"].append(fr3), red["moment3"].append(mr3)
        predicted = 4 * m_total * p.com_distance / T**2
        for key in ("com_bang_bang", "com_bang_bang_phi_opt"):
            worst = max(worst, abs(by[pre + key].max_inertial_force - predicted) / predicted)
        out += [
            Parameter(f"force_reduction{sfx}", fr, "", "engine: 1 - F(case 2) / F(case 1)", "peak shaking force reduction, CoM bang-bang vs end-effector quintic"),
            Parameter(f"moment_reduction{sfx}", mr, "", "engine: 1 - M(case 2) / M(case 1)", "peak shaking moment reduction, phi optimised vs end-effector quintic"),
            Parameter(f"force_reduction_case3{sfx}", fr3, "", "engine", "peak shaking force reduction, CoM trapezoidal vs end-effector quintic"),
            Parameter(f"moment_reduction_case3{sfx}", mr3, "", "engine", "peak shaking moment reduction, CoM trapezoidal vs end-effector quintic"),
        ]
    for key, label in (("force", "force"), ("moment", "moment")):
        out.append(Parameter(f"{key}_reduction_min", min(red[key]), "", "engine, over the trajectories", f"smallest peak {label} reduction (case 2 vs 1)"))
        out.append(Parameter(f"{key}_reduction_max", max(red[key]), "", "engine, over the trajectories", f"largest peak {label} reduction (case 2 vs 1)"))
    out.append(Parameter("bang_bang_force_deviation", worst, "", "engine vs 4 m d / T^2",
                         "largest relative difference of the bang-bang stages' peak force from 4 m d / T^2"))
    return out


def _notation() -> dict:
    from ...notation import Sym, ours, setting

    return {
        "balancing.test_square.centre": Sym("E", "centre of the tested square (Fig. 2)"),
        "balancing.test_square.side": ours("a", "edge length of the tested square"),
        "balancing.test_square.divisions": ours("n_{div}", "segments per edge (points P_1, P_2, ...)"),
        "balancing.test_square.first_corner": ours("P_1", "corner of P_1, points numbered counter-clockwise"),
        "balancing.trajectories[<k>]": Sym("P_iP_j", "a tip trajectory between two points of the square"),
        "balancing.trajectories[<k>].name": ours("name", "label of a tip trajectory"),
        "balancing.trajectories[<k>].start": ours("x_0", "start point of a tip trajectory"),
        "balancing.trajectories[<k>].end": ours("x_f", "end point of a tip trajectory"),
        "balancing.main_trajectory": ours("P_iP_j (shown)", "the trajectory shown first: headline, design summary, Figs. 3-4 (the paper: P15P7)"),
        "balancing.orientation.start": Sym("φ_0", "orientation φ of the last link at the start of every trajectory"),
        "balancing.orientation.end": Sym("φ_f", "orientation φ at the end"),
        "balancing.phi.degree": ours("deg φ", "degree of the polynomial law of φ (ends fixed to second order)"),
        "balancing.phi.starts": setting("starts", "multi-start: the 3-4-5 law plus random points"),
        "balancing.phi.seed": setting("seed", "picks the random starting points, the same ones at every build"),
        "balancing.phi.spread": setting("σ_c", "spread of the random starting coefficients"),
        "balancing.phi.max_evaluations": setting("evaluations", "objective evaluations per start (Nelder-Mead)"),
        "balancing.phi.tolerance": setting("tol", "Nelder-Mead tolerance"),
        "balancing.torque_rate_limit": ours("|τ̇|_{max}", "case 3: largest rate of change of any actuator torque (the paper: 3·10^4 N m/s)", unit="N m/s"),
        "balancing.rate_samples": setting("N_{rate}", "case 3: samples on which torque rates are measured"),
    }

#: Paper 003's symbols (Sec. 3, Fig. 2) for this method's inputs.
NOTATION = _notation()
