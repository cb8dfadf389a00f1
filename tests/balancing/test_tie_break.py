"""A stated tie-break for least mass (issue 20, item 8): when several designs reach the least
added mass, the page says so and the rule of balancing/tie_break.py picks one; a symmetric
five-bar gets a symmetric design of the same mass."""

from __future__ import annotations

import math

import numpy as np
import pytest
import yaml

from balpipe import registry
from balpipe.balancing import least_mass as LM
from balpipe.balancing import tie_break
from balpipe.loader import load_text
from generic_specs import _circles

ROOT = __import__('pathlib').Path(__file__).resolve().parents[2]


def sym_five_bar(regions: list[dict]) -> dict:
    """A five-bar mirror-symmetric about the y axis (legs, masses, regions)."""
    d, l1, l3 = 0.3, 0.25, 0.35
    th1 = 1.9
    th2 = math.pi - th1
    A1, A2 = np.array([-d / 2, 0]), np.array([d / 2, 0])
    B1 = A1 + l1 * np.array([math.cos(th1), math.sin(th1)])
    B2 = A2 + l1 * np.array([math.cos(th2), math.sin(th2)])
    C = _circles(B1, l3, B2, l3, sign=-1.0)
    ang = lambda u, v: math.atan2(v[1] - u[1], v[0] - u[0])  # noqa: E731
    bar = lambda n, L, m, pose, p, q: {"name": n, "mass": m, "com": [L / 2, 0], "inertia": m * L * L / 12,  # noqa: E731
                                       "pose": [float(x) for x in pose], "points": {p: [0, 0], q: [L, 0]}}
    rev = lambda n, a, b, pa, pb: {"type": "revolute", "name": n, "a": a, "b": b, "point_a": pa, "point_b": pb}  # noqa: E731
    return {
        "name": "symmetric five-bar",
        "mechanism": {
            "template": "custom", "frame_points": {"A1": A1.tolist(), "A2": A2.tolist()},
            "bodies": [bar("link1", l1, 1.0, (*A1, th1), "A1", "B1"), bar("link2", l1, 1.0, (*A2, th2), "A2", "B2"),
                       bar("link3", l3, 0.8, (*B1, ang(B1, C)), "B1", "C"), bar("link4", l3, 0.8, (*B2, ang(B2, C)), "B2", "C")],
            "joints": [rev("A1", "frame", "link1", "A1", "A1"), rev("A2", "frame", "link2", "A2", "A2"),
                       rev("B1", "link1", "link3", "B1", "B1"), rev("B2", "link2", "link4", "B2", "B2"),
                       rev("C", "link3", "link4", "C", "C")],
            "drivers": [{"name": "q1", "joint": "A1"}, {"name": "q2", "joint": "A2"}],
        },
        "motion": {"law": "quintic", "duration": 0.4,
                   "drive": {"q1": {"from": th1, "to": th1 + 0.3}, "q2": {"from": th2, "to": th2 - 0.3}}},
        "balancing": {"method": "force_balance", "counterweights": regions},
        "analysis": {"samples": 201}, "validation": {"enabled": False},
    }


DISCS = [{"body": "link1", "name": "cw1", "disc": {"centre": [-0.1, 0], "radius": 0.1}},
         {"body": "link2", "name": "cw2", "disc": {"centre": [-0.1, 0], "radius": 0.1}},
         {"body": "link3", "name": "cw3", "disc": {"centre": [0.1, 0], "radius": 0.3}},
         {"body": "link4", "name": "cw4", "disc": {"centre": [0.1, 0], "radius": 0.3}}]
SEGMENTS = [{"body": f"link{k}", "name": f"cw{k}", "segment": [[0, 0], [-0.15, 0]]} for k in (1, 2, 3, 4)]


def _balance(regions, monkeypatch=None, vertex=False):
    if vertex:
        monkeypatch.setattr(tie_break, "least_norm", lambda A, b, c, D, z0: (z0, True))
    s, _ = load_text(yaml.safe_dump(sym_five_bar(regions)), "s.yaml")
    res = registry.balance(s)
    return {p.name: p.value for p in res.parameters}, res


def test_symmetric_five_bar_gets_a_symmetric_least_mass_design(monkeypatch):
    vertex, _ = _balance(DISCS, monkeypatch, vertex=True)
    monkeypatch.undo()
    chosen, res = _balance(DISCS)
    # the solver's vertex is not symmetric (the optimum is a whole face) ...
    assert abs(vertex["cw1.mass"] - vertex["cw2.mass"]) > 0.1
    # ... the tie-break's design is, with the same least mass
    assert chosen["counterweight_mass"] == pytest.approx(vertex["counterweight_mass"], rel=1e-9)
    for a, b in (("cw1", "cw2"), ("cw3", "cw4")):
        assert chosen[f"{a}.mass"] == pytest.approx(chosen[f"{b}.mass"], rel=1e-6)
        assert chosen[f"{a}.x"] == pytest.approx(chosen[f"{b}.x"], abs=1e-6)
        assert chosen[f"{a}.y"] == pytest.approx(-chosen[f"{b}.y"], abs=1e-6)  # mirror: local y flips
    # the rule: the least sum of squares of the design parameters among the least-mass designs
    L = max(math.hypot(*p) for b in sym_five_bar(DISCS)["mechanism"]["bodies"] for p in b["points"].values())
    L = max(L, 0.15)
    norm = lambda d: sum(d[f"{c}.mass"] ** 2 * (1 + (d[f"{c}.x"] ** 2 + d[f"{c}.y"] ** 2) / L**2) for c in ("cw1", "cw2", "cw3", "cw4"))  # noqa: E731
    assert norm(chosen) < norm(vertex)
    assert any("more than one design" in n for n in res.notes)
    assert res.details["force_balance"]["least_mass_unique"] is False


def test_segments_too_symmetric_and_a_four_bar_unique():
    chosen, res = _balance(SEGMENTS)
    assert any("more than one design" in n for n in res.notes)
    assert chosen["cw1.mass"] == pytest.approx(chosen["cw2.mass"], rel=1e-6)
    assert chosen["cw3.mass"] == pytest.approx(chosen["cw4.mass"], rel=1e-6)
    four = yaml.safe_load(open(ROOT / "specs/custom_four_bar_balancing.yaml").read())
    four["balancing"] = four["compare"][0]["balancing"]
    four.pop("compare")
    s4, _ = load_text(yaml.safe_dump(four), "f.yaml")
    res4 = registry.balance(s4)
    assert not any("more than one design" in n for n in res4.notes)
    assert res4.details["force_balance"]["least_mass_unique"] is True


def test_least_distance_matches_a_brute_force_on_a_small_face():
    """min |D z|^2 on {z >= 0, z1 + z2 + z3 = 1} with D = I: z = (1/3, 1/3, 1/3)."""
    A = np.array([[1.0, 1.0, 1.0]])
    b = np.array([1.0])
    cost = np.array([1.0, 1.0, 1.0])
    z, unique = tie_break.least_norm(A, b, cost, np.eye(3), np.array([1.0, 0.0, 0.0]))
    assert not unique
    assert np.allclose(z, 1 / 3, atol=1e-6)
    # a unique optimum stays where the solver put it
    z, unique = tie_break.least_norm(A, b, np.array([1.0, 2.0, 3.0]), np.eye(3), np.array([1.0, 0.0, 0.0]))
    assert unique and np.allclose(z, [1, 0, 0])
    assert LM.tie_note(LM.Solution([], 1.0, 8, 0.0, [], unique=False))
