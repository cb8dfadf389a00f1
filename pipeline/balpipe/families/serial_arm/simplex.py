"""Nelder-Mead from several starts at once, each point of every start's simplex evaluated in one
call of a vectorised objective (paper 003's phi optimisation).

:func:`nelder_mead` is the downhill simplex of ``scipy.optimize.minimize(method="Nelder-Mead")``
(scipy 1.17's ``_minimize_neldermead``: standard coefficients rho = 1, chi = 2, psi = sigma = 1/2,
no bounds, an initial simplex given, at most ``maxfev`` evaluations, no iteration limit) written as
a generator: it yields each point it needs and receives its value, so that the searches from
several starts, which do not depend on each other, advance together (:func:`minimise_together`)
and an objective that costs mostly its fixed overhead per call (numpy on a few hundred samples)
evaluates one point of each search per call. Every arithmetic operation is scipy's, in its order,
on the same arrays: each search visits the points, and returns the optimum, that scipy's would,
bit for bit (tests/families/test_com_planning.py compares them).
"""

from __future__ import annotations

from collections.abc import Callable, Generator, Sequence

import numpy as np

#: a search: yields the points it needs, receives their values, returns (x, f(x)) at its optimum
Search = Generator[np.ndarray, float, tuple[np.ndarray, float]]


class _Exhausted(Exception):
    """The evaluation budget is spent (scipy's ``_MaxFuncCallError``)."""


class _Budget:
    def __init__(self, maxfev: int):
        self.maxfev, self.calls = maxfev, 0

    def evaluate(self, x: np.ndarray) -> Generator[np.ndarray, float, float]:
        """The value of x, asked of the caller (a copy of x, as scipy hands to its objective)."""
        if self.calls >= self.maxfev:
            raise _Exhausted
        self.calls += 1
        return float((yield np.copy(x)))


def nelder_mead(simplex: np.ndarray, maxfev: int, xatol: float, fatol: float) -> Search:
    """The search from ``simplex`` ((n + 1, n) vertices) until the simplex is within ``xatol``
    of its best vertex and its values within ``fatol`` of the best value, or ``maxfev``
    evaluations are spent; returns the best vertex and its value."""
    rho, chi, psi, sigma = 1, 2, 0.5, 0.5
    sim = np.atleast_2d(simplex).copy()
    sim = np.asarray(sim, dtype=sim.dtype if np.issubdtype(sim.dtype, np.inexact) else np.float64)
    n = sim.shape[1]
    budget = _Budget(maxfev)
    f = budget.evaluate
    fsim = np.full((n + 1,), np.inf, dtype=float)
    try:
        for k in range(n + 1):
            fsim[k] = yield from f(sim[k])
    except _Exhausted:
        pass
    finally:
        ind = np.argsort(fsim)
        sim = np.take(sim, ind, 0)
        fsim = np.take(fsim, ind, 0)
    ind = np.argsort(fsim)
    fsim = np.take(fsim, ind, 0)
    sim = np.take(sim, ind, 0)
    while budget.calls < maxfev:
        try:
            if np.max(np.ravel(np.abs(sim[1:] - sim[0]))) <= xatol and np.max(np.abs(fsim[0] - fsim[1:])) <= fatol:
                break
            xbar = np.add.reduce(sim[:-1], 0) / n
            xr = (1 + rho) * xbar - rho * sim[-1]
            fxr = yield from f(xr)
            if fxr < fsim[0]:
                xe = (1 + rho * chi) * xbar - rho * chi * sim[-1]
                fxe = yield from f(xe)
                if fxe < fxr:
                    sim[-1], fsim[-1] = xe, fxe
                else:
                    sim[-1], fsim[-1] = xr, fxr
            elif fxr < fsim[-2]:
                sim[-1], fsim[-1] = xr, fxr
            else:
                shrink = False
                if fxr < fsim[-1]:  # contraction outside
                    xc = (1 + psi * rho) * xbar - psi * rho * sim[-1]
                    fxc = yield from f(xc)
                    if fxc <= fxr:
                        sim[-1], fsim[-1] = xc, fxc
                    else:
                        shrink = True
                else:  # inside
                    xcc = (1 - psi) * xbar + psi * sim[-1]
                    fxcc = yield from f(xcc)
                    if fxcc < fsim[-1]:
                        sim[-1], fsim[-1] = xcc, fxcc
                    else:
                        shrink = True
                if shrink:
                    for j in range(1, n + 1):
                        sim[j] = sim[0] + sigma * (sim[j] - sim[0])
                        fsim[j] = yield from f(sim[j])
        except _Exhausted:
            pass
        ind = np.argsort(fsim)
        sim = np.take(sim, ind, 0)
        fsim = np.take(fsim, ind, 0)
    return sim[0], float(np.min(fsim))


def minimise_together(values: Callable[[list[int], np.ndarray], Sequence[float]], searches: Sequence[Search]
                      ) -> list[tuple[np.ndarray, float]]:
    """Run ``searches`` side by side: at each step the point every unfinished search needs,
    evaluated by ``values(asking, points)`` (the indices of the searches asking, their (k, n)
    points -> the k values) in one call. Returns each search's (x, f(x)), in the order given.
    The searches are independent: each gives what it gives alone."""
    results: list[tuple[np.ndarray, float] | None] = [None] * len(searches)
    pending: dict[int, np.ndarray] = {}
    for i in range(len(searches)):
        _advance(searches, i, None, pending, results)
    while pending:
        asking = list(pending)
        for i, v in zip(asking, values(asking, np.stack([pending[i] for i in asking]))):
            _advance(searches, i, v, pending, results)
    return [r for r in results if r is not None]


def _advance(searches: Sequence[Search], i: int, value: float | None, pending: dict, results: list) -> None:
    """Hand search i its point's value (None: start it); keep the next point it asks, or its result."""
    try:
        pending[i] = next(searches[i]) if value is None else searches[i].send(value)
    except StopIteration as done:
        pending.pop(i, None)
        results[i] = done.value
