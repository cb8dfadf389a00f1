"""Counterweight balancing of the slider-crank, and moment balancing of the Scott-Russell
mechanism without counter-rotations (paper 000, Sec. 3.1, eqs. 11-20)."""

from __future__ import annotations

from dataclasses import replace

from .template import SliderCrankMechanism
from ...model import Attachment
from ...spec_parts import SpecFieldError
from ...balancing.base import BalanceResult, Parameter, Stage
from ...balancing.context import BalanceContext
from ...balancing.scott_russell import eq20_lhs
from .specs import SliderCrankCounterweights


def _counterweight_masses(mech: SliderCrankMechanism, c1: float, c2: float) -> tuple[float, float]:
    """Eq. 15 in lengths: mcp2 = -(m2 p2 + m3 L2) / c2, mcp1 = -(m1 p1 + (m2 + mcp2 + m3) L1) / c1
    (p_i = r_i L_i the centre of mass positions, c_i = rcp_i L_i the counterweights').

    Derived from the linear momentum: the slider translates, so its momentum is m3 v_C wherever
    its centre of mass sits on it (s constant in the frame: d(C + s)/dt = v_C), and v_C = d/dt
    (L1 e1 + L2 e2) because C stays on the guide. The total momentum
    (m1 p1 + mcp1 c1 + (m2 + mcp2 + m3) L1) de1/dt + (m2 p2 + mcp2 c2 + m3 L2) de2/dt vanishes
    for every motion when both brackets do: eq. 15, with no term in the slider's offset."""
    m1, m2, m3 = mech.crank.mass, mech.coupler.mass, mech.slider.mass
    L1, L2 = mech.crank.length, mech.coupler.length
    mcp2 = -(m2 * mech.coupler.com + m3 * L2) / c2
    mcp1 = -(m1 * mech.crank.com + (m2 + mcp2 + m3) * L1) / c1
    return mcp1, mcp2


def is_scott_russell(mech: SliderCrankMechanism) -> bool:
    """Eq. 19: a = 0 and L1 = L2 (to round-off)."""
    L1, L2 = mech.crank.length, mech.coupler.length
    return abs(mech.offset) <= 1e-12 * L1 and abs(L1 - L2) <= 1e-12 * L1


