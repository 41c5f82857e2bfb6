"""A network solve shared by MPI ranks that each hold only their part of it.

Each rank has its :class:`~yade_electro.network.partition.LocalNetwork` (owned nodes and the
ghosts they touch) and its :class:`~yade_electro.network.partition.OwnedRows`; nothing holds
the whole graph. This module does the talking:

* :class:`GhostExchange` sends the owners' values of the ghosts to the ranks that see them
  (one ``Alltoallv``; the requests are exchanged once, when the share is set up);
* :func:`number_unknowns` numbers the owned free nodes contiguously per rank (offset: an
  exclusive scan of the counts) and gives every ghost its owner's number;
* :class:`PartitionedSystem` is PETSc's MPIAIJ matrix made from every rank's CSR rows (local
  sizes, preallocated from the CSR arrays, no off-process entries), values refreshed in place
  while the pattern holds, and CG with one of the preconditioners of :data:`PRECONDITIONERS`:

  ``'deflation'`` (default)
      A smoother with our geometric coarse space (piecewise constants on spatial clusters, as
      ``solver='cg-deflated'``), applied as A-DEF2 (``z = y + Q (r - A y)``, ``y = M^-1 r``,
      ``Q = W E^-1 W^T``) from a start projected so that ``W^T r_0 = 0``. ``W^T A y`` is
      ``(A W)^T y`` summed over the ranks (A is symmetric; each rank keeps its rows of
      ``A W``, a few entries at most), so an apply costs no product with A and one sum of
      ``k`` values over the ranks. The coarse matrix
      ``E = W^T A W`` (one row per cluster, at most ``max_clusters``) is gathered on every
      rank and factorised there (sparse LU in a symmetric ordering): a redundant coarse
      solve, as GAMG does on its coarsest level. The smoother M is block Jacobi with ICC(0) of
      each rank's diagonal block (``smoother='icc'``, default) or the diagonal (``'jacobi'``).
      Measured side by side on the jittered lattice rod at 1M unknowns on 2 ranks
      (``bench/bench_peers.py``'s partitioned lines): ICC took 28 iterations cold and 19
      re-solving, against 62 cold for Jacobi: re-solve 0.57 s against 0.71 s (GAMG 0.55 s).
      On the voronoi rod it saves fewer (21-27 against 30-36) and is the slower; the
      distributed engines take Jacobi there. The cluster cap grows with the size
      (:func:`auto_max_clusters`, 2,000 to 8,000): 8,000 instead of 2,000 took the 1M lattice
      from 35 to 25 iterations on one rank, cold 2.2 to 1.5 s; 20,000 cut only to 21
      iterations and made the coarse solve a third of an iteration.
  ``'hypre'``
      BoomerAMG with the 3-D options (HMIS coarsening, ext+i interpolation, P_max 4, one
      aggressive level).
  ``'gamg'``
      PETSc's smoothed aggregation (interpolation reused while the pattern holds).
  ``'jacobi'``
      For reference.

  The setup (the AMG hierarchy; the coarse factor and ICC blocks) is kept while only values
  change (PETSc would refactor the blocks at every change of values otherwise): the
  preconditioner is rebuilt when a solve on it takes more than ``rebuild_factor`` times the
  iterations of the first solve after the last setup (it is stopped there, and goes on from
  its iterate on the new setup).

Stopping rule, as the serial solvers: ``||A x - b|| <= max(rtol ||b||, atol)`` (the true
residual, KSP's unpreconditioned norm). Needs petsc4py and mpi4py (``make install``).
"""
from __future__ import annotations

import time
from typing import Optional

import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as spla

from ..core.errors import SolverError
from .petsc import HYPRE_3D, check_preconditioner, destroy_attributes, import_petsc

__all__ = ["GhostExchange", "number_unknowns", "PartitionedSystem", "PRECONDITIONERS", "mpi_comm",
           "cluster_labels", "auto_max_clusters", "summed"]

#: the preconditioners of a partitioned solve
PRECONDITIONERS = ("deflation", "hypre", "gamg", "jacobi")

def mpi_comm(comm=None):
    """The mpi4py communicator of ``comm`` (an mpi4py or petsc4py one; default: PETSc's
    ``COMM_WORLD``, all ranks of ``mpiexec``)."""
    if comm is None:
        comm = import_petsc().COMM_WORLD
    return comm.tompi4py() if hasattr(comm, "tompi4py") else comm


