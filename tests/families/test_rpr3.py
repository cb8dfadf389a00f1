"""Paper 000: the 3-RPR template, its idler-loop (Sec. 2) and Scott-Russell (Sec. 3) balancing."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from balpipe import registry, study
from balpipe.engine import analyse
from balpipe.loader import load
from balpipe.families.rpr3 import template as rpr3
from balpipe.spec import Spec
from balpipe.spec_parts import SpecFieldError
from _edits import replaced

SPECS = Path(__file__).resolve().parents[2] / "specs"
TOL = 1e-9


def params(result) -> dict[str, float]:
    return {p.name: p.value for p in result.parameters}


# --------------------------------------------------------------------------------------------
# random designs


def random_rpr3(r: np.random.Generator, *, actuation: str = "prismatic", legs: tuple[float, float] | None = None,
                scale: float = 1.0, duration: float = 0.3) -> dict:
    """A 3-RPR spec (dict) with random geometry, masses, inertias and a random motion away from
    phi = 0 (the homothetic, singular pose of prismatic actuation)."""
    Rb = float(r.uniform(0.25, 0.5))
    Rp = float(r.uniform(0.05, 0.15))
    L1 = float(r.uniform(0.02, 0.06))
    m1, m2, mp = (scale * float(r.uniform(0.2, 2.0)) for _ in range(3))
    cyl = legs[0] if legs else float(r.uniform(-1.0, 3.0) * L1)
    pc = legs[1] if legs else float(r.uniform(0.0, 1.0) * L1)
    start = r.uniform(-0.25, 0.25, 2) * Rb
    end = r.uniform(-0.25, 0.25, 2) * Rb
    f0, f1 = (float(r.uniform(15, 45)) * r.choice([-1, 1]) for _ in range(2))
    if f0 * f1 < 0:
        f1 = -f1
    return {
        "name": "random 3-RPR",
        "mechanism": {
            "template": "rpr3", "base_radius": Rb, "platform_radius": Rp, "actuation": actuation,
            "cylinder": {"mass": m1, "com": cyl, "inertia": scale * float(r.uniform(1e-4, 5e-3))},
            "piston": {"length": L1, "mass": m2, "com": pc, "inertia": scale * float(r.uniform(1e-4, 5e-3))},
            "platform": {"mass": mp, "inertia": scale * float(r.uniform(1e-3, 1e-2))},
        },
        "motion": {"law": "quintic", "duration": duration, "drive": {
            "x": {"from": float(start[0]), "to": float(end[0])},
            "y": {"from": float(start[1]), "to": float(end[1])},
            "phi": {"from": f"{f0} deg", "to": f"{f1} deg"},
        }},
        "analysis": {"samples": 121},
        "validation": {"enabled": False},
    }


def random_idler(r: np.random.Generator) -> dict:
    d = random_rpr3(r)
    L1 = d["mechanism"]["piston"]["length"]
    Rb = d["mechanism"]["base_radius"]
    # E off the platform's path, so that the loop E-F-P stays away from its folded and stretched
    # singular poses: |EP| in [0.25, 0.95] Rb, |L5 - L6| <= 0.1 Rb, L5 + L6 >= 1.1 Rb
    a = float(r.uniform(0, 2 * math.pi))
    E = [0.6 * Rb * math.cos(a), 0.6 * Rb * math.sin(a)]
    L5 = float(r.uniform(0.55, 0.65)) * Rb
    L6 = float(r.uniform(0.55, 0.65)) * Rb
    link = lambda L: {"length": L, "mass": float(r.uniform(0.2, 1.0)), "com": float(r.uniform(0.2, 0.8)) * L,  # noqa: E731
                      "inertia": float(r.uniform(5e-4, 3e-3))}
    d["balancing"] = {
        "method": "rpr3_idler_loop", "E": E,
        "link5": link(L5), "link6": link(L6), "branch": int(r.choice([-1, 1])),
        "counterweights": {"cylinder": -float(r.uniform(0.5, 2.0)) * L1, "piston": float(r.uniform(1.3, 2.0)) * L1,
                           "link5": -float(r.uniform(0.3, 0.8)) * L5, "link6": -float(r.uniform(0.3, 0.8)) * L6},
    }
    return d


def random_scott_russell(r: np.random.Generator, unknown: str) -> dict:
    d = random_rpr3(r, legs=None)
    m = d["mechanism"]
    m["cylinder"]["com"] = abs(m["cylinder"]["com"]) + 1e-3
    m["platform"]["inertia"] = m["platform"]["mass"] * m["platform_radius"] ** 2  # eq. 29
    L = float(r.uniform(0.5, 0.7)) * (m["base_radius"] + m["platform_radius"]) * 1.3
    link = lambda: {"length": L, "mass": float(r.uniform(0.5, 2.0)), "com": float(r.uniform(0.2, 0.8)) * L,  # noqa: E731
                    "inertia": float(r.uniform(0.005, 0.02))}
    L3 = m["piston"]["length"]
    d["balancing"] = {
        "method": "rpr3_scott_russell", "crank": link(), "coupler": link(), "branch": int(r.choice([-1, 1])),
        "counterweights": {"crank": -float(r.uniform(0.3, 0.8)) * L, "coupler": -float(r.uniform(0.3, 0.8)) * L,
                           "piston": -float(r.uniform(0.5, 1.5)) * L3, "cylinder": -float(r.uniform(0.5, 2.0)) * m["cylinder"]["com"]},
        "moment_unknown": unknown,
    }
    if unknown == "crank_counterweight_inertia":  # eq. 30e then needs a heavy coupler
        d["balancing"]["coupler"]["inertia"] = float(r.uniform(8.0, 12.0))
    return d


def valid(make, r: np.random.Generator, *args):
    """The first random design that the template and method accept (reach, singularity)."""
    for _ in range(50):
        spec = Spec.model_validate(make(r, *args))
        try:
            return spec, registry.balance(spec)
        except SpecFieldError:
            continue
    raise AssertionError("no valid random design in 50 tries")


def scales(an, model) -> dict[str, float]:
    """The size of the parts that must cancel: max over time of sum_k m_k |v_k| (momentum),
    sum_k m_k |r_k x v_k| + I_k |w_k| (angular momentum), sum_k m_k |a_k| (force) and
    sum_k m_k |r_k x a_k| + I_k |alpha_k| (moment), over the model's bodies."""
    m = np.array([b.mass_properties()[0] for b in model.bodies])
    inertia = np.array([b.mass_properties()[2] for b in model.bodies])
    r, v, a = an.q[:, :, :2], an.v, an.a
    cross = lambda x, y: np.abs(x[..., 0] * y[..., 1] - x[..., 1] * y[..., 0])  # noqa: E731
    return {
        "p": float(np.max(np.linalg.norm(v[:, :, :2], axis=2) @ m)),
        "h": float(np.max(cross(r, v[:, :, :2]) @ m + np.abs(v[:, :, 2]) @ inertia)),
        "f": float(np.max(np.linalg.norm(a[:, :, :2], axis=2) @ m)),
        "m": float(np.max(cross(r, a[:, :, :2]) @ m + np.abs(a[:, :, 2]) @ inertia)),
    }


