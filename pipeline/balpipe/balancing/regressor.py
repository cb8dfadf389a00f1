"""Momentum regressors of any planar :class:`~balpipe.model.Model` (paper 001, Sec. 3; DESIGN.md,
"The next layer").

For fixed kinematics the momenta are linear in the mass parameters. With body k's frame at
r_k (origin) and angle theta_k, e1 = A(theta_k) [1, 0], e2 = A(theta_k) [0, 1]:

    P   = sum_k  m_k r_k' + mx_k e1' + my_k e2'                                   (linear)
    H_O = sum_k  m_k (r_k - O) x r_k' + mx_k ((r_k - O) x e1' + e1 x r_k')
               + my_k ((r_k - O) x e2' + e2 x r_k') + J_k w_k                      (angular)

with the body's parameters (attachments included) m_k, (mx_k, my_k) = m_k c_k (first moments in
the body frame) and J_k = I_k + m_k |c_k|^2 (inertia about the body frame's origin). The
kinematics (r_k, theta_k and their rates) do not depend on the masses, so one set of sampled
states gives regressors Y with P = Y_P p and H = Y_H p for every mass distribution p.

States are sampled away from the motion's path: from configurations along it, the driven
coordinates are displaced at random (uniformly within +-0.6 rad, +-0.15 model sizes; halved in
each further round if too few samples close) and the constraints re-solved (Newton-Raphson, the
engine's; with redundant actuation, a subset of drivers that makes the system square),
and velocities are random combinations of the null space of the joint constraints' Jacobian (every
feasible velocity, independent of the drivers). Configurations whose joint Jacobian is nearly
singular (smallest to largest singular value below :data:`MIN_CONDITION`) are discarded. A
machine of one degree of freedom with at least :data:`BLOCK_COORDINATES` coordinates has its
trial states solved by blocks (:mod:`.state_blocks`: the same states to round-off, O(bodies) per
state instead of the SVD's O(bodies^3)).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..engine import Compiled, compile_model, jacobian, solve_positions
from ..engine.constraints import with_frame
from ..engine.fastpath import solve_positions_by_blocks
from ..engine.positions import newton_raphson
from ..mechanics.planar import cross
from ..model import Law, Model
from .state_blocks import BlockRound

MIN_CONDITION = 1e-7  # smallest / largest singular value of a kept configuration's Jacobian
ANGLE_SPREAD = 0.6  # rad: random displacement of angle drivers around the path
LENGTH_SPREAD = 0.15  # fraction of the model's size: displacement of length drivers
BLOCK_COORDINATES = 60  # from this many coordinates (20 bodies) on, trial states are solved by blocks
CHUNK = 256  # trial states solved together by blocks


@dataclass(frozen=True)
class _Table(Law):
    """A law that returns ``values[i]`` at 'time' i: one fixed driver value per sample."""

    values: np.ndarray

    def __call__(self, t: np.ndarray):
        v = self.values[np.asarray(t).astype(int)]
        z = np.zeros_like(v)
        return v, z, z


@dataclass
class States:
    """Sampled feasible states: body-frame poses ``pose`` (S, nb, 3) = (x, y, theta) of each
    body's frame origin and their rates ``rate`` (S, nb, 3); ``dof`` the mobility found;
    ``discarded`` the trial states solved and rejected."""

    names: list[str]
    pose: np.ndarray
    rate: np.ndarray
    dof: int
    discarded: int
    acc: np.ndarray | None = None  # (S, nb, 3) second derivatives, from analyses only

    @property
    def count(self) -> int:
        return self.pose.shape[0]


def param_names(model: Model, angular: bool = False) -> list[str]:
    """Parameter names in regressor column order: per body m, mx, my (and J)."""
    keys = ("m", "mx", "my", "J") if angular else ("m", "mx", "my")
    return [f"{k}[{b.name}]" for b in model.bodies for k in keys]


def parameters(model: Model, angular: bool = False) -> np.ndarray:
    """The model's parameter vector (column order of :func:`param_names`)."""
    out = []
    for b in model.bodies:
        m, c, i = b.mass_properties()
        out += [m, m * c[0], m * c[1]]
        if angular:
            out.append(i + m * (c[0] ** 2 + c[1] ** 2))
    return np.array(out, dtype=float)


def model_size(model: Model) -> float:
    """A length scale: the largest distance of a joint point or frame point from the origin of
    its body (at least 1 mm)."""
    r = [math.hypot(*p) for b in model.bodies for p in b.points.values()]
    r += [math.hypot(*p) for p in model.frame_points.values()]
    for j in model.joints:
        for attr in ("point_a", "point_b", "point_guide", "point_slider"):
            p = getattr(j, attr, None)
            if p is not None:
                r.append(math.hypot(*p))
    return max([1e-3] + r)


