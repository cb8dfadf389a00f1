"""Paths for a point or a pose: curves parametrised by arc length, timed by a law on the length.

A path is a chain of pieces of constant curvature: straight lines (kappa = 0) and circular arcs
(kappa = +-1/R, positive turning left). A polyline's corners are rounded by arcs of a given
radius tangent to both sides (tangent length r tan(|theta| / 2) for a turn theta). With P(s) the
point at arc length s, T(s) the unit tangent and N = J T its left normal, a timing law s(t)
gives the point's motion

    x = P(s),  x' = T s',  x'' = T s'' + kappa N s'^2

and, for a pose whose angle follows the tangent (heading), phi = phi_T(s) + offset,
phi' = kappa s', phi'' = kappa s'' (kappa is constant on each piece). A closed path (a circle)
repeats: s is taken modulo its length L and the heading gains one turn per lap.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..model import Law

Triple = tuple[np.ndarray, np.ndarray, np.ndarray]


@dataclass(frozen=True)
class Piece:
    """A line (``curvature`` 0) from ``start`` along the heading ``angle``, or an arc of signed
    ``curvature`` starting at ``start`` with tangent heading ``angle``; ``length`` > 0."""

    start: tuple[float, float]
    angle: float
    curvature: float
    length: float

    def evaluate(self, s: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Points (n, 2) and headings (n,) at arc lengths ``s`` from the piece's start."""
        k, a = self.curvature, self.angle
        h = a + k * s
        if k == 0:
            p = np.stack([self.start[0] + s * math.cos(a), self.start[1] + s * math.sin(a)], axis=-1)
        else:  # centre at start + N / k; point = centre - N(h) / k
            cx, cy = self.start[0] - math.sin(a) / k, self.start[1] + math.cos(a) / k
            p = np.stack([cx + np.sin(h) / k, cy - np.cos(h) / k], axis=-1)
        return p, h


class PathError(ValueError):
    """A path that cannot be built (a corner radius that does not fit, a point repeated)."""


@dataclass(frozen=True)
class Path:
    """A chain of :class:`Piece` (each starting where the previous one ends, tangent to it)."""

    pieces: tuple[Piece, ...]
    closed: bool = False

    @property
    def length(self) -> float:
        return float(sum(p.length for p in self.pieces))

    @property
    def turn(self) -> float:
        """Total change of heading along the path (rad)."""
        return float(sum(p.curvature * p.length for p in self.pieces))

    def geometry(self, s) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """Points (n, 2), unit tangents (n, 2), curvatures (n,) and headings (n,) at arc
        lengths ``s`` (closed paths: modulo the length; open ones: s in [0, L])."""
        s = np.asarray(s, dtype=float).reshape(-1)
        L = self.length
        laps = np.floor(s / L) if self.closed else np.zeros(s.shape)
        s = s - laps * L
        starts = np.concatenate([[0.0], np.cumsum([p.length for p in self.pieces])[:-1]])
        k = np.clip(np.searchsorted(starts, s, side="right") - 1, 0, len(self.pieces) - 1)
        P, H, K = np.zeros((s.size, 2)), np.zeros(s.size), np.zeros(s.size)
        for i, piece in enumerate(self.pieces):
            sel = k == i
            if np.any(sel):
                P[sel], H[sel] = piece.evaluate(s[sel] - starts[i])
                K[sel] = piece.curvature
        H = H + laps * self.turn
        return P, np.stack([np.cos(H), np.sin(H)], axis=-1), K, H


def corners(path: Path) -> list[tuple[float, float, tuple[float, float]]]:
    """The sharp corners of ``path`` (a polyline without corner radius): (arc length, turn of the
    tangent in rad, point) wherever a piece does not start along the heading the previous one
    ends with. A point passing one at speed v would turn its velocity at once: an infinite
    acceleration."""
    out = []
    s = 0.0
    for a, b in zip(path.pieces, path.pieces[1:]):
        s += a.length
        turn = math.remainder(b.angle - (a.angle + a.curvature * a.length), 2 * math.pi)
        if abs(turn) > 1e-9:
            out.append((s, turn, b.start))
    return out


def line(a, b) -> Path:
    d = (b[0] - a[0], b[1] - a[1])
    L = math.hypot(*d)
    if L == 0:
        raise PathError("the line's two ends are the same point")
    return Path((Piece(tuple(a), math.atan2(d[1], d[0]), 0.0, L),))


