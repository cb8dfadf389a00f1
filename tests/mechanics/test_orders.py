"""Orders of the shaking force and moment: exact on whole cycles, the in-line slider-crank's
primary and secondary against closed form and independent references, balanced stages at
round-off, and the textbook half-reciprocating counterweight."""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.integrate import quad

from balpipe.loader import load_text
from balpipe.mechanics.orders import nyquist_order, orders_of
from balpipe.study import run


def test_band_limited_signal_exact_on_the_engine_grid():
    """Random harmonics below Nyquist, sampled with both ends included over 3 cycles: every
    amplitude and phase back to round-off, and the rotating components from their definition."""
    rng = np.random.default_rng(7)
    cycles, P, N = 3, 0.37, 3 * 64 + 1
    t = np.linspace(0.0, cycles * P, N)
    w = 2 * math.pi / P
    n = 8
    A = rng.uniform(0.5, 2.0, (n, 3))
    ph = rng.uniform(-math.pi, math.pi, (n, 3))
    sig = np.zeros((N, 3)) + rng.normal(size=3)  # a constant (order 0) is not an order
    for k in range(n):
        sig += A[k] * np.cos((k + 1) * w * t[:, None] + ph[k])
    out = orders_of(t, sig[:, :2], sig[:, 2], cycles, n)
    assert [o.k for o in out] == list(range(1, n + 1)) and out[0].name == "primary" and out[1].name == "secondary"
    for k, o in enumerate(out):
        got = [(o.fx.amplitude, o.fx.phase), (o.fy.amplitude, o.fy.phase), (o.moment.amplitude, o.moment.phase)]
        for j, (a, p) in enumerate(got):
            assert a == pytest.approx(A[k, j], rel=1e-12)
            assert abs(np.angle(np.exp(1j * (p - ph[k, j])))) < 1e-12
        X, Y = A[k, 0] * np.exp(1j * ph[k, 0]), A[k, 1] * np.exp(1j * ph[k, 1])
        # F = Fx + i Fy = F+ e^{ikwt} + F- e^{-ikwt} at every sample
        Fp = o.forward.amplitude * np.exp(1j * o.forward.phase)
        Fm = o.backward.amplitude * np.exp(1j * o.backward.phase)
        kwt = (k + 1) * w * t
        direct = (np.real(X * np.exp(1j * kwt)) + 1j * np.real(Y * np.exp(1j * kwt)))
        assert np.max(np.abs(Fp * np.exp(1j * kwt) + Fm * np.exp(-1j * kwt) - direct)) < 1e-12 * (abs(X) + abs(Y))


def test_orders_stop_below_nyquist_and_refuse_partial_cycles():
    t = np.linspace(0.0, 2.0, 21)  # 20 samples over 2 cycles: Nyquist at order 5, reported up to 4
    assert nyquist_order(20, 2) == 4
    assert len(orders_of(t, np.zeros((21, 2)), np.zeros(21), 2, 50)) == 4
    with pytest.raises(ValueError, match="whole number of cycles"):
        orders_of(t, np.zeros((21, 2)), np.zeros(21), 2.5, 3)


R, L, M_ROT, M_REC, RPM = 0.05, 0.18, 0.8, 0.6, 1500.0
W = RPM * 2 * math.pi / 60


def slider_crank(crank_mass: float, crank_com: float, method: str = "none", cycles: int = 2,
                 samples: int = 801) -> str:
    """An in-line slider-crank, massless rod: rotating mass at the crank pin (or a crank whose
    centre of mass sits elsewhere), reciprocating mass in the slider, at constant speed."""
    balancing = {"none": "  method: none",
                 "force": "  method: slider_crank_counterweights\n  crank_counterweight: -0.05 m\n"
                          "  coupler_counterweight: -0.09 m"}[method]
    return f"""name: in-line slider-crank at constant speed
mechanism:
  template: slider_crank
  offset: 0 m
  crank:   {{length: {R} m, mass: {crank_mass} kg, com: {crank_com} m, inertia: 0.0001 kg m^2}}
  coupler: {{length: {L} m, mass: 0 kg, com: 0.09 m, inertia: 0 kg m^2}}
  slider:  {{mass: {M_REC} kg}}
motion:
  cycles: {cycles}
  drive:
    crank: {{law: constant_speed, speed: {RPM} rpm, from: 0 deg}}
analysis:
  samples: {samples}
balancing:
{balancing}
"""


def study_orders(text: str, n: int = 6):
    spec, _ = load_text(text, "s.yaml")
    study = run(spec, page=False)
    return [orders_of(s.analysis.t, s.analysis.force, s.analysis.moment, spec.motion.cycles, n) for s in study.stages]


