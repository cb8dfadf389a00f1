"""Complete shaking force and moment balancing of the 3-RPR by an idler loop between the base
and the platform (paper 000, Sec. 2, Figs. 2(b) and 3, eqs. 1-9).

The RRR chain E-F-P (link 5 = EF pivoted on the base at E, link 6 = FP pinned to the platform
at P) is added to the plain 3-RPR; eight counterweights (eqs. 5a-d) put the centre of mass of
every cylinder on A_i, of every piston on C_i, of link 6 (with the platform and the pistons
lumped at P) on F and of link 5 (with all that lumped at F) on E, so the total centre of mass
stays on E. The angular momentum is then eq. 8, cancelled by six chained counter-rotations
(eqs. 9a-d, massless discs, every mesh ratio -1): Icr1 on the base at each A_i geared to the
cylinder (w = -theta_i'); Icr2 carried by link 6 geared to the platform (w = 2 theta6' - phi');
Icr3 carried by link 5 geared to link 6 (w = 2 theta5' - theta6'); Icr4 on the base geared to
link 5 (w = -theta5'). The discs on moving carriers are what the "2 Icr" terms of eqs. 9c-d
pay for (../shared/reference/PAPERS.md).

Positions are signed lengths along the links, as the template's centres of mass: the paper's
rcp1 L1 from A_i, rcp2 L1 from B_i, rcp5 L5 from E, rcp6 L6 from F.
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
from .specs import Rpr3IdlerLoop

PATH = ("balancing",)


@dataclass(frozen=True)
class IdlerDesign:
    """The numbers eqs. 5 and 9 use, in lengths (p: centres of mass, c: counterweights)."""

    L1: float
    m1: float
    p1: float
    I1: float
    m2: float
    p2: float
    I2: float
    mp: float
    Ip: float
    Rp: float
    L5: float
    m5: float
    p5: float
    I5: float
    L6: float
    m6: float
    p6: float
    I6: float
    c1: float
    c2: float
    c5: float
    c6: float


def counterweight_masses(d: IdlerDesign) -> dict[str, float]:
    """Eqs. 5a-d in lengths: mcp1 = -m1 p1 / c1 (cylinder's centre of mass on A_i);
    mcp2 = -m2 (L1 - p2) / (L1 - c2) (piston's on C_i); mcp6 = -(M_P L6 + m6 p6) / c6 with
    M_P = 3 (m2 + mcp2) + mp lumped at P (link 6's on F); mcp5 = -((M_P + m6 + mcp6) L5 + m5 p5) / c5
    (link 5's on E)."""
    mcp1 = -d.m1 * d.p1 / d.c1
    mcp2 = -d.m2 * (d.L1 - d.p2) / (d.L1 - d.c2)
    MP = 3 * (d.m2 + mcp2) + d.mp
    mcp6 = -(MP * d.L6 + d.m6 * d.p6) / d.c6
    mcp5 = -((MP + d.m6 + mcp6) * d.L5 + d.m5 * d.p5) / d.c5
    return {"mcp1": mcp1, "mcp2": mcp2, "mcp6": mcp6, "mcp5": mcp5}


def counter_rotation_inertias(d: IdlerDesign, m: dict[str, float]) -> dict[str, float]:
    """Eqs. 9a-d: Icr1 = I1 + I2 + m1 p1^2 + mcp1 c1^2 + m2 (L1 - p2)^2 + mcp2 (L1 - c2)^2;
    Icr2 = Ip + 3 (m2 + mcp2) Rp^2; Icr3 = I6 + m6 p6^2 + mcp6 c6^2 + M_P L6^2 + 2 Icr2;
    Icr4 = I5 + m5 p5^2 + mcp5 c5^2 + (M_P + m6 + mcp6) L5^2 + 2 Icr3."""
    MP = 3 * (d.m2 + m["mcp2"]) + d.mp
    Icr1 = d.I1 + d.I2 + d.m1 * d.p1**2 + m["mcp1"] * d.c1**2 + d.m2 * (d.L1 - d.p2) ** 2 + m["mcp2"] * (d.L1 - d.c2) ** 2
    Icr2 = d.Ip + 3 * (d.m2 + m["mcp2"]) * d.Rp**2
    Icr3 = d.I6 + d.m6 * d.p6**2 + m["mcp6"] * d.c6**2 + MP * d.L6**2 + 2 * Icr2
    Icr4 = d.I5 + d.m5 * d.p5**2 + m["mcp5"] * d.c5**2 + (MP + d.m6 + m["mcp6"]) * d.L5**2 + 2 * Icr3
    return {"Icr1": Icr1, "Icr2": Icr2, "Icr3": Icr3, "Icr4": Icr4}


def design_of(mech: rpr3.Rpr3Mechanism, method: Rpr3IdlerLoop) -> IdlerDesign:
    cw = method.counterweights
    return IdlerDesign(
        L1=mech.piston.length, m1=mech.cylinder.mass, p1=mech.cylinder.com, I1=mech.cylinder.inertia,
        m2=mech.piston.mass, p2=mech.piston.com, I2=mech.piston.inertia,
        mp=mech.platform.mass, Ip=mech.platform.inertia, Rp=mech.platform_radius,
        L5=method.link5.length, m5=method.link5.mass, p5=method.link5.com, I5=method.link5.inertia,
        L6=method.link6.length, m6=method.link6.mass, p6=method.link6.com, I6=method.link6.inertia,
        c1=cw.cylinder, c2=cw.piston, c5=cw.link5, c6=cw.link6,
    )


def add_idler_loop(mech: rpr3.Rpr3Mechanism, method: Rpr3IdlerLoop, model: Model, t: np.ndarray) -> Model:
    """The 3-RPR with the RRR chain E-F-P (Fig. 2(b)); a located error where the chain cannot
    reach P."""
    pose = rpr3.pose_of(model)
    E = np.asarray(method.E, dtype=float)
    L5, L6 = method.link5.length, method.link6.length
    P = np.stack([pose.x(t)[0], pose.y(t)[0]], axis=1)
    dist = np.hypot(P[:, 0] - E[0], P[:, 1] - E[1])
    bad = (dist >= L5 + L6) | (dist <= abs(L5 - L6))
    if np.any(bad):
        k = int(np.argmax(bad))
        raise SpecFieldError(
            PATH + ("link6", "length"),
            f"the idler loop cannot reach P at t = {t[k]:.4g} s: |EP| = {dist[k]:.4g} m is outside "
            f"({abs(L5 - L6):.4g}, {L5 + L6:.4g}) m, the reach of links 5 ({L5:g} m) and 6 ({L6:g} m)",
        )
    d0 = dist[0]
    e = (P[0] - E) / d0
    a = (L5**2 - L6**2 + d0**2) / (2 * d0)
    h = math.sqrt(max(L5**2 - a**2, 0.0))
    F = E + a * e + method.branch * h * np.array([-e[1], e[0]])
    ang = lambda U, V: math.atan2(V[1] - U[1], V[0] - U[0])  # noqa: E731
    bodies = []
    for name, lk, a_, b_ in (("link5", method.link5, "E", "F"), ("link6", method.link6, "F", "P")):
        bodies.append(Body(name, lk.mass, (lk.com, lk.com_offset), lk.inertia,
                           {a_: (0.0, 0.0), b_: (lk.length, 0.0)}, outline=(a_, b_)))
    joints = (
        Revolute("E", FRAME, "link5", (float(E[0]), float(E[1])), (0.0, 0.0)),
        Revolute("F", "link5", "link6", (L5, 0.0), (0.0, 0.0)),
        Revolute("P", "link6", "platform", (L6, 0.0), (0.0, 0.0)),
    )
    out = model.add(tuple(bodies), joints, {
        "link5": (float(E[0]), float(E[1]), ang(E, F)),
        "link6": (float(F[0]), float(F[1]), ang(F, P[0])),
    })
    return replace(out, name="3-RPR with idler loop", frame_points={**out.frame_points, "E": (float(E[0]), float(E[1]))})


def balance(ctx: BalanceContext) -> BalanceResult:
    """Stages: unbalanced (plain 3-RPR), idler loop, counterweights (eqs. 5a-d), counter-rotations
    (eqs. 9a-d)."""
    mech: rpr3.Rpr3Mechanism = ctx.mechanism
    method: Rpr3IdlerLoop = ctx.balancing
    model = ctx.model
    for key in ("link5", "link6"):
        if getattr(method, key).com_offset:
            raise SpecFieldError(PATH + (key, "com_offset"), "eqs. 5 and 9 assume centres of mass on the link axes")
    t = rpr3.sample_times(model)  # where the idler loop must reach P (the motion's own samples)
    d = design_of(mech, method)
    cwp = PATH + ("counterweights",)
    if d.c1 == 0 or d.c5 == 0 or d.c6 == 0 or d.c2 == d.L1:
        raise SpecFieldError(cwp, "a counterweight on the joint it should balance about (A_i, C_i, E, F) cannot balance anything")
    m = counterweight_masses(d)
    where = {"mcp1": ("cylinder", "eq. 5a", "A_i"), "mcp2": ("piston", "eq. 5b", "C_i"),
             "mcp6": ("link6", "eq. 5c", "F"), "mcp5": ("link5", "eq. 5d", "E")}
    for name, (key, eq, joint) in where.items():
        if m[name] < 0:
            raise SpecFieldError(
                cwp + (key,),
                f"{eq} gives a negative counterweight mass {name} = {m[name]:.4g} kg at this position: "
                f"put the counterweight on the other side of {joint}",
            )
    I = counter_rotation_inertias(d, m)
    params = [
        Parameter("mcp1", m["mcp1"], "kg", "eq. 5a", "counterweight on each cylinder (link i1)"),
        Parameter("mcp2", m["mcp2"], "kg", "eq. 5b", "counterweight on each piston (link i2)"),
        Parameter("mcp6", m["mcp6"], "kg", "eq. 5c", "counterweight on link 6 (FP)"),
        Parameter("mcp5", m["mcp5"], "kg", "eq. 5d", "counterweight on link 5 (EF)"),
        Parameter("rcp1", d.c1 / d.L1, "", "spec", "cylinder counterweight position / L1, from A_i"),
        Parameter("rcp2", d.c2 / d.L1, "", "spec", "piston counterweight position / L1, from B_i"),
        Parameter("rcp5", d.c5 / d.L5, "", "spec", "link 5 counterweight position / L5, from E"),
        Parameter("rcp6", d.c6 / d.L6, "", "spec", "link 6 counterweight position / L6, from F"),
        Parameter("Icr1", I["Icr1"], "kg m^2", "eq. 9a", "counter-rotation on the base at each A_i, geared to the cylinder"),
        Parameter("Icr2", I["Icr2"], "kg m^2", "eq. 9b", "counter-rotation carried by link 6, geared to the platform"),
        Parameter("Icr3", I["Icr3"], "kg m^2", "eq. 9c", "counter-rotation carried by link 5, geared to link 6"),
        Parameter("Icr4", I["Icr4"], "kg m^2", "eq. 9d", "counter-rotation on the base at E, geared to link 5"),
    ]
    idler = add_idler_loop(mech, method, model, t)
    cw = idler
    L1 = d.L1
    for i in range(1, 4):
        cw = add_counterweight(cw, f"cyl{i}", f"mcp1 (leg {i})", m["mcp1"], (d.c1, 0.0))
        cw = add_counterweight(cw, f"piston{i}", f"mcp2 (leg {i})", m["mcp2"], (d.c2 - L1, 0.0))
    cw = add_counterweight(cw, "link5", "mcp5", m["mcp5"], (d.c5, 0.0))
    cw = add_counterweight(cw, "link6", "mcp6", m["mcp6"], (d.c6, 0.0))
    full = cw
    A = rpr3.base_points(mech.base_radius)
    s1 = 0.25 * mech.base_radius
    for i in range(3):
        at = A[i] * (1 + s1 / mech.base_radius)
        full = add_counter_rotation(full, f"cr1.{i + 1}", carrier=FRAME, at=(float(at[0]), float(at[1])),
                                    geared_to=f"cyl{i + 1}", ratio=-1.0, inertia=I["Icr1"],
                                    radius=s1 / 2, radius_geared=s1 / 2)
    s6, s5 = 0.3 * d.L6, 0.3 * d.L5
    full = add_counter_rotation(full, "cr2", carrier="link6", at=(d.L6 - s6, 0.0), geared_to="platform",
                                ratio=-1.0, inertia=I["Icr2"], radius=s6 / 2, radius_geared=s6 / 2)
    full = add_counter_rotation(full, "cr3", carrier="link5", at=(d.L5 - s5, 0.0), geared_to="link6",
                                ratio=-1.0, inertia=I["Icr3"], radius=s5 / 2, radius_geared=s5 / 2)
    E = np.asarray(method.E, dtype=float)
    th5 = idler.initial["link5"][2]
    at4 = E - s5 * np.array([math.cos(th5), math.sin(th5)])
    full = add_counter_rotation(full, "cr4", carrier=FRAME, at=(float(at4[0]), float(at4[1])), geared_to="link5",
                                ratio=-1.0, inertia=I["Icr4"], radius=s5 / 2, radius_geared=s5 / 2)
    stages = [replace(st, style=rpr3.STYLES[st.name]) for st in (
        Stage("unbalanced", "unbalanced", model, "the plain 3-RPR (Fig. 2(a))"),
        Stage("idler_loop", "idler loop", idler, "the RRR chain E-F-P added between the base and the platform (Fig. 2(b))"),
        Stage("counterweights", "counterweights", cw, "eight counterweights of eqs. 5a-d (Fig. 3)", balances="force"),
        Stage("counter_rotations", "counter-rotations", full,
              "six chained counter-rotations of eqs. 9a-d: three on the base at A_i, one on link 6, one on "
              "link 5, one on the base at E", balances="force+moment"),
    )]  # the paper's line styles
    notes = [
        "Counter-rotations are massless discs; Icr2 and Icr3 turn on moving carriers (links 6 and 5) "
        "and mesh with the platform and link 6: the '2 Icr2' and '2 Icr3' terms of eqs. 9c-d are "
        "their spin, 2 theta6' - phi' and 2 theta5' - theta6'.",
    ]
    return BalanceResult(params, stages, notes)


def _notation() -> dict:
    from ...notation import Sym, names_table, ours

    legs = range(1, 4)
    names = names_table(parts={
        "link5": Sym("link 5", "link 5 of the idler loop, EF"),
        "link6": Sym("link 6", "link 6 of the idler loop, FP"),
        **{f"mcp{j} (leg {i})": Sym(f"m_{{cp{j}}} (leg {i})", f"counterweight on link {i}{j} (eqs. 5a-b)")
           for j in (1, 2) for i in legs},
        "mcp5": Sym("m_{cp5}", "counterweight on link 5 (eq. 5d)"),
        "mcp6": Sym("m_{cp6}", "counterweight on link 6 (eq. 5c)"),
        **{f"cr1.{i}": Sym(f"I_{{cr1}} (leg {i})", f"counter-rotation on the base at A_{i} (eq. 9a)") for i in legs},
        "cr2": Sym("I_{cr2}", "counter-rotation carried by link 6, geared to the platform (eq. 9b)"),
        "cr3": Sym("I_{cr3}", "counter-rotation carried by link 5, geared to link 6 (eq. 9c)"),
        "cr4": Sym("I_{cr4}", "counter-rotation on the base at E (eq. 9d)"),
    }, params={
        **{f"mcp{j}": Sym(f"m_{{cp{j}}}", f"mass of counterweight {j} (eqs. 5a-d)") for j in (1, 2, 5, 6)},
        **{f"rcp{j}": Sym(f"r_{{cp{j}}}", f"position coefficient of counterweight {j}") for j in (1, 2, 5, 6)},
        **{f"Icr{k}": Sym(f"I_{{cr{k}}}", f"inertia of counter-rotation {k} (eqs. 9a-d)") for k in (1, 2, 3, 4)},
    })
    return dict(names) | {
        "balancing.E": Sym("E", "base pivot of the idler loop E-F-P (the paper: E = O)"),
        "balancing.link5.length": Sym("L_5", "length EF of link 5"),
        "balancing.link5.mass": Sym("m_5", "mass of link 5"),
        "balancing.link5.com": Sym("r_5 L_5", "centre of mass S_5 from E along EF"),
        "balancing.link5.com_offset": ours("e_5", "offset of S_5 normal to EF"),
        "balancing.link5.inertia": Sym("I_5", "axial moment of inertia of link 5"),
        "balancing.link6.length": Sym("L_6", "length FP of link 6"),
        "balancing.link6.mass": Sym("m_6", "mass of link 6"),
        "balancing.link6.com": Sym("r_6 L_6", "centre of mass S_6 from F along FP"),
        "balancing.link6.com_offset": ours("e_6", "offset of S_6 normal to FP"),
        "balancing.link6.inertia": Sym("I_6", "axial moment of inertia of link 6"),
        "balancing.branch": ours("σ", "assembly branch of the idler loop (side of F)"),
        "balancing.counterweights.cylinder": Sym("r_{cp1} L_1", "counterweight M_{cp1} on each cylinder, from A_i towards C_i (negative: beyond A_i)"),
        "balancing.counterweights.piston": Sym("r_{cp2} L_1", "counterweight M_{cp2} on each piston, from B_i towards C_i"),
        "balancing.counterweights.link5": Sym("r_{cp5} L_5", "counterweight M_{cp5} on link 5, from E towards F (negative: beyond E)"),
        "balancing.counterweights.link6": Sym("r_{cp6} L_6", "counterweight M_{cp6} on link 6, from F towards P (negative: beyond F)"),
    }

#: Paper 000's symbols (Sec. 2, Fig. 3, eqs. 4-9) for this method's inputs.
NOTATION = _notation()
