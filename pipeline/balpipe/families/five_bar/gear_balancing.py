"""Complete balancing of the fixed-sequence 5R (paper 004, Secs. IV-V, eqs. 9-21).

Shaking force: counterweights put the centre of mass of each distal link (with gear 3' or 4')
on its elbow B_j (eqs. 11-12), then that of each input link, loaded by the balanced distal link
at B_j, on its base pivot A_j (eqs. 15-16; eqs. 9-10 without gear masses). Each leg's centre of
mass is then fixed at A_j, so the shaking force vanishes for any motion.

Shaking moment: with the force balanced the angular momentum is the same about every point; per
leg, about A_j,

    H = J1 w1 + K3 w3 + J2 w2 + K4 w4 + I5 w5 + I6 w6 + I7 w7          (eqs. 14, 17)

with J_j the input link's inertia about A_j (gear 1' or 2' included) plus the balanced distal
link's mass times l_j^2, and K_{j+2} the balanced distal link's centroidal inertia (gear 3' or
4' included). Gears 6 and 7 turn on axes A1, A2 carried by the input links and mesh with gears
3', 4' fixed on the distal links (planetary, carrier the input link): w6 = w1 + U63 (w1 - w3),
w7 = w2 + U74 (w2 - w4), U63 = r3'/r6. The idler 5 turns with w5 = U51 w1, U51 = -r1'/r5, and
the inputs are coupled, w2 = U21 w1. H = 0 for every motion when the coefficients of w1, w3,
w4 vanish:

    I6 = K3 / U63,  I7 = K4 / U74                                       (eqs. 20, 21)
    I5 = -(J1 + (1 + U63) I6 + U21 (J2 + (1 + U74) I7)) / U51           (eq. 19)

Stages, following the paper's sections: ``counterweights`` adds the counterweights of eqs. 9-12
(Sec. IV, no gears 3', 4' yet); ``full`` fixes gears 3', 4' on the distal links with the
counterweights recomputed by eqs. 15-16 for their masses, adds the planetary gears 6, 7 and gives
gear 5 the inertia of eq. 19 (Sec. V).

The inertias are read from the force-balanced model's bodies, so every part on the links
(counterweights, gears, their masses) is accounted for. The paper's eq. 17 takes I1..I4 as the
balanced links' centroidal inertias; ``balanced_inertias`` reproduces that reading by giving each
counterweight the inertia that makes it so (possibly negative, see the notes).
"""

from __future__ import annotations

from dataclasses import replace

from .template import FiveBarMechanism, Synthesis
from ...model import Attachment, Body, Gear, Model, Revolute
from ...spec_parts import SpecFieldError
from ...balancing.base import BalanceResult, Parameter, Stage
from ...balancing.context import BalanceContext
from .specs import CounterRotation, FiveBarGearBalancing


def synthesis_of(model: Model) -> Synthesis:
    for d in model.drivers:
        syn = getattr(d.law, "synthesis", None)
        if syn is not None:
            return syn
    raise ValueError("the model has no fixed-sequence synthesis (a five-bar without coupling)")


def _inertias(links: dict[str, Body], syn: Synthesis, U: float) -> dict[str, float]:
    """Eqs. 19-21 from the force-balanced bodies (frames: origin at A_j / B_j, x along the link)."""
    out = {}
    for j, (prox, dist) in ((1, ("link1", "link3")), (2, ("link2", "link4"))):
        m, c, i = links[prox].mass_properties()
        md, cd, id_ = links[dist].mass_properties()
        lj = links[prox].point(f"B{j}")[0]
        out[f"J{j}"] = i + m * (c[0] ** 2 + c[1] ** 2) + md * lj**2
        out[f"K{j + 2}"] = id_ + md * (cd[0] ** 2 + cd[1] ** 2)  # about B_j (the com is there)
    out["I6"] = out["K3"] / U
    out["I7"] = out["K4"] / U
    out["I5"] = -(out["J1"] + (1 + U) * out["I6"] + syn.U21 * (out["J2"] + (1 + U) * out["I7"])) / syn.U51
    return out


