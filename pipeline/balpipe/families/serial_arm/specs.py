"""The spec sections of the family's balancing methods: pydantic classes only, so that the schema
(:mod:`balpipe.spec`) loads none of the methods' computing code, which imports them from here.
"""

from __future__ import annotations

from typing import Literal, Union

from pydantic import Field

from ...spec_parts import Strict
from ...units import Angle, Inertia, Length, Mass, PositiveLength, count, number, quantity


class Gear1p(Strict):
    """Gear 1', pivoted on link 1 at C."""

    position: Length = Field(description="l_AC: position of C along link 1 from A (between A and B in the paper)")
    mass: Mass = Field(0.0, description="m1'")
    ratio: number(lt=0) = Field(-1.0, description="w1' - w1 = ratio (w2 - w1); -1 for identical gears (the paper)")


class Gear2p(Strict):
    """Gear 2', fixed on link 2 at B."""

    mass: Mass = Field(0.0, description="m2'")
    inertia: Inertia = Field(0.0, description="I_S2'")


class Counterweight(Strict):
    """A counterweight at ``distance`` from the link's proximal joint, on the ray that cancels the
    first moment it must cancel; its mass is solved."""

    distance: PositiveLength = Field(description="distance from the joint (A for link 1, B for link 2)")
    inertia: Inertia = Field(0.0, description="centroidal inertia of the counterweight")


class Counterweights(Strict):
    link1: Counterweight = Field(description="puts the total centre of mass on A (condition 3)")
    link2: Counterweight = Field(description="puts link 2 + gear 2' centre of mass on B (condition 1)")


class FrameGear(Strict):
    """Gear 3 on the frame meshing with gear 1'' (fixed on link 1 at A), identical: theta3 = -theta1."""

    position: tuple[Length, Length] = Field(description="centre of gear 3 on the frame (its radius is half the distance to A)")


class GearDecoupling(Strict):
    """Paper 002: gear pair 1'-2' and mass redistribution (decoupled, linear dynamics), then gear 3."""

    method: Literal["gear_decoupling"] = Field(description="balancing method")
    gear_1p: Gear1p = Field(description="gear 1' on link 1 at C (its inertia is solved from condition 2)")
    gear_2p: Gear2p = Field(Gear2p(), description="gear 2' fixed on link 2 at B")
    counterweights: Counterweights = Field(description="counterweights whose masses conditions 1 and 3 give")
    counter_rotation: FrameGear = Field(description="gear 3 on the frame (I3 = J1)")


class TestSquare(Strict):
    """The tested zone of Fig. 2: a square whose edges are divided into ``divisions`` segments by
    the points P1 .. P(4 divisions), P1 at ``first_corner``, numbered counter-clockwise."""

    centre: tuple[Length, Length] = Field(description="centre E of the square")
    side: PositiveLength = Field(description="edge length")
    divisions: count(ge=1, le=50) = Field(4, description="segments per edge")
    first_corner: Literal["bottom-left", "bottom-right", "top-right", "top-left"] = Field(
        "bottom-left", description="corner of P1 (the paper's figure is not legible: bottom-left reproduces its list)"
    )

    def points(self) -> dict[str, tuple[float, float]]:
        cx, cy = self.centre
        h = self.side / 2
        corners = [(-h, -h), (h, -h), (h, h), (-h, h)]  # counter-clockwise from bottom-left
        start = ("bottom-left", "bottom-right", "top-right", "top-left").index(self.first_corner)
        corners = corners[start:] + corners[:start]
        out = {}
        k = 1
        for e in range(4):
            (x0, y0), (x1, y1) = corners[e], corners[(e + 1) % 4]
            for j in range(self.divisions):
                s = j / self.divisions
                out[f"P{k}"] = (cx + x0 + s * (x1 - x0), cy + y0 + s * (y1 - y0))
                k += 1
        return out


class TrajectorySpec(Strict):
    """A tip trajectory between two points (names of the test square's points or [x, y])."""

    name: str = Field(min_length=1, description="label of the trajectory")
    start: Union[str, tuple[Length, Length]] = Field(alias="from", description="start point of the tip")
    end: Union[str, tuple[Length, Length]] = Field(alias="to", description="end point of the tip")


class Orientation(Strict):
    start: Angle = Field(alias="from", description="phi at the start (the paper: 0 deg)")
    end: Angle = Field(alias="to", description="phi at the end (the paper: 120 deg)")


class PhiOptimisation(Strict):
    """phi(tau) = phi0 + (phif - phi0) s5(tau) + sum_k c_k 64 tau^3 (1 - tau)^3 (2 tau - 1)^k,
    k = 0 .. degree - 6: the degree-``degree`` polynomials with phi, phi', phi'' fixed at both ends."""

    degree: count(ge=5, le=14) = Field(8, description="degree of the polynomial (5: the 3-4-5 law, nothing to optimise)")
    starts: count(ge=1, le=50) = Field(4, description="multi-start: the 3-4-5 law plus starts - 1 random points")
    seed: count(ge=0) = Field(0, description="seed of the random starting points (numpy default_rng)")
    spread: quantity("angle", gt=0) = Field(0.5, description="standard deviation of the random starting coefficients (rad)")
    max_evaluations: count(ge=10, le=100_000) = Field(300, description="objective evaluations per start (Nelder-Mead)")
    tolerance: number(gt=0) = Field(1e-4, description="Nelder-Mead xatol (rad) and fatol (relative to the start's peak)")


class ComMotionPlanning(Strict):
    """Paper 003: the 3R arm's centre of mass on a bang-bang (and trapezoidal) law, phi optimised."""

    method: Literal["com_motion_planning"] = Field(description="balancing method")
    test_square: TestSquare | None = Field(None, description="the tested zone (Fig. 2), to name points P1..")
    trajectories: list[Union[str, TrajectorySpec]] = Field(
        [],
        description="tip trajectories, 'PiPj' on the test square or {name, from, to}; empty: the "
        "template's tip drive (motion.drive.tip)",
    )
    orientation: Orientation | None = Field(None, description="phi at both ends of every trajectory (with trajectories)")
    phi: PhiOptimisation = Field(PhiOptimisation(), description="the law of phi in case 2 and its optimisation")
    main_trajectory: str | None = Field(
        None, description="the trajectory shown first: the page's headline, design summary and stage figures, and "
        "Figs. 3-4 (the paper's figures show P15P7); default the first")
    torque_rate_limit: number(gt=0) = Field(
        3e4, description="case 3: largest rate of change of any actuator torque, N m/s (the paper: 3.10^4)"
    )
    rate_samples: count(ge=101, le=100_001) = Field(4001, description="case 3: samples on which torque rates are measured (central differences)")