def piston_acceleration_coefficient(k: int) -> complex:
    """C_k of the exact piston acceleration x'' (theta = w t), by adaptive quadrature of the
    closed-form second derivative: independent of any DFT."""
    def xdd(th: float) -> float:
        g = math.sqrt(L**2 - (R * math.sin(th)) ** 2)
        s = R**2 * math.sin(th) * math.cos(th)
        return W**2 * (-R * math.cos(th) - R**2 * math.cos(2 * th) / g - s**2 / g**3)
    re = quad(lambda th: xdd(th) * math.cos(k * th), 0, 2 * math.pi, epsabs=1e-12 * R * W**2, epsrel=1e-13, limit=200)[0]
    im = quad(lambda th: -xdd(th) * math.sin(k * th), 0, 2 * math.pi, epsabs=1e-12 * R * W**2, epsrel=1e-13, limit=200)[0]
    return complex(re, im) / math.pi


def test_inline_slider_crank_primary_and_secondary_exact():
    """Primary along the stroke (m_rot + m_rec) r w^2 and across it m_rot r w^2 (closed form,
    exact: the rod's correction has only even orders); secondary m_rec |C_2(x'')| of the exact
    kinematics by quadrature, and close to the series m_rec r w^2 (lambda + lambda^3/4 +
    15 lambda^5/128); all from the engine's force on its grid, to 1e-9."""
    (un,) = study_orders(slider_crank(M_ROT, R))
    p, s = un[0], un[1]
    assert p.fx.amplitude == pytest.approx((M_ROT + M_REC) * R * W**2, rel=1e-9)
    assert p.fy.amplitude == pytest.approx(M_ROT * R * W**2, rel=1e-9)
    for k in (2, 4):
        assert un[k - 1].fx.amplitude == pytest.approx(M_REC * abs(piston_acceleration_coefficient(k)), rel=1e-9)
        assert un[k - 1].fy.amplitude < 1e-9 * p.fx.amplitude  # no vertical motion but the crank pin's
    for k in (3, 5):  # odd orders above the first: none in the exact kinematics
        assert un[k - 1].fx.amplitude < 1e-9 * p.fx.amplitude
    lam = R / L
    series = M_REC * R * W**2 * (lam + lam**3 / 4 + 15 * lam**5 / 128)
    assert s.fx.amplitude == pytest.approx(series, rel=2 * lam**7)  # the next term is 35 lam^7 / 512
    # the shaking force is -dP/dt: the secondary's phase is that of -m_rec x'' at t = 0
    assert abs(np.angle(np.exp(1j * s.fx.phase) / -piston_acceleration_coefficient(2))) < 1e-9
    # forward and backward: the rotating mass turns forward; the stroke splits in halves
    assert p.forward.amplitude == pytest.approx((M_ROT + M_REC / 2) * R * W**2, rel=1e-9)
    assert p.backward.amplitude == pytest.approx(M_REC / 2 * R * W**2, rel=1e-9)


def test_independent_fft_of_the_exact_kinematics():
    """The engine's secondary against numpy's FFT of the closed-form piston acceleration on a
    fine grid of its own (4096 samples per turn)."""
    (un,) = study_orders(slider_crank(M_ROT, R), n=4)
    th = np.linspace(0, 2 * math.pi, 4096, endpoint=False)
    x = R * np.cos(th) + np.sqrt(L**2 - (R * np.sin(th)) ** 2)
    xdd = np.real(np.fft.ifft(np.fft.fft(x) * -(np.fft.fftfreq(4096, 1 / 4096) ** 2))) * W**2
    C = 2 * np.fft.rfft(-M_REC * xdd - M_ROT * -R * W**2 * np.cos(th)) / 4096
    for k in (1, 2, 4):
        assert un[k - 1].fx.amplitude == pytest.approx(abs(C[k]), rel=1e-9)


def test_force_balanced_stage_has_every_order_at_round_off():
    un, bal = study_orders(slider_crank(M_ROT, R, method="force"))
    scale = un[0].fx.amplitude
    assert scale > 100
    for o in bal:
        assert max(o.fx.amplitude, o.fy.amplitude, o.forward.amplitude, o.backward.amplitude) < 1e-10 * scale


