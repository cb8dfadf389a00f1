"""Slider-crank template (paper 000, Sec. 3.1, Fig. 5).

Crank AB (length L1) pivots on the frame at A; coupler BC (length L2); the slider at C moves
along a guide parallel to the x axis at distance ``offset`` (the paper's a) from A. The
Scott-Russell mechanism is the special case a = 0, L1 = L2 (eq. 19).
"""

from __future__ import annotations

import math
from typing import Literal

import numpy as np
from pydantic import Field

from ...mechanics.planar import bar_body
from ...model import FRAME, Body, Driver, Model, Prismatic, Revolute
from ...spec_parts import BodySpec, LinkSpec, SpecFieldError, Strict
from ...units import Length, Sign


class SliderCrankMechanism(Strict):
    """A slider-crank: crank AB on the frame at A, coupler BC, slider C on a guide along x."""

    template: Literal["slider_crank"] = Field(description="mechanism template")
    pivot: tuple[Length, Length] = Field((0.0, 0.0), description="position of the crank pivot A")
    offset: Length = Field(0.0, description="the guide's distance from A along +y (the paper's a)")
    crank: LinkSpec = Field(description="link 1, AB")
    coupler: LinkSpec = Field(description="link 2, BC")
    slider: BodySpec = Field(description="link 3, the slider; its frame origin is C")
    branch: Sign = Field(1, description="+1: slider on the +x side of B, -1: on the -x side")

    def drives(self) -> dict[str, str]:
        """Coordinates that can be driven, with their dimension."""
        return {"crank": "angle", "slider": "length"}


def crank_angles(mech: SliderCrankMechanism, slider_x: np.ndarray) -> np.ndarray:
    """Crank angles for slider positions x (measured from A along the guide), used when the
    slider is the driven coordinate: B on the counter-clockwise side of AC."""
    L1, L2, a = mech.crank.length, mech.coupler.length, mech.offset
    d = np.hypot(slider_x, a)
    cos_beta = (L1**2 + d**2 - L2**2) / (2 * L1 * d)
    if np.any(np.abs(cos_beta) > 1):
        raise ValueError("unreachable")
    return np.arctan2(a, slider_x) + np.arccos(cos_beta)


def build(mech: SliderCrankMechanism, laws: dict, t: np.ndarray) -> Model:
    """The unbalanced slider-crank model, driven at the crank or the slider.

    ``laws`` holds exactly one law, named "crank" or "slider". ``t`` is the analysis grid, used
    only to check reachability with a clear message before the engine runs.
    """
    if len(laws) != 1:
        raise SpecFieldError(("motion", "drive"), "drive exactly one of: crank, slider")
    ((drive, law),) = laws.items()
    L1, L2, a = mech.crank.length, mech.coupler.length, mech.offset
    A = np.array(mech.pivot, dtype=float)
    q = law(t)[0]
    if drive == "crank":
        theta = q
        gap = np.abs(a - L1 * np.sin(theta))
        if np.any(gap > L2):
            k = int(np.argmax(gap))
            raise SpecFieldError(
                ("mechanism", "coupler", "length"),
                f"the coupler ({L2:g} m) cannot reach the guide at t = {t[k]:.4g} s, crank angle "
                f"{math.degrees(theta[k]):.4g} deg (needs {gap[k]:.4g} m)",
            )
    else:
        try:
            theta = crank_angles(mech, q)
        except ValueError:
            raise SpecFieldError(
                ("motion", "drive", "slider"),
                f"slider positions outside the reach [{abs(L1 - L2):g}, {L1 + L2:g}] m of A",
            ) from None
    th0 = float(theta[0])
    B = A + L1 * np.array([math.cos(th0), math.sin(th0)])
    dy = a - L1 * math.sin(th0)
    cx = B[0] + mech.branch * math.sqrt(max(L2**2 - dy**2, 0.0))
    phi0 = math.atan2(A[1] + a - B[1], cx - B[0])
    crank = bar_body("crank", mech.crank, "A", "B", mech.crank.length)
    coupler = bar_body("coupler", mech.coupler, "B", "C", mech.coupler.length)
    slider = Body("slider", mech.slider.mass, tuple(mech.slider.com), mech.slider.inertia, {"C": (0.0, 0.0)}, kind="slider")
    guide_origin = (float(A[0]), float(A[1] + a))
    joints = (
        Revolute("A", FRAME, "crank", tuple(A), (0.0, 0.0)),
        Revolute("B", "crank", "coupler", (L1, 0.0), (0.0, 0.0)),
        Revolute("C", "coupler", "slider", (L2, 0.0), (0.0, 0.0)),
        Prismatic("guide", FRAME, "slider", guide_origin, (1.0, 0.0)),
    )
    driver = Driver(drive, ("joint", "A" if drive == "crank" else "guide"), law)
    xs = A[0] + L1 * np.cos(theta) + mech.branch * np.sqrt(np.maximum(L2**2 - (a - L1 * np.sin(theta)) ** 2, 0))
    lo, hi = float(xs.min()), float(xs.max())
    pad = 0.15 * max(hi - lo, L2)
    return Model(
        name="slider-crank",
        bodies=(crank, coupler, slider),
        joints=joints,
        drivers=(driver,),
        initial={"crank": (A[0], A[1], th0), "coupler": (B[0], B[1], phi0), "slider": (cx, A[1] + a, 0.0)},
        frame_points={"A": tuple(A)},
        guides=(((lo - pad, guide_origin[1]), (hi + pad, guide_origin[1])),),
    )


