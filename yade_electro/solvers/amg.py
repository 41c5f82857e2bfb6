"""CG preconditioned by a PyAMG smoothed-aggregation V-cycle, its hierarchy kept.

See :mod:`yade_electro.solvers` for the protocol and the choice of a solver.
"""
from __future__ import annotations

import logging
from typing import Optional

import scipy.sparse as sp

from ..core.errors import SolverError

# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.core.threads
from .cg import CGSolver

__all__ = ["AMGSolver"]

log = logging.getLogger(__name__)


class AMGSolver(CGSolver):
    """CG preconditioned by a PyAMG smoothed-aggregation V-cycle whose hierarchy is kept across
    value changes (see module doc).

    Parameters
    ----------
    rtol, maxiter : as :class:`CGSolver`
    resetup_factor : float
        Rebuild the hierarchy when a solve takes more than this many times the iterations of
        the first solve after the last setup (default 1.5).
    """

    name = "cg-amg"

    def __init__(self, rtol: float = 1e-10, maxiter: Optional[int] = None, resetup_factor: float = 1.5):
        super().__init__(rtol=rtol, preconditioner="jacobi", maxiter=maxiter)
        try:
            import pyamg  # noqa: F401,F811
        except ImportError:
            raise SolverError("solver 'cg-amg' needs PyAMG (install it with `make install` or "
                              "`pip install pyamg`), or use solver='cg-deflated'") from None
        self.preconditioner = "amg"
        self.resetup_factor = float(resetup_factor)
        self._ref_iterations = None
        self.n_resetups = 0

    def _setup(self, A):
        import pyamg
        self._Acsr = A if sp.isspmatrix_csr(A) else sp.csr_matrix(A)
        self._ml = pyamg.smoothed_aggregation_solver(self._Acsr, symmetry="symmetric", max_coarse=200)
        self._M = self._ml.aspreconditioner(cycle="V")
        self._ref_iterations = None

    def _update(self, A):
        # keep the hierarchy, give it the new finest operator
        self._ml.levels[0].A = self._Acsr
        self._M = self._ml.aspreconditioner(cycle="V")

    def solve(self, A, b, x0=None, atol: float = 0.0):
        x, info = super().solve(A, b, x0, atol)
        it = info["iterations"]
        if self._ref_iterations is None:
            self._ref_iterations = max(it, 1)
        elif it > self.resetup_factor * self._ref_iterations:
            log.info("cg-amg: %d iterations against %d after the last setup: rebuilding the hierarchy",
                     it, self._ref_iterations)
            self._A = None                       # full setup at the next solve
            self.n_resetups += 1
        return x, info
