"""The frame on elastic mounts: the textbook transmissibility and its phase, the equations of
motion in the time domain against an independent closed-form solution, natural frequencies of a
symmetric frame against closed form, random frames and loads, balanced stages at round-off and
the scaling of the floor forces with the mechanism's masses."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from balpipe.loader import SpecErrors, load_text
from balpipe.mechanics.mounts import Frame, Mount, modes, periodic_response, transient_response
from balpipe.report.frame_mounts import mounts_json, near_resonance
from balpipe.study import run

ROOT = Path(__file__).resolve().parents[2]


def x_isolator(m: float, k: float, c: float) -> Frame:
    """One spring-damper along x at the centre of mass, and two mounts along y only (at +-a on
    the line of the centre of mass) that hold y and rotation without touching x: x is a single
    degree of freedom m x'' + c x' + k x = F_x."""
    return Frame(m, 0.7 * m, (0.1, -0.2), (
        Mount("x", (0.1, -0.2), k, 0.0, c, 0.0),
        Mount("left", (-0.4, -0.2), 0.0, 3 * k, 0.0, 0.1 * c),
        Mount("right", (0.6, -0.2), 0.0, 3 * k, 0.0, 0.1 * c)))


@pytest.mark.parametrize("r, zeta", [(0.3, 0.05), (1.0, 0.1), (1.41421356, 0.2), (2.5, 0.02), (7.0, 0.3)])
def test_textbook_transmissibility_and_phase(r, zeta):
    """TR = sqrt(1 + (2 zeta r)^2) / sqrt((1 - r^2)^2 + (2 zeta r)^2) and the transmitted force's
    lag atan2(2 zeta r^3, 1 - r^2 + 4 zeta^2 r^2), from the orders of a harmonic force sampled as
    the engine samples it (both ends of 3 cycles), to 1e-9."""
    m, k = 12.0, 4.0e4
    wn = math.sqrt(k / m)
    c = 2 * zeta * m * wn
    frame = x_isolator(m, k, c)
    w = r * wn
    F0, phase0 = 250.0, 0.4
    t = np.linspace(0.0, 3 * 2 * math.pi / w, 3 * 64 + 1)
    Q = np.zeros((len(t), 3))
    Q[:, 0] = F0 * np.cos(w * t + phase0)
    resp = periodic_response(frame, t, Q, 3)
    f = resp.mount_forces(frame)[0, :, 0]  # the x mount on the floor
    C = 2 * np.fft.rfft(f)[3] / len(f)  # its order-1 complex amplitude
    TR = math.sqrt(1 + (2 * zeta * r) ** 2) / math.sqrt((1 - r**2) ** 2 + (2 * zeta * r) ** 2)
    lag = math.atan2(2 * zeta * r**3, 1 - r**2 + 4 * zeta**2 * r**2)
    assert abs(C) / F0 == pytest.approx(TR, rel=1e-9)
    assert abs(np.angle(C / (F0 * np.exp(1j * phase0))) + lag) < 1e-9
    # the RMS of a harmonic is its amplitude over sqrt 2; the peak is the amplitude
    assert resp.rms(f) == pytest.approx(TR * F0 / math.sqrt(2), rel=1e-9)
    # and the frame's velocity amplitude: F0 w / |k - m w^2 + i w c|
    v = resp.point_velocity(frame, frame.com)[:, 0]
    assert resp.rms(v) * math.sqrt(2) == pytest.approx(F0 * w / abs(k - m * w**2 + 1j * w * c), rel=1e-9)


def random_frame(rng: np.random.Generator, mounts: int = 3) -> Frame:
    m = rng.uniform(5, 500)
    return Frame(m, m * rng.uniform(0.01, 0.5), tuple(rng.uniform(-0.3, 0.3, 2)), tuple(
        Mount(f"m{i}", tuple(rng.uniform(-0.8, 0.8, 2)), rng.uniform(1e4, 1e6), rng.uniform(1e4, 1e6),
              rng.uniform(10, 3000), rng.uniform(10, 3000)) for i in range(mounts)))


