"""What a spec's loads do, for ``results.json``, the page and the time series: each load's peak
per stage, the friction's energy over the motion, the frame load beside the shaking load.

Definitions (DESIGN.md, "Loads, and what the frame feels"): the shaking force and moment are the
inertial ones (the moving links' weight less their momentum rates), unchanged by any load; the
frame load is everything the frame feels (bearings, slideways, the motors' reactions, the
frame-side reactions of internal loads) and equals the shaking load plus the external loads.
"""

from __future__ import annotations

import numpy as np

from ..mechanics.loads import AppliedLoad, ForceElement, JointFriction, TorsionElement

#: per load type: (the series shown, what it is, its unit)
# the series shown for each element (applied loads and joint friction choose theirs by the series)
_SHOWN: dict[type, tuple[str, str, str]] = {
    ForceElement: ("tension", "tension (pulls its ends together)", "N"),
    TorsionElement: ("torque", "torque on the joint's second body (negated)", "N m"),
}


def _kind(load) -> str:
    if isinstance(load, ForceElement):
        if load.law is not None and load.scale < 0:
            return "pressure x area"
        if load.law is not None:
            return "force law (table)"
        return "spring" + ("-damper" if load.damping and load.stiffness else "") if load.stiffness else (
            "damper" if load.damping else "constant force")
    if isinstance(load, TorsionElement):
        return "torsional spring/damper"
    if isinstance(load, AppliedLoad):
        return "applied " + ("table" if load.law is not None else "constant") + f" ({load.axes} axes)"
    return "joint friction"


def _peak(load, series: dict[str, np.ndarray]) -> tuple[str, float, str]:
    """(what, peak |value|, unit) of one load's series."""
    if isinstance(load, AppliedLoad):
        f = np.hypot(series["Fx"], series["Fy"])
        if np.any(f):
            return "|force|", float(np.max(f)), "N"
        return "|torque|", float(np.max(np.abs(series["torque"]))), "N m"
    if isinstance(load, JointFriction):
        key = "torque" if "torque" in series else "force"
        return f"|friction {key}|", float(np.max(np.abs(series[key]))), "N m" if key == "torque" else "N"
    key, what, unit = _SHOWN[type(load)]
    return f"|{key}|", float(np.max(np.abs(series[key]))), unit


def _energy(t: np.ndarray, p: np.ndarray) -> float:
    return float(np.sum(0.5 * (p[1:] + p[:-1]) * np.diff(t))) if len(t) > 1 else 0.0


def load_summary(stages: list) -> dict | None:
    """``stages``: (name, label, model, analysis). None when the model has no loads; else the
    loads (name, kind, source, per stage the peak and, for friction, the energy it dissipates over
    the motion) and per stage the peaks of the frame load beside those of the shaking load."""
    model0 = stages[0][2]
    if not model0.loads:
        return None
    rows = []
    for load in model0.loads:
        row = {"name": load.name, "kind": _kind(load), "source": load.source, "peaks": {}, "energy": {}}
        for name, _, _, an in stages:
            what, value, unit = _peak(load, an.loads[load.name])
            row.update(what=what, unit=unit)
            row["peaks"][name] = value
            if isinstance(load, JointFriction):
                row["energy"][name] = _energy(an.t, an.loads[load.name]["loss"])
        rows.append(row)
    frame = []
    for name, label, _, an in stages:
        F, M = an.frame_load
        frame.append({"stage": name, "label": label,
                      "max_frame_force": float(np.max(np.hypot(F[:, 0], F[:, 1]))),
                      "max_frame_moment": float(np.max(np.abs(M))),
                      "max_shaking_force": an.max_force, "max_shaking_moment": an.max_moment,
                      "friction_energy": sum(r["energy"].get(name, 0.0) for r in rows)})
    return {"loads": rows, "frame": frame,
            "external": any(ld.source == "external" for ld in model0.loads)}


#: the unit of a load's series (:mod:`balpipe.engine.loads`) as a column name ends with it
SERIES_UNITS = {"tension": "N", "length": "m", "power": "W", "loss": "W", "torque": "Nm", "angle": "rad",
                "Fx": "N", "Fy": "N", "force": "N", "reaction": "N", "normal": "N"}


def series_unit(key: str, keys) -> str:
    """The unit tag of the series ``key`` of a load whose series are ``keys``: a friction's
    ``rate`` and Coulomb magnitude ``coulomb`` follow its joint (rad/s and N m where it has a
    ``torque``, a revolute's; m/s and N for a prismatic pair's ``force``)."""
    turning = "torque" in keys
    if key == "rate":
        return "rad_s" if turning else "m_s"
    if key == "coulomb":
        return "Nm" if turning else "N"
    return SERIES_UNITS[key]


def load_columns(stage: str, an) -> list[tuple[str, np.ndarray]]:
    """The time series of the loads of one stage: the frame load (Fx, Fy, M about the moment
    point), then every series of every load (``stage.load.name.series_unit``,
    :func:`series_unit`); none without loads."""
    if an.frame_force is None:
        return []
    cols = [(f"{stage}.frame.Fx_N", an.frame_force[:, 0]), (f"{stage}.frame.Fy_N", an.frame_force[:, 1]),
            (f"{stage}.frame.M_Nm", an.frame_moment)]
    for name in an.loads:
        series = an.loads[name]
        cols += [(f"{stage}.load.{name}.{key}_{series_unit(key, series)}", v) for key, v in sorted(series.items())]
    return cols
