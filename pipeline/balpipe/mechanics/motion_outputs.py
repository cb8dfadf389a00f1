"""Positions in the outputs: every body's pose, every named point's path
and the total centre of mass, with their velocities, from one analysis.

Nothing is re-derived from the drawing or the report: the engine's frame poses (x_O, y_O,
theta) of each body's own frame and its centre-of-mass velocities v_S, omega give

    v_O = v_S - omega J (r_S - r_O),   r_P = r_O + R(theta) p,   v_P = v_O + omega J R(theta) p

(J: rotation by +90 deg, p: a named point in the body frame), and the total centre of mass and
its velocity are the analysis' own: r_G = sum m_k r_k / M, v_G = (linear momentum) / M.
Column names and units are listed in docs/motion.md ("Positions in the time series").
"""

from __future__ import annotations

import numpy as np

Column = tuple[str, np.ndarray]


def body_columns(model, an) -> list[Column]:
    """``pose.<body>.{x_m, y_m, angle_rad, vx_m_s, vy_m_s, omega_rad_s}`` of every moving body's
    frame origin, then ``point.<body>.<point>.{x_m, y_m, vx_m_s, vy_m_s}`` of its named points."""
    out: list[Column] = []
    fp = an.frame_pose
    for k, name in enumerate(an.names):
        xo, yo, th = fp[:, k, 0], fp[:, k, 1], fp[:, k, 2]
        w = an.v[:, k, 2]
        dx, dy = an.q[:, k, 0] - xo, an.q[:, k, 1] - yo  # r_S - r_O
        vxo, vyo = an.v[:, k, 0] + w * dy, an.v[:, k, 1] - w * dx
        out += [(f"pose.{name}.x_m", xo), (f"pose.{name}.y_m", yo), (f"pose.{name}.angle_rad", th),
                (f"pose.{name}.vx_m_s", vxo), (f"pose.{name}.vy_m_s", vyo), (f"pose.{name}.omega_rad_s", w)]
        c, s = np.cos(th), np.sin(th)
        for pname, (px, py) in model.body(name).points.items():
            rx, ry = c * px - s * py, s * px + c * py
            out += [(f"point.{name}.{pname}.x_m", xo + rx), (f"point.{name}.{pname}.y_m", yo + ry),
                    (f"point.{name}.{pname}.vx_m_s", vxo - w * ry), (f"point.{name}.{pname}.vy_m_s", vyo + w * rx)]
    return out


def com_columns(an) -> list[Column]:
    """``com.{x_m, y_m, vx_m_s, vy_m_s}``: the total centre of mass of the moving bodies and its
    velocity (the linear momentum over the total mass; zero for a massless mechanism)."""
    M = an.total_mass
    v = an.momentum / M if M > 0 else np.zeros_like(an.momentum)
    return [("com.x_m", an.com[:, 0]), ("com.y_m", an.com[:, 1]), ("com.vx_m_s", v[:, 0]), ("com.vy_m_s", v[:, 1])]


def motion_columns(model, an) -> list[Column]:
    """The positions and velocities of one stage: :func:`com_columns` then :func:`body_columns`."""
    return com_columns(an) + body_columns(model, an)