def _joint_and_driver_prims(c: Compiled) -> tuple[list, list]:
    """:func:`compile_model` appends one primitive per driver after the joints' (a driver may
    share its name with the joint it drives, so names cannot tell them apart)."""
    nd = len(c.model.drivers)
    return list(c.prims[: len(c.prims) - nd]), list(c.prims[len(c.prims) - nd :])


def _square_subset(c: Compiled, q: np.ndarray) -> Compiled:
    """The compiled model restricted to its joints and a set of drivers that make the system
    square and regular at ``q`` (all of them unless the actuation is redundant)."""
    n = 3 * c.nb
    joint_prims, driver_prims = _joint_and_driver_prims(c)
    chosen: list = []
    for p in driver_prims:
        trial = _restrict(c, joint_prims, chosen + [p])
        J = jacobian(trial, with_frame(q[None, :]))[0, :, 3:]
        if J.shape[0] <= n and np.linalg.matrix_rank(J) == J.shape[0]:
            chosen.append(p)
    return _restrict(c, joint_prims, chosen)


def _restrict(c: Compiled, joint_prims: list, driver_prims: list) -> Compiled:
    """A compiled model with these joints and drivers only (drivers last, as compile_model does;
    ``model`` keeps only the matching drivers so that the split above still holds)."""
    owner: list[str] = []
    rows: dict[str, int] = {}
    for p in joint_prims:
        owner.extend([p.owner] * p.rows)
    for p in driver_prims:
        rows[p.owner] = len(owner)
        owner.extend([p.owner] * p.rows)
    names = {p.owner for p in driver_prims}
    model = replace(c.model, drivers=tuple(d for d in c.model.drivers if d.name in names))
    return replace(c, model=model, prims=joint_prims + list(driver_prims), row_owner=owner, driver_rows=rows,
                   joint_rows={})


def sample_states(model: Model, t: np.ndarray, samples: int = 0, seed: int = 0, blocks: bool | None = None) -> States:
    """Feasible states of ``model`` around the motion on the time grid ``t``.

    ``samples`` = 0 picks 2 (number of parameters) + 12. Deterministic for a given seed.
    ``blocks``: each round's states solved by blocks (:mod:`.state_blocks`: one degree of
    freedom, O(bodies) per state, the same states to round-off) or densely (every Jacobian
    whole, O(bodies^3) per state); by default by blocks from :data:`BLOCK_COORDINATES`
    coordinates on, densely below (where the dense route costs less, and the results of small
    machines stay bit for bit those of the dense route).
    """
    rng = np.random.default_rng(seed)
    c = compile_model(model)
    nb = c.nb
    n = 3 * nb
    target = samples or 2 * 4 * nb + 12
    t = np.asarray(t, dtype=float)
    tc = np.unique(t[np.linspace(0, len(t) - 1, min(len(t), 9)).round().astype(int)])
    q_first, ok, _ = newton_raphson(_square_subset(c, c.q0), c.q0[None, :], t[:1], max_iter=50)
    sq = _square_subset(c, q_first[0] if ok[0] else c.q0)
    use_blocks = n >= BLOCK_COORDINATES if blocks is None else blocks
    base = solve_positions_by_blocks(sq, tc) if use_blocks else solve_positions(sq, tc)
    joint_prims, driver_prims = _joint_and_driver_prims(sq)
    base_values = np.array([p.law(tc)[0] for p in driver_prims]).T if driver_prims else np.zeros((len(tc), 0))
    joints_only = _restrict(sq, joint_prims, [])
    joint_rows = len(joints_only.row_owner)
    size = model_size(model)
    spread = np.array([
        LENGTH_SPREAD * size if _is_length(model, p) else ANGLE_SPREAD for p in driver_prims
    ])
    poses: list[np.ndarray] = []
    rates: list[np.ndarray] = []
    discarded, dof = 0, None
    for round_ in range(6):  # rounds, until enough good samples; smaller displacements each round
        need = target - sum(len(p) for p in poses)
        if need <= 0:
            break
        k = rng.integers(0, len(tc), size=2 * need)
        scale = rng.uniform(-1, 1, size=(2 * need, len(driver_prims)))
        scale[: len(tc)] = 0.0  # keep the path's own configurations too
        values = base_values[k] + scale * spread * 0.5**round_
        trial = replace(sq, prims=joint_prims + [
            replace(p, law=_Table(values[:, j])) for j, p in enumerate(driver_prims)
        ])
        block = BlockRound.of(trial, joint_rows) if use_blocks else None
        found = _block_round(block, joints_only, base[k], need) if block is not None else None
        if found is None:
            found = _dense_round(trial, joints_only, base[k])
        q, ok, rank, good, null_of, solved = found
        dof = n - rank if dof is None else dof
        discarded += int(np.count_nonzero(~good[:solved]))
        idx = np.flatnonzero(good)[:need]
        null = null_of(idx)  # (S, n, n - rank)
        v = np.einsum("snd,sd->sn", null, rng.normal(size=(len(idx), n - rank)))
        poses.append(q[idx])
        rates.append(v)
    q = np.concatenate(poses)[:target]
    v = np.concatenate(rates)[:target]
    if len(q) < min(target, 6):
        raise ValueError(f"only {len(q)} regular configurations found around the motion of {model.name!r}")
    return _body_frames(model, c, q, v, dof or 0, discarded)