def modal_solution(frame: Frame, t: np.ndarray, Q: np.ndarray, taus: np.ndarray):
    """An independent exact solution of M q'' + C q' + K q = Q(t) - Q(t_0) from rest, the load
    linear between samples: the complex modes of the state matrix, each driven by a linear
    forcing in closed form, y(tau) = e^{l tau} (y0 - alpha) + alpha + beta tau. Returns the
    samples of q, q' and, at the fractions ``taus`` of every step, q, q', q'' (q'' the closed
    form's own derivative, not the equations of motion) and the load there."""
    M, K, C = frame.mass_matrix(), frame.stiffness_matrix(), frame.damping_matrix()
    Mi = np.linalg.inv(M)
    A = np.block([[np.zeros((3, 3)), np.eye(3)], [-Mi @ K, -Mi @ C]])
    B = np.vstack([np.zeros((3, 3)), Mi])
    lam, V = np.linalg.eig(A)
    Vi = np.linalg.inv(V)
    dQ = Q - Q[0]
    y = np.zeros(6, complex)
    samples = [np.zeros(6)]
    inner = []
    for i in range(len(t) - 1):
        h = t[i + 1] - t[i]
        g0, g1 = Vi @ B @ dQ[i], Vi @ B @ ((dQ[i + 1] - dQ[i]) / h)
        beta = -g1 / lam
        alpha = (beta - g0) / lam
        for s in taus:
            tau = s * h
            z = V @ (np.exp(lam * tau) * (y - alpha) + alpha + beta * tau)
            zd = V @ (lam * np.exp(lam * tau) * (y - alpha) + beta)
            inner.append((np.real(z[:3]), np.real(z[3:]), np.real(zd[3:]), dQ[i] + (dQ[i + 1] - dQ[i]) * s))
        y = np.exp(lam * h) * (y - alpha) + alpha + beta * h
        samples.append(np.real(V @ y))
    return np.array(samples), inner


def test_time_domain_is_exact_for_the_piecewise_linear_load():
    """Random frames, random loads on a uniform grid: the state-transition's samples equal an
    independent modal closed form to 1e-9, and inside every step that closed form satisfies
    M q'' + C q' + K q = Q to 1e-9; at the samples, the floor forces and the load satisfy the
    frame's Newton-Euler equations M q'' = Q - sum G^T f to 1e-9."""
    rng = np.random.default_rng(11)
    for _ in range(4):
        frame = random_frame(rng, int(rng.integers(2, 5)))
        t = np.linspace(0.0, rng.uniform(0.05, 0.5), 201)
        Q = np.column_stack([rng.normal(0, 500, len(t)).cumsum(), rng.normal(0, 500, len(t)).cumsum(),
                             rng.normal(0, 50, len(t)).cumsum()])
        resp = transient_response(frame, t, Q)
        z, inner = modal_solution(frame, t, Q, np.array([0.0, 0.37, 0.81]))
        qs, vs = np.max(np.abs(z[:, :3]), axis=0), np.max(np.abs(z[:, 3:]), axis=0)
        assert np.all(np.abs(resp.q - z[:, :3]) <= 1e-9 * qs)
        assert np.all(np.abs(resp.v - z[:, 3:]) <= 1e-9 * vs)
        M, K, C = frame.mass_matrix(), frame.stiffness_matrix(), frame.damping_matrix()
        scale = np.max(np.abs(Q - Q[0]), axis=0)
        for q, v, a, load in inner:
            assert np.all(np.abs(M @ a + C @ v + K @ q - load) <= 1e-9 * scale)
        # at the samples: the closed form's own acceleration, the integrator's floor forces
        a_samples = np.array([a for k, (_, _, a, _) in enumerate(inner) if k % 3 == 0])
        f = resp.mount_forces(frame)
        held = sum(np.einsum("ij,nj->ni", frame.jacobian(m.at).T, f[j]) for j, m in enumerate(frame.mounts))
        residual = (Q - Q[0])[:-1] - held[:-1] - a_samples @ M.T
        assert np.all(np.abs(residual) <= 1e-9 * scale)


def test_time_domain_holds_a_constant_load_still():
    """A constant load is a static deflection: no motion, no change of the floor forces."""
    frame = random_frame(np.random.default_rng(2))
    t = np.linspace(0.0, 0.2, 51)
    resp = transient_response(frame, t, np.tile([300.0, -200.0, 15.0], (51, 1)))
    assert np.max(np.abs(resp.q)) == 0 and np.max(np.abs(resp.mount_forces(frame))) == 0


