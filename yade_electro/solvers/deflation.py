"""CG with a deflation (coarse) space of piecewise-constant vectors on clusters of nodes.

See :mod:`yade_electro.solvers` for the protocol and the choice of a solver.
"""
from __future__ import annotations

import logging
import time
from typing import Optional

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import SolverError

# OpenBLAS to one thread (YADE_ELECTRO_BLAS_THREADS, default 1): see yade_electro.core.threads
from .base import (breakdown, check_converged, nonfinite_rhs, nonfinite_solution, nonpositive_diagonal)
from .cg import CGSolver

__all__ = ["DeflatedCGSolver"]

log = logging.getLogger(__name__)


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
        Run the iterations compiled (:class:`yade_electro.native.DeflatedCG`, built at install;
        the coarse matrix then factorised by Eigen's sparse Cholesky) instead of numpy (default
        True; numpy when the kernel is not built). The same algorithm; other rounding.
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
        """The compiled iterations for this setup, or None (numpy): not asked for
        (``native=False``), or indices that do not fit int32. ``rows``: the row of each
        non-zero of A."""
        if not self.native or A.indices.dtype != np.int32 or A.indptr.dtype != np.int32:
            return None
        # where each row's diagonal sits in A.data (the compiled refill reads it there)
        diag_pos = np.flatnonzero(A.indices == rows)
        if diag_pos.size != n or not np.array_equal(rows[diag_pos], np.arange(n)):
            return None
        from ..native import DeflatedCG
        dcg = DeflatedCG(n, k)
        dcg.coarse_pattern(self._e_key)
        self._diag_pos = diag_pos.astype(np.int64)
        return dcg

    def _coarse_values(self):
        A, k = self._Acsr, self._k
        if self._dcg is not None:
            # compiled: the diagonal, W^T A and E's values in one pass, then E's factor
            status = self._dcg.refill(A, self._diag_pos, self._inv_diag, self._wta_slot, self._WtA, self._e_slot)
            if status == 2:
                raise nonpositive_diagonal()
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
                raise nonfinite_rhs(self.name, nb)
            x = np.zeros(b.shape[0]) if x0 is None else np.array(x0, dtype=np.float64, copy=True)
            t = time.perf_counter()
            it, res, status = self._dcg.solve(self._Acsr, self._inv_diag, self._lab, self._WtA, b, x, self.rtol,
                                              atol, self.maxiter or 10 * b.shape[0] + 10)
            if status == 2:
                raise breakdown(self.name, res)        # (res is then p.Ap)
            if not np.all(np.isfinite(x)):
                raise nonfinite_solution(self.name)
            check_converged(self.name, res, nb, self.rtol, atol, it)
            info = {"solver": self.name, "iterations": it, "residual": res,
                    "setup_time": self.setup_time, "iteration_time": time.perf_counter() - t}
        info["setup"] = fresh                   # (the numpy path's own check finds the setup done)
        info["compiled"] = self._dcg is not None
        info["clusters"] = self._k
        info["cluster_size"] = self.cluster_size_used
        return x, info