def balance(ctx: BalanceContext) -> BalanceResult:
    mech: SliderCrankMechanism = ctx.mechanism
    method: SliderCrankCounterweights = ctx.balancing
    model = ctx.model
    path = ("balancing",)
    c1, c2 = method.crank_counterweight, method.coupler_counterweight
    for key, c in (("crank_counterweight", c1), ("coupler_counterweight", c2)):
        if c == 0:
            raise SpecFieldError(path + (key,), "a counterweight at the joint itself cannot balance anything")
    if mech.crank.com_offset or mech.coupler.com_offset:
        raise SpecFieldError(
            ("mechanism",), "eq. 15 assumes centres of mass on the link axes (com_offset 0)"
        )
    mcp1, mcp2 = _counterweight_masses(mech, c1, c2)
    for key, m, name in (("coupler_counterweight", mcp2, "mcp2"), ("crank_counterweight", mcp1, "mcp1")):
        if m < 0:
            raise SpecFieldError(
                path + (key,),
                f"eq. 15 gives a negative counterweight mass {name} = {m:.4g} kg at this position: "
                "put the counterweight on the other side of the joint",
            )
    L1, L2 = mech.crank.length, mech.coupler.length
    params = [
        Parameter("mcp2", mcp2, "kg", "eq. 15", "counterweight on the coupler"),
        Parameter("mcp1", mcp1, "kg", "eq. 15", "counterweight on the crank"),
    ]
    notes: list[str] = []
    for attr, name in (("coupler_counterweight_mass", "mcp2"), ("crank_counterweight_mass", "mcp1")):
        built = getattr(method, attr)
        if built is not None:
            params.append(Parameter(f"{name}_built", built, "kg", "spec", f"as built, instead of eq. 15's {name}"))
            notes.append(f"The spec sets {name} = {built:.6g} kg as built; eq. 15 asks for {(mcp1 if name == 'mcp1' else mcp2):.6g} kg.")
    if method.crank_counterweight_mass is not None:
        mcp1 = method.crank_counterweight_mass
    if method.coupler_counterweight_mass is not None:
        mcp2 = method.coupler_counterweight_mass
    params += [
        Parameter("rcp1", c1 / L1, "", "spec", "crank counterweight position / L1"),
        Parameter("rcp2", c2 / L2, "", "spec", "coupler counterweight position / L2"),
    ]
    cw1 = Attachment("counterweight 1", mcp1, (c1, 0.0))
    cw2 = Attachment("counterweight 2", mcp2, (c2, 0.0))
    crank, coupler = model.body("crank"), model.body("coupler")
    cw_model = model.replace_body(crank.with_attachments(cw1)).replace_body(coupler.with_attachments(cw2))
    stages = [
        Stage("unbalanced", "unbalanced", model, "the mechanism as given"),
        Stage("counterweights", "counterweights", cw_model, "counterweights of eq. 15", balances="force"),
    ]
    sr = is_scott_russell(mech)
    if not sr:
        notes.append(
            "This slider-crank is not a Scott-Russell mechanism (eq. 19 needs a = 0 and L1 = L2): "
            "its angular momentum (eq. 17) is not constant, so the shaking moment cannot be "
            "cancelled by counterweights alone; it needs counter-rotations. The counterweight "
            "stage shows the moment that remains."
        )
        if method.moment_unknown is not None:
            raise SpecFieldError(
                path + ("moment_unknown",),
                f"eq. 20 holds only for a Scott-Russell mechanism (offset 0, L1 = L2; here offset "
                f"{mech.offset:g} m, L1 {L1:g} m, L2 {L2:g} m)",
            )
        return BalanceResult(params, stages, notes)
    if method.moment_unknown is None:
        notes.append("Scott-Russell geometry: eq. 20 could cancel the moment too; name moment_unknown to do it.")
        return BalanceResult(params, stages, notes)
    if mech.slider.com[1]:
        # the slider's angular momentum about C's line gains -m3 s_y v_C (s across the guide),
        # which eq. 20 does not hold; along the guide s x v_C = 0 and the offset drops out
        raise SpecFieldError(
            ("mechanism", "slider", "com"),
            f"eq. 20 needs the slider's centre of mass on the guide line; {mech.slider.com[1]:g} m across "
            "the guide adds a moment m3 s_y v_C that no counterweight inertia cancels",
        )
    # eq. 20: I1 + (m1 r1^2 + mcp1 rcp1^2 + m2 + mcp2) L1^2 - I2 - (m2 r2^2 + mcp2 rcp2^2) L1^2 = 0
    lhs = eq20_lhs(mech.crank.inertia, mech.crank.mass, mech.crank.com, mcp1, c1, L1,
                   mech.coupler.inertia, mech.coupler.mass, mech.coupler.com, mcp2, c2)
    if method.moment_unknown == "crank_counterweight_inertia":
        needed, on = -lhs, "crank"
    else:
        needed, on = lhs, "coupler"
    if needed < 0:
        other = "coupler" if on == "crank" else "crank"
        raise SpecFieldError(
            path + ("moment_unknown",),
            f"eq. 20 needs a negative inertia ({needed:.4g} kg m^2) on the {on} counterweight: solve "
            f"for {other}_counterweight_inertia instead",
        )
    name = "Icp1" if on == "crank" else "Icp2"
    params.append(Parameter(name, needed, "kg m^2", "eq. 20", f"centroidal inertia added to the {on} counterweight"))
    full = cw_model
    body = full.body(on)
    atts = tuple(
        Attachment(a.name, a.mass, a.position, needed, a.kind, a.radius)
        if a.name == ("counterweight 1" if on == "crank" else "counterweight 2") else a
        for a in body.attachments
    )
    full = full.replace_body(replace(body, attachments=atts))
    stages.append(
        Stage("full", "counterweights + inertia (eq. 20)", full,
              f"eq. 20 solved for the {on} counterweight's inertia", balances="force+moment")
    )
    return BalanceResult(params, stages, notes)


def _notation() -> dict:
    from ...notation import Sym, names_table, setting

    names = names_table(
        parts={f"counterweight {j}": Sym(f"m_{{cp{j}}}", f"counterweight M_{j} on link {j} (eq. 15)") for j in (1, 2)},
        params={**{f"mcp{j}": Sym(f"m_{{cp{j}}}", f"mass of counterweight M_{j} (eq. 15)") for j in (1, 2)},
                **{f"rcp{j}": Sym(f"r_{{cp{j}}}", f"position coefficient of counterweight M_{j}") for j in (1, 2)}})
    return dict(names) | {
        "balancing.crank_counterweight": Sym(
            "r_{cp1} L_1", "position of counterweight M_1 along the crank from A (negative: beyond A)"),
        "balancing.coupler_counterweight": Sym(
            "r_{cp2} L_2", "position of counterweight M_2 along the coupler from B (negative: beyond B)"),
        "balancing.crank_counterweight_mass": Sym("m_{cp1}", "mass of M_1 as built, instead of eq. 15's"),
        "balancing.coupler_counterweight_mass": Sym("m_{cp2}", "mass of M_2 as built, instead of eq. 15's"),
        "balancing.moment_unknown": setting("unknown", "the inertia that eq. 20 is solved for"),
    }

#: Paper 000's symbols (eqs. 14-15, 20) for this method's inputs.
NOTATION = _notation()
