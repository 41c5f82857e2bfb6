"""Linear solvers for the SPD systems of the network problems, with one protocol and kept setup.

Protocol (PyAMG-like): ``solver.solve(A, b, x0=None) -> (x, info)``. A solver keeps its setup
(preconditioner, coarse space, factorisation) while it is given the same matrix object ``A``.
When the *values* of ``A`` change in place (same sparsity pattern), the owner calls
``solver.update(A)``: each solver then does the least work that keeps it right (see below).
A different matrix object means a new structure and a full setup. ``x0`` is a warm start
(the previous solution); ``info`` reports ``iterations``, ``residual`` (relative), ``setup``
(True when this call made a full setup) and times.

Solvers
-------
``'cg'`` (``'cg-jacobi'``)
    Conjugate gradient with the diagonal (Jacobi) preconditioner. ``update``: new diagonal.
``'cg-deflated'``
    CG with the Jacobi preconditioner and a deflation (coarse) space of piecewise-constant
    vectors on clusters of about ``cluster_size`` neighbour spacings (subdomain deflation,
    Frank & Vuik, SIAM J. Sci. Comput. 23, 2001; algorithm of Saad et al., SIAM J. Sci.
    Comput. 21, 2000). The clusters come from the node coordinates (``set_geometry``; without
    them, from runs of a reverse Cuthill-McKee ordering of the matrix graph); the
    coarse matrix ``E = W^T A W`` is re-assembled by one scatter and refactorised on
    ``update`` (dense Cholesky up to 400 clusters, sparse LU above). The smooth error modes
    that make Jacobi-CG slow on elongated or fine packings are removed exactly, so the
    iteration count no longer grows with the number of elements.
``'cg-amg'``
    CG with a PyAMG smoothed-aggregation V-cycle. ``update``: the hierarchy is kept and only
    its finest operator replaced; it is rebuilt when an iteration count exceeds
    ``resetup_factor`` (1.5) times the count of the first solve after the last setup, i.e.
    when the kept hierarchy no longer fits the matrix (large value changes).
``'petsc'``, ``'petsc-hypre'``, ``'petsc-gamg'``
    PETSc's CG through petsc4py (imported only when asked for). On one rank, preconditioned
    by GAMG (``'petsc'``, ``'petsc-gamg'``) or BoomerAMG (``'petsc-hypre'``), see
    :mod:`yade_electro.solvers.petsc`. An engine under ``mpiexec`` with more than one rank
    runs distributed (:mod:`yade_electro.solvers.partitioned`): ``'petsc'`` then
    preconditions with our deflation.
``'petsc-auto'``
    Distributed: the run's first solves measure our deflation and GAMG and the faster is kept
    (:mod:`yade_electro.solvers.measured`). In one process it is ``'auto'``.
``'direct'``
    Sparse LU (SuperLU). ``update``: refactorisation (there is no cheaper exact update).
``'auto'``
    The solver measured fastest for the size (``bench/bench_solvers.py``; see
    :func:`auto_solver_name`).

Tolerance: CG stops at ``||A x - b|| <= max(rtol ||b||, atol)`` (default rtol 1e-10, atol 0;
``solve(A, b, x0, atol=...)`` sets a floor for right-hand sides at rounding level) and raises
:class:`~yade_electro.core.errors.SolverError` if it cannot get there.

Threads: importing this module holds OpenBLAS to ``YADE_ELECTRO_BLAS_THREADS`` threads
(default 1, as inside YADE; 0 leaves it alone): see :mod:`yade_electro.core.threads` and
``bench/bench_threads.py``.
"""
from __future__ import annotations

import logging
import warnings
from typing import Optional

from ..core.errors import SolverError
from ..core.threads import apply_default_limit
from .amg import AMGSolver
from .base import DirectSolver
from .cg import CGSolver
from .deflation import DeflatedCGSolver

# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.core.threads
apply_default_limit()

__all__ = ["make_solver", "solver_names", "auto_solver_name", "check_solver_name", "AUTO_DEFLATION_FROM"]


log = logging.getLogger(__name__)

#: From this many unknowns on, ``'auto'`` picks ``'cg-deflated'`` (below it, ``'cg'``).
#: Measured by ``bench/bench_solvers.py`` (docs/benchmarks.md): with its compiled
#: iterations the deflated CG is the faster from the smallest rod measured (84 unknowns: cold
#: solve 1.0 against 1.3 ms, re-solve 0.33 against 0.81 ms); with numpy's it was from about
#: 2,000 unknowns, the value used before. Below 80 unknowns any solve takes microseconds.
AUTO_DEFLATION_FROM = 80


def auto_solver_name(n_unknowns: int) -> str:
    """The solver ``'auto'`` stands for at a given size: ``'cg'`` below
    :data:`AUTO_DEFLATION_FROM` unknowns, ``'cg-deflated'`` from there on."""
    return "cg-deflated" if n_unknowns >= AUTO_DEFLATION_FROM else "cg"



_SOLVERS = {"direct": DirectSolver, "cg": CGSolver, "cg-jacobi": CGSolver, "cg-deflated": DeflatedCGSolver,
            "cg-amg": AMGSolver}


#: solvers in modules of their own, imported when asked for (their dependencies are optional)
_LAZY_SOLVERS = ("petsc", "petsc-hypre", "petsc-gamg", "petsc-auto")


def solver_names() -> tuple:
    """Names :func:`make_solver` knows (plus ``'auto'``)."""
    return tuple(sorted(list(_SOLVERS) + list(_LAZY_SOLVERS) + ["auto"]))


def make_solver(solver="auto", n_unknowns: Optional[int] = None, **kw):
    """A solver object from a name (see module doc), or an object with ``solve(A, b, x0=None)
    -> (x, info)`` passed through. ``'auto'`` needs ``n_unknowns``."""
    if hasattr(solver, "solve"):
        return solver
    if solver == "auto":
        if n_unknowns is None:
            raise ValueError("solver='auto' needs the number of unknowns")
        solver = auto_solver_name(n_unknowns)
    if solver == "petsc-auto":            # distributed runs measure; one process takes 'auto'
        return make_solver("auto", n_unknowns, **kw)
    if solver in _LAZY_SOLVERS:
        from .petsc import PETScSolver
        return PETScSolver(**{"preconditioner": "hypre" if solver == "petsc-hypre" else "gamg", **kw})
    try:
        cls = _SOLVERS[solver]
    except (KeyError, TypeError):
        raise ValueError(f"unknown solver {solver!r}; known: {', '.join(solver_names())}") from None
    if solver == "cg-amg":
        try:
            return cls(**kw)
        except SolverError as exc:
            warnings.warn(f"{exc}; falling back to 'cg-deflated'", stacklevel=2)
            return DeflatedCGSolver(**{k: v for k, v in kw.items() if k in ("rtol", "maxiter")})
    return cls(**kw)


def check_solver_name(solver) -> None:
    """Raise ValueError for an unknown solver name (objects with ``solve`` pass)."""
    if hasattr(solver, "solve"):
        return
    if solver != "auto" and solver not in _SOLVERS and solver not in _LAZY_SOLVERS:
        raise ValueError(f"unknown solver {solver!r}; known: {', '.join(solver_names())}")
    if solver in _LAZY_SOLVERS:          # missing petsc4py or hypre: say so when the engine is built
        from .petsc import check_preconditioner
        check_preconditioner("hypre" if solver == "petsc-hypre" else "gamg")
