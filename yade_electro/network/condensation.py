"""Dirichlet condensation of a network Laplacian, kept as a structure whose values are updated
in place: the one condensation the electrical and the thermal problems share.

The network: ``n`` nodes, ``m`` edges with values ``c`` (conductances [S] or [W/K]); its
Laplacian is ``K = A^T diag(c) A`` (A the incidence matrix). Some node sets are *groups*: the
nodes of a group are tied together (a perfect conductor, one value for all of them, e.g. an
electrode or a fixed-temperature set) and the group's value is imposed (Dirichlet). Nodes
may also be *excluded* (floating clusters: value 0, not solved for). What is left are the
unknowns ``u``, and

    K_uu x_u = f_u - K_ud x_d,        net flux leaving group g:  (K_dd x_d + K_du x_u)_g

:class:`ReducedSystem` computes, once per structure, the sparsity patterns of ``K_uu``
(with an explicit diagonal for every unknown), ``K_ud`` and ``K_dd`` and the linear maps from
the edge values to their CSR data. :meth:`ReducedSystem.assemble` then fills the data of the
*same* matrix objects from new edge values (K_uu by one compiled pass, numpy's scatter and
incidence product when it cannot be built; K_ud, K_dd by a sparse mat-vec each), so that solvers keep
their setup (see :mod:`yade_electro.solvers.registry`) and a change of values never rebuilds structure.
"""
from __future__ import annotations

from typing import Optional, Sequence

import numpy as np
import scipy.sparse as sp

__all__ = ["ReducedSystem"]