def assert_fully_balanced(spec: Spec, result) -> None:
    """The last stage keeps its total centre of mass fixed and its momenta constant (zero: it
    starts at rest) to round-off of the parts that cancel; the counterweight stage cancels the
    force but not the moment."""
    t = registry.time_grid(spec)
    first = analyse(result.stages[0].model, t)
    s0 = scales(first, result.stages[0].model)
    assert first.max_force > 1e-2 * s0["f"] and first.max_moment > 1e-2 * s0["m"]
    last = analyse(result.stages[-1].model, t)
    s = scales(last, result.stages[-1].model)
    assert np.max(np.linalg.norm(last.com - last.com[0], axis=1)) <= TOL * spec.mechanism.base_radius
    assert np.max(np.linalg.norm(last.momentum, axis=1)) <= TOL * s["p"]
    assert np.max(np.abs(last.angular_momentum)) <= TOL * s["h"]
    assert last.max_force <= TOL * s["f"]
    assert last.max_moment <= TOL * s["m"]
    cw = next(st for st in result.stages if st.name == "counterweights")
    an = analyse(cw.model, t)
    sc = scales(an, cw.model)
    assert an.max_force <= TOL * sc["f"]
    assert an.max_moment > 1e-2 * sc["m"]


@pytest.mark.parametrize("seed", range(4))
def test_idler_loop_balances_random_designs(seed):
    spec, result = valid(random_idler, np.random.default_rng(100 + seed))
    assert [s.name for s in result.stages] == ["unbalanced", "idler_loop", "counterweights", "counter_rotations"]
    assert_fully_balanced(spec, result)