def test_periodic_response_satisfies_the_equations_of_motion():
    """Random frames and random band-limited periodic loads (below the Nyquist order, with a
    constant): at every sample M q'' + C q' + K q equals the load less its mean to 1e-9, the
    time average of |f|^2 is the sum of the orders' (Parseval), and the frame's Newton-Euler
    equations hold with the floor forces."""
    rng = np.random.default_rng(5)
    for _ in range(5):
        frame = random_frame(rng)
        cycles, P = int(rng.integers(1, 4)), rng.uniform(0.01, 1.0)
        N = cycles * 96 + 1
        t = np.linspace(0.0, cycles * P, N)
        Q = np.zeros((N, 3)) + rng.normal(0, 100, 3)
        for k in range(1, 12):
            Q += rng.normal(0, 100, 3) * np.cos(2 * math.pi * k * t[:, None] / P + rng.uniform(0, 6, 3))
        r = periodic_response(frame, t, Q, cycles)
        M, K, C = frame.mass_matrix(), frame.stiffness_matrix(), frame.damping_matrix()
        load = Q[:-1] - Q[:-1].mean(axis=0)
        scale = np.max(np.abs(load), axis=0)
        assert np.all(np.abs(r.a @ M.T + r.v @ C.T + r.q @ K.T - load) <= 1e-9 * scale)
        f = r.mount_forces(frame)
        held = sum(np.einsum("ij,nj->ni", frame.jacobian(m.at).T, f[j]) for j, m in enumerate(frame.mounts))
        assert np.all(np.abs(load - held - r.a @ M.T) <= 1e-9 * scale)
        assert r.method == "orders" and r.orders == 47  # 96 samples per cycle: orders 1..47


def test_natural_frequencies_of_a_symmetric_two_mount_frame():
    """Two equal mounts at (+-a, -h) from the centre of mass: bounce at sqrt(2 ky / m); sway and
    rock coupled through h, the roots of (2 kx - w^2 m)(2 kx h^2 + 2 ky a^2 - w^2 J) = (2 kx h)^2;
    with h = 0 they part into sqrt(2 kx / m) and sqrt(2 ky a^2 / J). Random parameters."""
    rng = np.random.default_rng(3)
    for h_zero in (False, True, False, False):
        m, J = rng.uniform(10, 300), rng.uniform(0.5, 40)
        a, h = rng.uniform(0.1, 0.6), 0.0 if h_zero else rng.uniform(0.05, 0.4)
        kx, ky = rng.uniform(1e4, 1e6), rng.uniform(1e4, 1e6)
        cx, cy = rng.uniform(0, 500), rng.uniform(0, 500)
        c = tuple(rng.uniform(-1, 1, 2))
        frame = Frame(m, J, c, (Mount("r", (c[0] + a, c[1] - h), kx, ky, cx, cy),
                                Mount("l", (c[0] - a, c[1] - h), kx, ky, cx, cy)))
        got = sorted(md.frequency * 2 * math.pi for md in modes(frame))
        # the quadratic in w^2 of the coupled sway and rock
        A2, B2 = m * J, -(2 * kx * J + (2 * kx * h**2 + 2 * ky * a**2) * m)
        C2 = 2 * kx * (2 * kx * h**2 + 2 * ky * a**2) - (2 * kx * h) ** 2
        disc = math.sqrt(B2**2 - 4 * A2 * C2)
        expected = sorted([math.sqrt(2 * ky / m), math.sqrt((-B2 - disc) / (2 * A2)), math.sqrt((-B2 + disc) / (2 * A2))])
        if h_zero:
            assert sorted(expected) == pytest.approx(sorted([math.sqrt(2 * ky / m), math.sqrt(2 * kx / m),
                                                             math.sqrt(2 * ky * a**2 / J)]), rel=1e-12)
        assert got == pytest.approx(expected, rel=1e-9)
        bounce = min(modes(frame), key=lambda md: abs(md.frequency * 2 * math.pi - math.sqrt(2 * ky / m)))
        assert bounce.direction(frame) == (0.0, 1.0, 0.0)  # round-off of the decoupled motions is 0
        assert bounce.damping_ratio == pytest.approx(2 * cy / (2 * math.sqrt(2 * ky * m)), rel=1e-9)