def summed(comm, values, dtype=float) -> np.ndarray:
    """The element-wise sum over the ranks of an array, as ``dtype`` (collective). The type is
    forced: numpy's ``bincount`` of an empty array is int64 even with float weights, and a
    rank with no elements must not send integers where the others send floats."""
    from mpi4py import MPI
    v = np.ascontiguousarray(values, dtype=dtype)
    out = np.empty_like(v)
    comm.Allreduce(v, out, op=MPI.SUM)
    return out


def _owned_index(keys_owned: np.ndarray, wanted: np.ndarray, asker: int) -> np.ndarray:
    """Local indices of the owned nodes with keys ``wanted``; a key this rank does not own
    raises (a rank's ghost lists and another's ownership disagree)."""
    order = np.argsort(keys_owned, kind="stable")
    pos = np.searchsorted(keys_owned, wanted, sorter=order)
    pos = np.minimum(pos, max(keys_owned.shape[0] - 1, 0))
    idx = order[pos] if keys_owned.size else np.zeros(0, np.int64)
    bad = (idx.shape[0] != wanted.shape[0]) or (wanted.size and np.any(keys_owned[idx] != wanted))
    if bad:
        missing = wanted[:idx.shape[0]][keys_owned[idx] != wanted] if keys_owned.size else wanted
        raise SolverError(f"rank {asker} sees as ghosts nodes {missing[:5].tolist()} that the rank it names as their "
                          "owner does not own: the ranks disagree on who owns what")
    return idx


class GhostExchange:
    """The owners' values of a share's ghosts (see the module doc).

    Parameters
    ----------
    network : LocalNetwork
    comm : mpi4py communicator (all ranks take part, in the same order of calls)
    """

    def __init__(self, network, comm):
        from mpi4py import MPI
        self.MPI, self.comm, self.network = MPI, comm, network
        size, rank = comm.Get_size(), comm.Get_rank()
        owner = network.ghost_owner
        if owner.size and (owner.min() < 0 or owner.max() >= size or np.any(owner == rank)):
            raise SolverError(f"rank {rank}: ghost owners must be other ranks in 0..{size - 1}")
        self._order = np.argsort(owner, kind="stable")
        self._recv_counts = np.bincount(owner, minlength=size).astype(np.int64)
        bounds = np.concatenate([[0], np.cumsum(self._recv_counts)])
        keys = network.ghost_key[self._order]
        asked = comm.alltoall([keys[bounds[q]:bounds[q + 1]] for q in range(size)])
        self._send_index = np.concatenate(
            [_owned_index(network.owned_key, np.asarray(a, np.int64), q) for q, a in enumerate(asked)]
            or [np.zeros(0, np.int64)]).astype(np.int64)
        self._send_counts = np.array([len(a) for a in asked], np.int64)
        self._sdispl = np.concatenate([[0], np.cumsum(self._send_counts)[:-1]])
        self._rdispl = bounds[:-1]

    def ghosts(self, owned_values) -> np.ndarray:
        """The values on the ghosts, each from its owner's ``owned_values`` (one per owned
        node; float or int)."""
        v = np.asarray(owned_values)
        if v.shape[0] != self.network.n_owned:
            raise ValueError(f"owned_values must have {self.network.n_owned} entries, got {v.shape[0]}")
        kind = np.float64 if v.dtype.kind == "f" else np.int64
        mtype = self.MPI.DOUBLE if kind is np.float64 else self.MPI.INT64_T
        send = np.ascontiguousarray(v[self._send_index], dtype=kind)
        recv = np.empty(int(self._recv_counts.sum()), kind)
        self.comm.Alltoallv([send, (self._send_counts, self._sdispl), mtype],
                            [recv, (self._recv_counts, self._rdispl), mtype])
        out = np.empty_like(recv)
        out[self._order] = recv
        return out

    def local(self, owned_values) -> np.ndarray:
        """``owned_values`` followed by the ghosts' values: one per local node."""
        v = np.asarray(owned_values)
        return np.concatenate([v, self.ghosts(v).astype(v.dtype, copy=False)])