def _counterweighted(
    mech: FiveBarMechanism, method: FiveBarGearBalancing, model: Model, with_gears: bool
) -> tuple[dict[str, Body], dict[int, float], dict[int, tuple[float, float]]]:
    """Links 1-4 with their counterweights: eqs. 9-12 (``with_gears`` False) or eqs. 11-12 and
    15-16 with gears 3', 4' fixed on the distal links (True). Returns the bodies, the counterweight
    masses by index and, with balanced_inertias, (counterweight inertia, point-mass inertia)."""
    (p1, d1), (p2, d2) = mech.legs()
    cw = method.counterweights
    path = ("balancing", "counterweights")
    cr = method.counter_rotation
    U = cr.ratio
    targets = method.balanced_inertias
    bodies: dict[str, Body] = {}
    masses: dict[int, float] = {}
    icw: dict[int, tuple[float, float]] = {}

    def counterweight(j: int, lk, c: float, mass: float, target: float | None) -> Attachment:
        inertia = 0.0
        if target is not None:
            bare = Body("tmp", lk.mass, (lk.com, 0.0), lk.inertia, attachments=(Attachment("cw", mass, (c, 0.0)),))
            point_mass = bare.mass_properties()[2]
            inertia = target - point_mass
            icw[j] = (inertia, point_mass)
        return Attachment(f"counterweight {j}", mass, (c, 0.0), inertia)

    for j, (prox, dist, lp, ld) in enumerate((("link1", "link3", p1, d1), ("link2", "link4", p2, d2)), start=1):
        # eqs. 11-12: the distal link's centre of mass on B_j
        m_cw_d = -(ld.mass * ld.com) / cw.distal
        if m_cw_d < 0:
            raise SpecFieldError(
                path + ("distal",),
                f"eq. {10 + j} gives a negative counterweight mass m_CW{j + 2} = {m_cw_d:.4g} kg: put "
                f"the counterweight on the other side of B{j} (the link's centre of mass is beyond it)",
            )
        parts = [counterweight(j + 2, ld, cw.distal, m_cw_d, targets.distal if targets else None)]
        if with_gears:
            parts.append(Attachment(f"gear {j + 2}'", cr.gear_3p.mass, (0.0, 0.0), cr.gear_3p.inertia, "gear",
                                    U * lp.length / (1 + U)))
        dist_body = model.body(dist).with_attachments(*parts)
        m_dist = dist_body.mass_properties()[0]
        # eqs. 9-10 / 15-16: the input link's centre of mass, with the balanced distal link at B_j, on A_j
        m_cw_p = -(lp.mass * lp.com + m_dist * lp.length) / cw.proximal
        if m_cw_p < 0:
            raise SpecFieldError(
                path + ("proximal",),
                f"eq. {14 + j} gives a negative counterweight mass m_CW{j} = {m_cw_p:.4g} kg: put "
                f"the counterweight beyond A{j} (negative position)",
            )
        prox_body = model.body(prox)
        if with_gears and cr.gear_1p_inertia is not None:
            prox_body = replace(prox_body, attachments=tuple(
                replace(a, inertia=cr.gear_1p_inertia) if a.kind == "gear" else a for a in prox_body.attachments
            ))
        prox_body = prox_body.with_attachments(
            counterweight(j, lp, cw.proximal, m_cw_p, targets.proximal if targets else None)
        )
        bodies[prox], bodies[dist] = prox_body, dist_body
        masses[j], masses[j + 2] = m_cw_p, m_cw_d
    return bodies, masses, icw


