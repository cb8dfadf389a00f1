"""The reference loads that every relative figure of a study divides by.

Ratios (a stage's peak / the unbalanced stage's), the balance criterion, the agreement of the
reactions with the momentum rates and the pymunk residuals are all relative numbers. Dividing
by the unbalanced stage's peak alone fails when that peak is itself round-off: a spec whose
first (only) stage is already balanced has peaks ~1e-15 of its links' inertial loads, and
every ratio becomes noise over noise (0.8 to 741 on a reactionless arm).

So each denominator has an absolute floor from the model's own scale, the gross inertial loads
of the unbalanced stage (what the shaking loads would be if nothing cancelled):

    S_F = max_t sum_k m_k |a_k(t)|,
    S_M = max_t sum_k (m_k |r_k - O| |a_k(t)| + I_k |alpha_k(t)|),

with r_k, a_k the centre of mass of body k and its acceleration, alpha_k its angular
acceleration and O the moment point. |F_sh| = |sum m_k a_k| <= S_F and |M_sh| = |dH_O/dt| <= S_M
(without gravity; with gravity the inertial parts), so the unbalanced peaks never exceed them.
S_M takes |r| |a|, not |r x a|: a machine whose masses all move along lines through O (a Scotch
yoke on its axis) has no moment, and |r x a| = 0 would leave the moment figures no floor at all
(round-off 5e-15 N m over 3.6e-15 N m read "150 %", and the reactions "disagree by 1.6").
The reference is max(unbalanced inertial peak, FLOOR_FRACTION * S). On the specs and test
models the unbalanced peaks are 0.08 to 1.0 of S, so the floor (1 %) never replaces them; on an
already balanced arm it does, and the page says so.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from . import Analysis
from ..display import numbers
from ..display.units import DisplayUnits
from ..model import Model

#: fraction of the gross inertial load that is the smallest denominator of a relative figure
FLOOR_FRACTION = 0.01


def gross_inertial_loads(model: Model, analysis: Analysis) -> tuple[float, float]:
    """(S_F, S_M): the largest sums over the bodies of |m a| (N) and of
    m |r - O| |a| + |I alpha| (N m) along the motion (see the module's docstring)."""
    props = [b.mass_properties() for b in model.bodies]
    m = np.array([p[0] for p in props], dtype=float)
    inertia = np.array([p[2] for p in props], dtype=float)
    if not len(m):
        return 0.0, 0.0
    acc = analysis.a[:, :, :2]
    r = analysis.q[:, :, :2] - np.asarray(analysis.moment_point, dtype=float)
    arm = np.linalg.norm(r, axis=2) * np.linalg.norm(acc, axis=2)
    sf = float(np.max(np.linalg.norm(acc, axis=2) @ m))
    sm = float(np.max(arm @ m + np.abs(analysis.a[:, :, 2]) @ inertia))
    return sf, sm


@dataclass(frozen=True)
class LoadReference:
    """The denominators of a study's relative figures, and where they come from.

    ``force``/``moment``: the reference (N, N m); ``force_basis``/``moment_basis``:
    "unbalanced peak" or "floor" (FLOOR_FRACTION of the gross inertial load, used when the
    unbalanced peak is smaller); ``force_peak``/``moment_peak``: the unbalanced stage's inertial
    peaks; ``force_scale``/``moment_scale``: its gross inertial loads S_F, S_M.
    """

    force: float
    moment: float
    force_basis: str
    moment_basis: str
    force_peak: float
    moment_peak: float
    force_scale: float
    moment_scale: float
    floor_fraction: float = FLOOR_FRACTION

    @property
    def floored(self) -> bool:
        return self.force_basis != "unbalanced peak" or self.moment_basis != "unbalanced peak"

    def describe(self, which: str, units: DisplayUnits | None = None) -> str:
        """One phrase for the page: what the force (moment) figures are relative to, its loads in
        the page's display ``units`` (SI without)."""
        u = units or DisplayUnits()
        value, basis = (self.force, self.force_basis) if which == "force" else (self.moment, self.moment_basis)
        q = "force" if which == "force" else "moment"
        if basis == "unbalanced peak":
            return f"the unbalanced stage's peak {which} ({u.text(value, q)})"
        return (
            f"{numbers.num(self.floor_fraction)} of the gross inertial {which} ({u.text(value, q)}), "
            f"larger than the unbalanced stage's peak ({u.text(self.force_peak if which == 'force' else self.moment_peak, q, digits=3)})"
        )

    def to_json(self) -> dict:
        return {
            "force": float(self.force),
            "moment": float(self.moment),
            "force_basis": self.force_basis,
            "moment_basis": self.moment_basis,
            "unbalanced_force_peak": float(self.force_peak),
            "unbalanced_moment_peak": float(self.moment_peak),
            "gross_inertial_force": float(self.force_scale),
            "gross_inertial_moment": float(self.moment_scale),
            "floor_fraction": float(self.floor_fraction),
        }


def load_reference(model: Model, analysis: Analysis, floor_fraction: float = FLOOR_FRACTION) -> LoadReference:
    """The reference of a study from its unbalanced stage (``model`` and its ``analysis``)."""
    f0, m0 = analysis.max_inertial_force, analysis.max_inertial_moment
    sf, sm = gross_inertial_loads(model, analysis)
    ff, fm = floor_fraction * sf, floor_fraction * sm
    return LoadReference(
        force=max(f0, ff), moment=max(m0, fm),
        force_basis="unbalanced peak" if f0 >= ff else "floor",
        moment_basis="unbalanced peak" if m0 >= fm else "floor",
        force_peak=f0, moment_peak=m0, force_scale=sf, moment_scale=sm, floor_fraction=floor_fraction,
    )