def _notation() -> dict:
    from ...notation import Sym, drive_table, names_table, ours

    table = {
        "mechanism.pivot": Sym("A", "the crank's pivot on the frame"),
        "mechanism.offset": Sym("a", "offset of the slider's guide from A (Scott-Russell: a = 0, eq. 19)"),
        "mechanism.crank.length": Sym("L_1", "length AB of the crank, link 1"),
        "mechanism.crank.mass": Sym("m_1", "mass of the crank"),
        "mechanism.crank.com": Sym("r_1 L_1", "distance of the crank's centre of mass S_1 from A along AB"),
        "mechanism.crank.com_offset": ours("e_1", "offset of S_1 normal to AB"),
        "mechanism.crank.inertia": Sym("I_1", "axial moment of inertia of the crank about S_1"),
        "mechanism.coupler.length": Sym("L_2", "length BC of the coupler, link 2"),
        "mechanism.coupler.mass": Sym("m_2", "mass of the coupler"),
        "mechanism.coupler.com": Sym("r_2 L_2", "distance of the coupler's centre of mass S_2 from B along BC"),
        "mechanism.coupler.com_offset": ours("e_2", "offset of S_2 normal to BC"),
        "mechanism.coupler.inertia": Sym("I_2", "axial moment of inertia of the coupler about S_2"),
        "mechanism.slider.mass": Sym("m_3", "mass of the slider, link 3"),
        "mechanism.slider.com": Sym("d_{CS3}", "centre of mass S_3 of the slider from C"),
        "mechanism.slider.inertia": Sym("I_3", "axial moment of inertia of the slider"),
        "mechanism.branch": ours("σ", "assembly branch: +1 puts the slider on the +x side of B"),
        "motion.duration": Sym("t_f", "duration of the motion"),
    }
    drives = {"crank": Sym("θ_1", "crank angle"), "slider": ours("x_C", "slider position along the guide")}
    table.update(drive_table(drives))
    # the model's names (Sec. 3.1, Fig. 5): links 1-3 (crank AB, coupler BC, slider), joints A, B, C
    table.update(names_table(drivers=drives, parts={
        "crank": Sym("link 1", "the crank AB"), "coupler": Sym("link 2", "the coupler BC"),
        "slider": Sym("link 3", "the slider at C")}))
    return table


#: Paper 000's symbols (Sec. 3.1, Fig. 5, eqs. 11-20) for this template's inputs.
NOTATION = _notation()