def balance(ctx: BalanceContext) -> BalanceResult:
    mech: FiveBarMechanism = ctx.mechanism
    method: FiveBarGearBalancing = ctx.balancing
    model = ctx.model
    if mech.coupling is None:
        raise SpecFieldError(
            ("mechanism", "coupling"),
            "five_bar_gear_balancing balances the fixed-sequence five-bar: give the coupling gears "
            "(the gear 5 counter-rotation needs the inputs coupled)",
        )
    syn = synthesis_of(model)
    (p1, d1), (p2, d2) = mech.legs()
    for key, lk in (("proximal", p1), ("distal", d1), ("proximal_2", p2), ("distal_2", d2)):
        if lk.com_offset:
            raise SpecFieldError(
                ("mechanism", "links", key if getattr(mech.links, key) is not None else key.split("_")[0], "com_offset"),
                "eqs. 9-16 assume centres of mass on the link axes (com_offset 0)",
            )
    cw = method.counterweights
    for key in ("proximal", "distal"):
        if getattr(cw, key) == 0:
            raise SpecFieldError(("balancing", "counterweights", key),
                                 "a counterweight on the joint itself cannot balance anything")
    cr = method.counter_rotation
    U = cr.ratio
    if method.point_mass_stage and method.balanced_inertias is None:
        raise SpecFieldError(
            ("balancing", "point_mass_stage"),
            "the point-mass stage is the alternative to balanced_inertias; without them the full "
            "stage already has point-mass counterweights",
        )
    point_mass_full = None
    params: list[Parameter] = []
    notes: list[str] = []
    P = lambda *a: params.append(Parameter(*a))  # noqa: E731

    P("theta1i", syn.theta1i, "rad", "eqs. 1-8", "input angle of link 1 at the initial position")
    P("theta1f", syn.theta1f, "rad", "eqs. 1-8", "input angle of link 1 at the final position")
    P("theta2i", syn.theta2i, "rad", "eqs. 1-8", "input angle of link 2 at the initial position")
    P("theta2f", syn.theta2f, "rad", "eqs. 1-8", "input angle of link 2 at the final position")
    P("dtheta1", syn.dtheta1, "rad", "Sec. III", "rotation of link 1")
    P("dtheta2", syn.dtheta2, "rad", "Sec. III", "rotation of link 2")
    P("U21", syn.U21, "", "Sec. III: U21 = dtheta2 / dtheta1", "transmission ratio w2 / w1")
    P("r1p", syn.r1p, "m", "spec", "radius of gear 1'")
    P("r2p", syn.r2p, "m", "Sec. VI: r2' = r1' / U21", "radius of gear 2'")
    P("r5", syn.r5, "m", "Sec. VI: r1' + 2 r5 + r2' = |A1A2|", "radius of the idler gear 5")
    P("U51", syn.U51, "", "U51 = -r1' / r5 (eq. 17)", "w5 / w1")
    P("path_deviation", syn.path_deviation, "m", "Fig. 7 (forward kinematics)",
      "largest distance of the gripper path from the straight segment between the two positions")

    cw_links, cw_masses, _ = _counterweighted(mech, method, model, with_gears=False)
    links, masses, icw = _counterweighted(mech, method, model, with_gears=True)
    gear_masses = cr.gear_3p.mass != 0
    for j, (lp, ld) in ((1, (p1, d1)), (2, (p2, d2))):
        P(f"mCW{j}", masses[j], "kg", f"eq. {14 + j}" + ("" if gear_masses else f" (= eq. {8 + j}: no gear masses)"),
          f"counterweight on input link {j}")
        if gear_masses:
            P(f"mCW{j}_no_gears", cw_masses[j], "kg", f"eq. {8 + j}",
              f"counterweight on input link {j} before gears {j + 2}', {j + 5} are added (counterweights stage)")
        P(f"mCW{j + 2}", masses[j + 2], "kg", f"eq. {10 + j}", f"counterweight on distal link {j + 2}")
        ms_p = lp.mass + masses[j]
        P(f"m{j}_star", ms_p, "kg", "eq. 14: m* = m + m_CW", f"balanced input link {j} (link + counterweight)")
        # a massless link and counterweight have no centre of mass: 0 (on the joint)
        P(f"r{j}_star", -(lp.mass * lp.com + masses[j] * cw.proximal) / ms_p if ms_p else 0.0, "m", "Sec. VI",
          f"distance of the balanced link {j}'s centre of mass from A{j}, on the side opposite B{j}")
        ms_d = ld.mass + masses[j + 2]
        P(f"m{j + 2}_star", ms_d, "kg", "eq. 14: m* = m + m_CW", f"balanced distal link {j + 2} (link + counterweight)")
        P(f"r{j + 2}_star", abs(ld.mass * ld.com + masses[j + 2] * cw.distal) / ms_d if ms_d else 0.0, "m", "Sec. VI",
          f"distance of the balanced link {j + 2}'s centre of mass from B{j} (0: on the joint)")

    cw_model = model
    for b in cw_links.values():
        cw_model = cw_model.replace_body(b)

    I = _inertias(links, syn, U)
    for j, lp in ((1, p1), (2, p2)):
        r_planet = lp.length / (1 + U)
        P(f"r{j + 2}p", U * r_planet, "m", f"U{j + 5}{j + 2} = r{j + 2}'/r{j + 5}, r{j + 2}' + r{j + 5} = l{j}",
          f"radius of gear {j + 2}' on distal link {j + 2} at B{j}")
        P(f"r{j + 5}", r_planet, "m", f"U{j + 5}{j + 2} = r{j + 2}'/r{j + 5}, r{j + 2}' + r{j + 5} = l{j}",
          f"radius of the planetary gear {j + 5} at A{j}")
    P("U63", U, "", "spec", "w6 = w1 + U63 (w1 - w3)")
    P("U74", U, "", "spec", "w7 = w2 + U74 (w2 - w4)")
    P("J1", I["J1"], "kg m^2", "eq. 17", "I1 + I1' + m1* r1*^2 + m3* l1^2: input leg 1 about A1")
    P("J2", I["J2"], "kg m^2", "eq. 17", "I2 + I2' + m2* r2*^2 + m4* l2^2: input leg 2 about A2")
    P("K3", I["K3"], "kg m^2", "eq. 17", "I3 + I3': balanced distal link 3 about B1")
    P("K4", I["K4"], "kg m^2", "eq. 17", "I4 + I4': balanced distal link 4 about B2")
    P("I6", I["I6"], "kg m^2", "eq. 20", "axial inertia of the planetary gear 6")
    P("I7", I["I7"], "kg m^2", "eq. 21", "axial inertia of the planetary gear 7")
    P("I5", I["I5"], "kg m^2", "eq. 19", "axial inertia of the idler gear 5 (replaces the unbalanced one)")

    if icw:
        for j in sorted(icw):
            P(f"Icw{j}", icw[j][0], "kg m^2", "balanced_inertias (eq. 17's I1..I4)",
              f"centroidal inertia given to counterweight {j} so that the balanced link has the stated inertia")
        negative = {j: v for j, v in icw.items() if v[0] < 0}
        # the same design with point-mass counterweights, for comparison
        pm_links = {
            n: replace(b, attachments=tuple(
                replace(a, inertia=0.0) if a.kind == "counterweight" else a for a in b.attachments
            ))
            for n, b in links.items()
        }
        Ipm = _inertias(pm_links, syn, U)
        for k in ("I5", "I6", "I7"):
            P(f"{k}_point_masses", Ipm[k], "kg m^2", {"I5": "eq. 19", "I6": "eq. 20", "I7": "eq. 21"}[k],
              f"{k} with point-mass counterweights on the bare links (no balanced_inertias)")
        if method.point_mass_stage:
            point_mass_full = _full_stage(model, pm_links, Ipm, mech, cr)
        if negative:
            listing = ", ".join(
                f"link {j}: stated {v[0] + v[1]:.4g} < {v[1]:.4g} kg m^2" for j, v in sorted(negative.items())
            )
            notes.append(
                "The balanced links' inertias of eq. 17 (balanced_inertias) are smaller than those of "
                f"the bare links with point-mass counterweights ({listing}): no real counterweight "
                "can give them. The model realises the paper's reading with counterweights of "
                "negative centroidal inertia (Icw parameters); with point-mass counterweights the "
                f"design needs I5 = {Ipm['I5']:.4g}, I6 = {Ipm['I6']:.4g}, I7 = {Ipm['I7']:.4g} kg m^2"
                + (" (the stage 'full, point-mass counterweights')." if method.point_mass_stage else ".")
            )

    # full stage: gears 3', 4' on the distal links, planetary gears 6, 7, gear 5 with I5
    full = _full_stage(model, links, I, mech, cr)
    gear5 = model.body("gear5")
    if I["I5"] < gear5.inertia:
        notes.append(
            f"Gear 5 as built ({gear5.inertia:.4g} kg m^2) has more inertia than eq. 19 needs "
            f"({I['I5']:.4g} kg m^2): the full stage uses the computed value."
        )
    if cr.gear_1p_inertia is not None:
        notes.append(
            f"Gears 1' and 2' have {cr.gear_1p_inertia:.4g} kg m^2 in the full stage "
            "(balancing.counter_rotation.gear_1p_inertia) and the inertia of mechanism.coupling in the "
            "unbalanced and counterweights stages."
        )
    stages = [
        Stage("unbalanced", "unbalanced", model, "the fixed-sequence five-bar with gears 1', 5, 2'"),
        Stage("counterweights", "counterweights", cw_model, "counterweights of eqs. 9-12", balances="force"),
        Stage("full", "counterweights + counter-rotating gears", full,
              "gears 3', 4' on the distal links with the counterweights of eqs. 15-16, planetary gears "
              "6, 7 (eqs. 20-21) and gear 5 with the inertia of eq. 19", balances="force+moment"),
    ]
    if point_mass_full is not None:
        stages.append(Stage(
            "full_point_masses", "full, point-mass counterweights", point_mass_full,
            "as the full stage, with point-mass counterweights (no inertia of their own) on the bare "
            "links and gears 5, 6, 7 with the inertias eqs. 19-21 give for them (I5_point_masses, "
            "I6_point_masses, I7_point_masses)", balances="force+moment",
        ))
    return BalanceResult(params, stages, notes)