def _dense_round(trial: Compiled, joints_only: Compiled, guess: np.ndarray):
    """One round's trial states solved densely: (q, converged, rank, good, null vectors of the
    states ``idx``, number of states solved: all) with the rank the median of the states' numerical ranks (1e-9) and good
    the converged states whose joint Jacobian has s_rank > MIN_CONDITION s_1."""
    q, ok, _ = newton_raphson(trial, guess, np.arange(len(guess), dtype=float))
    Jj = jacobian(joints_only, with_frame(q))[:, :, 3:]
    u, s, vt = np.linalg.svd(Jj)
    rank = int(np.median(np.sum(s > 1e-9 * s[:, :1], axis=1)))
    good = ok & (s[:, rank - 1] > MIN_CONDITION * s[:, 0]) if rank > 0 else ok
    return q, ok, rank, good, lambda idx: np.transpose(vt[idx, rank:, :], (0, 2, 1)), len(q)


def _block_round(block: BlockRound, joints_only: Compiled, guess: np.ndarray, need: int):
    """:func:`_dense_round` by blocks (:mod:`.state_blocks`), in chunks of :data:`CHUNK` states
    (the memory of a chunk, whatever the number of states), with the SVD only for the states
    the block route does not certify. The trial states are independent of each other, so the
    chunks stop as soon as the states solved decide the round as the whole would: the first
    ``need`` good states among them, and more than half of all the states certified (the median
    rank is then m). Returns None when the rank is not the joints' row count (then the dense
    round decides every state)."""
    S, n, m = len(guess), guess.shape[1], block.m
    q, null_b = np.zeros((S, n)), np.zeros((S, n))
    ok, sure, good = np.zeros(S, bool), np.zeros(S, bool), np.zeros(S, bool)
    ranks = np.full(S, m)
    fallback: dict[int, np.ndarray] = {}  # state -> its SVD's null space (uncertified, converged states)
    majority = S // 2 + 1
    done = 0
    while done < S:
        hi = min(S, done + CHUNK)
        part = slice(done, hi)
        q[part], ok[part] = block.newton(guess[part], np.arange(done, hi, dtype=float))
        sure[part], null_b[part] = block.certify(q[part], MIN_CONDITION)
        good[part] = ok[part] & sure[part]
        unsure = done + np.flatnonzero(~sure[part] & ok[part])
        if unsure.size:
            _, su, vtu = np.linalg.svd(jacobian(joints_only, with_frame(q[unsure]))[:, :, 3:])
            ranks[unsure] = np.sum(su > 1e-9 * su[:, :1], axis=1)
            good[unsure] = su[:, m - 1] > MIN_CONDITION * su[:, 0]
            for i, k in enumerate(unsure.tolist()):
                fallback[k] = vtu[i, m:, :].T
        done = hi
        if np.count_nonzero(sure[:done]) >= majority and np.count_nonzero(good[:done]) >= need:
            break
    if np.count_nonzero(sure[:done]) < majority:  # every state solved: the median as counted densely
        rest = np.flatnonzero(~sure & ~ok)
        if rest.size:
            s = np.linalg.svd(jacobian(joints_only, with_frame(q[rest]))[:, :, 3:], compute_uv=False)
            ranks[rest] = np.sum(s > 1e-9 * s[:, :1], axis=1)
        if int(np.median(ranks)) != m:
            return None

    def null_of(idx: np.ndarray) -> np.ndarray:
        out = null_b[idx][:, :, None].copy()
        for i, k in enumerate(idx.tolist()):
            if k in fallback:
                out[i] = fallback[k]
        return out

    return q, ok, m, good, null_of, done