def _pattern(rows, cols, shape, native: bool = False):
    """A CSR matrix (zero data) with one entry per distinct (row, col) and, for every input
    pair, the index of its entry in ``data``; and whether the pairs were all distinct.

    ``native``: distinct pairs by the compiled helper
    (:func:`yade_electro.native.csr_pattern`, the same pattern and slots in one call);
    repeated pairs go the ways below (``native=False``, the tests' reference, goes there too).

    Distinct pairs (the usual case: an edge list without repeats) go through scipy's COO to
    CSR conversion, a counting sort by row and a sort within each row, both in C, carrying
    each pair's position in ``data``; repeated pairs through a sort of one int64 key per
    pair (np.unique). With the first, the whole structure of the 1M-element ``voronoi``
    system (16.7M pairs) took about 3 s instead of 7.8 s (``bench/bench_scale.py``)."""
    nr, nc = shape
    rows = np.asarray(rows)
    N = rows.size
    if native and N:
        from ..native import csr_pattern
        got = csr_pattern(rows, cols, shape)
        if got is not None:
            indptr, indices, slot = got
            M = sp.csr_matrix((np.zeros(N), indices, indptr), shape=shape)
            M.has_sorted_indices = True
            return M, slot, True
    if 0 < N < 2 ** 53:
        M = sp.csr_matrix((np.arange(N, dtype=float), (rows, cols)), shape=shape)   # sums repeats
        if M.nnz == N:
            slot = np.empty(N, dtype=np.int64)
            slot[M.data.astype(np.int64)] = np.arange(N)
            M.data = np.zeros(N)
            return M, slot, True
    key = rows.astype(np.int64) * nc + np.asarray(cols).astype(np.int64)
    ukey, slot = np.unique(key, return_inverse=True)
    indptr = np.searchsorted(ukey // nc, np.arange(nr + 1)) if nc else np.zeros(nr + 1, dtype=np.int64)
    M = sp.csr_matrix((np.zeros(ukey.size), (ukey % nc).astype(np.int32) if nc else ukey.astype(np.int32),
                       indptr), shape=shape)
    return M, slot.reshape(-1), ukey.size == N


def _small_index(a, bound):
    """``a`` as int32 when its values stay below ``bound`` (half the memory), else int64."""
    return np.asarray(a, dtype=np.int32 if bound < 2 ** 31 else np.int64)


def _map(slots, edge, sign, nnz, m):
    """Sparse (nnz x m) matrix taking edge values to CSR data."""
    if len(slots) == 0:                 # (no group: scipy's COO conversion would cost 0.4 ms)
        return sp.csr_matrix((nnz, m))
    return sp.csr_matrix((sign, (slots, edge)), shape=(nnz, m))


def _empty_csr(rows: int, cols: int):
    """An all-zero CSR matrix (no stored entry)."""
    return sp.csr_matrix((np.zeros(0), np.zeros(0, dtype=np.int32), np.zeros(rows + 1, dtype=np.int32)),
                         shape=(rows, cols))


class ReducedSystem:
    """Structure of a network Laplacian condensed on Dirichlet groups.

    Parameters
    ----------
    n_nodes : int
    edges : (m, 2) int array of node indices
    groups : sequence of int arrays
        Disjoint node sets, each one Dirichlet super-node (order kept: group g is column g
        of ``K_ud``).
    exclude : (n,) bool array, optional
        Nodes left out (they must not share an edge of non-zero value with kept nodes).
    native : bool
        Use the compiled helpers where they build (default): the patterns of ``K_uu`` and of
        the incidence matrix (:func:`yade_electro.native.csr_pattern`) and the fill of
        ``K_uu`` (:func:`yade_electro.native.laplacian_fill`); False: scipy and numpy only.

    Attributes
    ----------
    unknown_nodes : (nu,) node index of every unknown, in unknown order
    unknown_index : (n,) unknown index of every node (-1 for group and excluded nodes)
    group_of : (n,) group of every node (-1 elsewhere)
    Kuu, Kud, Kdd : CSR matrices (nu x nu, nu x ng, ng x ng) filled by :meth:`assemble`
    diagonal_slots : (nu,) index of each unknown's diagonal entry in ``Kuu.data``
    """

    def __init__(self, n_nodes: int, edges, groups: Sequence = (), exclude: Optional[np.ndarray] = None,
                 native: bool = True):
        n = int(n_nodes)
        edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        m = edges.shape[0]
        ng = len(groups)
        group_of = np.full(n, -1, dtype=np.int64)
        for g, nodes in enumerate(groups):
            nodes = np.asarray(nodes, dtype=np.int64)
            if np.any(group_of[nodes] >= 0):
                raise ValueError("groups of a ReducedSystem must be disjoint")
            group_of[nodes] = g
        excluded = np.zeros(n, bool) if exclude is None else np.asarray(exclude, bool).copy()
        excluded &= group_of < 0
        unknown = (group_of < 0) & ~excluded
        unknown_nodes = np.flatnonzero(unknown)
        nu = unknown_nodes.size
        uidx = np.full(n, -1, dtype=np.int64)
        uidx[unknown_nodes] = np.arange(nu)
        self.n, self.m, self.n_groups, self.n_unknowns = n, m, ng, nu
        self.edges, self.group_of, self.excluded = edges, group_of, excluded
        self.unknown_nodes, self.unknown_index = unknown_nodes, uidx

        i, j = edges[:, 0], edges[:, 1]
        ui, uj, gi, gj = uidx[i], uidx[j], group_of[i], group_of[j]
        eid = np.arange(m)
        uu = (ui >= 0) & (uj >= 0)
        ud_i = (ui >= 0) & (gj >= 0)          # i unknown, j in a group
        ud_j = (uj >= 0) & (gi >= 0)
        dd = (gi >= 0) & (gj >= 0) & (gi != gj)
        self.dropped = ~(uu | ud_i | ud_j | dd)   # same group, or touching an excluded node

        # K_uu: off-diagonals of unknown-unknown edges, the diagonal of every unknown. Kept as
        # index arrays (int32 where they fit): each uu edge's two off-diagonal slots, filled by
        # a scatter, and the unknowns' incidence matrix for the diagonal
        rows = np.concatenate([ui[uu], uj[uu], np.arange(nu)])
        cols = np.concatenate([uj[uu], ui[uu], np.arange(nu)])
        self.Kuu, slot, self._uu_distinct = _pattern(rows, cols, (nu, nu), native)
        del rows, cols
        nuu = int(uu.sum())
        nnz = self.Kuu.nnz
        self.diagonal_slots = slot[2 * nuu:]
        self._e_uu = None if nuu == m else _small_index(eid[uu], m)        # None: every edge
        self._off = (_small_index(slot[:nuu], nnz), _small_index(slot[nuu:2 * nuu], nnz))
        del slot
        # the diagonal: the unknowns' incidence matrix (nu x m, ones), a CSR mat-vec
        inc_rows = np.concatenate([ui[uu], uj[uu], ui[ud_i], uj[ud_j]])
        inc_cols = np.concatenate([eid[uu], eid[uu], eid[ud_i], eid[ud_j]])
        self._incidence, _, _ = _pattern(inc_rows, inc_cols, (nu, m), native)   # distinct: an edge meets a row once
        self._incidence.data[:] = 1.0
        del inc_rows, inc_cols

        if ng == 0:
            # no group (a heat problem without fixed temperatures): empty K_ud, K_dd and maps; scipy's
            # constructors and transposes below cost about 1 ms at 2,000 unknowns, at each new structure
            self.Kud, self.Kdd = _empty_csr(nu, 0), _empty_csr(0, 0)
            self._ud_map = self._dd_map = None
            self._Kdu_pattern, self._Kdu_from_ud = _empty_csr(0, nu), np.zeros(0, dtype=np.int64)
        else:
            # K_ud: -c between an unknown and a group
            rows = np.concatenate([ui[ud_i], uj[ud_j]])
            cols = np.concatenate([gj[ud_i], gi[ud_j]])
            self.Kud, slot, _ = _pattern(rows, cols, (nu, ng))
            self._ud_map = _map(slot, np.concatenate([eid[ud_i], eid[ud_j]]), -np.ones(slot.size), self.Kud.nnz, m)

            # K_dd: group-group couplings and the group diagonals
            rows = np.concatenate([gi[dd], gj[dd], gi[dd], gj[dd], gj[ud_i], gi[ud_j], np.arange(ng)])
            cols = np.concatenate([gj[dd], gi[dd], gi[dd], gj[dd], gj[ud_i], gi[ud_j], np.arange(ng)])
            self.Kdd, slot, _ = _pattern(rows, cols, (ng, ng))
            ndd = int(dd.sum())
            e_dd = eid[dd]
            edge_of = np.concatenate([e_dd, e_dd, e_dd, e_dd, eid[ud_i], eid[ud_j]])
            sign = np.concatenate([-np.ones(2 * ndd), np.ones(2 * ndd + int(ud_i.sum()) + int(ud_j.sum()))])
            self._dd_map = _map(slot[:edge_of.size], edge_of, sign, self.Kdd.nnz, m)
            # K_du = K_ud^T: its pattern once, and where each of its entries sits in K_ud.data
            tagged = self.Kud.copy()
            tagged.data = np.arange(1, tagged.nnz + 1, dtype=float)
            self._Kdu_pattern = tagged.T.tocsr()
            self._Kdu_from_ud = self._Kdu_pattern.data.astype(np.int64) - 1
        self._Kdu = None
        self._assembled = False
        self._native = bool(native)     # K_uu filled by the compiled pass when it builds (its pattern too)
        self.compiled = None            # how the last assembly went (None: numpy asked for, or none yet)

    # -- values ------------------------------------------------------------------------------
    def assemble(self, values, diagonal=None):
        """Fill ``Kuu``, ``Kud``, ``Kdd`` (the same objects) from edge ``values`` (m,), plus an
        optional extra diagonal (nu,) on the unknowns (e.g. ``h A`` or ``C / dt``). Returns
        ``(Kuu, Kud)``."""
        c = np.ascontiguousarray(values, dtype=float)
        if c.shape != (self.m,):
            raise ValueError(f"assemble needs one value per edge ({self.m}), got shape {c.shape}")
        self._assembled = True
        data = self.Kuu.data
        if diagonal is not None:
            diagonal = np.broadcast_to(np.asarray(diagonal, dtype=float), (self.n_unknowns,))
        if not self._fill_compiled(c, diagonal):
            cu = c if self._e_uu is None else c[self._e_uu]
            o1, o2 = self._off
            if self._uu_distinct:                 # one edge per off-diagonal slot: a scatter
                data[o1] = -cu
                data[o2] = -cu
                data[self.diagonal_slots] = 0.0
            else:                                 # repeated edges add up
                data[:] = -(np.bincount(o1, cu, data.size) + np.bincount(o2, cu, data.size))
            data[self.diagonal_slots] += self._incidence @ c
            if diagonal is not None:
                self.Kuu.data[self.diagonal_slots] += diagonal
        if self._ud_map is not None:
            self.Kud.data[:] = self._ud_map @ c
            self.Kdd.data[:] = self._dd_map @ c
        self._Kdu = None
        return self.Kuu, self.Kud

    def _fill_compiled(self, c, diagonal) -> bool:
        """K_uu's values by the compiled pass (:func:`yade_electro.native.laplacian_fill`: the
        numpy form's operations, 2-3x faster at 5,000-20,000 unknowns); False when it is not
        asked for (``native=False``: the numpy form, the tests' reference)."""
        if not self._native:
            return False
        from ..native import laplacian_fill
        o1, o2 = self._off
        laplacian_fill(self.Kuu.data, c, self._e_uu, o1, o2, self.diagonal_slots, self._incidence, diagonal)
        self.compiled = True
        return True

    @property
    def Kdu(self):
        """``K_ud`` transposed (CSR, ng x nu), made when first asked for after an assembly;
        None before the first."""
        if self._Kdu is None and self.Kud.data.size + self.Kud.shape[1] and self._assembled:
            self._Kdu_pattern.data = self.Kud.data[self._Kdu_from_ud]
            self._Kdu = self._Kdu_pattern
        return self._Kdu

    def unknown_diagonal(self) -> np.ndarray:
        """The diagonal of ``Kuu`` (nu,) as last assembled."""
        return self.Kuu.data[self.diagonal_slots].copy()

    # -- results -----------------------------------------------------------------------------
    def expand(self, x_unknown, x_group) -> np.ndarray:
        """Node values (n,) from the unknowns' and the groups' values (excluded nodes: 0)."""
        x = np.zeros(self.n)
        x[self.unknown_nodes] = x_unknown
        ing = self.group_of >= 0
        if np.any(ing):
            x[ing] = np.asarray(x_group, dtype=float)[self.group_of[ing]]
        return x

    def group_flux(self, x_unknown, x_group) -> np.ndarray:
        """Net flux leaving each group into the network, ``K_dd x_d + K_du x_u`` (ng,)."""
        out = self.Kdd @ np.asarray(x_group, dtype=float)
        if self.n_unknowns and self.Kdu is not None:
            out = out + self.Kdu @ np.asarray(x_unknown, dtype=float)
        return out