def _full_stage(model: Model, links: dict[str, Body], I: dict[str, float], mech: FiveBarMechanism,
                cr: CounterRotation) -> Model:
    """The unbalanced model with the counterweighted links (gears 3', 4' on the distal ones), gear
    5 given the I5 of eq. 19 and the planetary gears 6, 7 (I6, I7 of eqs. 20-21) on axes A1, A2
    carried by the input links, meshing with gears 3', 4' (r3' + r6 = l1, r4' + r7 = l2)."""
    (p1, _), (p2, _) = mech.legs()
    U = cr.ratio
    full = model
    for b in links.values():
        full = full.replace_body(b)
    gear5 = full.body("gear5")
    full = full.replace_body(replace(gear5, inertia=I["I5"] - sum(a.inertia for a in gear5.attachments)))
    new_bodies: list[Body] = []
    new_joints: list[Revolute | Gear] = []
    init: dict[str, tuple[float, float, float]] = {}
    for j, prox, dist in ((1, "link1", "link3"), (2, "link2", "link4")):
        lp = (p1, p2)[j - 1]
        r_planet = lp.length / (1 + U)
        name = f"gear{j + 5}"
        A = model.initial[prox]
        new_bodies.append(Body(name, cr.planet_mass, (0.0, 0.0), I[f"I{j + 5}"], {f"A{j}": (0.0, 0.0)},
                               radius=r_planet, kind="gear"))
        init[name] = (A[0], A[1], 0.0)
        new_joints += [
            Revolute(f"A{j}-{j + 5}", prox, name, (0.0, 0.0), (0.0, 0.0)),
            Gear(f"{j + 2}'-{j + 5}", dist, name, prox, -U, None, U * r_planet, r_planet, cr.pressure_angle),
        ]
    return full.add(tuple(new_bodies), tuple(new_joints), init)


