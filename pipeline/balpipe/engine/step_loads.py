"""A model's loads at one state, in plain floats: the pymunk run's per-step evaluation.

:func:`balpipe.engine.loads.terms` evaluates the loads along a motion with numpy, which costs
70 to 170 microseconds a call for one sample on the specs' loads (numpy on arrays of one or two
numbers): more than the pymunk step it comes before. :class:`StepLoads` compiles, once per model, what each load needs (body
indices, its points relative to the centres of mass, its constants, its table's rows) into
Python closures that evaluate one state with floats and :mod:`math`.

Guarantee: the generalized forces Q and the Coulomb frictions' unit forces equal those of
``terms`` at the same state to 1e-12 of their largest (``tests/validate/test_step_loads.py``, every
kind of load at random states), and to the last bit where numpy's ``cos``, ``sin``,
``linalg.norm`` and two-term ``einsum`` round as :mod:`math` and the written-out sums do (they
do on the machines measured; the specs' simulated results are the same bytes): the same
operations in the same order, the tension, torque, stroke and table formulas being the engine's
own (:func:`~balpipe.engine.loads.tension`, :func:`~balpipe.engine.loads.torsion`,
:func:`~balpipe.engine.loads.stroke`, :meth:`~balpipe.mechanics.loads.LoadTable.at`). Only what
acts on the moving bodies is evaluated: the frame's reactions and the external loads' totals are
the analysis' business.
"""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from ..mechanics.loads import Anchor, AppliedLoad, ForceElement, JointFriction, LoadTable, Load, TorsionElement
from ..model import FRAME, Model, Prismatic, Revolute
from .compile import Compiled
from .loads import deflection, driver, stroke, tension, torsion, unknown_argument

#: (cos, sin) of each body's angle at the state (None for a body no load turns with)
Trig = list[tuple[float, float] | None]
#: one Coulomb friction's unit generalized force: (coordinate, value) pairs, the others zero
Unit = list[tuple[int, float]]
#: a compiled load: adds its generalized forces to Q and its Coulomb unit force (if any) to units
Term = Callable[[float, list[float], list[float], Trig, list[float], list[Unit]], None]
#: a compiled anchor: (P_x, P_y, V_x, V_y) of the point at the state
Point = Callable[[list[float], list[float], Trig], tuple[float, float, float, float]]
#: a compiled table argument: (x, rate) at the state, given the element's own (deflection, rate)
Argument = Callable[[float, list[float], list[float], Trig, tuple[float, float]], tuple[float, float]]

_NO_TURN = (1.0, 0.0)  # the frame's angle: np.cos(0), np.sin(0)