@pytest.mark.parametrize("seed,unknown", [(0, "coupler_inertia"), (1, "crank_counterweight_inertia"),
                                          (2, "coupler_counterweight_inertia"), (3, "coupler_inertia")])
def test_scott_russell_balances_random_designs(seed, unknown):
    spec, result = valid(random_scott_russell, np.random.default_rng(200 + seed), unknown)
    assert [s.name for s in result.stages] == ["unbalanced", "scott_russell", "counterweights", "counter_rotations"]
    assert result.stages[-1].balances == "force+moment"
    assert_fully_balanced(spec, result)


def test_scott_russell_without_eq_30e_is_force_balanced_only():
    r = np.random.default_rng(7)
    spec, result = valid(random_scott_russell, r, None)
    p = params(result)
    assert abs(p["Ieq2_as_given"]) > 1e-6
    assert result.stages[-1].balances == "force"
    t = registry.time_grid(spec)
    last = analyse(result.stages[-1].model, t)
    s = scales(last, result.stages[-1].model)
    assert last.max_force <= TOL * s["f"]
    assert last.max_moment > 1e-2 * s["m"]


# --------------------------------------------------------------------------------------------
# actuator efforts at the actuated joints


def _leg_jacobian_by_hand(spec: Spec, an) -> np.ndarray:
    """Rows [u_i, (C_i - P) x u_i] (prismatic) or [n_i, (C_i - P) x n_i] / rho_i (revolute),
    from the analysed poses of the cylinders and the platform."""
    k = an.names.index("platform")
    P, phi = an.frame_pose[:, k, :2], an.frame_pose[:, k, 2]
    c = rpr3.platform_points(spec.mechanism.platform_radius)
    A = rpr3.base_points(spec.mechanism.base_radius)
    rows = []
    for i in range(3):
        th = an.frame_pose[:, an.names.index(f"cyl{i + 1}"), 2]
        u = np.stack([np.cos(th), np.sin(th)], axis=1)
        rc = np.stack([np.cos(phi) * c[i, 0] - np.sin(phi) * c[i, 1], np.sin(phi) * c[i, 0] + np.cos(phi) * c[i, 1]], 1)
        rho = np.linalg.norm(P + rc - A[i], axis=1)
        v = u if spec.mechanism.actuation == "prismatic" else np.stack([-u[:, 1], u[:, 0]], 1) / rho[:, None]
        rows.append(np.stack([v[:, 0], v[:, 1], rc[:, 0] * v[:, 1] - rc[:, 1] * v[:, 0]], 1))
    return np.stack(rows, axis=1)


@pytest.mark.parametrize("actuation", ["prismatic", "revolute"])
def test_actuator_efforts_are_the_platform_wrench_through_the_leg_jacobians(actuation):
    """Massless legs: J^T f = (mp a_P, Ip phi''), f the axial forces (torques) at the actuated joints."""
    r = np.random.default_rng(31)
    for _ in range(50):
        d = random_rpr3(r, actuation=actuation)
        for part in ("cylinder", "piston"):
            d["mechanism"][part].update(mass=0.0, inertia=0.0)
        spec = Spec.model_validate(d)
        try:
            model = registry.unbalanced_model(spec)
            break
        except SpecFieldError:
            continue
    an = analyse(model, registry.time_grid(spec))
    names = [f"{'rho' if actuation == 'prismatic' else 'theta'}{i}" for i in (1, 2, 3)]
    f = np.stack([an.efforts[n] for n in names], axis=1)
    k = an.names.index("platform")
    pl = spec.mechanism.platform
    wrench = np.concatenate([pl.mass * an.a[:, k, :2], pl.inertia * an.a[:, k, 2:3]], axis=1)
    J = _leg_jacobian_by_hand(spec, an)
    mapped = np.einsum("nij,ni->nj", J, f)
    assert np.max(np.abs(mapped - wrench)) <= 1e-9 * np.max(np.abs(wrench))
    assert np.max(np.abs(wrench)) > 0.1


