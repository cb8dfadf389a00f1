"""Positions in timeseries.csv (issue 20, item 6) against independent computations: the centre
of mass from the bodies' poses and masses, its velocity and acceleration from finite
differences (M a_G = minus the shaking force without gravity), the named points where the
joints make them coincide, their velocities from finite differences."""

from __future__ import annotations

import io
import math
from pathlib import Path

import balpipe  # noqa: F401
import numpy as np
import pytest
from conftest import slider_crank_spec

from balpipe.loader import load
from balpipe.report.results import timeseries_csv
from balpipe.study import run

ROOT = Path(__file__).resolve().parents[2]


def table(study) -> dict[str, np.ndarray]:
    """The CSV's columns, and every stage's pose and point columns that the CSV writes once,
    under an earlier stage's name (the same motion), read from there."""
    text = timeseries_csv(study)
    head = text.splitlines()[0].split(",")
    data = np.loadtxt(io.StringIO(text), delimiter=",", skiprows=1)
    cols = {h: data[:, k] for k, h in enumerate(head)}
    names = [s.stage.name for s in study.stages]
    for h in list(cols):
        stage, rest = h.split(".", 1) if "." in h else ("", "")
        if rest.startswith(("pose.", "point.")):
            for later in names[names.index(stage) + 1:]:
                cols.setdefault(f"{later}.{rest}", cols[h])
    return cols


def test_a_shared_motion_is_written_once():
    """Stages whose bodies move alike (the counterweights change the masses, not the motion)
    share their pose and point columns: written under the first stage's name only, the centre
    of mass (which the counterweights move) per stage."""
    study = run(load(ROOT / "specs" / "custom_stephenson_six_bar_120rpm.yaml").spec)
    head = timeseries_csv(study).splitlines()[0].split(",")
    first, second = study.stages[0].stage.name, study.stages[1].stage.name
    assert f"{first}.pose.crank.x_m" in head and f"{second}.pose.crank.x_m" not in head
    assert f"{first}.com.x_m" in head and f"{second}.com.x_m" in head
    assert len(head) == len(set(head))


def check_stage(cols: dict, t: np.ndarray, sr, gravity_free: bool) -> None:
    n, model = sr.stage.name, sr.stage.model
    M = model.total_mass()
    # the centre of mass from the bodies' frame poses, each body's own centre and mass
    G = np.zeros((len(t), 2))
    for b in model.bodies:
        m, (cx, cy), _ = b.mass_properties()
        x, y, th = (cols[f"{n}.pose.{b.name}.{c}"] for c in ("x_m", "y_m", "angle_rad"))
        G[:, 0] += m * (x + np.cos(th) * cx - np.sin(th) * cy)
        G[:, 1] += m * (y + np.sin(th) * cx + np.cos(th) * cy)
    G /= M
    scale = max(1.0, float(np.max(np.abs(G))))
    assert np.max(np.abs(G[:, 0] - cols[f"{n}.com.x_m"])) < 1e-10 * scale
    assert np.max(np.abs(G[:, 1] - cols[f"{n}.com.y_m"])) < 1e-10 * scale
    h = t[1] - t[0]
    inner = slice(2, -2)
    for c in ("x", "y"):
        v = cols[f"{n}.com.v{c}_m_s"]
        fd = np.gradient(cols[f"{n}.com.{c}_m"], h)
        assert np.max(np.abs(fd - v)[inner]) < 2e-3 * max(np.max(np.abs(v)), 1e-9) + 1e-9
        if gravity_free:  # M a_G = -F (the shaking force is minus the momentum's rate)
            F = cols[f"{n}.F{c}_N"]
            a = np.gradient(v, h)
            assert np.max(np.abs(M * a + F)[inner]) < 5e-3 * max(np.max(np.abs(F)), 1e-9) + 1e-6
    # every point's velocity is the time derivative of its path; the frame origins' too
    for b in model.bodies:
        for key in [f"pose.{b.name}"] + [f"point.{b.name}.{p}" for p in b.points]:
            for c in ("x", "y"):
                v = cols[f"{n}.{key}.v{c}_m_s"]
                fd = np.gradient(cols[f"{n}.{key}.{c}_m"], h)
                assert np.max(np.abs(fd - v)[inner]) < 2e-3 * max(np.max(np.abs(v)), 1e-9) + 1e-9, (key, c)


def test_six_bar_positions_and_centre_of_mass():
    study = run(load(ROOT / "specs" / "custom_stephenson_six_bar_120rpm.yaml").spec)
    cols = table(study)
    t = cols["t_s"]
    for sr in study.stages:
        check_stage(cols, t, sr, gravity_free=True)
    # the joints make their points coincide: C of the coupler and of the connector, D of both
    for a, b in (("coupler.C", "connector.C"), ("connector.D", "lever.D"), ("crank.A", "coupler.A")):
        for c in ("x_m", "y_m", "vx_m_s", "vy_m_s"):
            assert np.allclose(cols[f"unbalanced.point.{a}.{c}"], cols[f"unbalanced.point.{b}.{c}"], atol=1e-9)
    # the pivot on the frame stays put, the crank turns at 120 rpm
    assert np.allclose(cols["unbalanced.point.crank.A0.x_m"], 0, atol=1e-12)
    assert np.allclose(cols["unbalanced.pose.crank.omega_rad_s"], 4 * math.pi)
    # force balanced: the centre of mass stands still
    G = cols["counterweights.com.x_m"], cols["counterweights.com.y_m"]
    assert np.ptp(G[0]) < 1e-9 and np.ptp(G[1]) < 1e-9 and np.max(np.abs(cols["counterweights.com.vx_m_s"])) < 1e-9


@pytest.mark.parametrize("seed", range(3))
def test_random_slider_cranks(seed):
    spec = slider_crank_spec(np.random.default_rng(seed), analysis={"samples": 801})
    study = run(spec)
    cols = table(study)
    for sr in study.stages:
        check_stage(cols, cols["t_s"], sr, gravity_free=True)


def test_with_gravity_the_weight_stays_out_of_the_centre_of_mass():
    spec = slider_crank_spec(np.random.default_rng(7), gravity=True, analysis={"samples": 801, "gravity": True})
    study = run(spec)
    cols = table(study)
    for sr in study.stages:
        check_stage(cols, cols["t_s"], sr, gravity_free=False)
