"""cvxpy's Clarabel interface with a cheaper re-solve: the same problem data, the same answers.

A front (:mod:`.partial_fronts`) solves one compiled problem at many values of a parameter that
only enters the constraints' right-hand side ``b``. cvxpy's own interface hands Clarabel the whole
data (P, q, A, b) at every re-solve, and Clarabel copies and rescales all of it (by the
equilibration of its first data). :func:`solver` returns a cvxpy solver (a subclass of cvxpy's
``CLARABEL``, so the same compilation and the same data) that does that full update once, at the
first re-solve, and afterwards updates ``b`` alone while P, q and A are unchanged, bit for bit.

Why the first re-solve still updates everything: the set-up scales A in the steps of its
equilibration, a data update in one step (E A D), and the two round differently; from the first
full update on, the solver holds A as every later full update would leave it, so skipping them
changes no bit of any answer (a test compares the two interfaces on random parameters).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

NAME = "BALPIPE_CLARABEL"  # cvxpy refuses a custom solver under a supported solver's name


@dataclass
class Cached:
    """A Clarabel solver and the (P, q, A) it holds since its last full update (None before)."""

    solver: object
    data: tuple | None = None

    def holds(self, P, q, A) -> bool:
        """True when the solver's P, q and A are these, bit for bit, after a full update."""
        if self.data is None:
            return False
        return all(_same(x, y) for x, y in zip(self.data, _arrays(P, q, A)))


def _arrays(P, q, A) -> tuple:
    return (P.indptr, P.indices, P.data, np.asarray(q), A.indptr, A.indices, A.data)


def _same(x: np.ndarray, y: np.ndarray) -> bool:
    return x.shape == y.shape and x.dtype == y.dtype and bool(np.array_equal(x, y))


@functools.cache
def solver():
    """The solver instance to pass as ``problem.solve(solver=...)`` (one instance: cvxpy keys its
    compiled problem on it). Imports cvxpy."""
    import scipy.sparse as sp
    from cvxpy.reductions.solvers.conic_solvers.clarabel_conif import CLARABEL, dims_to_solver_cones

    class Clarabel(CLARABEL):
        """cvxpy's ``CLARABEL`` whose re-solves update only ``b`` where nothing else changed."""

        def name(self) -> str:
            return NAME

        def solve_via_data(self, data, warm_start: bool, verbose: bool, solver_opts, solver_cache=None):
            """As ``CLARABEL.solve_via_data``; a cached solver whose P, q and A are these gets
            ``b`` alone."""
            import clarabel

            A, b, q = data["A"], data["b"], data["c"]
            P = sp.triu(data["P"] if "P" in data else sp.csc_array((q.size, q.size))).tocsc()
            cached = solver_cache.get(NAME) if warm_start and solver_cache is not None else None
            if cached is not None and cached.holds(P, q, A):
                cached.solver.update(b=b)
            elif cached is not None and hasattr(cached.solver, "update") and cached.solver.is_data_update_allowed():
                settings = self.parse_solver_opts(verbose, solver_opts, cached.solver.get_settings())
                try:
                    cached.solver.update(P=P, q=q, A=A, b=b, settings=settings)
                    cached.data = tuple(x.copy() for x in _arrays(P, q, A))
                except Exception:  # another sparsity pattern or size: a new solver, as cvxpy does
                    cached = None
            else:
                cached = None
            if cached is None:
                cones = dims_to_solver_cones(data[self.DIMS])
                cached = Cached(clarabel.DefaultSolver(P, q, A, b, cones, self.parse_solver_opts(verbose, solver_opts)))
            results = cached.solver.solve()
            if solver_cache is not None:
                solver_cache[NAME] = cached
            return results

    return Clarabel()