def test_near_resonance_names_the_orders_inside_the_band():
    """An order within the band of a natural frequency is named, one outside is not."""
    frame = Frame(10.0, 1.0, (0.0, 0.0), (Mount("a", (0.5, 0.0), 1e4, 1e4), Mount("b", (-0.5, 0.0), 1e4, 1e4)))
    f = sorted(md.frequency for md in modes(frame))
    hits = near_resonance(frame, f[0] / 3 * 1.19, 0.2)  # order 3 at 1.19 f1: inside
    assert any(h["order"] == 3 and h["mode"] == 1 for h in hits)
    assert not any(h["mode"] == 1 and h["order"] == 3 for h in near_resonance(frame, f[0] / 3 * 1.21, 0.2))
    assert near_resonance(frame, None, 0.2) == []


FRAME = """
frame:
  mass: 80 kg
  inertia: 6 kg m^2
  com: [0.1, -0.05]
  mounts:
    - {at: [-0.3, -0.2], kx: 120 kN/m, ky: 200 kN/m, cx: 300 N s/m, cy: 500 N s/m}
    - {at: [0.5, -0.2], kx: 120 kN/m, ky: 200 kN/m, cx: 300 N s/m, cy: 500 N s/m}
  points: [{name: top, at: [0.1, 0.3]}]
  limits: {velocity_rms: 1 mm/s, force_peak: 300 N}
"""


def four_bar(periodic: bool) -> str:
    text = (ROOT / "specs" / "custom_four_bar_balancing.yaml").read_text(encoding="utf-8")
    if periodic:
        text = text.replace("""  law: quintic
  duration: 0.5 s
  drive:
    crank: {from: 0 deg, to: 360 deg}""", """  cycles: 1
  drive:
    crank: {law: constant_speed, speed: 120 rpm, from: 0 deg}""")
    return text + FRAME


@pytest.mark.parametrize("periodic", [True, False])
def test_a_balanced_stage_transmits_round_off(periodic):
    """The four-bar's complete force and moment balance: floor forces and velocities at
    round-off of the unbalanced ones, by orders and in the time domain; the force-only balance
    still rocks the frame with its shaking moment."""
    spec, _ = load_text(four_bar(periodic), "s.yaml")
    out = mounts_json(run(spec, page=False))
    assert out["method"] == ("orders" if periodic else "time")
    un, bal, force_only = out["stages"]["unbalanced"], out["stages"]["counter_rotations"], out["stages"]["force_only:counterweights"]
    for a, b in zip(un["mounts"], bal["mounts"]):
        assert b["peak"] <= 1e-9 * a["peak"] and b["rms"] <= 1e-9 * a["rms"]
    for a, b in zip(un["velocity"], bal["velocity"]):
        assert b["rms"] <= 1e-9 * a["rms"]
    assert all(c["verdict"] == "within limit" for c in bal["limits"])
    assert max(m["peak"] for m in force_only["mounts"]) > 1e-3 * max(m["peak"] for m in un["mounts"])
    assert [v["name"] for v in un["velocity"]] == ["com", "mount1", "mount2", "top"]


def scaled(text: str, k: float) -> str:
    """The four-bar with every link's mass and inertia times k (the frame unchanged)."""
    import re
    head, frame = text.split("\nframe:")
    head = re.sub(r"(mass|inertia): ([0-9.e+-]+) (kg m\^2|kg)", lambda m: f"{m.group(1)}: {float(m.group(2)) * k!r} {m.group(3)}", head)
    return head + "\nframe:" + frame


@pytest.mark.parametrize("periodic", [True, False])
def test_masses_times_k_scale_the_floor_forces_by_k(periodic):
    """Every mass and inertia of the mechanism times k (counterweights follow): the frame's
    loads, floor forces and velocities times k, to 1e-9; the modes do not move."""
    k = 2.75
    base = four_bar(periodic)
    a = mounts_json(run(load_text(base, "s.yaml")[0], page=False))
    b = mounts_json(run(load_text(scaled(base, k), "s.yaml")[0], page=False))
    assert b["modes"] == a["modes"]
    for name in ("unbalanced", "force_only:counterweights"):
        for x, y in zip(a["stages"][name]["mounts"], b["stages"][name]["mounts"]):
            assert y["peak"] == pytest.approx(k * x["peak"], rel=1e-9) and y["rms"] == pytest.approx(k * x["rms"], rel=1e-9)
        for x, y in zip(a["stages"][name]["velocity"], b["stages"][name]["velocity"]):
            assert y["rms_x"] == pytest.approx(k * x["rms_x"], rel=1e-9)


