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
``'petsc'``
    PETSc's CG + GAMG through petsc4py, distributed over the ranks of ``mpiexec`` (see
    :mod:`yade_electro.petsc_solver`; imported only when asked for).
``'direct'``
    Sparse LU (SuperLU). ``update``: refactorisation (there is no cheaper exact update).
``'auto'``
    The solver measured fastest for the size (``bench/bench_solvers.py``; see
    :func:`auto_solver_name`).

Tolerance: CG stops at ``||A x - b|| <= max(rtol ||b||, atol)`` (default rtol 1e-10, atol 0;
``solve(A, b, x0, atol=...)`` sets a floor for right-hand sides at rounding level) and raises
:class:`~yade_electro.errors.SolverError` if it cannot get there.

Threads: importing this module holds OpenBLAS to ``YADE_ELECTRO_BLAS_THREADS`` threads
(default 1, as inside YADE; 0 leaves it alone): see :mod:`yade_electro.threads` and
``bench/bench_threads.py``.
"""
from __future__ import annotations

import logging
import time
import warnings
from typing import Optional

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from .errors import SolverError
from .threads import apply_default_limit

# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.threads
apply_default_limit()

__all__ = ["make_solver", "solver_names", "auto_solver_name", "Solver", "CGSolver", "DeflatedCGSolver", "AMGSolver",
           "DirectSolver", "AUTO_DEFLATION_FROM"]

log = logging.getLogger(__name__)

#: From this many unknowns on, ``'auto'`` picks ``'cg-deflated'`` (below it, ``'cg'``).
#: Measured by ``bench/bench_solvers.py`` (see the README's solver table): with its compiled
#: iterations the deflated CG is the faster from the smallest rod measured (84 unknowns: cold
#: solve 1.0 against 1.3 ms, re-solve 0.33 against 0.81 ms); with numpy's it was from about
#: 2,000 unknowns, the value used before. Below 80 unknowns any solve takes microseconds.
AUTO_DEFLATION_FROM = 80


def auto_solver_name(n_unknowns: int) -> str:
    """The solver ``'auto'`` stands for at a given size: ``'cg'`` below
    :data:`AUTO_DEFLATION_FROM` unknowns, ``'cg-deflated'`` from there on."""
    return "cg-deflated" if n_unknowns >= AUTO_DEFLATION_FROM else "cg"


def _residual(A, x, b):
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
        return x, {"solver": self.name, "iterations": 0, "residual": _residual(A, x, b),
                   "setup": fresh, "setup_time": self.setup_time}


def _nonfinite_rhs(name, nb) -> SolverError:
    return SolverError(f"{name}: the right-hand side is not finite (||b|| = {nb}); check sources and values")


def _breakdown(name, pq) -> SolverError:
    return SolverError(f"{name} broke down (p.Ap = {pq:.3g} <= 0): the matrix is not positive "
                       "definite; check for negative or non-finite conductances")


def _nonfinite_solution(name) -> SolverError:
    return SolverError(f"{name} produced non-finite values; check conductances for inf/nan")


def _nonpositive_diagonal() -> SolverError:
    return SolverError("the matrix has a non-positive diagonal entry: a node with no conducting edge "
                       "was left among the unknowns")


def _check_converged(name, res, nb, rtol, atol, it):
    if res * nb > 10 * max(rtol * nb, atol):
        raise SolverError(f"{name} did not converge: relative residual {res:.3e} > rtol {rtol:g} "
                          f"after {it} iterations; raise maxiter or use solver='direct'")


def _pcg(A, b, x, M, rtol, maxiter, name, deflate=None, atol=0.0):
    """Preconditioned CG from ``x`` (modified in place) to ``||r|| <= max(rtol ||b||, atol)``;
    ``deflate`` = (coarse_correct, project) makes it the deflated CG of Saad et al. (2000).
    A start worse than zero (``||b - A x|| > ||b||``) is replaced by zero. Returns (x,
    iterations, relative residual)."""
    nb = np.linalg.norm(b)
    if nb == 0:
        x[:] = 0.0
        return x, 0, 0.0
    if not np.isfinite(nb):
        raise _nonfinite_rhs(name, nb)
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
                raise _breakdown(name, pq)
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
        raise _nonfinite_solution(name)
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
            raise _nonpositive_diagonal()
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
        x, it, res = _pcg(self._Acsr, b, x, self._M, self.rtol, self.maxiter or 10 * n + 10, self.name,
                          self._deflation(), atol)
        _check_converged(self.name, res, np.linalg.norm(b), self.rtol, atol, it)
        return x, {"solver": self.name, "iterations": it, "residual": res, "setup": fresh,
                   "setup_time": self.setup_time, "iteration_time": time.perf_counter() - t}


class DeflatedCGSolver(CGSolver):
    """Jacobi-CG deflated by piecewise-constant vectors on spatial clusters (see module doc).

    Parameters
    ----------
    rtol, maxiter : as :class:`CGSolver`
    cluster_size : float
        Cluster edge length in mean neighbour spacings (default 3, the fastest measured on
        the rod packings: 35 iterations at 5,000 and 20,000 elements against 134 and 209
        for Jacobi-CG).
    max_clusters : int or None
        When ``cluster_size`` would make more clusters than this, the clusters grow until
        there are about this many (None: never). The coarse matrix's LU costs more than the
        iterations the extra clusters save: on the lattice rods of ``bench/bench_scale.py``
        at 1M unknowns, 37,044 clusters took 10.9 s (8.2 s of setup, 32 iterations) and
        5,082 took 4.0 s (60 iterations); at 500k, 19,074 took 4.1 s and 2,673 took 1.6 s.
    native : bool
        Run the iterations compiled (:class:`yade_electro.native.DeflatedCG`, built on first
        use; the coarse matrix then factorised by Eigen's sparse Cholesky) instead of numpy
        (default True; numpy when it cannot be built). The same algorithm; other rounding.
    """

    name = "cg-deflated"
    #: default ``max_clusters``
    MAX_CLUSTERS = 2000
    #: up to this many clusters the coarse matrix is factorised dense (Cholesky), above it sparse (LU)
    DENSE_LIMIT = 400

    def __init__(self, rtol: float = 1e-10, maxiter: Optional[int] = None, cluster_size: float = 3.0,
                 max_clusters: Optional[int] = MAX_CLUSTERS, native: bool = True):
        super().__init__(rtol=rtol, preconditioner="jacobi", maxiter=maxiter)
        self.native = bool(native)
        self._dcg = None            # the compiled iterations (native.DeflatedCG) of the current setup
        if not cluster_size > 0:
            raise ValueError(f"cluster_size must be > 0, got {cluster_size}")
        if max_clusters is not None and not int(max_clusters) >= 1:
            raise ValueError(f"max_clusters must be >= 1 or None, got {max_clusters}")
        self.cluster_size = float(cluster_size)
        self.max_clusters = None if max_clusters is None else int(max_clusters)
        self.cluster_size_used = None
        self._coords = None
        self._spacing = None

    def set_geometry(self, coords, spacing=None):
        coords = np.asarray(coords, dtype=float)
        if coords.ndim != 2 or coords.shape[1] != 3:
            raise ValueError(f"coords must be (n, 3), got {coords.shape}")
        self._coords, self._spacing = coords, spacing
        self._A = None                                   # new clusters at the next solve

    def _clusters(self, A):
        n = A.shape[0]
        X = self._coords
        if X is None or X.shape[0] != n:
            # no geometry: consecutive runs of a reverse Cuthill-McKee ordering (compact
            # groups of neighbours), of the size a spatial cluster would have
            from scipy.sparse.csgraph import reverse_cuthill_mckee
            order = reverse_cuthill_mckee(A.tocsr(), symmetric_mode=True)
            size = max(int(round(0.5 * self.cluster_size ** 3)), 2)
            lab = np.empty(n, dtype=np.int64)
            lab[order] = np.arange(n) // size
            return lab, int(lab.max()) + 1 if n else 0
        lo, hi = X.min(axis=0), X.max(axis=0)
        h = self._spacing
        if not h or not np.isfinite(h) or h <= 0:
            h = float(np.prod(np.maximum(hi - lo, 1e-300))) ** (1 / 3) / max(n, 1) ** (1 / 3)
        size = self.cluster_size
        lab, k = self._cells(X, lo, size * h)
        if self.max_clusters and k > self.max_clusters:       # larger clusters, fewer of them
            size *= (k / self.max_clusters) ** (1.0 / 3.0)
            lab, k = self._cells(X, lo, size * h)
        self.cluster_size_used = size
        return lab, k

    @staticmethod
    def _cells(X, lo, edge):
        """Labels 0..k-1 of the cubic cells of side ``edge`` holding the points, numbered in
        lexicographic (x, y, z) order as np.unique(cell, axis=0) would, without its sort of n
        rows: one integer key per cell, compacted by a count."""
        cell = np.floor((X - lo) / edge).astype(np.int64)
        dims = cell.max(axis=0) + 1
        key = (cell[:, 0] * dims[1] + cell[:, 1]) * dims[2] + cell[:, 2]
        present = np.bincount(key, minlength=int(np.prod(dims))) > 0
        return (np.cumsum(present) - 1)[key], int(present.sum())

    def _setup(self, A):
        super()._setup(A)
        A = self._Acsr
        n = A.shape[0]
        lab, k = self._clusters(A)
        self._lab, self._k = lab, k
        rows = np.repeat(np.arange(n), np.diff(A.indptr))
        cols = A.indices
        # E = W^T A W (k x k): each non-zero (i, j) adds to (lab_i, lab_j)
        ekey = lab[rows] * k + lab[cols]
        if k * k <= 50_000_000:          # the keys fit a count: the same sorted keys, no sort of nnz
            present = np.bincount(ekey, minlength=k * k) > 0
            uek = np.flatnonzero(present)
            eslot = (np.cumsum(present) - 1)[ekey]
        else:
            uek, eslot = np.unique(ekey, return_inverse=True)
        self._e_key, self._e_slot = uek, eslot
        self._dcg = self._compiled(A, n, k, rows)
        if self._dcg is not None:
            # compiled: W^T A's structural pattern and each non-zero's entry in it at once (one
            # pass over A), so that every value update, the first too, is a refill
            indptr, indices, self._wta_slot = self._dcg.wta_pattern(A, lab)
            self._WtA = sp.csr_matrix((np.zeros(indices.size), indices, indptr), shape=(k, n))
        else:
            # numpy: W^T A (k x n) by one sparse product with W^T (scipy's, in C; a sort of one
            # key per non-zero here cost more than the iterations at 5,000 unknowns). The
            # product drops entries that cancel (a cluster's column sum can be exactly 0), so
            # the first value update makes the structural pattern (the product with |A|'s
            # pattern) and where each non-zero of A goes in it; updates then refill it in place
            # by a bincount
            self._Wt = sp.csr_matrix((np.ones(n), (lab, np.arange(n))), shape=(k, n))
            self._WtA = self._Wt @ A
            self._wta_slot = None
        self._coarse_values()

    def _compiled(self, A, n, k, rows):
        """The compiled iterations for this setup, or None (numpy): not asked for, indices
        that do not fit int32, or no compiler. ``rows``: the row of each non-zero of A."""
        if not self.native or A.indices.dtype != np.int32 or A.indptr.dtype != np.int32:
            return None
        # where each row's diagonal sits in A.data (the compiled refill reads it there)
        diag_pos = np.flatnonzero(A.indices == rows)
        if diag_pos.size != n or not np.array_equal(rows[diag_pos], np.arange(n)):
            return None
        from .native import DeflatedCG, NativeError
        try:
            dcg = DeflatedCG(n, k)
        except NativeError as exc:
            log.info("cg-deflated: the compiled iterations are not available (%s); numpy instead", exc)
            self.native = False
            return None
        dcg.coarse_pattern(self._e_key)
        self._diag_pos = diag_pos.astype(np.int64)
        return dcg

    def _coarse_values(self):
        A, k = self._Acsr, self._k
        if self._dcg is not None:
            # compiled: the diagonal, W^T A and E's values in one pass, then E's factor
            status = self._dcg.refill(A, self._diag_pos, self._inv_diag, self._wta_slot, self._WtA, self._e_slot)
            if status == 2:
                raise _nonpositive_diagonal()
            if status == 1:
                raise SolverError("the coarse matrix of 'cg-deflated' is not positive definite (Eigen LLT)")
            return
        if self._wta_slot is not None:
            self._WtA.data[:] = np.bincount(self._wta_slot, A.data, self._WtA.nnz)
        ev = np.bincount(self._e_slot, A.data, self._e_key.size)
        if k <= self.DENSE_LIMIT:
            # small coarse space: a dense Cholesky factor (LAPACK, no checks in the way)
            E = np.zeros(k * k)
            E[self._e_key] = ev
            E = E.reshape(k, k)
            from scipy.linalg.lapack import dpotrf, dpotrs
            L, info = dpotrf(E, lower=1, clean=0, overwrite_a=1)
            if info != 0:
                raise SolverError(f"the coarse matrix of 'cg-deflated' is not positive definite (LAPACK potrf "
                                  f"info {info})")

            def coarse_solve(v, L=L):
                return dpotrs(L, v, lower=1)[0]
            self._coarse_solve = coarse_solve
        else:
            E = sp.csc_matrix((ev, (self._e_key // k, self._e_key % k)), shape=(k, k))
            lu = spla.splu(E, permc_spec="COLAMD")
            self._coarse_solve = lu.solve
        lab, k = self._lab, self._k
        WtA, coarse_solve = self._WtA, self._coarse_solve

        def coarse(r):                       # W E^-1 W^T r
            return coarse_solve(np.bincount(lab, r, k))[lab]

        def project(z):                      # W E^-1 (A W)^T z
            return coarse_solve(WtA @ z)[lab]
        self._defl = (coarse, project)

    def _update(self, A):
        if self._dcg is None:
            self._set_diagonal()            # (the compiled refill does it otherwise)
        if self._wta_slot is None:
            # the structural pattern of W^T A (no cancellation: a product of ones) and the
            # entry (lab_i, j) each non-zero (i, j) of A adds to, by a binary search among its
            # sorted keys
            Acsr, n = self._Acsr, A.shape[0]
            ones = sp.csr_matrix((np.ones(Acsr.nnz), Acsr.indices, Acsr.indptr), shape=Acsr.shape)
            W = self._Wt @ ones
            W.sort_indices()
            pattern = np.repeat(np.arange(self._k, dtype=np.int64), np.diff(W.indptr)) * n + W.indices
            rows = np.repeat(np.arange(n), np.diff(Acsr.indptr))
            self._wta_slot = np.searchsorted(pattern, self._lab[rows] * n + Acsr.indices)
            self._WtA = W
        self._coarse_values()

    def _deflation(self):
        return self._defl

    def solve(self, A, b, x0=None, atol: float = 0.0):
        fresh = self._ensure_setup(A)
        if self._dcg is None:
            x, info = super().solve(A, b, x0, atol)
        else:
            b = np.ascontiguousarray(b, dtype=np.float64)
            nb = np.linalg.norm(b)
            if not np.isfinite(nb):
                raise _nonfinite_rhs(self.name, nb)
            x = np.zeros(b.shape[0]) if x0 is None else np.array(x0, dtype=np.float64, copy=True)
            t = time.perf_counter()
            it, res, status = self._dcg.solve(self._Acsr, self._inv_diag, self._lab, self._WtA, b, x, self.rtol,
                                              atol, self.maxiter or 10 * b.shape[0] + 10)
            if status == 2:
                raise _breakdown(self.name, res)        # (res is then p.Ap)
            if not np.all(np.isfinite(x)):
                raise _nonfinite_solution(self.name)
            _check_converged(self.name, res, nb, self.rtol, atol, it)
            info = {"solver": self.name, "iterations": it, "residual": res,
                    "setup_time": self.setup_time, "iteration_time": time.perf_counter() - t}
        info["setup"] = fresh                   # (the numpy path's own check finds the setup done)
        info["compiled"] = self._dcg is not None
        info["clusters"] = self._k
        info["cluster_size"] = self.cluster_size_used
        return x, info


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


_SOLVERS = {"direct": DirectSolver, "cg": CGSolver, "cg-jacobi": CGSolver, "cg-deflated": DeflatedCGSolver,
            "cg-amg": AMGSolver}


#: solvers in modules of their own, imported when asked for (their dependencies are optional)
_LAZY_SOLVERS = ("petsc",)


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
    if solver == "petsc":
        from .petsc_solver import PETScSolver
        return PETScSolver(**kw)
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
    if solver == "petsc":                # missing petsc4py: say so when the engine is built
        from .petsc_solver import import_petsc
        import_petsc()


__all__ += ["check_solver_name"]
