"""Balancing against the loads: partial_balance's efforts, joint and frame loads count the spec's
applied loads, so a pumpjack's crank counterbalance is chosen for the least peak or RMS net
gearbox torque under its rod load; checked against a re-analysis and against references solved
here (scipy's linear programme, numpy's least squares) on the counterweight's own torque."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from scipy.optimize import linprog

from balpipe import registry, study
from balpipe.balancing.partial import method as P
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.spec_parts import SpecFieldError

SPECS = Path(__file__).resolve().parents[2] / "specs"
PUMPJACK = SPECS / "custom_pumpjack_rod_load_partial.yaml"


def _pumpjack(objective=None, budget=None):
    spec = load(PUMPJACK).spec
    b = spec.balancing
    if objective is not None:
        b = b.model_copy(update={"objective": [b.objective[0].model_copy(update={"measure": objective})]})
    if budget is not None:
        b = b.model_copy(update={"budget": b.budget.model_copy(update={"mass": budget})})
    return spec.model_copy(update={"balancing": b})


def _unbalanced(spec):
    model = registry.unbalanced_model(spec)
    t = registry.time_grid(spec)
    return model, t, analyse(model, t, (0.0, -spec.analysis.g) if spec.analysis.gravity else (0.0, 0.0))


def _counterweight_torque(spec, t):
    """The crank torque a point mass on the crank adds per unit first moment (s_x, s_y in the
    crank's axes) at constant crank speed: its weight's moment about the crankshaft, g (cos th s_x
    - sin th s_y) (a crank-fixed mass turning at constant speed needs no torque to turn)."""
    model, t, an = _unbalanced(spec)
    k = [b.name for b in model.bodies].index("crank")
    th = an.q[:, k, 2]
    g = spec.analysis.g
    return g * np.stack([np.cos(th), -np.sin(th)], axis=1), an.efforts["crank"]


def test_the_counterweights_torque_is_its_weights_moment():
    """The reference's model of a counterweight, checked on the textbook design (5300 kg at
    [0.8, 0]) analysed by the engine with the rod load: the torques differ by exactly g m x."""
    spec = _pumpjack()
    T, tau0 = _counterweight_torque(spec, None)
    res = study.run(spec.model_copy(update={"balancing": spec.compare[0].balancing, "compare": []}), page=False)
    tau = res.stages[1].analysis.efforts["crank"]
    assert np.max(np.abs(tau - tau0 - T @ np.array([5300 * 0.8, 0.0]))) <= 1e-9 * np.max(np.abs(tau0))


def test_least_peak_gearbox_torque_under_the_rod_load_equals_a_linear_programme():
    """min over the first moment s (|s| <= 0.9 m x 8000 kg) of max_t |tau0 + T s|: the LP's
    polygonal disc (a 720-gon, inside the true one by 1e-5) brackets the optimum from above."""
    spec = _pumpjack()
    program, out, objective, _ = P.solve(P.motion_maps(registry.context(spec)), spec.balancing)
    T, tau0 = _counterweight_torque(spec, None)
    s = out.z[1:3]
    ours = float(np.max(np.abs(tau0 + T @ s)))
    assert ours == pytest.approx(objective[0].value(out.z), rel=1e-9)  # the maps count the rod load
    # the LP: variables (sx, sy, u); |tau0 + T s| <= u; s inside a 720-gon of radius 0.9 x 8000
    R = 0.9 * 8000.0
    ang = np.linspace(0, 2 * np.pi, 721)[:-1]
    A = np.vstack([np.c_[T, -np.ones(len(T))], np.c_[-T, -np.ones(len(T))],
                   np.c_[np.cos(ang), np.sin(ang), np.zeros(720)]])
    b = np.r_[-tau0, tau0, np.full(720, R * np.cos(np.pi / 720))]
    lp = linprog([0, 0, 1], A_ub=A, b_ub=b, bounds=[(None, None)] * 3, method="highs")
    assert lp.status == 0
    assert ours <= lp.fun * (1 + 1e-7)  # the LP's region is inside ours
    assert ours == pytest.approx(lp.fun, rel=1e-4)
    assert ours < 0.35 * float(np.max(np.abs(tau0)))  # the rod load's torque largely counterbalanced


def test_least_rms_gearbox_torque_is_the_least_squares_counterbalance_exactly():
    """The RMS objective: the time-RMS (trapezoidal weights written here) of tau0 + T s is least
    at the weighted least-squares s, which is inside the budget's disc; balpipe's to 1e-9."""
    spec = _pumpjack(objective="rms")
    program, out, *_ = P.solve(P.motion_maps(registry.context(spec)), spec.balancing)
    T, tau0 = _counterweight_torque(spec, None)
    n = len(tau0)
    w = np.r_[0.5, np.ones(n - 2), 0.5] / (n - 1)
    r = np.sqrt(w)
    s_ref = np.linalg.lstsq(T * r[:, None], -tau0 * r, rcond=None)[0]
    assert np.hypot(*s_ref) < 0.9 * 8000
    assert np.max(np.abs(out.z[1:3] - s_ref)) <= 1e-9 * np.hypot(*s_ref)
    assert out.precision is not None and out.precision <= 1e-9


def test_the_partial_stage_is_judged_by_the_gearbox_torque():
    from balpipe.report.results import results_dict

    r = results_dict(study.run(_pumpjack()), "pumpjack.yaml", "h", False)
    assert r["verdict"]["level"] == "good"
    assert r["verdict"]["text"].startswith("objective reduced: peak effort of crank reduced by")
    partial = next(s for s in r["stages"] if s["name"] == "partial")
    textbook = next(s for s in r["stages"] if s["name"].endswith("counterbalance"))
    assert partial["max_actuator_effort"] <= textbook["max_actuator_effort"]  # the optimum beats the rule


def test_frame_load_maps_add_the_outside_load():
    """The frame force map = the shaking force map + the rod load (an outside load), at any design."""
    spec = _pumpjack()
    maps = P.motion_maps(registry.context(spec))[0]
    F, S = maps.loads["frame_force"], maps.loads["shaking_force"]
    model, t, an = _unbalanced(spec)
    assert np.max(np.abs((F.b0 - S.b0) - (an.frame_force - an.force))) <= 1e-9 * np.max(np.abs(an.frame_force))
    assert np.array_equal(F.A, S.A)


def test_coulomb_friction_is_a_located_error():
    spec = load(SPECS / "custom_compressor_gas_pressure.yaml").spec
    d = spec.model_dump(mode="json", exclude_none=True)
    bal = {"method": "partial_balance", "counterweights": [{"body": "crank", "name": "cw", "disc": {"centre": [0, 0], "radius": 0.05}}],
           "objective": [{"load": "joint", "joint": "A"}], "budget": {"mass": 3}, "fronts": None}
    spec = spec.model_copy(update={"balancing": type(spec).model_validate({**d, "balancing": bal}).balancing})
    with pytest.raises(SpecFieldError) as err:
        registry.balance(spec)
    assert err.value.path == ("balancing", "method") and "Coulomb friction of main_bearing, piston_rings" in err.value.message


COMPRESSOR = SPECS / "custom_compressor_gas_pressure_partial.yaml"


def _bearing_terms(spec):
    """The main bearing's force (joint A) of the unbalanced compressor under its gas force, and
    what a crank counterweight adds per unit first moment (crank axes) at constant speed: its
    centripetal force, -w^2 R(th) s, through the bearing (no torque, no other joint's force)."""
    model, t, an = _unbalanced(spec)
    k = [b.name for b in model.bodies].index("crank")
    th, w = an.q[:, k, 2], an.v[:, k, 2]
    R0 = np.stack([an.reactions["A"]["Fx"], an.reactions["A"]["Fy"]], axis=1)
    c, s = np.cos(th), np.sin(th)
    T = np.stack([np.stack([c, -s], axis=1), np.stack([s, c], axis=1)], axis=1) * (w * w)[:, None, None]
    return R0, T


def test_least_peak_main_bearing_load_under_the_gas_force_equals_a_cvxpy_reference():
    """min over s (|s| <= 60 mm x 3 kg) of max_t |R0 + sigma T s| (sigma the sign the textbook
    design shows) written with cvxpy here, against balpipe's optimum: value and design."""
    import cvxpy as cp

    spec = load(COMPRESSOR).spec
    program, out, objective, _ = P.solve(P.motion_maps(registry.context(spec)), spec.balancing)
    R0, T = _bearing_terms(spec)
    res = study.run(spec.model_copy(update={"balancing": spec.compare[0].balancing, "compare": []}), page=False)
    R = np.stack([res.stages[1].analysis.reactions["A"][k] for k in ("Fx", "Fy")], axis=1)
    s_text = np.array([-1.58 * 0.05, 0.0])
    sigma = 1.0 if np.max(np.abs(R - R0 - T @ s_text)) < np.max(np.abs(R - R0 + T @ s_text)) else -1.0
    assert np.max(np.abs(R - R0 - sigma * (T @ s_text))) <= 1e-9 * np.max(np.abs(R0))
    s = cp.Variable(2)
    u = cp.Variable()
    scale = float(np.max(np.linalg.norm(R0, axis=1)))
    A = sigma * T / scale
    cons = [cp.norm(s) <= 0.06 * 3.0] + [cp.norm(R0[n] / scale + A[n] @ s) <= u for n in range(len(R0))]
    cp.Problem(cp.Minimize(u), cons).solve(solver=cp.CLARABEL)
    ours = float(np.max(np.linalg.norm(R0 + sigma * (T @ out.z[1:3]), axis=1)))
    assert ours == pytest.approx(objective[0].value(out.z), rel=1e-9)  # the maps count the gas force
    assert ours == pytest.approx(float(u.value) * scale, rel=1e-7)
    assert np.max(np.abs(out.z[1:3] - s.value)) <= 1e-5 * 0.18
    assert ours < 0.8 * scale  # the gas force's bearing load a quarter lower
