"""The solver protocol's base class, the direct solver and the checks every solver shares.

See :mod:`yade_electro.solvers` for the protocol and the choice of a solver.
"""
from __future__ import annotations

import logging
import time

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import SolverError

# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.core.threads

__all__ = ["Solver", "DirectSolver", "relative_residual", "check_converged", "nonfinite_rhs", "breakdown", "nonfinite_solution", "nonpositive_diagonal"]

log = logging.getLogger(__name__)


def relative_residual(A, x, b):
    nb = np.linalg.norm(b)
    r = np.linalg.norm(A @ x - b)
    return r / nb if nb > 0 else r


class Solver:
    """Base of the solvers: keeps the setup while it is given the same matrix object, counts
    setups and value updates (see module doc). Subclasses define ``_setup(A)``, optionally
    ``_update(A)`` (default: a full setup), and ``solve``."""

    name = "?"

    def __init__(self):
        self._A = None
        self.setup_time = 0.0
        self.n_setups = 0
        self.n_updates = 0

    def _ensure_setup(self, A) -> bool:
        if A is not self._A:
            t = time.perf_counter()
            self._setup(A)
            self._A = A
            self.setup_time = time.perf_counter() - t
            self.n_setups += 1
            return True
        return False

    def update(self, A):
        """The values of ``A`` (the kept matrix object) changed in place, same pattern."""
        if A is not self._A:
            self._A = None          # a new structure: full setup at the next solve
            return
        self.n_updates += 1
        self._update(A)

    def _update(self, A):
        self._setup(A)

    def set_geometry(self, coords, spacing=None):
        """Coordinates (n, 3) [m] of the unknowns and their mean neighbour spacing [m]; used by
        solvers that build a coarse space, ignored by the others."""

    def _setup(self, A):  # pragma: no cover - abstract
        raise NotImplementedError


class DirectSolver(Solver):
    """Sparse LU (SuperLU, COLAMD ordering), kept while the matrix is unchanged and redone on
    ``update``. Exact to rounding."""

    name = "direct"

    def _setup(self, A):
        self._lu = spla.splu(sp.csc_matrix(A), permc_spec="COLAMD")

    def solve(self, A, b, x0=None, atol: float = 0.0):
        fresh = self._ensure_setup(A)
        x = self._lu.solve(np.asarray(b, dtype=float))
        if not np.all(np.isfinite(x)):
            raise SolverError("the direct solve produced non-finite values (singular matrix?)")
        return x, {"solver": self.name, "iterations": 0, "residual": relative_residual(A, x, b),
                   "setup": fresh, "setup_time": self.setup_time}


def nonfinite_rhs(name, nb) -> SolverError:
    return SolverError(f"{name}: the right-hand side is not finite (||b|| = {nb}); check sources and values")


def breakdown(name, pq) -> SolverError:
    return SolverError(f"{name} broke down (p.Ap = {pq:.3g} <= 0): the matrix is not positive "
                       "definite; check for negative or non-finite conductances")


def nonfinite_solution(name) -> SolverError:
    return SolverError(f"{name} produced non-finite values; check conductances for inf/nan")


def nonpositive_diagonal() -> SolverError:
    return SolverError("the matrix has a non-positive diagonal entry: a node with no conducting edge "
                       "was left among the unknowns")


def check_converged(name, res, nb, rtol, atol, it):
    if res * nb > 10 * max(rtol * nb, atol):
        raise SolverError(f"{name} did not converge: relative residual {res:.3e} > rtol {rtol:g} "
                          f"after {it} iterations; raise maxiter or use solver='direct'")
