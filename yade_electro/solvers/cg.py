"""Preconditioned conjugate gradient, and CG with the Jacobi preconditioner.

See :mod:`yade_electro.solvers` for the protocol and the choice of a solver.
"""
from __future__ import annotations

import logging
import time
from typing import Optional

import numpy as np
import scipy.sparse as sp


# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.core.threads
from .base import (Solver, breakdown, check_converged, nonfinite_rhs, nonfinite_solution, nonpositive_diagonal)

__all__ = ["pcg", "CGSolver"]

log = logging.getLogger(__name__)


def pcg(A, b, x, M, rtol, maxiter, name, deflate=None, atol=0.0):
    """Preconditioned CG from ``x`` (modified in place) to ``||r|| <= max(rtol ||b||, atol)``;
    ``deflate`` = (coarse_correct, project) makes it the deflated CG of Saad et al. (2000).
    A start worse than zero (``||b - A x|| > ||b||``) is replaced by zero. Returns (x,
    iterations, relative residual)."""
    nb = np.linalg.norm(b)
    if nb == 0:
        x[:] = 0.0
        return x, 0, 0.0
    if not np.isfinite(nb):
        raise nonfinite_rhs(name, nb)
    tol = max(rtol * nb, atol)
    r = b - A @ x
    if np.linalg.norm(r) > nb:
        x[:] = 0.0
        r = b.copy()
    if deflate is not None:
        coarse, project = deflate
        x += coarse(r)                      # remove the coarse error components at once
        r = b - A @ x
    rn = np.linalg.norm(r)
    it = 0
    if rn > tol:
        z = M(r)
        p = z.copy() if deflate is None else z - project(z)
        rz = r @ z
        while it < maxiter:
            it += 1
            q = A @ p
            pq = p @ q
            if not pq > 0:
                raise breakdown(name, pq)
            a = rz / pq
            x += a * p
            r -= a * q
            rn = np.sqrt(r @ r)
            if rn <= tol:
                break
            z = M(r)
            rz_new = r @ z
            p *= rz_new / rz
            p += z
            if deflate is not None:
                p -= project(z)
            rz = rz_new
    res = np.linalg.norm(b - A @ x) / nb
    if not np.all(np.isfinite(x)):
        raise nonfinite_solution(name)
    return x, it, res


class CGSolver(Solver):
    """Jacobi-preconditioned conjugate gradient (the paper's choice) for SPD systems.

    Parameters
    ----------
    rtol : float
        Stop when ||A x - b|| <= rtol ||b|| (default 1e-10).
    preconditioner : {'jacobi', 'none'}
        The diagonal, or none (for tests). AMG is :class:`AMGSolver`.
    maxiter : int, optional
        Default 10 n.
    """

    name = "cg"

    def __init__(self, rtol: float = 1e-10, preconditioner: str = "jacobi", maxiter: Optional[int] = None):
        super().__init__()
        if preconditioner not in ("jacobi", "none"):
            raise ValueError(f"preconditioner must be 'jacobi' or 'none' (AMG is solver 'cg-amg'), "
                             f"got {preconditioner!r}")
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must be in (0, 1), got {rtol}")
        self.rtol, self.preconditioner, self.maxiter = float(rtol), preconditioner, maxiter

    def _setup(self, A):
        self._Acsr = A if sp.isspmatrix_csr(A) else sp.csr_matrix(A)
        self._set_diagonal()

    def _set_diagonal(self):
        if self.preconditioner == "none":
            self._M = lambda r: r
            return
        d = self._Acsr.diagonal()
        if np.any(d <= 0):
            raise nonpositive_diagonal()
        inv = 1.0 / d
        self._inv_diag = inv
        self._M = lambda r: inv * r

    def _update(self, A):
        self._set_diagonal()

    def _deflation(self):
        return None

    def solve(self, A, b, x0=None, atol: float = 0.0):
        """Solve ``A x = b`` from ``x0`` to ``||A x - b|| <= max(rtol ||b||, atol)``."""
        fresh = self._ensure_setup(A)
        b = np.asarray(b, dtype=float)
        n = b.shape[0]
        x = np.zeros(n) if x0 is None else np.array(x0, dtype=float, copy=True)
        t = time.perf_counter()
        x, it, res = pcg(self._Acsr, b, x, self._M, self.rtol, self.maxiter or 10 * n + 10, self.name,
                          self._deflation(), atol)
        check_converged(self.name, res, np.linalg.norm(b), self.rtol, atol, it)
        return x, {"solver": self.name, "iterations": it, "residual": res, "setup": fresh,
                   "setup_time": self.setup_time, "iteration_time": time.perf_counter() - t}
