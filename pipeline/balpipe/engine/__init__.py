"""The generic planar multibody engine: kinematics, inverse dynamics and shaking loads.

Coordinates are absolute: body k has q_k = (x, y, theta) of its centre of mass (attachments
included). The frame is body 0 with q_0 = 0; it takes part in the constraint Jacobian so that
``-J_0^T lambda`` is directly the load the mechanism puts on the frame (force, and moment about
the origin O).

Every joint and driver reduces to three constraint primitives, each vectorised over the N time
samples:

* ``coincident``: r_i + A_i s_i - r_j - A_j s_j = 0 (2 rows; revolute joints);
* ``angle``: sum_k c_k theta_k - c0 - f(t) = 0 (relative angles, gears, angle drivers,
  the rotation lock of a prismatic pair);
* ``projection``: (A_i a)^T (r_j + A_j s_j - r_i - A_i s_i) - c0 - f(t) = 0 (the guide of a
  prismatic pair, prismatic drivers, point-coordinate drivers).

Position analysis is Newton-Raphson on Phi(q, t) = 0; velocities solve Phi_q q' = nu and
accelerations Phi_q q'' = gamma (Haug, Computer-Aided Kinematics and Dynamics, ch. 3 and 6).
Inverse dynamics solves Phi_q^T lambda = Q - M q'' (M q'' + Phi_q^T lambda = Q).

Redundant actuation (more drivers than degrees of freedom, e.g. a 4-RRR with four base motors):
the consistent over-determined position, velocity and acceleration equations are solved in least
squares (Gauss-Newton, exact for consistent drivers; by the normal equations, refined, where they are
well conditioned, :mod:`.normal`, else by QR), and the
multipliers are those whose actuator efforts have the least norm (:func:`.dynamics.solve_multipliers`). The
joints alone must not be over-constrained. The shaking
loads are computed twice, independently:

(a) reactions: F_sh, M_sh = -Phi_{q0}^T lambda (all frame joints, actuator reactions and gear
    mesh couples on the frame); a gear pair with pitch radii has its row rewritten as tooth
    forces at the pitch point for the dynamics (:func:`.dynamics.tooth_rows`, :mod:`balpipe.mechanics.meshes`), so
    that its bearings carry the tooth force;
(b) momentum: F_sh = sum m g - dP/dt, M_O = sum r x m g - dH_O/dt.

Modules, one job each: :mod:`.compile` (primitives, :func:`compile_model`), :mod:`.constraints`
(Phi, Phi_q, nu, gamma), :mod:`.positions` (continuation; its solves on the block path in
:mod:`.newton_blocks`), :mod:`.kinematics` (velocities, accelerations),
:mod:`.dynamics` (multipliers, tooth loads, reactions), :mod:`.normal` (the redundant systems' solves by
the normal equations), :mod:`.analysis` (:class:`Analysis`,
:func:`analyse`), :mod:`.structure` and :mod:`.fastpath` (the block-triangular path),
:mod:`.warmstart` (a new geometry of a closed loop solved from fixed anchors:
:func:`record_anchors`, :func:`warm_start`), :mod:`.shared` (the general path's models of one
geometry placed in its frame motion, solved once), :mod:`.conditioning` (the largest condition
number of a motion, with SVDs only where it can be: :func:`condition_peak`).
"""

from .analysis import Analysis, analyse, clear_cache, compiled, condition_peak
from .compile import Compiled, compile_model
from .constraints import acceleration_rhs, jacobian, residual, velocity_rhs
from .errors import AnalysisError
from .warmstart import Anchors, record as record_anchors, warm_start
from .positions import condition_numbers, follow_motion, redundancy, solve_positions

__all__ = [
    "Analysis", "AnalysisError", "Anchors", "Compiled", "acceleration_rhs", "analyse", "clear_cache", "compile_model", "compiled", "condition_peak", "jacobian",
    "record_anchors", "redundancy", "residual", "solve_positions", "velocity_rhs", "warm_start",
]