def test_limits_are_judged_and_verdicts_worded():
    spec, _ = load_text(four_bar(True), "s.yaml")
    out = mounts_json(run(spec, page=False))
    un = out["stages"]["unbalanced"]
    worst = max(max(p["rms_x"], p["rms_y"]) for p in un["velocity"])
    (v,) = [c for c in un["limits"] if c["quantity"] == "velocity_rms"]
    assert v["value"] == worst and v["limit"] == pytest.approx(1e-3)
    assert worst > 1e-3 and v["verdict"] == "exceeds"
    (f,) = [c for c in un["limits"] if c["quantity"] == "force_peak"]
    assert f["value"] == max(m["peak"] for m in un["mounts"])


def test_mounts_that_do_not_hold_the_frame_are_a_located_error():
    text = four_bar(True).replace("kx: 120 kN/m", "kx: 0 N/m")
    with pytest.raises(SpecErrors) as exc:
        load_text(text, "s.yaml")
    (e,) = [str(x) for x in exc.value.errors]
    assert e.startswith("s.yaml:") and "frame" in e and "free to move along x" in e
    dup = four_bar(True).replace("points: [{name: top", "points: [{name: mount1")
    with pytest.raises(SpecErrors, match="mount1 used twice"):
        load_text(dup, "s.yaml")


def test_a_spec_without_frame_has_no_mounts_in_results():
    from balpipe.report.results import results_dict
    spec, _ = load_text(four_bar(True).split("\nframe:")[0] + "\n", "s.yaml")
    out = results_dict(run(spec, page=False), "s.yaml", "h", simulated=False)
    assert "mounts" not in out


def test_docs_example_runs_in_the_time_domain(capsys):
    text = (ROOT / "docs" / "mounts.md").read_text(encoding="utf-8")
    code = text.split("```python\n", 1)[1].split("```", 1)[0]
    namespace: dict = {}
    exec(compile(code, "docs/mounts.md", "exec"), namespace)
    mounts = namespace["mounts"]
    assert mounts["method"] == "time" and mounts["frequency"] is None and mounts["near_resonance"] == []
    out = capsys.readouterr().out
    assert "natural frequencies:" in out and "mount1: peak" in out and "velocity at" in out
    assert all(m["peak"] > 0 for m in mounts["stages"]["unbalanced"]["mounts"])


def test_v_twin_example_on_its_mounts():
    """specs/custom_v_twin_6000rpm.yaml as docs/mounts.md describes it: modes between 10 and 23
    Hz, none near an order of 100 Hz; the primary balance cuts the floor forces more than twenty
    times and meets the spec's velocity limit, the unbalanced engine does not; the complete force
    balance's shaking moment rocks the block (floor forces over seven times the primary
    balance's)."""
    from balpipe.loader import load
    spec = load(ROOT / "specs" / "custom_v_twin_6000rpm.yaml").spec
    out = mounts_json(run(spec, page=False))
    freqs = [m["frequency"] for m in out["modes"]]
    assert 10 < min(freqs) and max(freqs) < 23 and out["near_resonance"] == [] and out["frequency"] == pytest.approx(100)
    rms = {name: max(m["rms"] for m in s["mounts"]) for name, s in out["stages"].items()}
    assert rms["unbalanced"] > 20 * rms["textbook:primary"]
    assert rms["complete:counterweights"] > 7 * rms["textbook:primary"]
    verdict = {name: s["limits"][0]["verdict"] for name, s in out["stages"].items()}
    assert verdict["unbalanced"] == "exceeds" and verdict["textbook:primary"] == "within limit"
    assert max(max(p["rms_x"], p["rms_y"]) for p in out["stages"]["unbalanced"]["velocity"]) > 0.4