class StepLoads:
    """The loads of ``model`` (compiled ``c``) at one state: ``Q, units = loads(t, q, v)`` with
    q, v the 3 nb centre-of-mass coordinates and rates as lists of floats; Q (3 nb floats) every
    load's generalized force except Coulomb friction, ``units[j]`` the unit force of the j-th
    Coulomb friction (:attr:`coulomb` names them, in the engine's order). Equal to
    :func:`balpipe.engine.loads.terms` at that state (module docstring). :attr:`bodies`: the
    bodies (indices, ascending) the loads act on or read: only their entries of q and v are
    read, and only theirs of Q and the units can be nonzero."""

    def __init__(self, model: Model, c: Compiled):
        self.model, self.c = model, c
        self.nb = c.nb
        self.index = {n: k for k, n in enumerate(c.names)}
        self.coulomb: list[str] = []
        self._turning: set[int] = set()
        self._read: set[int] = set()
        self._terms = [self._compile(load) for load in model.loads]
        self._turn = sorted(self._turning)
        self.bodies = sorted(self._read)

    def __call__(self, t: float, q: list[float], v: list[float]) -> tuple[list[float], list[Unit]]:
        trig: Trig = [None] * self.nb
        for k in self._turn:
            th = q[3 * k + 2]
            trig[k] = (math.cos(th), math.sin(th))
        Q = [0.0] * (3 * self.nb)
        units: list[Unit] = []
        for term in self._terms:
            term(t, q, v, trig, Q, units)
        return Q, units

    # ---- compilation --------------------------------------------------------------------------

    def _compile(self, load: Load) -> Term:
        if isinstance(load, ForceElement):
            return self._element(load)
        if isinstance(load, TorsionElement):
            return self._torsion(load)
        if isinstance(load, AppliedLoad):
            return self._applied(load)
        if isinstance(load, JointFriction):
            return self._friction(load)
        raise TypeError(load)  # pragma: no cover - the Load union is closed

    def _body(self, name: str) -> int | None:
        if name == FRAME:
            return None
        try:
            k = self.index[name]
        except KeyError:
            raise ValueError(f"a load refers to unknown body {name!r}") from None
        self._read.add(k)
        return k

    def _turns(self, k: int | None) -> None:
        if k is not None:
            self._turning.add(k)

    def _point(self, a: Anchor) -> tuple[int | None, Point]:
        """The anchor's body and its point at a state (the engine's ``_Motion.point``)."""
        k = self._body(a.body)
        p = np.asarray(a.point, dtype=float)
        if k is None:
            px, py = float(p[0]), float(p[1])
            return None, lambda q, v, trig: (px, py, 0.0, 0.0)
        ax, ay = (float(x) for x in p - self.c.com_local[k])
        i = 3 * k
        self._turns(k)

        def point(q: list[float], v: list[float], trig: Trig) -> tuple[float, float, float, float]:
            c, s = trig[k] or _NO_TURN
            rx, ry = c * ax - s * ay, s * ax + c * ay
            w = v[i + 2]
            return q[i] + rx, q[i + 1] + ry, v[i] + w * -ry, v[i + 1] + w * rx

        return k, point

    def _argument(self, law: LoadTable, own: bool) -> Argument:
        """A table's argument at a state (the engine's ``_Motion.argument``)."""
        kind = law.argument[0]
        if kind == "time":
            return lambda t, q, v, trig, own: (t, 1.0)
        if kind == "driver":
            d = driver(self.model, law.argument[1])

            def position(t: float, q: list[float], v: list[float], trig: Trig, own: tuple[float, float]) -> tuple[float, float]:
                x, xd, _ = d.law(np.array([t]))
                return float(np.asarray(x, dtype=float).reshape(-1)[0]), float(np.asarray(xd, dtype=float).reshape(-1)[0])

            return position
        if kind == "stroke":
            _, body, p, direction, origin = law.argument
            _, point = self._point(Anchor(body, p))

            def moved(t: float, q: list[float], v: list[float], trig: Trig, own: tuple[float, float]) -> tuple[float, float]:
                px, py, vx, vy = point(q, v, trig)
                return stroke(px, py, vx, vy, direction, origin)

            return moved
        if kind == "deflection" and own:
            return lambda t, q, v, trig, own: own
        raise unknown_argument(law)

    def _element(self, e: ForceElement) -> Term:
        ka, pa = self._point(e.a)
        kb, pb = self._point(e.b)
        argument = None if e.law is None else self._argument(e.law, True)
        table, preload = e.law, float(e.preload)

        def term(t: float, q: list[float], v: list[float], trig: Trig, Q: list[float], units: list[Unit]) -> None:
            pax, pay, vax, vay = pa(q, v, trig)
            pbx, pby, vbx, vby = pb(q, v, trig)
            dx, dy = pbx - pax, pby - pay
            L = math.sqrt(dx * dx + dy * dy)
            ux, uy = dx / L, dy / L
            Ld = (vbx - vax) * ux + (vby - vay) * uy
            law = None if argument is None or table is None else table.at(*argument(t, q, v, trig, deflection(e, L, Ld)))
            T = tension(e, preload, L, Ld, law)
            if ka is not None:
                _push(Q, q, ka, pax, pay, T * ux, T * uy)
            if kb is not None:
                _push(Q, q, kb, pbx, pby, -T * ux, -T * uy)

        return term

    def _torsion(self, e: TorsionElement) -> Term:
        jt = self.model.joint(e.joint)
        if isinstance(jt, Prismatic):
            raise ValueError(f"torsion element on {e.joint!r}: a prismatic joint has no relative angle")
        ka, kb = self._body(jt.a), self._body(jt.b)
        preload = float(e.preload)

        def term(t: float, q: list[float], v: list[float], trig: Trig, Q: list[float], units: list[Unit]) -> None:
            tha, wa = (0.0, 0.0) if ka is None else (q[3 * ka + 2], v[3 * ka + 2])
            thb, wb = (0.0, 0.0) if kb is None else (q[3 * kb + 2], v[3 * kb + 2])
            T = torsion(e, preload, thb - tha, wb - wa)
            for k, s in ((kb, -1.0), (ka, 1.0)):
                if k is not None:
                    Q[3 * k + 2] += s * T

        return term

    def _applied(self, e: AppliedLoad) -> Term:
        k, point = self._point(e.at)
        argument = None if e.law is None else self._argument(e.law, False)
        table = e.law
        fx, fy = (float(x) for x in np.asarray(e.force, dtype=float))
        torque, body_axes = e.torque, e.axes == "body"

        def term(t: float, q: list[float], v: list[float], trig: Trig, Q: list[float], units: list[Unit]) -> None:
            if k is None:
                return  # on the frame: not simulated
            px, py, _, _ = point(q, v, trig)
            value = 1.0 if argument is None or table is None else table.at(*argument(t, q, v, trig, (0.0, 0.0)))
            gx, gy = fx, fy
            if body_axes:
                c, s = trig[k] or _NO_TURN
                gx, gy = c * fx - s * fy, s * fx + c * fy
            _push(Q, q, k, px, py, gx * value, gy * value)
            Q[3 * k + 2] += torque * value

        return term

    def _friction(self, e: JointFriction) -> Term:
        jt = self.model.joint(e.joint)
        viscous = e.viscous
        if isinstance(jt, Revolute):
            ka, kb = self._body(jt.a), self._body(jt.b)
            coulomb = e.coefficient * e.pin_radius != 0.0

            def revolute(t: float, q: list[float], v: list[float], trig: Trig, Q: list[float], units: list[Unit]) -> None:
                rate = (0.0 if kb is None else v[3 * kb + 2]) - (0.0 if ka is None else v[3 * ka + 2])
                direction = _against(rate)
                unit: Unit = []
                for k, s in ((kb, 1.0), (ka, -1.0)):
                    if k is not None:
                        Q[3 * k + 2] += -s * viscous * rate
                        unit.append((3 * k + 2, s * direction))
                if coulomb:
                    units.append(unit)

            if coulomb:
                self.coulomb.append(e.name)
            return revolute
        if isinstance(jt, Prismatic):
            kg = self._body(jt.guide)
            ks, point = self._point(Anchor(jt.slider, jt.point_slider))
            self._turns(kg)
            axis = np.asarray(jt.axis, dtype=float)
            a0, a1 = (float(x) for x in axis / np.linalg.norm(axis))
            coulomb = e.coefficient != 0.0

            def prismatic(t: float, q: list[float], v: list[float], trig: Trig, Q: list[float], units: list[Unit]) -> None:
                px, py, vx, vy = point(q, v, trig)
                c, s = _NO_TURN if kg is None else trig[kg] or _NO_TURN
                ux, uy = c * a0 - s * a1, s * a0 + c * a1
                if kg is not None:  # less the guide's velocity at the slider's point
                    i = 3 * kg
                    w = v[i + 2]
                    vx, vy = vx - (v[i] + w * -(py - q[i + 1])), vy - (v[i + 1] + w * (px - q[i]))
                rate = vx * ux + vy * uy
                direction = _against(rate)
                unit: Unit = []
                for k, s in ((ks, 1.0), (kg, -1.0)):
                    if k is not None:
                        f = -s * viscous * rate
                        _push(Q, q, k, px, py, f * ux, f * uy)
                        g = s * direction
                        i = 3 * k
                        unit += [(i, g * ux), (i + 1, g * uy), (i + 2, (px - q[i]) * (g * uy) - (py - q[i + 1]) * (g * ux))]
                if coulomb:
                    units.append(unit)

            if coulomb:
                self.coulomb.append(e.name)
            return prismatic
        raise ValueError(f"friction {e.name!r}: joint {e.joint!r} is a gear pair, not a revolute or prismatic joint")


def _push(Q: list[float], q: list[float], k: int, px: float, py: float, fx: float, fy: float) -> None:
    """Add a force (fx, fy) at (px, py) on body k: to its (x, y) and its moment to its angle."""
    i = 3 * k
    Q[i] += fx
    Q[i + 1] += fy
    Q[i + 2] += (px - q[i]) * fy - (py - q[i + 1]) * fx


def _against(rate: float) -> float:
    """-sgn(rate), as ``-np.sign`` gives it (0 at rest, NaN for NaN)."""
    if rate > 0.0:
        return -1.0
    if rate < 0.0:
        return 1.0
    return float(-np.sign(rate))
