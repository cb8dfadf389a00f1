"""Random custom four-bars and five-bars (spec dictionaries) for the generic balancing tests."""

from __future__ import annotations

import math

import numpy as np


def _circles(p, r1, q, r2, sign=1.0):
    """Intersection of the circles (p, r1), (q, r2); ``sign`` picks the branch."""
    p, q = np.asarray(p, float), np.asarray(q, float)
    d = float(np.linalg.norm(q - p))
    a = (r1 * r1 - r2 * r2 + d * d) / (2 * d)
    h = math.sqrt(max(r1 * r1 - a * a, 0.0))
    e = (q - p) / d
    return p + a * e + sign * h * np.array([-e[1], e[0]])


def _bar(name, L, rng, pose, first="P", second="Q"):
    m = float(rng.uniform(0.3, 2.0))
    return {"name": name, "mass": m, "com": [float(rng.uniform(0.2, 0.8) * L), float(rng.uniform(-0.1, 0.1) * L)],
            "inertia": m * L * L * float(rng.uniform(0.05, 0.12)), "pose": [float(pose[0]), float(pose[1]), float(pose[2])],
            "points": {first: [0.0, 0.0], second: [L, 0.0]}}


def four_bar(rng: np.random.Generator, method: dict | None = None) -> dict:
    """A Grashof crank-rocker (crank shortest) turning its crank by 1.2-2 turns' worth of angle."""
    while True:
        a, b, c, d = (float(x) for x in (rng.uniform(0.05, 0.1), rng.uniform(0.25, 0.35),
                                          rng.uniform(0.2, 0.3), rng.uniform(0.25, 0.35)))
        if a + max(b, c, d) <= 0.9 * (sum((a, b, c, d)) - a - max(b, c, d)):
            break
    th = float(rng.uniform(0, 2 * math.pi))
    A = np.array([a * math.cos(th), a * math.sin(th)])
    B = _circles(A, b, (d, 0.0), c)
    bodies = [
        _bar("crank", a, rng, (0, 0, th), "O2", "A"),
        _bar("coupler", b, rng, (A[0], A[1], math.atan2(*(B - A)[::-1])), "A", "B"),
        _bar("rocker", c, rng, (d, 0, math.atan2(B[1], B[0] - d)), "O4", "B"),
    ]
    spec = {
        "name": "random four-bar",
        "mechanism": {"template": "custom", "frame_points": {"O2": [0, 0], "O4": [d, 0]}, "bodies": bodies,
                      "joints": [
                          {"type": "revolute", "name": "O2", "a": "frame", "b": "crank", "point_a": "O2", "point_b": "O2"},
                          {"type": "revolute", "name": "A", "a": "crank", "b": "coupler", "point_a": "A", "point_b": "A"},
                          {"type": "revolute", "name": "B", "a": "coupler", "b": "rocker", "point_a": "B", "point_b": "B"},
                          {"type": "revolute", "name": "O4", "a": "frame", "b": "rocker", "point_a": "O4", "point_b": "O4"}],
                      "drivers": [{"name": "crank", "joint": "O2"}]},
        "motion": {"law": "quintic", "duration": 0.4,
                   "drive": {"crank": {"from": th, "to": th + float(rng.uniform(1.2, 2.0)) * math.pi}}},
        "analysis": {"samples": 201},
        "validation": {"enabled": False},
    }
    if method is not None:
        spec["balancing"] = method
    return spec


FOUR_BAR_REGIONS = [
    {"body": "crank", "name": "cw_crank", "disc": {"centre": [-0.05, 0], "radius": 0.05}},
    {"body": "coupler", "name": "cw_coupler", "disc": {"centre": [0.15, 0], "radius": 0.3}},
    {"body": "rocker", "name": "cw_rocker", "disc": {"centre": [-0.15, 0], "radius": 0.15}},
]
FOUR_BAR_DISCS = [
    {"name": "disc_crank", "carrier": "frame", "at": [0, 0], "geared_to": "crank", "ratio": -1},
    {"name": "disc_coupler", "carrier": "crank", "at": "O2", "geared_to": "coupler", "ratio": -1},
    {"name": "disc_rocker", "carrier": "frame", "at": "O4", "geared_to": "rocker", "ratio": -1},
]