def states_from_analysis(model: Model, *analyses, samples: np.ndarray | None = None) -> States:
    """The states along engine analyses of ``model`` (its own motions, concatenated): for checking
    Y_P p = P and Y_H p = H against the engine, or for conditions restricted to a family of
    motions (e.g. a translating platform: several analyses of such motions, passed to
    ``conditions.find(model, t, states=...)``). ``samples``: only these indices of the
    concatenated samples, in that order (each sample's state is computed alone, so it is the
    same bits as in the states of every sample)."""
    c = compile_model(model)

    def rows(field: str) -> np.ndarray:
        x = np.concatenate([getattr(a, field).reshape(len(a.t), -1) for a in analyses])
        return x if samples is None else x[samples]

    return _body_frames(model, c, rows("q"), rows("v"), -1, 0, rows("a"))


def _is_length(model: Model, prim) -> bool:
    return hasattr(prim, "a")  # projection primitives drive lengths (prismatic, x, y)


def _body_frames(model: Model, c: Compiled, q: np.ndarray, v: np.ndarray, dof: int, discarded: int,
                 acc: np.ndarray | None = None) -> States:
    """Centre-of-mass coordinates -> body-frame origins: r_o = r_c - A c, r_o' = r_c' - w A' c,
    r_o'' = r_c'' - (alpha perp(A c) - w^2 A c)."""
    S = q.shape[0]
    qb, vb = q.reshape(S, c.nb, 3), v.reshape(S, c.nb, 3)
    pose, rate = qb.copy(), vb.copy()
    ab = None if acc is None else acc.reshape(S, c.nb, 3).copy()
    for k, b in enumerate(model.bodies):
        _, com, _ = b.mass_properties()
        th, w = qb[:, k, 2], vb[:, k, 2]
        co, si = np.cos(th), np.sin(th)
        ax, ay = co * com[0] - si * com[1], si * com[0] + co * com[1]
        pose[:, k, 0] -= ax
        pose[:, k, 1] -= ay
        rate[:, k, 0] -= -w * ay
        rate[:, k, 1] -= w * ax
        if ab is not None:
            al = ab[:, k, 2]
            ab[:, k, 0] -= -al * ay - w * w * ax
            ab[:, k, 1] -= al * ax - w * w * ay
    return States(c.names, pose, rate, dof, discarded, ab)


def _columns(states: States, point: tuple[float, float] = (0.0, 0.0)):
    th, w = states.pose[..., 2], states.rate[..., 2]
    co, si = np.cos(th), np.sin(th)
    r = states.pose[..., :2] - np.asarray(point)
    rd = states.rate[..., :2]
    e1, e2 = np.stack([co, si], -1), np.stack([-si, co], -1)
    de1, de2 = w[..., None] * e2, -w[..., None] * e1
    return r, rd, e1, e2, de1, de2, w


def linear_regressor(states: States) -> np.ndarray:
    """Y_P (2 S, 3 nb): rows Px, Py per sample, columns m, mx, my per body."""
    r, rd, e1, e2, de1, de2, w = _columns(states)
    S, nb = w.shape
    Y = np.stack([rd, de1, de2], axis=2)  # (S, nb, 3, 2)
    return np.transpose(Y, (0, 3, 1, 2)).reshape(2 * S, 3 * nb)