def test_actuator_power_is_the_rate_of_kinetic_energy():
    """Massive legs, prismatic actuators: sum f_i rho_i' = dT/dt (no other joint does work)."""
    r = np.random.default_rng(5)
    for _ in range(50):
        spec = Spec.model_validate(random_rpr3(r))
        try:
            model = registry.unbalanced_model(spec)
            break
        except SpecFieldError:
            continue
    t = registry.time_grid(spec)
    an = analyse(model, t)
    power = sum(an.efforts[d.name] * d.law(t)[1] for d in model.drivers)
    m = np.array([b.mass_properties()[0] for b in model.bodies])
    inertia = np.array([b.mass_properties()[2] for b in model.bodies])
    dT = (np.einsum("k,nkd,nkd->n", m, an.a[:, :, :2], an.v[:, :, :2])
          + np.einsum("k,nk,nk->n", inertia, an.a[:, :, 2], an.v[:, :, 2]))
    assert np.max(np.abs(power - dT)) <= 1e-9 * np.max(np.abs(dT))


def test_leg_laws_are_exact_derivatives():
    spec = Spec.model_validate(random_rpr3(np.random.default_rng(3), actuation="revolute"))
    model = registry.unbalanced_model(spec)
    t = np.linspace(0.01, 0.29, 7)
    h = 1e-6
    for d in model.drivers:
        q, qd, qdd = d.law(t)
        qp, qdp, _ = d.law(t + h)
        qm, qdm, _ = d.law(t - h)
        assert np.allclose((qp - qm) / (2 * h), qd, rtol=1e-6, atol=1e-8)
        assert np.allclose((qdp - qdm) / (2 * h), qdd, rtol=1e-5, atol=1e-6)


def _first_valid(seed: int, **kw) -> tuple[Spec, object]:
    r = np.random.default_rng(seed)
    for _ in range(50):
        spec = Spec.model_validate(random_rpr3(r, **kw))
        try:
            return spec, analyse(registry.unbalanced_model(spec), registry.time_grid(spec))
        except SpecFieldError:
            continue
    raise AssertionError("no valid random design")


def test_loads_scale_with_mass_and_duration():
    """Scaling every mass and inertia by k scales loads and efforts by k; halving the duration
    multiplies them by 4."""
    _, base = _first_valid(11)
    _, heavy = _first_valid(11, scale=2.5)
    _, fast = _first_valid(11, duration=0.15)
    for other, k in ((heavy, 2.5), (fast, 4.0)):
        assert other.max_force == pytest.approx(k * base.max_force, rel=1e-9)
        assert other.max_moment == pytest.approx(k * base.max_moment, rel=1e-9)
        for name, e in base.efforts.items():
            assert np.max(np.abs(other.efforts[name] - k * e)) <= 1e-9 * np.max(np.abs(k * e))


# --------------------------------------------------------------------------------------------
# errors


def _bad(tmp_path, text: str) -> str:
    f = tmp_path / "s.yaml"
    f.write_text(text)
    loaded = load(f)
    with pytest.raises(SpecFieldError) as exc:
        registry.balance(loaded.spec)
    return str(loaded.error(exc.value))


PAPER_IDLER = (SPECS / "paper000_rpr3_idler_loop.yaml").read_text()


def test_pose_outside_the_workspace_names_the_time_and_the_leg(tmp_path):
    text = replaced(PAPER_IDLER, "  actuation: revolute", "  actuation: revolute\n  stroke: [0.12 m, 0.5 m]")
    msg = _bad(tmp_path, text)
    line = next(k for k, s in enumerate(text.splitlines(), 1) if s.strip().startswith("x: {from"))
    assert msg.startswith(f"{tmp_path / 's.yaml'}:{line}:")
    assert "motion.drive: the platform pose at t = " in msg
    assert "leg 1 (A1C1) would be" in msg and "shorter than its minimum 0.12 m" in msg


def test_prismatic_actuation_at_the_homothetic_pose_is_singular(tmp_path):
    msg = _bad(tmp_path, replaced(PAPER_IDLER, "  actuation: revolute", "  actuation: prismatic"))
    assert "mechanism.actuation: prismatic actuation is singular at t = 0 s" in msg
    assert "leg lines A_iC_i meet in one point" in msg


def test_printed_counterweight_positions_give_a_located_negative_mass(tmp_path):
    msg = _bad(tmp_path, replaced(PAPER_IDLER, "cylinder: -0.1 m      # rcp1 = -2", "cylinder: 0.025 m"))
    assert "balancing.counterweights.cylinder: eq. 5a gives a negative counterweight mass mcp1 = -3 kg" in msg


