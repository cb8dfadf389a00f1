"""Warnings of a motion that passes near a dead centre or a singularity, each
with its stated threshold.

Three measures, each with its stated threshold, on the stage's own analysis:

* the transmission angle of every RRR dyad of the prescribed motion (:mod:`balpipe.diagnose.dyads`):
  the angle at its middle joint between its two links, folded into [0, 90] deg. At 0 the dyad
  is stretched or folded (a dead centre): its ends no longer determine its motion and the
  forces through it grow like 1 / sin(angle). Warned below :data:`TRANSMISSION_LIMIT`;
* the condition number of the constraint Jacobian of the prescribed motion (joints and
  drivers), warned above :data:`CONDITION_LIMIT`: a singular configuration of any kind;
* with named actuators, the condition number of the actuated system (joints and actuators,
  :func:`balpipe.engine.dynamics.actuation_condition`), warned above :data:`CONDITION_LIMIT`:
  the motors lose control of the mechanism there (an actuation dead centre).

Each warning gives the time, the configuration (every body's pose) and the effort spike: the
peak |effort| over the motion, its actuator and time, and its ratio to the median |effort|.
"""

from __future__ import annotations

import math

import numpy as np

from . import dyads
from ..engine import Analysis, compile_model, condition_peak
from ..model import Model

TRANSMISSION_LIMIT = math.radians(10.0)
CONDITION_LIMIT = 1e4


def _configuration(model: Model, an: Analysis, k: int) -> dict[str, list[float]]:
    return {b.name: [float(v) for v in an.pose(k, b.name)] for b in model.bodies}


def _spike(an: Analysis) -> dict | None:
    if not an.efforts:
        return None
    name = max(an.efforts, key=lambda n: float(np.max(np.abs(an.efforts[n]))))
    e = np.abs(np.asarray(an.efforts[name], dtype=float))
    k = int(np.argmax(e))
    med = float(np.median(e))
    return {"actuator": name, "peak": float(e[k]), "time": float(an.t[k]),
            "ratio_to_median": float(e[k] / med) if med > 0 else None}


def _spike_text(spike: dict | None) -> str:
    if spike is None:
        return ""
    ratio = f", {spike['ratio_to_median']:.3g} times its median" if spike["ratio_to_median"] else ""
    return f"; effort spike: {spike['actuator']} peaks at {spike['peak']:.4g} at t = {spike['time']:.4g} s{ratio}"


def find(model: Model, an: Analysis, stage: str = "") -> list[dict]:
    """The warnings of one stage's analysis (JSON-ready dicts: kind, message, time, value,
    limit, configuration, effort_spike)."""
    out = []
    spike = _spike(an)
    where = f"stage {stage!r}: " if stage else ""
    c = compile_model(model)
    q = an.q.reshape(len(an.t), -1)
    poses = {name: an.frame_pose[:, k] for k, name in enumerate(an.names)}
    for b in dyads.blocks(c, q[0]):
        d = b.dyad
        if d is None:
            continue
        Ei, Ej = dyads.end_points(model, d, poses)
        mu = dyads.transmission_angle(d, Ei, Ej)
        k = int(np.argmin(mu))
        if mu[k] < TRANSMISSION_LIMIT:
            out.append({
                "kind": "dead_centre", "time": float(an.t[k]), "value": math.degrees(float(mu[k])),
                "limit": math.degrees(TRANSMISSION_LIMIT), "dyad": d.name, "joints": d.joints,
                "configuration": _configuration(model, an, k), "effort_spike": spike,
                "message": f"{where}the motion passes near a dead centre at t = {an.t[k]:.4g} s: the dyad "
                           f"{d.name} (joints {d.joints}) has a transmission angle of {math.degrees(float(mu[k])):.3g} deg "
                           f"at joint {d.middle.name} (warned below {math.degrees(TRANSMISSION_LIMIT):g} deg)"
                           + _spike_text(spike),
            })
    for key, what in (("condition", "the constraint Jacobian of the prescribed motion is ill-conditioned"),
                      ("actuation_condition", "the actuators lose control of the mechanism (the actuated system is ill-conditioned)")):
        found = condition_peak(an, key)
        if found is None:
            continue
        k, cond = found
        if cond > CONDITION_LIMIT:
            out.append({
                "kind": "singular" if key == "condition" else "actuation", "time": float(an.t[k]),
                "value": cond, "limit": CONDITION_LIMIT, "configuration": _configuration(model, an, k),
                "effort_spike": spike,
                "message": f"{where}near a singular configuration at t = {an.t[k]:.4g} s: {what} (condition number "
                           f"{cond:.3g}, warned above {CONDITION_LIMIT:.0e})" + _spike_text(spike),
            })
    return out


def unique(warnings: list[dict]) -> list[dict]:
    """One warning per kind, place and time: the stages of a spec share their motion, so a dead
    centre of the first stage is that of every stage (the first stage's warning, with its
    effort spike, is kept)."""
    seen, out = set(), []
    for w in warnings:
        key = (w["kind"], w.get("dyad"), round(w["time"], 12))
        if key not in seen:
            seen.add(key)
            out.append(w)
    return out