def five_bar(rng: np.random.Generator, method: dict | None = None) -> dict:
    """A 2-DOF five-bar (both base joints driven on their own laws) near a well-conditioned pose."""
    d = float(rng.uniform(0.15, 0.3))
    l1, l2 = (float(x) for x in rng.uniform(0.2, 0.3, 2))
    l3, l4 = (float(x) for x in rng.uniform(0.3, 0.4, 2))
    th1, th2 = float(rng.uniform(1.6, 2.0)), float(rng.uniform(1.1, 1.5))
    B1 = np.array([l1 * math.cos(th1), l1 * math.sin(th1)])
    B2 = np.array([d + l2 * math.cos(th2), l2 * math.sin(th2)])
    C = _circles(B1, l3, B2, l4, sign=-1.0)
    ang = lambda u, v: math.atan2(v[1] - u[1], v[0] - u[0])  # noqa: E731
    bodies = [
        _bar("link1", l1, rng, (0, 0, th1), "A1", "B1"),
        _bar("link2", l2, rng, (d, 0, th2), "A2", "B2"),
        _bar("link3", l3, rng, (B1[0], B1[1], ang(B1, C)), "B1", "C"),
        _bar("link4", l4, rng, (B2[0], B2[1], ang(B2, C)), "B2", "C"),
    ]
    rev = lambda n, a, b, pa, pb: {"type": "revolute", "name": n, "a": a, "b": b, "point_a": pa, "point_b": pb}  # noqa: E731
    spec = {
        "name": "random five-bar",
        "mechanism": {"template": "custom", "frame_points": {"A1": [0, 0], "A2": [d, 0]}, "bodies": bodies,
                      "joints": [rev("A1", "frame", "link1", "A1", "A1"), rev("A2", "frame", "link2", "A2", "A2"),
                                 rev("B1", "link1", "link3", "B1", "B1"), rev("B2", "link2", "link4", "B2", "B2"),
                                 rev("C", "link3", "link4", "C", "C")],
                      "drivers": [{"name": "q1", "joint": "A1"}, {"name": "q2", "joint": "A2"}]},
        "motion": {"law": "quintic", "duration": 0.4, "drive": {
            "q1": {"from": th1, "to": th1 + float(rng.uniform(0.2, 0.4))},
            "q2": {"from": th2, "to": th2 - float(rng.uniform(0.2, 0.4)), "law": "cycloidal"}}},
        "analysis": {"samples": 201},
        "validation": {"enabled": False},
    }
    if method is not None:
        spec["balancing"] = method
    return spec


FIVE_BAR_REGIONS = [
    {"body": "link1", "name": "cw1", "disc": {"centre": [-0.15, 0], "radius": 0.15}},
    {"body": "link2", "name": "cw2", "disc": {"centre": [-0.15, 0], "radius": 0.15}},
    {"body": "link3", "name": "cw3", "disc": {"centre": [0.15, 0], "radius": 0.35}},
    {"body": "link4", "name": "cw4", "disc": {"centre": [0.15, 0], "radius": 0.35}},
]
FIVE_BAR_DISCS = [
    {"name": "d1", "carrier": "frame", "at": "A1", "geared_to": "link1", "ratio": -1},
    {"name": "d2", "carrier": "frame", "at": "A2", "geared_to": "link2", "ratio": -1},
    {"name": "d3", "carrier": "link1", "at": "A1", "geared_to": "link3", "ratio": -1},
    {"name": "d4", "carrier": "link2", "at": "A2", "geared_to": "link4", "ratio": -1},
]