def test_idler_loop_out_of_reach(tmp_path):
    msg = _bad(tmp_path, replaced(PAPER_IDLER, "link6: {length: 0.1581 m", "link6: {length: 0.03 m"))
    assert "balancing.link6.length: the idler loop cannot reach P at t = 0 s" in msg


def test_scott_russell_needs_eq_29(tmp_path):
    text = replaced((SPECS / "paper000_rpr3_scott_russell.yaml").read_text(),
                    "platform: {mass: 1 kg, inertia: 0.01 kg m^2}", "platform: {mass: 1 kg, inertia: 0.02 kg m^2}")
    msg = _bad(tmp_path, text)
    assert "mechanism.platform.inertia: eq. 29" in msg and "Ip = mp Rp^2 = 0.01" in msg


def test_scott_russell_out_of_reach_names_the_leg(tmp_path):
    # crank and coupler both (eq. 19 needs L2 = L1)
    text = replaced((SPECS / "paper000_rpr3_scott_russell.yaml").read_text(), "length: 0.25 m", "length: 0.12 m", count=2)
    msg = _bad(tmp_path, text)
    assert "balancing.crank.length: the Scott-Russell mechanism of leg 2 cannot reach C at t = " in msg


# --------------------------------------------------------------------------------------------
# the paper's numerical applications


@pytest.fixture
def idler(studies):
    return studies("paper000_rpr3_idler_loop.yaml")


def test_idler_loop_reproduces_the_paper(idler):
    p = params(idler.balance)
    published = {"mcp1": 0.75, "mcp2": 0.37, "mcp5": 21.66, "mcp6": 6.92,  # mcp5/mcp6 labels swapped in the text
                 "Icr1": 0.01917, "Icr2": 0.02665, "Icr3": 0.18169, "Icr4": 0.72781}
    for name, value in published.items():
        assert abs(p[name] - value) <= 0.005 * value, name
    assert p["mcp1"] == pytest.approx(0.75, rel=1e-12) and p["mcp2"] == pytest.approx(0.37, rel=1e-12)
    m = {s.stage.name: study.stage_metrics(s, idler.unbalanced, TOL) for s in idler.stages}
    assert idler.unbalanced.analysis.max_force == pytest.approx(34.39, abs=0.01)
    assert idler.unbalanced.analysis.max_moment == pytest.approx(1.439, abs=0.001)
    assert abs(m["counterweights"].moment_ratio - 17) <= 0.5
    assert m["counter_rotations"].force_ratio <= TOL and m["counter_rotations"].moment_ratio <= TOL
    assert idler.ok and all(r["status"] == "agrees" for r in idler.references)


def test_scott_russell_as_printed_and_corrected(studies):
    printed = studies("paper000_rpr3_scott_russell.yaml")
    corrected = studies("paper000_rpr3_scott_russell_corrected.yaml")
    for s in (printed, corrected):
        p = params(s.balance)
        for name, value in {"mcp1": 11.71, "mcp2": 3.17, "mcp3": 0.33, "mcp4": 0.75}.items():
            assert abs(p[name] - value) <= 0.005 * value + 0.005, name  # printed to 2 decimals
        refs = {r["name"]: r for r in s.references}
        for name in ("Icr", "counterweights.moment_ratio"):
            assert refs[name]["status"] == "differs" and refs[name]["expected"] == "differ"
        assert s.ok
    assert params(printed.balance)["Icr"] == pytest.approx(1.2738, abs=1e-4)
    assert params(corrected.balance)["Icr"] == pytest.approx(1.0976, abs=1e-4)
    assert params(corrected.balance)["I2"] == pytest.approx(0.40769, abs=1e-5)
    last = corrected.stages[-1]
    assert last.stage.balances == "force+moment"
    assert last.analysis.max_moment <= TOL * corrected.unbalanced.analysis.max_moment
    assert last.analysis.max_force <= TOL * corrected.unbalanced.analysis.max_force
    # the printed I2 violates eq. 30e: about 18 % of the Scott-Russell legs' peak moment remains
    sr = next(s for s in printed.stages if s.stage.name == "scott_russell")
    assert 0.15 < printed.stages[-1].analysis.max_moment / sr.analysis.max_moment < 0.21
    assert printed.stages[-1].stage.balances == "force"