def angular_regressor(states: States, point: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Y_H (S, 4 nb): angular momentum about ``point``, columns m, mx, my, J per body."""
    r, rd, e1, e2, de1, de2, w = _columns(states, point)
    cols = [cross(r, rd), cross(r, de1) + cross(e1, rd), cross(r, de2) + cross(e2, rd), w]
    S, nb = w.shape
    return np.stack(cols, axis=2).reshape(S, 4 * nb)


@dataclass
class RowSpace:
    """Rank and row-space basis of a regressor by SVD, columns scaled to one unit.

    ``basis`` (rank, ncols) spans the rows of Y in the original units; ``singular`` all the
    singular values of the scaled regressor (largest first); the rank counts those above
    ``tolerance`` x the largest; ``gap`` = last kept / first dropped (inf when none dropped)."""

    rank: int
    basis: np.ndarray
    singular: np.ndarray
    tolerance: float
    gap: float


def row_space(Y: np.ndarray, scale: np.ndarray, tolerance: float = 1e-9) -> RowSpace:
    """Y p = (Y D) (D^-1 p) with D = diag(scale): the SVD of the scaled Y gives the rank; its
    right singular vectors, times D^-1, the conditions C p = 0 in the original units."""
    Ys = Y * scale
    norm = np.linalg.norm(Ys)
    if norm == 0:
        return RowSpace(0, np.zeros((0, Y.shape[1])), np.zeros(min(Y.shape)), tolerance, math.inf)
    _, s, vt = np.linalg.svd(Ys, full_matrices=False)
    rank = int(np.sum(s > tolerance * s[0]))
    gap = float(s[rank - 1] / s[rank]) if 0 < rank < len(s) and s[rank] > 0 else math.inf
    return RowSpace(rank, vt[:rank] / scale, s, tolerance, gap)


def _accelerations(states: States):
    """Body-frame origin accelerations r_o'' (S, nb, 2), e1'' and e2'' (S, nb, 2), alpha (S, nb)."""
    if states.acc is None:
        raise ValueError("these states have no accelerations (use states_from_analysis)")
    th, w, al = states.pose[..., 2], states.rate[..., 2], states.acc[..., 2]
    co, si = np.cos(th), np.sin(th)
    e1, e2 = np.stack([co, si], -1), np.stack([-si, co], -1)
    dde1 = al[..., None] * e2 - (w * w)[..., None] * e1
    dde2 = -al[..., None] * e1 - (w * w)[..., None] * e2
    return states.acc[..., :2], e1, e2, dde1, dde2, al


def shaking_regressor(states: States, gravity: tuple[float, float] = (0.0, 0.0),
                      point: tuple[float, float] = (0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """Shaking force and moment, linear in (m, mx, my, J) per body (the momentum route of
    :mod:`balpipe.engine`, differentiated): F = sum m g - dP/dt and, about ``point`` P,
    M_P = sum (r_c - P) x m g - dH_P/dt, with r = r_o - P, e1'' = alpha e2 - w^2 e1,
    e2'' = -alpha e1 - w^2 e2:

        dP/dt   = sum m r_o'' + mx e1'' + my e2''
        dH_P/dt = sum m r x r_o'' + mx (r x e1'' + e1 x r_o'') + my (r x e2'' + e2 x r_o'') + J alpha

    Returns Y_F (S, 2, 4 nb) and Y_M (S, 4 nb): F = Y_F p, M = Y_M p with p = parameters(model,
    angular=True)."""
    rdd, e1, e2, dde1, dde2, al = _accelerations(states)
    g = np.asarray(gravity, dtype=float)
    r = states.pose[..., :2] - np.asarray(point, dtype=float)
    S, nb = al.shape
    gS = np.broadcast_to(g, rdd.shape)
    YF = np.stack([gS - rdd, -dde1, -dde2, np.zeros_like(rdd)], axis=2)  # (S, nb, 4, 2)
    YM = np.stack([
        cross(r, gS) - cross(r, rdd),
        cross(e1, gS) - cross(r, dde1) - cross(e1, rdd),
        cross(e2, gS) - cross(r, dde2) - cross(e2, rdd),
        -al,
    ], axis=2)  # (S, nb, 4)
    return np.transpose(YF, (0, 3, 1, 2)).reshape(S, 2, 4 * nb), YM.reshape(S, 4 * nb)


def dynamics_regressor(states: States, gravity: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
    """Y_D (S, 3 nb, 4 nb): the inertial less the applied (weight) generalized forces of every body
    in body-frame-origin coordinates (x, y, theta of the frame origin), linear in (m, mx, my, J):

        x, y:  m (r_o'' - g) + mx e1'' + my e2''
        theta: mx e1 x (r_o'' - g) + my e2 x (r_o'' - g) + J alpha

    (Newton-Euler about the frame origin: J = I + m |c|^2). The dynamics read
    Phi_q^T lambda = -Y_D p in these coordinates (:mod:`balpipe.balancing.mass_sweep`)."""
    rdd, e1, e2, dde1, dde2, al = _accelerations(states)
    a = rdd - np.asarray(gravity, dtype=float)
    S, nb = al.shape
    Y = np.zeros((S, nb, 3, nb, 4))
    for k in range(nb):
        Y[:, k, 0:2, k, 0] = a[:, k]
        Y[:, k, 0:2, k, 1] = dde1[:, k]
        Y[:, k, 0:2, k, 2] = dde2[:, k]
        Y[:, k, 2, k, 1] = cross(e1[:, k], a[:, k])
        Y[:, k, 2, k, 2] = cross(e2[:, k], a[:, k])
        Y[:, k, 2, k, 3] = al[:, k]
    return Y.reshape(S, 3 * nb, 4 * nb)
