"""The planar vocabulary (balpipe.mechanics.planar): cross, rotate, wrap_angle, world_point and
the bar body, checked against their definitions on random inputs, and defined nowhere else."""

from __future__ import annotations

import ast
import math
from pathlib import Path

import numpy as np
import pytest

from balpipe.mechanics.planar import bar_body, cross, rotate, world_point, wrap_angle
from balpipe.spec_parts import LinkSpec

PACKAGE = Path(__file__).resolve().parents[2] / "pipeline" / "balpipe"
RNG = np.random.default_rng(37)


def test_cross_is_the_z_of_the_3d_cross_product():
    u, w = RNG.normal(size=(50, 2)), RNG.normal(size=(50, 2))
    z = np.cross(np.pad(u, ((0, 0), (0, 1))), np.pad(w, ((0, 0), (0, 1))))[:, 2]
    assert np.allclose(cross(u, w), z, rtol=1e-14, atol=1e-14)
    assert np.array_equal(cross(u, w), -cross(w, u))
    assert np.array_equal(cross(u, u), np.zeros(50))


@pytest.mark.parametrize("theta_shape, s_shape", [((40,), (2,)), ((40, 3), (3, 2)), ((40, 1), (40, 3, 2)), ((), (2,))])
def test_rotate_is_the_rotation_matrix_broadcast(theta_shape, s_shape):
    theta, s = RNG.uniform(-7, 7, size=theta_shape), RNG.normal(size=s_shape)
    out = rotate(theta, s)
    th = np.broadcast_to(theta, out.shape[:-1])
    A = np.stack([np.stack([np.cos(th), -np.sin(th)], -1), np.stack([np.sin(th), np.cos(th)], -1)], -2)
    assert np.allclose(out, np.einsum("...ij,...j->...i", A, np.broadcast_to(s, out.shape)), rtol=1e-13, atol=1e-13)
    assert np.allclose(np.linalg.norm(out, axis=-1), np.linalg.norm(np.broadcast_to(s, out.shape), axis=-1))


def test_rotate_composes_and_inverts():
    a, b, s = RNG.uniform(-4, 4, 30), RNG.uniform(-4, 4, 30), RNG.normal(size=(30, 2))
    assert np.allclose(rotate(a, rotate(b, s)), rotate(a + b, s), atol=1e-13)
    assert np.allclose(rotate(-a, rotate(a, s)), s, atol=1e-13)


def test_wrap_angle_gives_the_shorter_rotation():
    a = RNG.uniform(-50, 50, 1000)
    w = wrap_angle(a)
    assert np.all(w > -np.pi) and np.all(w <= np.pi)
    assert np.allclose(np.round((a - w) / (2 * np.pi)), (a - w) / (2 * np.pi), atol=1e-9)
    assert wrap_angle(math.pi) == math.pi and wrap_angle(-math.pi) == math.pi
    for x in a[:20]:
        y = wrap_angle(float(x))
        assert type(y) is float and y == float(wrap_angle(np.array([x]))[0])


def test_world_point_one_pose_and_many_agree():
    poses, p = RNG.normal(size=(25, 3)), tuple(RNG.normal(size=2))
    many = world_point(poses, p)
    one = np.array([world_point(tuple(map(float, q)), p) for q in poses])
    assert many.shape == (25, 2)
    assert np.allclose(many, one, rtol=1e-15, atol=1e-15)
    assert np.allclose(many, poses[:, :2] + rotate(poses[:, 2], np.array(p)), atol=1e-14)


def test_bar_body_puts_its_ends_on_the_x_axis():
    link = LinkSpec(length=0.3, mass=1.2, com=0.1, com_offset=0.02, inertia=0.01)
    b = bar_body("crank", link, "A", "B", link.length)
    assert b.points == {"A": (0.0, 0.0), "B": (0.3, 0.0)} and b.outline == ("A", "B")
    assert (b.mass, b.com, b.inertia, b.attachments, b.kind) == (1.2, (0.1, 0.02), 0.01, (), "link")


COPIES = {"cross", "_cross", "rotate", "_rotate", "_rotate_all", "_wrap", "wrap_angle", "_link", "_link_body",
          "_global_point", "_to_global"}


def test_the_vocabulary_is_defined_once():
    found = []
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "planar.py" and path.parent.name == "mechanics":
            continue
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if isinstance(node, ast.FunctionDef) and node.name in COPIES:
                found.append(f"{path.relative_to(PACKAGE)}:{node.lineno}: def {node.name}")
            if isinstance(node, ast.Assign) and isinstance(node.value, ast.Lambda):
                found += [f"{path.relative_to(PACKAGE)}:{node.lineno}: {t.id} = lambda" for t in node.targets
                          if isinstance(t, ast.Name) and t.id in COPIES]
    assert not found, "\n".join(found)