def test_template_figures_reproduce_fig_4(idler):
    figs = list(idler.extra_figures())
    titles = [f[0] for f in figs]
    assert titles[0].startswith("Shaking force and moment, every stage (Fig. 4")
    assert "17.07" in figs[1][1]  # the factor relative to the plain 3-RPR


def test_methods_compared_on_the_same_3rpr(studies, pages):
    """Issue 9, item 5, through the generic ``compare:`` block: both methods' stages on the same 3-RPR
    in the "Designs side by side" table with the counter-rotations needed and the peak moment
    before them; the paper's Fig. 8 keeps the main design's stages only."""
    from balpipe.report.results import results_dict

    s = studies("paper000_rpr3_scott_russell_corrected.yaml")
    assert s.ok, s.problems
    out = results_dict(s, "x.yaml", "h", simulated=False)
    rows = {r["stage"]: r for r in out["comparison"]["rows"]}
    assert list(rows) == ["unbalanced", "scott_russell", "counterweights", "counter_rotations",
                          "idler:idler_loop", "idler:counterweights", "idler:counter_rotations"]
    sr, idl = rows["counter_rotations"], rows["idler:counter_rotations"]
    assert sr["counter_rotations"] == 3 and idl["counter_rotations"] == 6  # "counter-rotations divided by 2"
    assert rows["counterweights"]["counter_rotations"] == 0 and rows["idler:counterweights"]["counter_rotations"] == 0
    assert sr["moment_before_counter_rotations"] == rows["counterweights"]["max_shaking_moment"]
    assert idl["moment_before_counter_rotations"] == rows["idler:counterweights"]["max_shaking_moment"]
    un = rows["unbalanced"]
    for r in (sr, idl):  # both balance force and moment; the counterweights raised the moment first
        assert r["max_shaking_force"] <= TOL * un["max_shaking_force"]
        assert r["max_shaking_moment"] <= TOL * un["max_shaking_moment"]
        assert r["moment_before_counter_rotations"] > 5 * un["max_shaking_moment"]
        assert r["added_mass"] > 0 and r["added_inertia"] > 0 and r["max_actuator_effort"] > 0
        assert r["max_joint_load"] > 0 and r["max_joint_load_joint"]
    by_name = {st.stage.name: st for st in s.stages}
    assert idl["added_mass"] == pytest.approx(by_name["idler:counter_rotations"].added_mass)
    html = pages("paper000_rpr3_scott_russell_corrected.yaml")
    assert "Designs side by side" in html and "Peak |M| before counter-rotations (N m)" in html
    assert "idler loop (Sec. 2): counter-rotations" in html
    # Fig. 8 and the factor table: the Scott-Russell stages only
    extra = list(s.extra_figures())  # drawn once for both checks
    title, svg, _ = extra[0]
    assert title.startswith("Shaking force and moment, every stage (Fig. 8") and "idler" not in svg
    assert "idler" not in extra[1][1]


def test_prismatic_equivalent_of_revolute_torques():
    """The axial forces that the page shows for revolute-actuated specs equal the efforts of the
    same motion driven at the prismatic pairs."""
    r = np.random.default_rng(41)
    for _ in range(50):
        d = random_rpr3(r, actuation="revolute")
        try:
            spec_r = Spec.model_validate(d)
            model_r = registry.unbalanced_model(spec_r)
            d["mechanism"]["actuation"] = "prismatic"
            spec_p = Spec.model_validate(d)
            model_p = registry.unbalanced_model(spec_p)
            break
        except SpecFieldError:
            continue
    t = registry.time_grid(spec_r)
    ar, ap = analyse(model_r, t), analyse(model_p, t)
    tau = np.stack([ar.efforts[f"theta{i}"] for i in (1, 2, 3)], axis=1)
    f = rpr3.prismatic_equivalent(spec_r.mechanism, rpr3.pose_of(model_r), t, tau)
    fp = np.stack([ap.efforts[f"rho{i}"] for i in (1, 2, 3)], axis=1)
    assert np.max(np.abs(f - fp)) <= 1e-9 * np.max(np.abs(fp))
    # the shaking loads do not depend on the actuation
    assert np.max(np.abs(ar.force - ap.force)) <= 1e-9 * ar.max_force
    assert np.max(np.abs(ar.moment - ap.moment)) <= 1e-9 * ar.max_moment
