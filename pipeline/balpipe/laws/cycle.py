"""A cycle of segments: pick, move, dwell, return, each with its own law and duration.

Segment k runs on local time u in [0, d_k] from the end position of segment k - 1. The cycle
of period P = sum d_k repeats: q(t + P) = q(t) + D with D the cycle's net displacement (0 for a
pick-and-place that comes back, a turn for a crank that keeps turning), so a motion of several
cycles is in steady state. :func:`joins` measures the state jumps at the joins (the wrap-around
included); the spec builder refuses a jump in velocity.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..model import Law

Triple = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class Cycle(Law):
    """Segments (laws on local time, each starting where the previous one ends) of durations
    ``durations``; repeated with period sum(durations) and net displacement per cycle."""

    segments: tuple[Law, ...]
    durations: tuple[float, ...]

    @property
    def period(self) -> float:
        return float(sum(self.durations))

    @property
    def displacement(self) -> float:
        return float(self.segments[-1](np.array([self.durations[-1]]))[0][0] - self.segments[0](np.array([0.0]))[0][0])

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        P = self.period
        n = np.floor(t / P)
        local = t - n * P
        # the last sample of a whole number of cycles belongs to the end of the cycle before
        at_end = (local == 0) & (t > 0)
        n = np.where(at_end, n - 1, n)
        local = np.where(at_end, P, local)
        starts = np.concatenate([[0.0], np.cumsum(self.durations)[:-1]])
        k = np.clip(np.searchsorted(starts, local, side="right") - 1, 0, len(self.segments) - 1)
        q, qd, qdd = np.zeros(t.shape), np.zeros(t.shape), np.zeros(t.shape)
        for i, seg in enumerate(self.segments):
            sel = k == i
            if np.any(sel):
                a, b, c = seg(np.clip(local[sel] - starts[i], 0.0, self.durations[i]))  # no round-off past its end
                q[sel], qd[sel], qdd[sel] = a, b, c
        return q + n * self.displacement, qd, qdd


def end_state(law: Law, duration: float) -> tuple[float, float, float]:
    q, qd, qdd = law(np.array([0.0, duration]))
    return float(q[1]), float(qd[1]), float(qdd[1])


def start_state(law: Law) -> tuple[float, float, float]:
    q, qd, qdd = law(np.array([0.0]))
    return float(q[0]), float(qd[0]), float(qdd[0])


def joins(cycle: Cycle) -> list[tuple[float, float, float]]:
    """(dq, dq', dq'') at the end of every segment k: the next segment's start state (the first
    one's, shifted by the displacement, after the last) minus segment k's end state."""
    out = []
    n = len(cycle.segments)
    D = cycle.displacement
    for k in range(n):
        e = end_state(cycle.segments[k], cycle.durations[k])
        s = start_state(cycle.segments[(k + 1) % n])
        shift = D if k == n - 1 else 0.0
        out.append((s[0] + shift - e[0], s[1] - e[1], s[2] - e[2]))
    return out
