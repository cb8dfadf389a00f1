"""The frame on its mounts, per stage, for ``results.json`` and the page: what each stage's loads
on the frame (:attr:`balpipe.engine.Analysis.frame_load`: the shaking loads plus the external
loads) do to a frame on elastic mounts (the spec's ``frame``, :mod:`balpipe.mechanics.mounts`).

A periodic motion (whole cycles, every drive periodic: :func:`.orders_table.periodic_cycles`)
gives the steady state by orders; any other motion the response in the time domain, from rest
under the first sample's load. Either way the static part (the mean, or the start's static
load) is left out: the forces and velocities are what the motion adds. All values SI (N, m/s,
Hz); the page shows velocities in mm/s.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from ..mechanics.mounts import Frame, Response, modes, periodic_response, transient_response
from .orders_table import ORDERS, periodic_cycles


def stage_response(spec: Any, analysis: Any) -> Response:
    """The frame's motion under one stage's loads on the frame (by orders when the motion is
    periodic, in the time domain otherwise)."""
    frame = spec.frame.model()
    force, moment = analysis.frame_load
    Q = frame.load_about_com(force, moment, tuple(analysis.moment_point))
    cycles = periodic_cycles(spec.motion)
    if cycles is not None:
        return periodic_response(frame, analysis.t, Q, cycles)
    return transient_response(frame, analysis.t, Q)


def _points(spec: Any, frame: Frame) -> list[tuple[str, str, tuple[float, float]]]:
    """(name, kind, point) where velocities are reported: centre of mass, mounts, named points."""
    return ([("com", "centre of mass", frame.com)] + [(m.name, "mount", m.at) for m in frame.mounts]
            + [(p.name, "point", (float(p.at[0]), float(p.at[1]))) for p in spec.frame.points])


def judge(value: float, limit: float | None) -> str | None:
    """"within limit" or "exceeds" (None without a limit)."""
    if limit is None:
        return None
    return "within limit" if value <= limit else "exceeds"


def stage_json(spec: Any, analysis: Any) -> dict:
    """One stage's floor forces per mount (peak and RMS of the force vector, RMS along x and y,
    N), vibration velocities per point (RMS along x, y and of the vector, peak of the vector,
    m/s) and the comparison with the spec's limits."""
    frame = spec.frame.model()
    r = stage_response(spec, analysis)
    forces = r.mount_forces(frame)
    mounts: list[dict[str, Any]] = []
    for m, f in zip(frame.mounts, forces):
        mounts.append({"name": m.name, "at": list(m.at), "peak": float(np.max(np.linalg.norm(f, axis=1))),
                       "rms": r.rms(f), "rms_x": r.rms(f[:, 0]), "rms_y": r.rms(f[:, 1])})
    velocity: list[dict[str, Any]] = []
    for name, kind, p in _points(spec, frame):
        v = r.point_velocity(frame, p)
        velocity.append({"name": name, "kind": kind, "at": list(p), "rms_x": r.rms(v[:, 0]), "rms_y": r.rms(v[:, 1]),
                         "rms": r.rms(v), "peak": float(np.max(np.linalg.norm(v, axis=1)))})
    limits = spec.frame.limits
    worst_v = max(velocity, key=lambda p: max(p["rms_x"], p["rms_y"]))
    worst_f = max(mounts, key=lambda m: m["peak"])
    checks = []
    if limits.velocity_rms is not None:
        value = max(worst_v["rms_x"], worst_v["rms_y"])
        checks.append({"quantity": "velocity_rms", "where": worst_v["name"], "value": value,
                       "limit": limits.velocity_rms, "verdict": judge(value, limits.velocity_rms)})
    if limits.force_peak is not None:
        checks.append({"quantity": "force_peak", "where": worst_f["name"], "value": worst_f["peak"],
                       "limit": limits.force_peak, "verdict": judge(worst_f["peak"], limits.force_peak)})
    return {"method": r.method, "orders_solved": r.orders, "mounts": mounts, "velocity": velocity, "limits": checks}


def near_resonance(frame: Frame, frequency: float | None, band: float, orders: int = ORDERS) -> list[dict]:
    """The excitation orders 1..``orders`` of a cycle of ``frequency`` (Hz) within ``band`` (a
    fraction) of a natural frequency: ``{order, frequency, mode, natural_frequency, ratio}``;
    none for a motion without orders (``frequency`` None)."""
    if frequency is None:
        return []
    out = []
    for i, mode in enumerate(modes(frame)):
        for k in range(1, orders + 1):
            ratio = k * frequency / mode.frequency
            if abs(ratio - 1.0) <= band:
                out.append({"order": k, "frequency": k * frequency, "mode": i + 1,
                            "natural_frequency": mode.frequency, "ratio": ratio})
    return out


def mounts_json(study: Any) -> dict | None:
    """What ``results.json`` holds under ``mounts`` (None when the spec has no ``frame``): the
    frame, its natural modes, the excitation orders near them, the limits and, per stage name,
    :func:`stage_json`."""
    spec = study.spec
    if spec.frame is None:
        return None
    frame = spec.frame.model()
    cycles = periodic_cycles(spec.motion)
    frequency = 1.0 / spec.motion.period if cycles is not None else None
    return {
        "frame": {"mass": frame.mass, "inertia": frame.inertia, "com": list(frame.com),
                  "mounts": [{"name": m.name, "at": list(m.at), "kx": m.kx, "ky": m.ky, "cx": m.cx, "cy": m.cy}
                             for m in frame.mounts]},
        "method": "orders" if cycles is not None else "time",
        "frequency": frequency,
        "modes": [{"mode": i + 1, "frequency": m.frequency, "shape": list(m.shape),
                   "direction": list(m.direction(frame)), "damping_ratio": m.damping_ratio}
                  for i, m in enumerate(modes(frame))],
        "resonance_band": spec.frame.resonance_band,
        "near_resonance": near_resonance(frame, frequency, spec.frame.resonance_band),
        "limits": {"velocity_rms": spec.frame.limits.velocity_rms, "force_peak": spec.frame.limits.force_peak},
        "stages": {s.stage.name: stage_json(spec, s.analysis) for s in study.stages},
    }
