"""Complete shaking force and moment balancing of the 3-RPR with a Scott-Russell mechanism in
each leg (paper 000, Sec. 3, Figs. 6-7, eqs. 21-30).

In leg i a crank AB (link 1, length L1) pivots on the base at A_i and a coupler BC (link 2,
L2 = L1, eq. 19) joins it to the point C of the piston (the template's B_i), which slides on the
line through A_i: a Scott-Russell mechanism whose guide (the cylinder, link 4) turns. The
piston (link 3) reaches the platform at C_i = C + L3 u_i. The platform is replaced by three
point masses mpi = mp / 3 at C_i (eq. 29, which needs Ip = mp Rp^2); the counterweights of
eqs. 30a-d then keep the leg's centre of mass on A_i: mcp4 on the cylinder (its centre of mass
on A_i), mcp3 on the piston (piston + mpi on C), mcp2 on the coupler (coupler + all that on B),
mcp1 on the crank (everything on A_i). With eq. 30e the crank and coupler contribute no
angular momentum of their own (Ieq2 = 0, eq. 28) and the leg's angular momentum is
Ieq1 theta_i' (eq. 26): one counter-rotation per leg, on the base, geared to the cylinder with
ratio -1 and inertia Icr = Ieq1 (eq. 30f), cancels it.

Positions are signed lengths: the crank's centre of mass and counterweight from A_i (r1 L1,
rcp1 L1), the coupler's from B (r2 L2, rcp2 L2), the piston's from C (the template's piston
com, r3 L3, and rcp3 L3), the cylinder's from A_i (the template's cylinder com, r4 L3, and
rcp4 L3).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from . import template as rpr3
from ...model import FRAME, Body, Model, Revolute
from ...spec_parts import SpecFieldError
from ...balancing.base import BalanceResult, Parameter, Stage
from ...balancing.context import BalanceContext
from ...balancing.parts import add_counter_rotation, add_counterweight
from ...balancing.scott_russell import eq20_lhs
from .specs import MomentUnknown, Rpr3ScottRussell

PATH = ("balancing",)


@dataclass(frozen=True)
class LegDesign:
    """The numbers eqs. 29-30 use, in lengths (p: centres of mass, c: counterweights)."""

    L1: float
    m1: float
    p1: float
    I1: float
    m2: float
    p2: float
    I2: float
    L3: float
    m3: float
    p3: float
    I3: float
    m4: float
    p4: float
    I4: float
    mpi: float
    c1: float
    c2: float
    c3: float
    c4: float
    Icp1: float = 0.0  # centroidal inertias of the crank's and coupler's counterweights
    Icp2: float = 0.0


def counterweight_masses(d: LegDesign) -> dict[str, float]:
    """Eqs. 30a-d in lengths: mcp4 = -m4 p4 / c4; mcp3 = -(m3 p3 + mpi L3) / c3;
    mcp2 = -(m2 p2 + (m3 + mcp3 + mpi) L1) / c2; mcp1 = -(m1 p1 + (m2 + mcp2 + m3 + mcp3 + mpi) L1) / c1."""
    mcp4 = -d.m4 * d.p4 / d.c4
    mcp3 = -(d.m3 * d.p3 + d.mpi * d.L3) / d.c3
    mcp2 = -(d.m2 * d.p2 + (d.m3 + mcp3 + d.mpi) * d.L1) / d.c2
    mcp1 = -(d.m1 * d.p1 + (d.m2 + mcp2 + d.m3 + mcp3 + d.mpi) * d.L1) / d.c1
    return {"mcp1": mcp1, "mcp2": mcp2, "mcp3": mcp3, "mcp4": mcp4}


def ieq2(d: LegDesign, m: dict[str, float]) -> float:
    """Eq. 28 (= the right-hand side of eq. 30e): I1 + m1 p1^2 + mcp1 c1^2 + (m2 + mcp2) L1^2
    - I2 - m2 p2^2 - mcp2 c2^2, counterweight inertias added to I1 and I2."""
    return eq20_lhs(d.I1 + d.Icp1, d.m1, d.p1, m["mcp1"], d.c1, d.L1, d.I2 + d.Icp2, d.m2, d.p2, m["mcp2"], d.c2)


def counter_rotation_inertia(d: LegDesign, m: dict[str, float]) -> float:
    """Eq. 30f (= Ieq1 of eq. 27 with mpi at C_i): (m1 p1^2 + mcp1 c1^2 + m2 (L1 - p2)^2
    + mcp2 (L1 - c2)^2) + I1 + I2 + I3 + I4 + m3 p3^2 + mcp3 c3^2 + m4 p4^2 + mcp4 c4^2 + mpi L3^2."""
    return (d.m1 * d.p1**2 + m["mcp1"] * d.c1**2 + d.m2 * (d.L1 - d.p2) ** 2 + m["mcp2"] * (d.L1 - d.c2) ** 2
            + d.I1 + d.Icp1 + d.I2 + d.Icp2 + d.I3 + d.I4
            + d.m3 * d.p3**2 + m["mcp3"] * d.c3**2 + d.m4 * d.p4**2 + m["mcp4"] * d.c4**2 + d.mpi * d.L3**2)


def solve_moment_unknown(d: LegDesign, m: dict[str, float], unknown: MomentUnknown) -> tuple[LegDesign, str, float]:
    """Eq. 30e solved for ``unknown`` (linear in each of them): the design, the parameter's name
    and its value."""
    r = ieq2(d, m)
    name, field_, sign = {
        "crank_inertia": ("I1", "I1", -1), "coupler_inertia": ("I2", "I2", +1),
        "crank_counterweight_inertia": ("Icp1", "Icp1", -1), "coupler_counterweight_inertia": ("Icp2", "Icp2", +1),
    }[unknown]
    value = getattr(d, field_) + sign * r
    if value < 0:
        raise SpecFieldError(
            PATH + ("moment_unknown",),
            f"eq. 30e needs a negative {name} = {value:.4g} kg m^2: solve for the "
            f"{'coupler' if sign < 0 else 'crank'}'s inertia (or its counterweight's) instead",
        )
    return replace(d, **{field_: value}), name, value


def design_of(mech: rpr3.Rpr3Mechanism, method: Rpr3ScottRussell) -> LegDesign:
    cw = method.counterweights
    return LegDesign(
        L1=method.crank.length, m1=method.crank.mass, p1=method.crank.com, I1=method.crank.inertia,
        m2=method.coupler.mass, p2=method.coupler.com, I2=method.coupler.inertia,
        L3=mech.piston.length, m3=mech.piston.mass, p3=mech.piston.com, I3=mech.piston.inertia,
        m4=mech.cylinder.mass, p4=mech.cylinder.com, I4=mech.cylinder.inertia,
        mpi=mech.platform.mass / 3, c1=cw.crank, c2=cw.coupler, c3=cw.piston, c4=cw.cylinder,
    )


def add_scott_russell_legs(mech: rpr3.Rpr3Mechanism, method: Rpr3ScottRussell, model: Model, d: LegDesign) -> Model:
    """Crank ``crank{i}`` (origin A_i, x along AB) and coupler ``coupler{i}`` (origin B, x along
    BC) in every leg; a located error where |A_iC| leaves (0, 2 L1)."""
    t = rpr3.sample_times(model)
    pose = rpr3.pose_of(model)
    rho = rpr3.leg_lengths(mech, pose, t)
    AC = rho - d.L3
    L1 = d.L1
    bad = (AC <= 0) | (AC >= 2 * L1)
    if np.any(bad):
        k = int(np.argmax(bad.any(axis=1)))
        i = int(np.argmax(bad[k]))
        raise SpecFieldError(
            PATH + ("crank", "length"),
            f"the Scott-Russell mechanism of leg {i + 1} cannot reach C at t = {t[k]:.4g} s: |A{i + 1}C| = "
            f"{AC[k, i]:.4g} m is outside (0, {2 * L1:.4g}) m (twice the crank length)",
        )
    A = rpr3.base_points(mech.base_radius)
    bodies, joints, init = [], [], {}
    for i in range(3):
        n = i + 1
        th = model.initial[f"cyl{n}"][2]
        beta = method.branch * math.acos(AC[0, i] / (2 * L1))
        B = A[i] + L1 * np.array([math.cos(th + beta), math.sin(th + beta)])
        for name, lk, a_, b_ in ((f"crank{n}", method.crank, "A", "B"), (f"coupler{n}", method.coupler, "B", "C")):
            bodies.append(Body(name, lk.mass, (lk.com, lk.com_offset), lk.inertia,
                               {a_: (0.0, 0.0), b_: (lk.length, 0.0)}, outline=(a_, b_)))
        init[f"crank{n}"] = (float(A[i, 0]), float(A[i, 1]), th + beta)
        init[f"coupler{n}"] = (float(B[0]), float(B[1]), th - beta)
        joints += [
            Revolute(f"A{n}'", FRAME, f"crank{n}", (float(A[i, 0]), float(A[i, 1])), (0.0, 0.0)),
            Revolute(f"SR-B{n}", f"crank{n}", f"coupler{n}", (L1, 0.0), (0.0, 0.0)),
            Revolute(f"SR-C{n}", f"coupler{n}", f"piston{n}", (L1, 0.0), (-d.L3, 0.0)),
        ]
    return replace(model.add(tuple(bodies), tuple(joints), init), name="3-RPR with Scott-Russell legs")


def _set_inertia(model: Model, body: str, inertia: float) -> Model:
    return model.replace_body(replace(model.body(body), inertia=inertia))


def balance(ctx: BalanceContext) -> BalanceResult:
    """Stages: unbalanced (plain 3-RPR), Scott-Russell legs, counterweights (eqs. 30a-d),
    counter-rotations (eq. 30f; moment balanced when eq. 30e holds)."""
    mech: rpr3.Rpr3Mechanism = ctx.mechanism
    method: Rpr3ScottRussell = ctx.balancing
    model = ctx.model
    for key in ("crank", "coupler"):
        if getattr(method, key).com_offset:
            raise SpecFieldError(PATH + (key, "com_offset"), "eqs. 30 assume centres of mass on the link axes")
    L1, L2 = method.crank.length, method.coupler.length
    if abs(L1 - L2) > 1e-12 * L1:
        raise SpecFieldError(PATH + ("coupler", "length"),
                             f"a Scott-Russell mechanism needs L2 = L1 (eq. 19); got L1 = {L1:g} m, L2 = {L2:g} m")
    pl = mech.platform
    Ieq = pl.mass * mech.platform_radius**2
    if abs(pl.inertia - Ieq) > 1e-9 * max(Ieq, 1e-300):
        raise SpecFieldError(
            ("mechanism", "platform", "inertia"),
            f"eq. 29 replaces the platform by three point masses mp/3 at C_i, which needs Ip = mp Rp^2 = "
            f"{Ieq:.6g} kg m^2 (got {pl.inertia:.6g})",
        )
    d = design_of(mech, method)
    cwp = PATH + ("counterweights",)
    for key, c in (("crank", d.c1), ("coupler", d.c2), ("piston", d.c3), ("cylinder", d.c4)):
        if c == 0:
            raise SpecFieldError(cwp + (key,), "a counterweight on the joint itself cannot balance anything")
    m = counterweight_masses(d)
    where = {"mcp4": ("cylinder", "eq. 30a", "A_i"), "mcp3": ("piston", "eq. 30b", "C"),
             "mcp2": ("coupler", "eq. 30c", "B"), "mcp1": ("crank", "eq. 30d", "A_i")}
    for name, (key, eq, joint) in where.items():
        if m[name] < 0:
            raise SpecFieldError(cwp + (key,), f"{eq} gives a negative counterweight mass {name} = {m[name]:.4g} kg "
                                               f"at this position: put the counterweight on the other side of {joint}")
    params = [
        Parameter("mpi", d.mpi, "kg", "eq. 29", "point mass replacing the platform at each C_i"),
        Parameter("mcp1", m["mcp1"], "kg", "eq. 30d", "counterweight on each crank (link 1)"),
        Parameter("mcp2", m["mcp2"], "kg", "eq. 30c", "counterweight on each coupler (link 2)"),
        Parameter("mcp3", m["mcp3"], "kg", "eq. 30b", "counterweight on each piston (link 3)"),
        Parameter("mcp4", m["mcp4"], "kg", "eq. 30a", "counterweight on each cylinder (link 4)"),
        Parameter("rcp1", d.c1 / d.L1, "", "spec", "crank counterweight position / L1, from A_i"),
        Parameter("rcp2", d.c2 / d.L1, "", "spec", "coupler counterweight position / L2, from B"),
        Parameter("rcp3", d.c3 / d.L3, "", "spec", "piston counterweight position / L3, from C"),
        Parameter("rcp4", d.c4 / d.L3, "", "spec", "cylinder counterweight position / L3, from A_i"),
    ]
    notes: list[str] = []
    residual = ieq2(d, m)
    params.append(Parameter("Ieq2_as_given", residual, "kg m^2", "eq. 28 (eq. 30e: must be 0)",
                            "the crank-coupler's own angular momentum coefficient for the design as given"))
    design = d
    if method.moment_unknown is not None:
        design, name, value = solve_moment_unknown(d, m, method.moment_unknown)
        params.append(Parameter(name, value, "kg m^2", "eq. 30e", {
            "I1": "crank inertia that eq. 30e needs", "I2": "coupler inertia that eq. 30e needs",
            "Icp1": "inertia of the crank's counterweight (a disc) that eq. 30e needs",
            "Icp2": "inertia of the coupler's counterweight (a disc) that eq. 30e needs"}[name]))
        if name in ("I1", "I2"):
            body = "crank" if name == "I1" else "coupler"
            notes.append(f"Eq. 30e is solved for the {body}'s inertia {name} = {value:.6g} kg m^2 (the spec gives "
                         f"{getattr(d, name):.6g}): every stage uses the redesigned {body}s.")
    Icr = counter_rotation_inertia(design, m)
    params.append(Parameter("Icr", Icr, "kg m^2", "eq. 30f", "counter-rotation on the base at each A_i, geared to the cylinder"))
    ok30e = abs(ieq2(design, m)) <= 1e-12 * max(Icr, 1e-300)
    if not ok30e:
        notes.append(
            f"Eq. 30e does not hold for this design (Ieq2 = {residual:.6g} kg m^2 instead of 0): the crank and "
            "coupler keep an angular momentum of their own, which no counter-rotation geared to the cylinder "
            "cancels, so the last stage is force balanced only. Name balancing.moment_unknown to solve eq. 30e."
        )
    sr = add_scott_russell_legs(mech, method, model, d)
    if design.I1 != d.I1 or design.I2 != d.I2:
        for i in range(1, 4):
            sr = _set_inertia(_set_inertia(sr, f"crank{i}", design.I1), f"coupler{i}", design.I2)
    cw = sr
    for i in range(1, 4):
        cw = add_counterweight(cw, f"crank{i}", f"mcp1 (leg {i})", m["mcp1"], (d.c1, 0.0), design.Icp1)
        cw = add_counterweight(cw, f"coupler{i}", f"mcp2 (leg {i})", m["mcp2"], (d.c2, 0.0), design.Icp2)
        cw = add_counterweight(cw, f"piston{i}", f"mcp3 (leg {i})", m["mcp3"], (d.c3 - d.L3, 0.0))
        cw = add_counterweight(cw, f"cyl{i}", f"mcp4 (leg {i})", m["mcp4"], (d.c4, 0.0))
    full = cw
    A = rpr3.base_points(mech.base_radius)
    s = 0.25 * mech.base_radius
    for i in range(3):
        at = A[i] * (1 + s / mech.base_radius)
        full = add_counter_rotation(full, f"cr{i + 1}", carrier=FRAME, at=(float(at[0]), float(at[1])),
                                    geared_to=f"cyl{i + 1}", ratio=-1.0, inertia=Icr, radius=s / 2, radius_geared=s / 2)
    stages = [replace(st, style=rpr3.STYLES[st.name]) for st in (
        Stage("unbalanced", "unbalanced", model, "the plain 3-RPR (Fig. 2(a))"),
        Stage("scott_russell", "Scott-Russell legs", sr, "a crank and a coupler (L1 = L2) added to every leg (Fig. 6)"),
        Stage("counterweights", "counterweights", cw, "four counterweights per leg, eqs. 30a-d", balances="force"),
        Stage("counter_rotations", "counter-rotations", full,
              "one counter-rotation per leg on the base, geared to the cylinder (eq. 30f, Fig. 7)"
              + ("" if ok30e else "; eq. 30e does not hold, so the moment remains"),
              balances="force+moment" if ok30e else "force", paper_claims="force+moment"),
    )]  # the paper's line styles
    return BalanceResult(params, stages, notes)


def _notation() -> dict:
    from ...notation import Sym, names_table, ours, setting

    legs = range(1, 4)
    links = {"crank": 1, "coupler": 2, "piston": 3, "cyl": 4}
    names = names_table(parts={
        **{f"{b}{i}": Sym(f"link {j} (leg {i})", f"link {j} of leg {i}'s Scott-Russell mechanism (Fig. 6)")
           for b, j in links.items() for i in legs},
        **{f"mcp{j} (leg {i})": Sym(f"m_{{cp{j}}} (leg {i})", f"counterweight on link {j} of leg {i} (eqs. 30a-d)")
           for j in links.values() for i in legs},
        **{f"cr{i}": Sym(f"I_{{cr}} (leg {i})", f"counter-rotation of leg {i} on the base at A_{i} (eq. 30f)") for i in legs},
    }, params={
        **{f"mcp{j}": Sym(f"m_{{cp{j}}}", f"mass of counterweight {j} (eqs. 30a-d)") for j in links.values()},
        **{f"rcp{j}": Sym(f"r_{{cp{j}}}", f"position coefficient of counterweight {j}") for j in links.values()},
        "Icr": Sym("I_{cr}", "inertia of each leg's counter-rotation (eq. 30f)"),
    })
    return dict(names) | {
        # Sec. 3 renumbers the leg: the piston is link 3, the cylinder link 4 (Fig. 6)
        "mechanism.cylinder.mass": Sym("m_4", "mass of each cylinder, link 4 of the leg (Sec. 3.2)"),
        "mechanism.cylinder.com": Sym("r_4 L_3", "centre of mass S_4 of the cylinder from A_i towards C_i"),
        "mechanism.cylinder.inertia": Sym("I_4", "axial moment of inertia of each cylinder (printed \"I_6\" in Sec. 3.4)"),
        "mechanism.piston.length": Sym("L_3", "length of the piston, link 3"),
        "mechanism.piston.mass": Sym("m_3", "mass of each piston, link 3"),
        "mechanism.piston.com": Sym("r_3 L_3", "centre of mass S_3 of the piston from C"),
        "mechanism.piston.inertia": Sym("I_3", "axial moment of inertia of each piston"),
        "balancing.crank.length": Sym("L_1", "length AB of the Scott-Russell crank, link 1"),
        "balancing.crank.mass": Sym("m_1", "mass of the crank"),
        "balancing.crank.com": Sym("r_1 L_1", "centre of mass S_1 of the crank from A_i along AB"),
        "balancing.crank.com_offset": ours("e_1", "offset of S_1 normal to AB"),
        "balancing.crank.inertia": Sym("I_1", "axial moment of inertia of the crank"),
        "balancing.coupler.length": Sym("L_2", "length BC of the coupler, link 2 (L_2 = L_1, eq. 19)"),
        "balancing.coupler.mass": Sym("m_2", "mass of the coupler"),
        "balancing.coupler.com": Sym("r_2 L_2", "centre of mass S_2 of the coupler from B along BC"),
        "balancing.coupler.com_offset": ours("e_2", "offset of S_2 normal to BC"),
        "balancing.coupler.inertia": Sym("I_2", "axial moment of inertia of the coupler"),
        "balancing.branch": ours("σ", "+1: B on the left of the leg axis A_i → C_i"),
        "balancing.counterweights.crank": Sym("r_{cp1} L_1", "counterweight M_{cp1} on the crank, from A_i towards B (negative: beyond A_i)"),
        "balancing.counterweights.coupler": Sym("r_{cp2} L_2", "counterweight M_{cp2} on the coupler, from B towards C (negative: beyond B)"),
        "balancing.counterweights.piston": Sym("r_{cp3} L_3", "counterweight M_{cp3} on the piston, from C (negative: away from C_i)"),
        "balancing.counterweights.cylinder": Sym("r_{cp4} L_3", "counterweight M_{cp4} on the cylinder, from A_i towards C_i (negative: beyond A_i)"),
        "balancing.moment_unknown": setting("unknown", "the inertia that eq. 30e is solved for"),
    }

#: Paper 000's symbols (Sec. 3, Figs. 6-7, eqs. 21-30) for this method's inputs; they rename the
#: 3-RPR's cylinder and piston as Sec. 3 does.
NOTATION = _notation()