def watt_six_bar(ratios) -> dict:
    """A Watt-II six-bar of ours (a crank-rocker whose ternary rocker drives a second four-bar loop)
    at 60 rpm, moment_balance with counterweights on every link and five counter-rotating discs
    (on the frame geared to the crank, the first and the output rocker; on the crank geared to the
    first coupler; on the ternary rocker geared to the second coupler) of the given ``ratios``."""
    a, b, c, d = 0.08, 0.30, 0.25, 0.30
    O4, O6 = np.array([d, 0.0]), np.array([0.55, 0.10])
    th = 0.3
    A = a * np.array([math.cos(th), math.sin(th)])
    B = _circles(A, b, O4, c)
    psi = math.atan2(B[1] - O4[1], B[0] - O4[0])
    Cl = np.array([0.10, -0.12])  # C on rocker4 (its frame: x toward B)
    R = np.array([[math.cos(psi), -math.sin(psi)], [math.sin(psi), math.cos(psi)]])
    C = O4 + R @ Cl
    e, f = 0.30, 0.22
    D = _circles(C, e, O6, f)
    ang = lambda p, q: math.atan2(q[1] - p[1], q[0] - p[0])  # noqa: E731

    def bar(name, m, L, pose, pts, I=None):
        return {"name": name, "mass": m, "com": [L / 2, 0.0], "inertia": I or m * L * L / 12, "pose": list(map(float, pose)), "points": pts}
    phi1, phi2, phi6 = ang(A, B), ang(C, D), ang(O6, D)
    bodies = [
        bar("crank", 0.5, a, (0, 0, th), {"O2": [0, 0], "A": [a, 0]}),
        bar("coupler1", 1.0, b, (A[0], A[1], phi1), {"A": [0, 0], "B": [b, 0]}),
        {"name": "rocker4", "mass": 1.2, "com": [0.1, -0.03], "inertia": 0.008, "pose": [float(O4[0]), float(O4[1]), psi],
         "points": {"O4": [0, 0], "B": [c, 0], "C": Cl.tolist()}},
        bar("coupler2", 0.9, e, (C[0], C[1], phi2), {"C": [0, 0], "D": [e, 0]}),
        bar("rocker6", 0.7, f, (O6[0], O6[1], phi6), {"O6": [0, 0], "D": [f, 0]}),
    ]
    J = lambda n, x, y, p: {  # noqa: E731
        "type": "revolute", "name": n, "a": x, "b": y, "point_a": p, "point_b": p}
    cws = [{"body": "crank", "name": "cw_crank", "segment": [[0, 0], [-0.08, 0]]},
           {"body": "coupler1", "name": "cw_c1", "disc": {"centre": [0.15, 0], "radius": 0.3}},
           {"body": "rocker4", "name": "cw_r4", "disc": {"centre": [0.0, 0.0], "radius": 0.2}},
           {"body": "coupler2", "name": "cw_c2", "disc": {"centre": [0.15, 0], "radius": 0.3}},
           {"body": "rocker6", "name": "cw_r6", "segment": [[0, 0], [-0.15, 0]]}]
    discs = [("d_crank", "frame", "O2", "crank"), ("d_c1", "crank", "O2", "coupler1"), ("d_r4", "frame", "O4", "rocker4"),
             ("d_c2", "rocker4", "O4", "coupler2"), ("d_r6", "frame", "O6", "rocker6")]
    return {
        "name": "Watt-II six-bar", "mechanism": {"template": "custom",
            "frame_points": {"O2": [0, 0], "O4": O4.tolist(), "O6": O6.tolist()}, "bodies": bodies,
            "joints": [J("O2", "frame", "crank", "O2"), J("A", "crank", "coupler1", "A"), J("B", "coupler1", "rocker4", "B"),
                       J("O4", "frame", "rocker4", "O4"), J("C", "rocker4", "coupler2", "C"), J("D", "coupler2", "rocker6", "D"),
                       J("O6", "frame", "rocker6", "O6")],
            "drivers": [{"name": "crank", "joint": "O2"}]},
        "motion": {"cycles": 1, "drive": {"crank": {"law": "constant_speed", "from": th, "speed": "60 rpm"}}},
        "balancing": {"method": "moment_balance", "counterweights": cws,
                      "counter_rotations": [{"name": n, "carrier": cr, "at": at, "geared_to": g, "ratio": r}
                                            for (n, cr, at, g), r in zip(discs, ratios)]},
        "analysis": {"samples": 181}, "validation": {"enabled": False}}