def test_page_shows_the_frame_on_its_mounts_only_with_a_frame():
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict
    for text, framed in ((four_bar(True), True), (four_bar(True).split("\nframe:")[0] + "\n", False)):
        spec, _ = load_text(text, "s.yaml")
        study = run(spec)
        html = render_page(study, results_dict(study, "s.yaml", "h", simulated=False), text)
        assert ("The frame on its mounts</h2>" in html) == framed
        if framed:
            assert "What balancing did to the floor" in html and "Natural modes" in html
            assert "exceeds: " in html and " mm/s vs 1 mm/s" in html and "within limit" in html
            assert "1.61e-12" not in html  # the balanced stage's velocity is round-off, shown as 0
            assert "Near resonance</strong>" in html and "order 4 (8 Hz) near mode 1 (8.263 Hz)" in html


def test_external_loads_reach_the_mounts_through_the_frame_load():
    """The pumpjack's well load is external: the frame feels the shaking loads plus it (the
    frame load), and so do its mounts; the shaking loads alone would give other floor forces."""
    from balpipe.loader import load
    from balpipe.report.frame_mounts import stage_json
    spec = load(ROOT / "specs" / "custom_pumpjack_rod_load.yaml").spec
    framed, _ = load_text((ROOT / "specs" / "custom_pumpjack_rod_load.yaml").read_text(encoding="utf-8") + FRAME,
                          str(ROOT / "specs" / "custom_pumpjack_rod_load.yaml"))
    study = run(spec, page=False)
    an = study.unbalanced.analysis
    frame = framed.frame.model()
    got = stage_json(framed, an)
    assert got["method"] == "time"
    for source, same in ((an.frame_load, True), ((an.force, an.moment), False)):
        r = transient_response(frame, an.t, frame.load_about_com(*source, tuple(an.moment_point)))
        peaks = [float(np.max(np.linalg.norm(f, axis=1))) for f in r.mount_forces(frame)]
        assert (peaks == [m["peak"] for m in got["mounts"]]) == same
    assert np.max(np.abs(an.frame_load[0] - an.force)) > 0.1 * np.max(np.abs(an.force))


def test_the_moment_point_does_not_move_the_frame():
    """The frame load's moment is moved to the frame's centre of mass: another
    analysis.moment_point gives the same floor forces and velocities (to 1e-9), by orders and in
    the time domain."""
    for periodic in (True, False):
        text = four_bar(periodic)
        a = mounts_json(run(load_text(text, "s.yaml")[0], page=False))
        moved = text.replace("\nanalysis:\n", "\nanalysis:\n  moment_point: [0.7, -0.4]\n", 1)
        assert moved != text
        b = mounts_json(run(load_text(moved, "s.yaml")[0], page=False))
        for name, s in a["stages"].items():
            for x, y in zip(s["mounts"], b["stages"][name]["mounts"]):
                assert y["peak"] == pytest.approx(x["peak"], rel=1e-9, abs=1e-9 * a["stages"]["unbalanced"]["mounts"][0]["peak"])
            for x, y in zip(s["velocity"], b["stages"][name]["velocity"]):
                assert y["rms"] == pytest.approx(x["rms"], rel=1e-9, abs=1e-9 * a["stages"]["unbalanced"]["velocity"][0]["rms"])


def test_mounts_section_reads_in_the_pages_display_units():
    """``report.units: engineering``: the frame's mass, position, floor forces and limits on the
    page in the chosen units (kN, mm), the same numbers as the SI page scaled; results.json stays SI."""
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict
    pages = {}
    for units in ("SI", "engineering"):
        text = four_bar(True).replace("force_peak: 300 N", "force_peak: 2 N") + f"report:\n  units: {units}\n"
        spec, _ = load_text(text, "s.yaml")
        study = run(spec)
        results = results_dict(study, "s.yaml", "h", simulated=False)
        html = render_page(study, results, text)
        pages[units] = html.split("The frame on its mounts</h2>")[1].split("<h3>Natural modes</h3>")[0]
        assert results["mounts"]["frame"]["com"] == [0.1, -0.05]
    si, eng = pages["SI"], pages["engineering"]
    assert "centre of mass at (0.1, -0.05) m)" in si and "centre of mass at (100, -50) mm)" in eng
    assert "<th>peak (N)</th>" in si and "<th>peak (kN)</th>" in eng and "(N)</th>" not in eng
    assert "(0.1, 0.3) m</td>" in si and "(100, 300) mm</td>" in eng
    assert " N vs 2 N" in si and " kN vs 0.002 kN" in eng
    assert "RMS force on the floor (N)" in si and "RMS force on the floor (kN)" in eng  # the figure's axis too