def test_half_reciprocating_counterweight_halves_the_primary_and_moves_half_across():
    """A crank counterweight m_rot + m_rec/2 at radius r opposite the pin: primary along the
    stroke m_rec r w^2 / 2 and the same across it (the textbook result); the secondary unchanged."""
    (un,) = study_orders(slider_crank(M_ROT, R))
    m_cw = M_ROT + M_REC / 2
    mass = M_ROT + m_cw
    com = (M_ROT * R - m_cw * R) / mass
    (cw,) = study_orders(slider_crank(mass, com))
    half = M_REC * R * W**2 / 2
    assert cw[0].fx.amplitude == pytest.approx(half, rel=1e-9)
    assert cw[0].fy.amplitude == pytest.approx(half, rel=1e-9)
    assert cw[0].forward.amplitude < 1e-9 * half  # what remains turns backward only
    assert cw[0].backward.amplitude == pytest.approx(half, rel=1e-9)
    assert cw[1].fx.amplitude == pytest.approx(un[1].fx.amplitude, rel=1e-9)


def test_docs_example_runs_and_prints_the_closed_form_primary(capsys):
    from pathlib import Path
    text = (Path(__file__).parents[2] / "docs" / "orders.md").read_text()
    code = text.split("```python\n", 1)[1].split("```", 1)[0]
    namespace: dict = {}
    exec(compile(code, "docs/orders.md", "exec"), namespace)
    w = 3000 * 2 * math.pi / 60
    assert namespace["primary"].fx.amplitude == pytest.approx(0.9 * 0.04 * w**2, rel=1e-9)
    assert f"primary: {0.9 * 0.04 * w**2:.1f} N" in capsys.readouterr().out


def test_results_json_carries_orders_only_for_periodic_motions():
    from balpipe.report.results import results_dict
    spec, _ = load_text(slider_crank(M_ROT, R, cycles=1, samples=201), "s.yaml")
    out = results_dict(run(spec), "s.yaml", "h", simulated=False)
    o = out["orders"][out["stages"][0]["name"]]
    assert o["cycles"] == 1 and o["frequency"] == pytest.approx(RPM / 60, rel=1e-12)
    assert [h["name"] for h in o["orders"][:3]] == ["primary", "secondary", "order 3"]
    assert o["orders"][0]["fx"]["amplitude"] == pytest.approx((M_ROT + M_REC) * R * W**2, rel=1e-9)
    aperiodic = slider_crank(M_ROT, R, samples=201).replace(
        "  cycles: 2\n", "  duration: 0.1 s\n")
    spec, _ = load_text(aperiodic, "s.yaml")
    assert results_dict(run(spec), "s.yaml", "h", simulated=False)["orders"] == {"unbalanced": None}


def test_page_shows_the_orders_table_or_says_there_are_none():
    from balpipe.report.page import render_page
    from balpipe.report.results import results_dict
    for text, periodic in ((slider_crank(M_ROT, R, cycles=1, samples=201), True),
                           (slider_crank(M_ROT, R, samples=201).replace("  cycles: 2\n", "  duration: 0.1 s\n"), False)):
        spec, _ = load_text(text, "s.yaml")
        study = run(spec)
        html = render_page(study, results_dict(study, "s.yaml", "h", simulated=False), text)
        assert ">Orders</h2>" in html
        assert ("primary" in html and "secondary" in html) == periodic
        assert ("have no orders" in html) != periodic
        assert ("peak force of the order" in html) == periodic  # the figure's axis
        section = html.split(">Orders</h2>", 1)[1].split("<h2", 1)[0]
        assert ("of reference)" in section) == periodic  # the odd orders above 1: round-off, shown as 0


def test_v_twin_example_primary_turns_forward_and_its_counterweight_leaves_the_secondary():
    """specs/custom_v_twin_6000rpm.yaml: a 90-degree V's primary force is a constant vector
    turning with the crank (backward component at round-off); the textbook counterweight cancels
    it and leaves the secondary untouched, horizontal (the V's secondary acts across the V's
    axis of symmetry), with no odd orders."""
    from pathlib import Path

    from balpipe.loader import load
    from balpipe.report.orders_table import stage_orders
    spec = load(Path(__file__).parents[2] / "specs" / "custom_v_twin_6000rpm.yaml").spec
    study = run(spec, page=False)
    by = {s.stage.name: stage_orders(spec.motion, s.analysis) for s in study.stages}
    un, tb = by["unbalanced"], by["textbook:primary"]
    scale = un[0].forward.amplitude
    assert un[0].backward.amplitude < 1e-9 * scale
    # the spec writes the textbook counterweight to 6 significant digits (1.37619 kg): 2.8e-7 remains
    assert max(tb[0].fx.amplitude, tb[0].fy.amplitude) < 1e-6 * scale
    assert tb[0].backward.amplitude < 1e-9 * scale  # a crank counterweight only removes a forward vector
    assert tb[1].fx.amplitude == pytest.approx(un[1].fx.amplitude, rel=1e-9) and tb[1].fx.amplitude > 0.1 * scale
    assert un[1].fy.amplitude < 1e-9 * scale and un[2].fx.amplitude + un[2].fy.amplitude < 1e-9 * scale