def arc(centre, radius: float, start_angle: float, sweep: float) -> Path:
    """From the angle ``start_angle`` about ``centre``, turning by ``sweep`` (counter-clockwise
    when positive); a full turn (|sweep| = 2 pi) is a closed circle."""
    if sweep == 0:
        raise PathError("the arc's sweep is zero")
    sign = 1.0 if sweep > 0 else -1.0
    start = (centre[0] + radius * math.cos(start_angle), centre[1] + radius * math.sin(start_angle))
    piece = Piece(start, start_angle + sign * math.pi / 2, sign / radius, radius * abs(sweep))
    return Path((piece,), closed=abs(abs(sweep) - 2 * math.pi) < 1e-12)


def polyline(points, corner_radius: float) -> Path:
    """Straight sides through ``points`` with every interior corner rounded by an arc of
    ``corner_radius``; raises :class:`PathError` naming the corner whose arc does not fit."""
    pts = [np.asarray(p, dtype=float) for p in points]
    dirs, lens = [], []
    for k in range(len(pts) - 1):
        d = pts[k + 1] - pts[k]
        L = float(np.hypot(*d))
        if L == 0:
            raise PathError(f"points {k} and {k + 1} coincide")
        dirs.append(d / L)
        lens.append(L)
    cut = [0.0] * (len(pts))  # tangent length of the fillet at each point
    turns = [0.0] * (len(pts))
    for k in range(1, len(pts) - 1):
        u1, u2 = dirs[k - 1], dirs[k]
        th = math.atan2(u1[0] * u2[1] - u1[1] * u2[0], float(u1 @ u2))
        if abs(th) > math.pi - 1e-9:
            raise PathError(f"the path turns back on itself at point {k}: no rounded corner fits")
        turns[k] = th
        cut[k] = corner_radius * math.tan(abs(th) / 2)
    pieces = []
    for k in range(len(pts) - 1):
        free = lens[k] - cut[k] - cut[k + 1]
        if free < -1e-12 * lens[k]:
            raise PathError(f"the corner radius {corner_radius:g} m does not fit on side {k}-{k + 1} "
                            f"({lens[k]:.4g} m long; the rounded corners need {cut[k] + cut[k + 1]:.4g} m)")
        a = math.atan2(dirs[k][1], dirs[k][0])
        p0 = pts[k] + dirs[k] * cut[k]
        if free > 1e-12 * lens[k]:
            pieces.append(Piece((float(p0[0]), float(p0[1])), a, 0.0, free))
        th = turns[k + 1] if k + 1 < len(pts) - 1 else 0.0
        if th != 0.0 and corner_radius > 0:
            q0 = pts[k + 1] - dirs[k] * cut[k + 1]
            pieces.append(Piece((float(q0[0]), float(q0[1])), a, math.copysign(1.0 / corner_radius, th),
                                corner_radius * abs(th)))
    return Path(tuple(pieces))


@dataclass(frozen=True)
class PathMotion:
    """A path timed by a law ``timing`` on its arc length: the point's x, y and the heading
    angle (plus ``offset``), each with two exact time derivatives; or a fixed angle ``offset``
    when ``heading`` is False."""

    path: Path
    timing: Law
    heading: bool = True
    offset: float = 0.0

    def values(self, t) -> tuple[Triple, Triple, Triple]:
        t = np.asarray(t, dtype=float).reshape(-1)
        s, sd, sdd = (np.asarray(v, dtype=float).reshape(-1) for v in self.timing(t))
        P, T, K, H = self.path.geometry(s)
        N = np.stack([-T[:, 1], T[:, 0]], axis=-1)
        V = T * sd[:, None]
        A = T * sdd[:, None] + N * (K * sd**2)[:, None]
        if self.heading:
            phi = (H + self.offset, K * sd, K * sdd)
        else:
            phi = (np.full(t.shape, self.offset), np.zeros(t.shape), np.zeros(t.shape))
        return (P[:, 0], V[:, 0], A[:, 0]), (P[:, 1], V[:, 1], A[:, 1]), phi


@dataclass(frozen=True)
class PathComponent(Law):
    """One coordinate (0: x, 1: y, 2: angle) of a :class:`PathMotion`, as a driver's law."""

    motion: PathMotion
    index: int

    def __call__(self, t) -> Triple:
        t = np.asarray(t, dtype=float)
        out = self.motion.values(t)[self.index]
        q, qd, qdd = (np.asarray(v).reshape(t.shape) for v in out)
        return q, qd, qdd
