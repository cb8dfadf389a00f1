"""Decoupling a 2R arm by a gear pair and mass redistribution, then cancelling its shaking
moment with one counter-rotating gear (paper 002, Sec. 4, eqs. 3-20).

The parts (Fig. 3): gear 2' fixed on link 2 at joint B; gear 1' pivoted on link 1 at C (a
revolute) and meshing with 2', so that w1' - w1 = rho (w2 - w1) (carrier link 1, rho = -1 for the
paper's identical gears); counterweights on links 2 and 1. With link 1's assembly (link,
attachments; mass m_a, centre of mass c_a from A, centroidal inertia I_a), gear 1' (m_g at C,
inertia I_g) and link 2's assembly (link, gear 2', counterweight; m_b, centre of mass c_b from
B, inertia I_b), the kinetic energy gives the mass matrix (eqs. 4-6 with the gear):

    M11 = I_a + m_a |c_a|^2 + m_g |AC|^2 + I_g + I_b + m_b (l1^2 + |c_b|^2 + 2 l1 (c_bx cos q2 - c_by sin q2))
    M12 = rho I_g + I_b + m_b (|c_b|^2 + l1 (c_bx cos q2 - c_by sin q2))
    M22 = rho^2 I_g + I_b + m_b |c_b|^2

and the gravity torques D1, D2 of eqs. 13-14 are those of the total centre of mass. Hence the
three decoupling conditions:

    (1) c_b = 0: link 2 with gear 2' has its centre of mass on B          (l_BS2 = 0)
    (2) rho I_g + I_b = 0: I_S1' = I_S2 + I_S2' for rho = -1
    (3) m_a c_a + m_g AC + m_b (l1, 0) = 0: the total centre of mass on A  (m1 l_AS1 = m1' l_AC + (m2 + m2') l1)

and then tau1 = J1 q1'', tau2 = J2 q2'' (eqs. 17-18) with J1 = M11, J2 = M22 constant, the
shaking force is the constant weight (eq. 19) and the shaking moment about A is -J1 q1''
(eq. 20). Gear 1'' fixed on link 1 at A meshes with gear 3 on the frame (theta3 = -theta1): with
I3 = J1 the total angular momentum J1 q1' + I3 (-q1') vanishes and so does the shaking moment.

The counterweights' masses are solved from conditions (1) and (3) for the distances the spec
chooses (each on the ray that cancels its link's first moment), gear 1''s inertia from (2).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .template import SerialArmMechanism
from ...model import FRAME, Attachment, Model
from ...spec_parts import SpecFieldError
from ...balancing.base import BalanceResult, Parameter, Stage
from ...balancing.context import BalanceContext
from ...balancing.parts import add_counter_rotation, add_counterweight
from .specs import GearDecoupling

ROOT = ("balancing",)


@dataclass(frozen=True)
class MassMatrix2R:
    """Closed form of the 2R (+ gear 1') mass matrix: M_ij = k0 + kc cos q2 + ks sin q2."""

    M11: tuple[float, float, float]
    M12: tuple[float, float, float]
    M22: tuple[float, float, float]

    def values(self, q2: np.ndarray) -> np.ndarray:
        c, s = np.cos(q2), np.sin(q2)
        ent = [np.asarray(k[0] + k[1] * c + k[2] * s, dtype=float) for k in (self.M11, self.M12, self.M22)]
        return np.stack([np.stack([ent[0], ent[1]], -1), np.stack([ent[1], ent[2]], -1)], -2)

    def text(self, entry: str) -> str:
        """'0.132 + 0.054 cos θ₂'; a coefficient below 1e-12 of the matrix's largest is round-off
        and reads 0."""
        k0, kc, ks = getattr(self, entry)
        scale = max(abs(v) for e in (self.M11, self.M12, self.M22) for v in e)
        out = f"{k0:.6g}" if abs(k0) > 1e-12 * scale else "0"
        for v, f in ((kc, "cos θ₂"), (ks, "sin θ₂")):
            if abs(v) > 1e-12 * scale:
                out += f" {'+' if v > 0 else '-'} {abs(v):.6g} {f}"
        return out


def _assembly(model: Model, name: str) -> tuple[float, np.ndarray, float]:
    m, c, i = model.body(name).mass_properties()
    return m, np.asarray(c, dtype=float), i


def mass_matrix_2r(model: Model, l1: float, gear: tuple[float, float, float, float] | None) -> MassMatrix2R:
    """The closed form above for a model with bodies link1, link2 (and gear 1': (m_g, AC, I_g, rho))."""
    ma, ca, Ia = _assembly(model, "link1")
    mb, cb, Ib = _assembly(model, "link2")
    mg, ac, Ig, rho = gear if gear is not None else (0.0, 0.0, 0.0, 0.0)
    cb2 = float(cb @ cb)
    k11 = Ia + ma * float(ca @ ca) + mg * ac**2 + Ig + Ib + mb * (l1**2 + cb2)
    return MassMatrix2R(
        (k11, 2 * mb * l1 * cb[0], -2 * mb * l1 * cb[1]),
        (rho * Ig + Ib + mb * cb2, mb * l1 * cb[0], -mb * l1 * cb[1]),
        (rho**2 * Ig + Ib + mb * cb2, 0.0, 0.0),
    )


def balance(ctx: BalanceContext) -> BalanceResult:
    mech: SerialArmMechanism = ctx.mechanism
    method: GearDecoupling = ctx.balancing
    model = ctx.model
    if len(mech.links) != 2:
        raise SpecFieldError(("mechanism", "links"), f"gear_decoupling balances a 2R arm (got {len(mech.links)} links)")
    # a payload on link 2 is part of link 2's assembly: conditions (1)-(3) include it
    l1 = mech.links[0].length
    g1, g2, cw = method.gear_1p, method.gear_2p, method.counterweights
    if not 0 <= g1.position < l1:
        raise SpecFieldError(ROOT + ("gear_1p", "position"),
                             f"C must lie on link 1 between A and B so that gears 1' and 2' can mesh (0 <= l_AC < l1 = {l1:g} m)")
    params: list[Parameter] = []
    P = lambda *a: params.append(Parameter(*a))  # noqa: E731
    notes: list[str] = []

    # gear 2' on link 2 at B, then the link 2 counterweight: condition (1)
    r_mesh = l1 - g1.position  # |CB| = r1' + r2'
    rho = g1.ratio
    r1p = r_mesh / (1 - rho)  # r2' / r1' = -rho
    r2p = r_mesh - r1p
    dec = model.replace_body(model.body("link2").with_attachments(
        Attachment("gear 2'", g2.mass, (0.0, 0.0), g2.inertia, "gear", r2p)))
    m2, c2, _ = _assembly(dec, "link2")
    first2 = m2 * c2
    m_cw2 = float(np.hypot(*first2)) / cw.link2.distance
    u2 = -first2 / np.hypot(*first2) if m_cw2 > 0 else np.array([-1.0, 0.0])
    if m_cw2 > 0:
        dec = add_counterweight(dec, "link2", "counterweight 2", m_cw2, tuple(cw.link2.distance * u2), cw.link2.inertia)
    mb, cb, Ib = _assembly(dec, "link2")
    # gear 1' inertia from condition (2)
    Ig = -Ib / rho
    # link 1 counterweight: condition (3), the total centre of mass on A
    m1, c1, _ = _assembly(dec, "link1")
    first1 = m1 * c1 + g1.mass * np.array([g1.position, 0.0]) + mb * np.array([l1, 0.0])
    m_cw1 = float(np.hypot(*first1)) / cw.link1.distance
    u1 = -first1 / np.hypot(*first1) if m_cw1 > 0 else np.array([-1.0, 0.0])
    if m_cw1 > 0:
        dec = add_counterweight(dec, "link1", "counterweight 1", m_cw1, tuple(cw.link1.distance * u1), cw.link1.inertia)
    dec = add_counter_rotation(dec, "gear1p", carrier="link1", at=(g1.position, 0.0), geared_to="link2",
                               ratio=rho, inertia=Ig, mass=g1.mass, radius=r1p, radius_geared=r2p)
    ma, ca, Ia = _assembly(dec, "link1")

    after = mass_matrix_2r(dec, l1, (g1.mass, g1.position, Ig, rho))
    J1, J2 = after.M11[0], after.M22[0]
    cond1 = float(np.hypot(*cb))
    cond2 = rho * Ig + Ib
    total_first = ma * ca + g1.mass * np.array([g1.position, 0.0]) + mb * np.array([l1, 0.0])
    cond3 = float(np.hypot(*total_first))

    # gear 3 on the frame, identical to gear 1'' on link 1 at A: theta3 = -theta1, I3 = J1
    A = np.asarray(mech.base, dtype=float)
    G3 = np.asarray(method.counter_rotation.position, dtype=float)
    d3 = float(np.hypot(*(G3 - A)))
    if d3 == 0:
        raise SpecFieldError(ROOT + ("counter_rotation", "position"), "gear 3 cannot sit on joint A")
    full = add_counter_rotation(dec, "gear3", carrier=FRAME, at=tuple(G3), geared_to="link1", ratio=-1.0,
                                inertia=J1, radius=d3 / 2, radius_geared=d3 / 2)
    full = full.replace_body(full.body("link1").with_attachments(
        Attachment("gear 1''", 0.0, (0.0, 0.0), 0.0, "gear", d3 / 2)))

    m_link1 = mech.links[0].mass + m_cw1
    P("m_cw2", m_cw2, "kg", "condition (1): c_b = 0", "counterweight on link 2 (centre of mass of link 2 + gear 2' on B)")
    P("cw2_angle", math.degrees(math.atan2(u2[1], u2[0])), "deg", "condition (1)", "direction of counterweight 2 in link 2's frame (180: beyond B)")
    P("m_cw1", m_cw1, "kg", "condition (3): total centre of mass on A", "counterweight on link 1")
    P("cw1_angle", math.degrees(math.atan2(u1[1], u1[0])), "deg", "condition (3)", "direction of counterweight 1 in link 1's frame (180: beyond A)")
    P("m1", m_link1, "kg", "Sec. 4", "redistributed link 1: link + counterweight 1 (gear 1' excluded)")
    bare1 = dec.body("link1")
    mm1, cc1, ii1 = bare1.mass_properties()
    P("l_AS1", float(np.hypot(*cc1)), "m", "Sec. 4", "distance of the redistributed link 1's centre of mass from A (on the side opposite B)")
    P("I_S1", ii1, "kg m^2", "Sec. 4", "centroidal inertia of the redistributed link 1")
    P("m2_plus_m2p", mb, "kg", "Sec. 4", "link 2 with gear 2' and counterweight 2")
    P("l_BS2", cond1, "m", "condition (1)", "distance of link 2 + gear 2''s centre of mass from B")
    P("I_S2_plus_I_S2p", Ib, "kg m^2", "Sec. 4", "centroidal inertia of link 2 with gear 2' and counterweight 2 (about B)")
    P("I_S1p", Ig, "kg m^2", "condition (2): I_S1' = -(I_S2 + I_S2')/rho", "axial inertia of gear 1'")
    P("r1p", r1p, "m", "|CB| = r1' + r2', r2' = -rho r1'", "pitch radius of gear 1'")
    P("r2p", r2p, "m", "|CB| = r1' + r2'", "pitch radius of gear 2'")
    P("J1", J1, "kg m^2", "eq. 17", "decoupled inertia of joint 1: tau1 = J1 q1''")
    P("J2", J2, "kg m^2", "eq. 18", "decoupled inertia of joint 2: tau2 = J2 q2''")
    P("I3", J1, "kg m^2", "Sec. 4: I3 = J1, theta3 = -theta1", "axial inertia of the counter-rotating gear 3 on the frame")
    P("condition1_residual", cond1, "m", "condition (1)", "|c_b| after redistribution (0: satisfied)")
    P("condition2_residual", cond2, "kg m^2", "condition (2)", "rho I_S1' + I_S2 + I_S2' (0: satisfied)")
    P("condition3_residual", cond3, "kg m", "condition (3)", "|m_a c_a + m1' AC + m_b AB| (0: total centre of mass on A)")
    P("M12_max_after", float(max(abs(v) for v in after.M12)), "kg m^2", "eq. 5", "largest coefficient of M12 after decoupling")
    if cw.link1.inertia or cw.link2.inertia:
        notes.append(
            "The counterweights carry the centroidal inertias the spec gives (balancing.counterweights): "
            "the decoupling conditions fix only the redistributed links' inertias (paper 002 lists only "
            "those), so the counterweights' own are the spec's choice."
        )

    stages = [
        Stage("unbalanced", "unbalanced", model, "the 2R arm as given"),
        Stage("decoupled", "decoupled", dec,
              "gear 2' on link 2 at B, gear 1' on link 1 at C, counterweights (conditions 1-3): "
              "tau_i = J_i q_i'', constant shaking force", balances="force"),
        Stage("decoupled_counter_rotation", "decoupled + counter-rotation", full,
              "gear 1'' on link 1 at A meshing with gear 3 on the frame, I3 = J1", balances="force+moment"),
    ]
    return BalanceResult(params, stages, notes)


def _notation() -> dict:
    """Paper 002's symbols (Figs. 1, 3-4, eqs. 3-16): joints A, B, centres of mass S_1, S_2,
    angles θ_1, θ_2; they replace the serial arm's generic ones for the 2R arm."""
    from ...notation import Sym, drive_table, names_table, ours

    drives = {"q1": Sym("θ_1", "angle of link 1 relative to the base"),
              "q2": Sym("θ_2", "angle of link 2 relative to link 1")}
    table = drive_table(drives, end_time="T")
    # the model's names (Figs. 1, 3): drivers θ_1, θ_2, gears 1' (on link 1 at C) and 3 (on the
    # frame), joints A (frame-link 1), B (link 1-link 2), C (gear 1' on link 1)
    table.update(names_table(
        drivers=drives,
        parts={"gear1p": Sym("gear 1'", "gear 1', turning on link 1 at C, meshing with gear 2'"),
               "gear3": Sym("gear 3", "gear 3 on the frame, meshing with gear 1'' (θ_3 = −θ_1)")},
        joints={"J1": Sym("A", "joint A of link 1 on the frame"), "J2": Sym("B", "joint B between links 1 and 2"),
                "link1-gear1p": Sym("C", "joint C of gear 1' on link 1")},
        params={"J1": Sym("J_1", "inertia that actuator 1 sees once decoupled (eq. 17)"),
                "J2": Sym("J_2", "inertia that actuator 2 sees once decoupled (eq. 18)"),
                "I3": Sym("I_3", "inertia of gear 3 (I_3 = J_1)"),
                "m1": Sym("m_1", "mass of link 1 as redistributed"), "l_AS1": Sym("l_{AS1}", "A to S_1"),
                "l_BS2": Sym("l_{BS2}", "B to S_2"), "I_S1": Sym("I_{S1}", "inertia of link 1 about S_1"),
                "I_S1p": Sym("I_{S1'}", "inertia of gear 1'"),
                "m2_plus_m2p": Sym("m_2 + m_{2'}", "link 2 with gear 2'"),
                "I_S2_plus_I_S2p": Sym("I_{S2} + I_{S2'}", "link 2 with gear 2'")},
    ))
    table.update({
        "mechanism.base": Sym("A", "joint A of link 1 on the frame"),
        "mechanism.links[0].length": Sym("l_1", "length AB of link 1"),
        "mechanism.links[0].mass": Sym("m_1", "mass of link 1"),
        "mechanism.links[0].com": Sym("l_{AS1}", "distance of link 1's centre of mass S_1 from A"),
        "mechanism.links[0].com_offset": ours("e_1", "offset of S_1 normal to AB"),
        "mechanism.links[0].inertia": Sym("I_{S1}", "axial moment of inertia of link 1 about S_1"),
        "mechanism.links[1].length": ours("l_2", "length of link 2 from B (its tip; the dynamics do not depend on it)"),
        "mechanism.links[1].mass": Sym("m_2", "mass of link 2"),
        "mechanism.links[1].com": Sym("l_{BS2}", "distance of link 2's centre of mass S_2 from B"),
        "mechanism.links[1].com_offset": ours("e_2", "offset of S_2 normal to link 2"),
        "mechanism.links[1].inertia": Sym("I_{S2}", "axial moment of inertia of link 2 about S_2"),
        "motion.duration": ours("T", "duration of the motion"),
        "balancing.gear_1p.position": Sym("l_{AC}", "position of gear 1''s axis C along link 1 from A"),
        "balancing.gear_1p.mass": Sym("m_{1'}", "mass of gear 1'"),
        "balancing.gear_1p.ratio": ours("U_{1'2}", "ω_1' − ω_1 = U (ω_2 − ω_1); −1 for identical gears"),
        "balancing.gear_2p.mass": Sym("m_{2'}", "mass of gear 2', fixed on link 2 at B"),
        "balancing.gear_2p.inertia": Sym("I_{S2'}", "axial moment of inertia of gear 2'"),
        "balancing.counterweights.link1.distance": ours("l_{A,cw1}", "distance of link 1's counterweight from A (puts the total centre of mass on A)"),
        "balancing.counterweights.link1.inertia": ours("I_{cw1}", "centroidal inertia of link 1's counterweight"),
        "balancing.counterweights.link2.distance": ours("l_{B,cw2}", "distance of link 2's counterweight from B (puts link 2 + gear 2' centre of mass on B)"),
        "balancing.counterweights.link2.inertia": ours("I_{cw2}", "centroidal inertia of link 2's counterweight"),
        "balancing.counter_rotation.position": ours("O_3", "centre of the counter-rotating gear 3 on the frame (I_3 = J_1)"),
    })
    return table

#: Paper 002's symbols for this method's inputs and for the 2R arm it balances.
NOTATION = _notation()