def _notation() -> dict:
    from ...notation import Sym, names_table, ours, setting

    links = range(1, 5)
    names = names_table(
        parts={f"counterweight {j}": Sym(f"m_{{CW{j}}}", f"counterweight on link {j} (eqs. 9-12)") for j in links},
        params={**{f"theta{j}{e}": Sym(f"θ_{{{j}{e}}}", f"input angle of link {j} at the {w} position")
                   for j in (1, 2) for e, w in (("i", "initial"), ("f", "final"))},
                **{f"mCW{j}": Sym(f"m_{{CW{j}}}", f"mass of counterweight {j}") for j in links},
                **{f"m{j}_star": Sym(f"m_{j}^*", f"mass of the balanced link {j} (eq. 14)") for j in links},
                **{f"r{j}_star": Sym(f"r_{j}^*", f"centre of mass of the balanced link {j}") for j in links},
                **{f"r{j}p": Sym(f"r_{{{j}'}}", f"pitch radius of gear {j}'") for j in links},
                **{f"r{k}": Sym(f"r_{k}", f"pitch radius of gear {k}") for k in (5, 6, 7)},
                **{f"I{k}": Sym(f"I_{k}", f"axial moment of inertia of gear {k} (eqs. 19-21)") for k in (5, 6, 7)},
                **{f"U{ab}": Sym(f"U_{{{ab}}}", "transmission ratio") for ab in ("21", "51", "63", "74")}})
    return dict(names) | {
        "balancing.counterweights.proximal": Sym(
            "−r_{CW1} = −r_{CW2}", "counterweights 1, 2 along A_jB_j from A_j (negative: beyond A_j, at r_{CW} from it)"),
        "balancing.counterweights.distal": Sym(
            "−r_{CW3} = −r_{CW4}", "counterweights 3, 4 along B_jP from B_j (negative: beyond B_j)"),
        "balancing.counter_rotation.ratio": Sym("U_{63} = U_{74}", "ratios of the planetary gears 6, 7 to gears 3', 4'"),
        "balancing.counter_rotation.gear_3p.mass": Sym("m_{3'} = m_{4'}", "mass of gears 3', 4' on the distal links at B_j"),
        "balancing.counter_rotation.gear_3p.inertia": Sym("I_{3'} = I_{4'}", "axial moment of inertia of gears 3', 4'"),
        "balancing.counter_rotation.planet_mass": ours("m_6 = m_7", "mass of the planetary gears 6, 7 (their inertias are computed, eqs. 20-21)"),
        "balancing.counter_rotation.gear_1p_inertia": Sym("I_{1'} = I_{2'}", "axial moment of inertia of gears 1', 2' in the moment-balanced design"),
        "balancing.counter_rotation.pressure_angle": ours("α", "pressure angle of the meshes 3'-6 and 4'-7"),
        "balancing.balanced_inertias.proximal": Sym("I_1 = I_2", "centroidal inertia of the balanced input links (link + counterweight), as eq. 17 reads it"),
        "balancing.balanced_inertias.distal": Sym("I_3 = I_4", "centroidal inertia of the balanced distal links, as eq. 17 reads it"),
        "balancing.point_mass_stage": setting("point masses", "also analyse the balancing with point-mass counterweights on the bare links"),
    }

#: Paper 004's symbols (eqs. 9-21, Sec. VI) for this method's inputs.
NOTATION = _notation()