def number_unknowns(exchange: GhostExchange, fixed_owned) -> "tuple[np.ndarray, int]":
    """Global numbers of the unknowns: the owned nodes not in ``fixed_owned`` (a boolean mask),
    contiguous per rank in rank order; -1 for fixed nodes, ghosts included. Returns the local
    numbering (one per local node) and the global count."""
    fixed = np.asarray(fixed_owned, dtype=bool)
    comm = exchange.comm
    n_free = int(np.count_nonzero(~fixed))
    offset = comm.exscan(n_free)
    offset = 0 if offset is None else int(offset)
    own = np.full(fixed.shape[0], -1, np.int64)
    own[~fixed] = offset + np.arange(n_free)
    return exchange.local(own), int(comm.allreduce(n_free))


def auto_max_clusters(n_global: int) -> int:
    """The deflation's default cluster cap: one cluster per 100 unknowns, between 2,000 and
    8,000. Every rank holds the coarse factor: at 1M unknowns 8,000 clusters (2,000 before)
    took the lattice rod from 35 to 25 iterations; at 215k unknowns on 2 ranks, 8,000 would
    add 30-40 MB to each rank (the memory case's ``mem_ratio`` 0.64, against 0.59 with this
    rule; target 0.6)."""
    return int(min(8000, max(2000, n_global // 100)))


def cluster_labels(pos_owned, comm, spacing: float, cluster_size: float = 3.0,
                   max_clusters: Optional[int] = 8000) -> "tuple[np.ndarray, int]":
    """Cluster of every owned node (piecewise-constant coarse space of the deflation): cells of
    ``cluster_size * spacing`` [m] on the bounding box of all ranks' nodes, grown until at most
    ``max_clusters`` are occupied, numbered by the occupied cells of every rank. Returns the
    labels and the number of clusters."""
    from mpi4py import MPI
    p = np.asarray(pos_owned, dtype=float).reshape(-1, 3)
    lo, hi = np.empty(3), np.empty(3)
    comm.Allreduce(p.min(axis=0) if p.size else np.full(3, np.inf), lo, op=MPI.MIN)
    comm.Allreduce(p.max(axis=0) if p.size else np.full(3, -np.inf), hi, op=MPI.MAX)
    h = max(float(cluster_size * spacing), 1e-300)
    while True:
        shape = np.maximum(np.floor((hi - lo) / h).astype(np.int64) + 1, 1)
        cell = np.minimum(((p - lo) / h).astype(np.int64), shape - 1)
        flat = (cell[:, 0] * shape[1] + cell[:, 1]) * shape[2] + cell[:, 2]
        occupied = np.unique(np.concatenate(comm.allgather(np.unique(flat))))
        if max_clusters is None or occupied.shape[0] <= max_clusters:
            return np.searchsorted(occupied, flat).astype(np.int64), int(occupied.shape[0])
        h *= (occupied.shape[0] / max_clusters) ** (1.0 / 3.0) * 1.05


class _DeflationPC:
    """petsc4py's Python preconditioner context of ``'deflation'`` (see the module doc)."""

    def __init__(self, system: "PartitionedSystem", labels: np.ndarray, k: int, smoother: str = "icc"):
        # PETSc's PC holds this context and the system holds the PC: a cycle through C that
        # Python never frees; PartitionedSystem.destroy breaks it. (A weak reference here let
        # Python drop the system, but PETSc then freed the PC, and called into this context,
        # after Python had ended: a segfault at exit.)
        self.system = system
        self.labels, self.k = labels, k
        self.smoother = smoother
        self.factor = None
        self._local = None

    def build(self, data: np.ndarray):
        """D^-1, the rows of A W and the factor of E = W^T A W from the current CSR values
        (collective)."""
        s = self.system
        rows = s.rows
        self.inv_diag = 1.0 / s.diagonal_of(data)
        if self.smoother == "icc":                  # block Jacobi, ICC(0) of each rank's block
            if self._local is None:
                PETSc = s.PETSc
                lp = PETSc.PC().create(comm=s._pcomm)
                lp.setOptionsPrefix("yepdef_")
                PETSc.Options()["yepdef_sub_pc_type"] = "icc"
                lp.setType(PETSc.PC.Type.BJACOBI)
                lp.setFromOptions()
                self._local, self._yv = lp, s.matrix.createVecLeft()
            # PCApply sets a PC up again whenever its matrix's values changed: kept (refactored
            # only here) as the rest of the setup
            self._local.setReusePreconditioner(False)
            self._local.setOperators(s.matrix)
            self._local.setUp()
            self._local.setReusePreconditioner(True)
        k = self.k
        # (A W)^T on the owned rows: W^T A y = (A W)^T y summed over the ranks (A symmetric),
        # so the apply needs no product with A. A W has A's row pattern with the columns'
        # clusters as columns: the entries of one cluster add up (in place)
        aw = sp.csr_matrix((np.array(data, dtype=float), s.column_labels(self.labels).astype(np.int32),
                            np.array(rows.indptr)), shape=(rows.n_rows, k))   # its own indptr: merged in place
        aw.sum_duplicates()
        aw.eliminate_zeros()
        self.awt = aw.T.tocsr()
        row_label = np.repeat(self.labels, np.diff(aw.indptr))
        c = sp.coo_matrix((aw.data, (row_label, aw.indices)), shape=(k, k)).tocsr().tocoo()
        del aw, row_label
        parts = s.comm.allgather((c.row.astype(np.int64), c.col.astype(np.int64), c.data))
        E = sp.coo_matrix((np.concatenate([q[2] for q in parts]),
                           (np.concatenate([q[0] for q in parts]), np.concatenate([q[1] for q in parts]))),
                          shape=(k, k)).tocsc()
        try:
            # E is SPD: a symmetric ordering and no pivoting (measured at 1M unknowns, 6,912
            # clusters: a third of COLAMD's fill, solves 4 times faster)
            self.factor = spla.splu(E, permc_spec="MMD_AT_PLUS_A", diag_pivot_thresh=0.0,
                                    options={"SymmetricMode": True})
        except RuntimeError as exc:
            raise SolverError(f"the deflation's coarse matrix is singular ({exc}): a part of the network is "
                              "connected to no fixed value") from None

    def _correction(self, w_owned: np.ndarray) -> np.ndarray:
        """W E^-1 (the ranks' sum of ``w_owned``) on the owned rows (collective)."""
        return self.factor.solve(summed(self.system.comm, w_owned))[self.labels]

    def coarse(self, r_owned: np.ndarray) -> np.ndarray:
        """Q r on the owned rows (collective)."""
        return self._correction(np.bincount(self.labels, r_owned, self.k))

    def apply(self, pc, x, y):
        """z = y0 + Q (r - A y0), y0 = D^-1 r, with W^T A y0 = (A W)^T y0: one sum over the
        ranks (k values) and no product with A."""
        r = x.getArray(readonly=True)
        if self._local is None:
            y0 = self.inv_diag * r
        else:
            self._local.apply(x, self._yv)
            y0 = self._yv.getArray(readonly=True)
        y.setArray(y0 + self._correction(np.bincount(self.labels, r, self.k) - self.awt @ y0))


class PartitionedSystem:
    """CG on PETSc's MPIAIJ matrix of every rank's :class:`OwnedRows` (see the module doc).

    Parameters
    ----------
    rows : OwnedRows
    n_global : int
        The number of unknowns over all ranks.
    comm : mpi4py communicator
    preconditioner : one of :data:`PRECONDITIONERS`
    rtol : float
    coords : (n_owned_rows, 3) positions [m] of the owned unknowns ('deflation'), optional
    spacing : float
        Mean neighbour spacing [m] ('deflation': clusters of ``cluster_size`` spacings).
    max_clusters : int, None or 'auto'
        The cap on the clusters ('auto': :func:`auto_max_clusters`).
    options : dict of extra PETSc options (prefix ``yep_``), e.g. ``{"pc_gamg_threshold": 0.02}``
    smoother : 'icc' (default) or 'jacobi'
        The deflation's smoother: block Jacobi with an incomplete Cholesky (ICC(0)) of each
        rank's diagonal block, or the diagonal.
    """

    def __init__(self, rows, n_global: int, comm, preconditioner: str = "deflation",
                 rtol: float = 1e-10, maxiter: Optional[int] = None, coords=None, spacing: Optional[float] = None,
                 cluster_size: float = 3.0, max_clusters="auto", rebuild_factor: float = 2.0,
                 options: Optional[dict] = None, smoother: str = "icc"):
        if preconditioner not in PRECONDITIONERS:
            raise ValueError(f"preconditioner must be one of {', '.join(PRECONDITIONERS)}, got {preconditioner!r}")
        if not (0 < rtol < 1):
            raise ValueError(f"rtol must be in (0, 1), got {rtol}")
        self.PETSc = check_preconditioner(preconditioner)
        if smoother not in ("icc", "jacobi"):
            raise ValueError(f"smoother must be 'icc' or 'jacobi', got {smoother!r}")
        self.smoother = smoother
        if preconditioner == "deflation" and (coords is None or spacing is None):
            raise ValueError("preconditioner='deflation' needs coords= (the owned unknowns' positions) and spacing=")
        self.rows, self.n_global, self.comm = rows, int(n_global), comm
        self.preconditioner, self.rtol, self.maxiter = preconditioner, float(rtol), maxiter
        self.rebuild_factor = float(rebuild_factor)
        self.options = dict(options or {})
        self._coords, self._spacing = coords, spacing
        if max_clusters == "auto":
            max_clusters = auto_max_clusters(self.n_global)
        self._cluster = (cluster_size, max_clusters)
        self._pcomm = self.PETSc.Comm(comm) if not hasattr(comm, "tompi4py") else comm
        self.matrix = None
        self._ghost_columns = None
        self.setups, self.setup_time, self._base_iterations = 0, 0.0, None

    def destroy(self):
        """Free PETSc's objects now (collective: every rank calls it; see
        :func:`~yade_electro.solvers.petsc.destroy_attributes`): a system that is replaced must
        be, or it stays in memory (measured: 5-20 MB each at 54k unknowns a rank)."""
        if getattr(self, "_deflation", None) is not None:
            destroy_attributes(self._deflation, ("_local", "_yv"))
        destroy_attributes(self, ("_ksp", "matrix", "_x", "_b", "work"))

    # -- the matrix --------------------------------------------------------------------------
    def diagonal_of(self, data: np.ndarray) -> np.ndarray:
        """The diagonal entries of the owned rows for CSR values ``data``."""
        return np.asarray(data)[self.rows.diagonal_index]

    def column_labels(self, labels_owned: np.ndarray) -> np.ndarray:
        """The deflation cluster of every CSR column (collective: ghosts' labels from owners)."""
        rows = self.rows
        net = rows.network
        lab_nodes = np.full(net.n_owned, -1, np.int64)
        lab_nodes[rows.free_owned] = labels_owned
        local = self._exchange.local(lab_nodes)
        has = rows.unknown >= 0
        u, lab = rows.unknown[has], local[has]
        order = np.argsort(u)
        return lab[order[np.searchsorted(u, rows.indices, sorter=order)]]

    def set_values(self, data, exchange: Optional[GhostExchange] = None):
        """New CSR values (same pattern): the first call makes the matrix and the solver,
        later ones refill in place and keep the preconditioner (collective)."""
        PETSc = self.PETSc
        rows = self.rows
        data = np.ascontiguousarray(data, dtype=PETSc.ScalarType)
        if exchange is not None:
            self._exchange = exchange
        ip, ix = np.asarray(rows.indptr, dtype=PETSc.IntType), np.asarray(rows.indices, dtype=PETSc.IntType)
        t = time.perf_counter()
        if self.matrix is None:
            n = rows.n_rows
            M = PETSc.Mat().createAIJ(size=((n, self.n_global), (n, self.n_global)), csr=(ip, ix, data),
                                      comm=self._pcomm)
            M.setOption(PETSc.Mat.Option.SPD, True)
            M.setOption(PETSc.Mat.Option.NO_OFF_PROC_ENTRIES, True)
            M.setOption(PETSc.Mat.Option.NEW_NONZERO_ALLOCATION_ERR, True)
            M.assemble()
            self.matrix = M
            self._x, self._b = M.createVecs()
            self.work = M.createVecLeft()
            self._make_ksp()
        else:
            self.matrix.setValuesCSR(ip, ix, data)
            self.matrix.assemble()
            self._ksp.setOperators(self.matrix)
            self._ksp.getPC().setReusePreconditioner(True)
        if self.preconditioner == "deflation" and self._deflation.factor is None:
            self._deflation.build(data)
        self.setup_time += time.perf_counter() - t

    def _make_ksp(self):
        PETSc = self.PETSc
        ksp = PETSc.KSP().create(comm=self._pcomm)
        ksp.setOptionsPrefix("yep_")
        opts = PETSc.Options()
        chosen = dict(HYPRE_3D) if self.preconditioner == "hypre" else {}
        if self.preconditioner == "gamg":
            chosen.update(pc_gamg_type="agg", pc_gamg_reuse_interpolation="true", pc_gamg_agg_nsmooths="1")
        chosen.update(self.options)
        for k, v in chosen.items():
            opts["yep_" + k] = v
        ksp.setOperators(self.matrix)
        ksp.setType(PETSc.KSP.Type.CG)
        ksp.setNormType(PETSc.KSP.NormType.UNPRECONDITIONED)
        pc = ksp.getPC()
        if self.preconditioner == "deflation":
            labels, k = cluster_labels(self._coords, self.comm, self._spacing, *self._cluster)
            self._deflation = _DeflationPC(self, labels, k, self.smoother)
            pc.setType(PETSc.PC.Type.PYTHON)
            pc.setPythonContext(self._deflation)
        else:
            pc.setType({"hypre": PETSc.PC.Type.HYPRE, "gamg": PETSc.PC.Type.GAMG,
                        "jacobi": PETSc.PC.Type.JACOBI}[self.preconditioner])
        ksp.setFromOptions()
        self._ksp = ksp
        self.setups += 1

    def _rebuild(self):
        """A fresh preconditioner for the current values (collective)."""
        t = time.perf_counter()
        if self.preconditioner == "deflation":
            # the values from PETSc's own copy (rows in order, columns sorted: ours), not a
            # second copy kept here (11 MB at 108k rows)
            _, ix, data = self.matrix.getValuesCSR()
            if data.shape[0] != self.rows.nnz or not np.array_equal(ix, self.rows.indices):
                raise SolverError("PETSc's matrix no longer has the pattern of the rows it was made from")
            self._deflation.build(data)
        self._ksp.getPC().setReusePreconditioner(False)
        self._ksp.setOperators(self.matrix)
        self.setups += 1
        self._base_iterations = None
        self.setup_time += time.perf_counter() - t

    # -- products and solves -------------------------------------------------------------------
    def mult(self, x_owned) -> np.ndarray:
        """``A x`` on the owned rows (collective)."""
        self._x.setArray(np.asarray(x_owned, dtype=float))
        self.matrix.mult(self._x, self.work)
        return self.work.getArray(readonly=True).copy()

    def solve(self, b_owned, x0=None, atol: float = 0.0) -> "tuple[np.ndarray, dict]":
        """Solve ``A x = b`` on the owned rows (collective); returns x and an info dict."""
        b = np.asarray(b_owned, dtype=float)
        comm = self.comm
        nb = float(np.sqrt(comm.allreduce(float(b @ b))))
        if not np.isfinite(nb):
            raise SolverError("the right-hand side has non-finite values")
        tol = max(self.rtol * nb, atol)
        info = {"solver": f"partitioned-{self.preconditioner}", "ranks": comm.Get_size(), "setups": self.setups}
        if tol == 0.0:
            return np.zeros_like(b), dict(info, iterations=0, residual=0.0, iteration_time=0.0)
        t = time.perf_counter()
        start = np.zeros_like(b) if x0 is None else np.array(x0, dtype=float)
        # on a kept setup, stop at rebuild_factor times the count after the last setup: the
        # values drifted, so rebuild and go on from there
        cap = None if self._base_iterations is None else int(self.rebuild_factor * max(self._base_iterations, 5))
        it, reason = self._krylov(b, start, tol, cap)
        if reason < 0 and cap is not None:
            self._rebuild()
            it2, reason = self._krylov(b, self._x.getArray(readonly=True).copy(), tol)
            it += it2
            self._base_iterations = it2
        if self._base_iterations is None:
            self._base_iterations = it
        x = self._x.getArray(readonly=True).copy()
        res = float(np.sqrt(comm.allreduce(float(np.sum((self.mult(x) - b) ** 2)))))
        if reason < 0 or not np.isfinite(res) or res > 10 * tol:
            raise SolverError(f"partitioned CG + {self.preconditioner} did not converge: KSP reason {reason}, "
                              f"relative residual {res / nb:.3e} > rtol {self.rtol:g} after {it} iterations")
        return x, dict(info, iterations=int(it), residual=res / nb if nb else res,
                       iteration_time=time.perf_counter() - t, setups=self.setups)

    def _krylov(self, b, x, tol, max_it=None):
        if self.preconditioner == "deflation":          # start with W^T r_0 = 0
            x = x + self._deflation.coarse(b - self.mult(x))
        ksp = self._ksp
        self._b.setArray(b)
        self._x.setArray(x)
        ksp.setInitialGuessNonzero(True)
        limit = self.maxiter or 10 * self.n_global + 10
        ksp.setTolerances(rtol=1e-300, atol=max(tol, 1e-300), max_it=limit if max_it is None else min(limit, max_it))
        ksp.solve(self._b, self._x)
        return ksp.getIterationNumber(), ksp.getConvergedReason()
