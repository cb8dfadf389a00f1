"""Mass-only sweeps without building every design: k + 1 designs built for k varied fields,
the affinity checked against designs built in full.

When the varied fields change only mass parameters at fixed geometry, each design's parameter
vectors p (chosen stage and unbalanced stage; (m, mx, my, J) per body, as
:func:`balpipe.balancing.regressor.parameters`), its added mass and added inertia are affine in
the varied values x: the masses, inertias and counterweight masses a template or a balancing
method computes are linear in the spec's masses and inertias (force balancing, eq. 15 of paper
000; inertia counterweights, eq. 20, at fixed counterweight positions). Then

    f(x) = f(lo) + sum_j (x_j - lo_j) / (hi_j - lo_j) * (f(lo + (hi_j - lo_j) e_j) - f(lo)),

so k + 1 designs built in full (the box's lower corner and one step per varied field) give every
design's f as one matrix product, without validating, templating or balancing a spec per design.

Affinity is checked, not assumed: the route is taken only when every probe keeps the base
geometry (:func:`balpipe.balancing.mass_sweep.geometry_key`) and the same parts, and f, built in full at
check designs (the box's upper corner, and designs of the sweep itself), equals the affine
prediction to :data:`TOL` of its scale; :func:`balpipe.sweep.run` then builds the designs on the
Pareto fronts in full and compares them too. Otherwise (a length, a duration, a counterweight
position, a centre of mass) it builds every design. These are checks at finite points: a method
whose output were affine at all of them but not between them would slip through. f also holds
the declared masses and inertias (bodies and attachments), so that a design a method would
refuse for a negative one (eq. 20's counterweight inertia) is found and built in full for its
own error. The varied values in SI are converted per value exactly as the spec's unit parser
does (number times the unit's factor), not interpolated.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np

from ..mechanics.sampling import spread_indices

TOL = 1e-11  # relative: the prediction at the check designs must agree with the full build
CHECKS = 3   # designs of the sweep itself built in full as checks (besides the upper corner)
STEPS = (1.0, 0.5, 0.25)  # probe steps along a field, as fractions of its span


def numeric(raw: Any) -> float:
    """The number of a raw vary value (``1.5`` or ``"1.5 kg"``)."""
    return float(raw) if not isinstance(raw, str) else float(raw.split(maxsplit=1)[0])


def declared(model) -> list[float]:
    """The masses and inertias as declared (bodies, then their attachments): a method refuses a
    design where one is negative (e.g. eq. 20's counterweight inertia), even when its body's
    totals are positive."""
    out: list[float] = []
    for b in model.bodies:
        out += [b.mass, b.inertia]
        for a in b.attachments:
            out += [a.mass, a.inertia]
    return out


def _signature(model) -> tuple:
    return tuple((b.name, tuple(a.name for a in b.attachments)) for b in model.bodies)


def _features(row: dict, extra: list[float]) -> np.ndarray | None:
    """A probe's f: added mass, added inertia, p of the stage, p of the unbalanced stage, the
    declared masses and inertias of both; None if the design failed or left the base geometry."""
    if "error" in row or row.get("route") != "mass" or "unbalanced_p" not in row:
        return None
    return np.concatenate([[row["added_mass"], row["added_inertia"]], row["p"], row["unbalanced_p"], extra])


def _si_factor(vary, probes: list[tuple[float, float]]) -> float | None:
    """The factor from the vary's unit to SI, as :func:`balpipe.units.parse` applies it, checked
    on the probes' (number, validated SI value) pairs."""
    from ..units import normalise_unit, kinds_of

    factors = {1.0} if not normalise_unit(vary.unit) else set(kinds_of(vary.unit).values())
    fits = [f for f in factors if all(x * f == si for x, si in probes)]
    return fits[0] if len(fits) == 1 else None


@dataclass
class AffineRoute:
    """f(x) = f0 + U(x) @ D for the designs of one plan (see the module docstring)."""

    lo: np.ndarray      # (k,) lower corner
    span: np.ndarray    # (k,) hi - lo (1 where a field has one value)
    f0: np.ndarray      # (nf,)
    D: np.ndarray       # (k, nf)
    factors: list[float]
    n_p: int            # length of p of the chosen stage
    n_p0: int           # length of p of the unbalanced stage
    names: tuple        # body names of the chosen and of the unbalanced stage
    probes: int = 0     # designs built in full to find and check the map

    def predict(self, X: np.ndarray) -> np.ndarray:
        return self.f0 + ((X - self.lo) / self.span) @ self.D

    def parameters(self, F: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """p of the chosen stage and of the unbalanced stage, rows of F."""
        return F[:, 2 : 2 + self.n_p], F[:, 2 + self.n_p : 2 + self.n_p + self.n_p0]

    def unbuildable(self, F: np.ndarray) -> np.ndarray:
        """Per row of F: a negative declared mass or inertia, or a body with a negative mass or
        centroidal inertia (:func:`balpipe.balancing.mass_sweep.check_parameters`); such designs are built
        in full for their own error."""
        from ..balancing.mass_sweep import check_parameters

        p, p0 = self.parameters(F)
        dec = F[:, 2 + self.n_p + self.n_p0 :]
        tiny = 1e-12 * max(1e-300, float(np.max(np.abs(self.f0[2 + self.n_p + self.n_p0 :]), initial=0.0)))
        bad = np.any(dec < -tiny, axis=1)
        for P, names in ((p, self.names[0]), (p0, self.names[1])):
            bad |= np.array([why is not None for why in check_parameters(names, P)], dtype=bool)
        return bad

    def rows(self, designs: list[tuple]) -> tuple[list[dict], np.ndarray]:
        """Rows as :func:`balpipe.sweep.evaluate_chunk` returns them (route ``mass``) but for their
        parameter vectors, which are the columns of F: [added mass, added inertia, p, p0]."""
        X = np.array([[numeric(v) for v in d] for d in designs], dtype=float).reshape(len(designs), len(self.lo))
        F = self.predict(X)
        rows = []
        for i, values in enumerate(designs):
            rows.append({"design": i, "values": values, "si": [float(x * f) for x, f in zip(X[i], self.factors)],
                         "added_mass": float(F[i, 0]), "added_inertia": float(F[i, 1]), "route": "mass"})
        return rows, F


def _box(p) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = [], []
    for v in p.varies:
        xs = [numeric(x) for x in v.values] if v.values else [float(v.lo), float(v.hi)]
        lo.append(min(xs))
        hi.append(max(xs))
    return np.array(lo), np.array(hi)


def build_route(p, keys: tuple, names: tuple[list[str], list[str]], anchors=None) -> AffineRoute | None:
    """Probe the plan's sweep (k + 1 full designs, then the checks); the route, or None when the
    designs are not affine in the varied values at the base geometry. ``keys``: the geometry keys
    of the base design's chosen and unbalanced stages; ``names``: their bodies' names;
    ``anchors``: where the probes' closed-loop motions start (:func:`balpipe.sweep.run`)."""
    from .evaluate import build_design, evaluate_chunk

    if keys[0] is None or keys[1] is None or not p.designs:
        return None
    paths = [v.path for v in p.varies]
    lo, hi = _box(p)
    k = len(lo)
    span = np.where(hi > lo, hi - lo, 1.0)

    signature: list[tuple] = []

    def full(x: np.ndarray) -> tuple[np.ndarray | None, dict]:
        values = tuple(v.raw(xj) for v, xj in zip(p.varies, x))
        row = evaluate_chunk(p.data, paths, [(0, values)], p.stage, keys, anchors)[0]
        if "error" in row:
            return None, row
        _, sr, base = build_design(p.data, paths, values, p.stage)
        sig = (_signature(sr.model), _signature(base.model))
        if signature and sig != signature[0]:  # other parts (a counterweight appears): not affine
            row["error"] = "other parts"
            return None, row
        signature.append(sig)
        return _features(row, declared(sr.model) + declared(base.model)), row

    f0, row0 = full(lo)
    if f0 is None:
        return None
    pairs: list[list[tuple[float, float]]] = [[(lo[j], row0["si"][j])] for j in range(k)]
    D = np.zeros((k, f0.size))
    for j in range(k):
        if hi[j] == lo[j]:
            continue
        for frac in STEPS:  # the whole span, or a part where the far end cannot be built
            x = lo.copy()
            x[j] = lo[j] + frac * (hi[j] - lo[j])
            f, row = full(x)
            if f is not None:
                break
        else:
            return None
        D[j] = (f - f0) / frac
        pairs[j].append((x[j], row["si"][j]))
    factors = [_si_factor(v, pr) for v, pr in zip(p.varies, pairs)]
    if any(f is None for f in factors):
        return None
    route = AffineRoute(lo, span, f0, D, factors, len(row0["p"]), len(row0["unbalanced_p"]), names)
    picks = spread_indices(len(p.designs), CHECKS)
    checks = [hi] + [np.array([numeric(v) for v in p.designs[i]], dtype=float) for i in picks]
    route.probes = 1 + int(np.count_nonzero(hi > lo)) + len(checks)
    scale = np.abs(f0) + np.abs(D).sum(axis=0)
    scale = np.maximum(scale, 1e-4 * scale.max())  # components that are zero up to round-off
    for x in checks:
        f, row = full(x)
        predicted = route.predict(x[None, :])
        if f is None:  # a design that cannot be built must be one whose predicted parameters say so
            if row.get("error") in (None, "other parts") or not route.unbuildable(predicted)[0]:
                return None
        elif np.any(np.abs(predicted[0] - f) > TOL * scale):
            return None
    return route
