"""One rank's share of a network, and the rows of the reduced system it owns (numpy; the
compiled CSR pattern of :mod:`yade_electro.native` when it is built).

A distributed run splits the elements between ranks: each rank *owns* some nodes and sees,
as *ghosts*, the nodes of other ranks its own nodes are joined to. :class:`LocalNetwork`
holds one rank's share: owned nodes first (local indices ``0..n_owned-1``), ghosts after,
and the edges with at least one owned end, so an edge between two ranks is held by both.
The owner computes: each rank writes only the rows of its own unknowns, so no entry is ever
sent to another rank.

:class:`OwnedRows` turns such a share into its block of rows of the reduced matrix (the
Laplacian of the conductances, plus a diagonal, with the fixed-value nodes eliminated
symmetrically: their columns move to the right-hand side), in CSR form with the global
numbers of the unknowns as column indices: what PETSc's MPIAIJ takes. The pattern is made
once; :meth:`OwnedRows.values` refills the values in place (conductances change, edges keep).
Nothing here talks to other ranks: the global numbers come from
:mod:`yade_electro.solvers.partitioned`. Stacking every rank's rows gives the serial matrix
(``tests/test_partition.py`` checks it in one process).

Units: conductances in S or W/K, values in V or K, as the caller's physics.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import GraphError

__all__ = ["LocalNetwork", "OwnedRows", "split_network"]


def _pattern(rows, cols, n_rows: int, n_cols: int):
    """(indptr, indices, slot) of the CSR pattern of the (row, col) pairs, columns sorted in
    each row, ``slot`` the position of each pair in the data (repeated pairs share one): the
    compiled counting sort (:func:`yade_electro.native.csr_pattern`) for distinct pairs, else
    one sorted int64 key per pair."""
    from ..native import NativeError, csr_pattern
    try:
        got = csr_pattern(rows, cols, (n_rows, n_cols)) if rows.size else None
    except NativeError:
        got = None
    if got is not None:
        return got
    uniq, slot = np.unique(rows * n_cols + cols, return_inverse=True)
    ur = uniq // n_cols
    return (np.concatenate([[0], np.cumsum(np.bincount(ur, minlength=n_rows))]), uniq - ur * n_cols,
            slot.reshape(-1))


def _ro(a, dtype):
    a = np.ascontiguousarray(a, dtype=dtype)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class LocalNetwork:
    """One rank's share of a network.

    Parameters
    ----------
    owned_key : (n_owned,) int
        A key of every owned node that its owner and the ranks that see it agree on (YADE's
        body id); unique.
    ghost_key : (g,) int
        The keys of the ghost nodes (local indices ``n_owned..n_owned+g-1``).
    ghost_owner : (g,) int
        The rank that owns each ghost.
    edges : (m, 2) int
        Local node indices of the edges this rank holds; every edge has an owned end, none
        repeats and none is a loop.
    """

    owned_key: np.ndarray
    ghost_key: np.ndarray
    ghost_owner: np.ndarray
    edges: np.ndarray

    def __post_init__(self):
        ok = _ro(np.asarray(self.owned_key).reshape(-1), np.int64)
        gk = _ro(np.asarray(self.ghost_key).reshape(-1), np.int64)
        go = _ro(np.asarray(self.ghost_owner).reshape(-1), np.int64)
        e = _ro(np.asarray(self.edges).reshape(-1, 2), np.int64)
        if go.shape != gk.shape:
            raise GraphError(f"ghost_owner has {go.shape[0]} entries for {gk.shape[0]} ghosts")
        keys = np.concatenate([ok, gk])
        if np.unique(keys).shape[0] != keys.shape[0]:
            raise GraphError("a node key repeats among the owned nodes and ghosts of this rank")
        n_local = keys.shape[0]
        if e.size and (e.min() < 0 or e.max() >= n_local):
            raise GraphError(f"edge indices must be in 0..{n_local - 1}")
        if e.size and np.any(e[:, 0] == e[:, 1]):
            raise GraphError("an edge joins a node to itself")
        if e.size and np.any((e[:, 0] >= ok.shape[0]) & (e[:, 1] >= ok.shape[0])):
            raise GraphError("an edge joins two ghosts: a rank holds only edges with an owned end")
        lo, hi = np.minimum(e[:, 0], e[:, 1]), np.maximum(e[:, 0], e[:, 1])
        if np.unique(lo * n_local + hi).shape[0] != e.shape[0]:
            raise GraphError("an edge repeats in this rank's share")
        for name, val in (("owned_key", ok), ("ghost_key", gk), ("ghost_owner", go), ("edges", e)):
            object.__setattr__(self, name, val)

    @property
    def n_owned(self) -> int:
        return int(self.owned_key.shape[0])

    @property
    def n_local(self) -> int:
        """Owned nodes and ghosts."""
        return int(self.owned_key.shape[0] + self.ghost_key.shape[0])

    @property
    def keys(self) -> np.ndarray:
        """Keys of the local nodes: owned, then ghosts."""
        return np.concatenate([self.owned_key, self.ghost_key])


def split_network(n_nodes: int, edges, owner, rank: int, keys=None) -> "tuple[LocalNetwork, np.ndarray]":
    """Rank ``rank``'s share of a whole network whose node ``i`` is owned by ``owner[i]``
    (for tests and for scenes every rank holds whole). Returns the share and the indices of
    its edges in ``edges``. Ghosts are the other ranks' nodes joined to an owned node."""
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    owner = np.asarray(owner, dtype=np.int64)
    keys = np.arange(n_nodes) if keys is None else np.asarray(keys, dtype=np.int64)
    mine = owner == rank
    held = np.flatnonzero(mine[e[:, 0]] | mine[e[:, 1]])
    he = e[held]
    owned = np.flatnonzero(mine)
    ghosts = np.setdiff1d(he.ravel(), owned)
    local = np.full(n_nodes, -1, np.int64)
    local[owned] = np.arange(owned.shape[0])
    local[ghosts] = owned.shape[0] + np.arange(ghosts.shape[0])
    share = LocalNetwork(keys[owned], keys[ghosts], owner[ghosts], local[he])
    return share, held


class OwnedRows:
    """The rows of a rank's own unknowns in the reduced system, as CSR arrays.

    ``A = K_uu + diag(d)`` on the owned free nodes, ``K`` the Laplacian of the edge
    conductances; the columns of fixed nodes (owned or ghost) go to the right-hand side as
    ``r_i = sum_j c_ij v_j`` (symmetric elimination: the matrix stays SPD, which GAMG needs).

    Parameters
    ----------
    network : LocalNetwork
    unknown : (n_local,) int
        Global number of each local node's unknown, -1 for a fixed node. Owned free nodes
        must be numbered contiguously and in order (``offset + 0, 1, ...``): row ``k`` of this
        rank is its ``k``-th owned free node.
    """

    def __init__(self, network: LocalNetwork, unknown):
        u = np.asarray(unknown, dtype=np.int64)
        if u.shape != (network.n_local,):
            raise ValueError(f"unknown must have {network.n_local} entries (owned nodes, then ghosts), got {u.shape}")
        n_own = network.n_owned
        self.network = network
        self.unknown = _ro(u, np.int64)
        self.free_owned = _ro(np.flatnonzero(u[:n_own] >= 0), np.int64)
        own_u = u[self.free_owned]
        if own_u.size and np.any(np.diff(own_u) != 1):
            raise ValueError("the owned unknowns must be numbered contiguously in node order")
        self.offset = int(own_u[0]) if own_u.size else 0
        self.n_rows = int(own_u.shape[0])
        self.row_of = np.full(network.n_local, -1, np.int64)
        self.row_of[self.free_owned] = np.arange(self.n_rows)
        e = network.edges
        # per direction (a, b): edges whose a-end is an owned unknown, whether their b-end is
        # free (an off-diagonal entry) or fixed (the right-hand side); masks and the small
        # fixed parts are kept, the rows are gathered again when values are made (a few
        # bytes per edge kept, not tens: 63 MB at 630k edges before)
        self._on, self._free, self._fixed = [], [], []
        rows, cols = [np.arange(self.n_rows)], [own_u]
        for a, b in ((0, 1), (1, 0)):
            ra = self.row_of[e[:, a]]
            on = ra >= 0
            ub = u[e[:, b]]
            free_b = on & (ub >= 0)
            fixed_b = np.flatnonzero(on & (ub < 0))
            self._on.append(on)
            self._free.append(free_b)
            self._fixed.append((fixed_b, ra[fixed_b], e[fixed_b, b]))
            rows.append(ra[free_b])
            cols.append(ub[free_b])
            del ra, ub
        r, c = np.concatenate(rows), np.concatenate(cols)
        del rows, cols
        width = max(int(u.max()) + 1 if u.size else 1, 1)     # > every column number
        indptr, indices, slot = _pattern(r, c, self.n_rows, width)
        small = width < 2 ** 31 - 1 and indices.size < 2 ** 31 - 1     # 32-bit indices: half the memory
        self.indices = _ro(indices, np.int32 if small else np.int64)
        self.indptr = _ro(indptr, np.int32 if small else np.int64)
        self._slot = slot.astype(np.int32) if small else slot
        #: the position in the values of each row's diagonal entry
        self.diagonal_index = _ro(self._slot[:self.n_rows], np.int64)

    @property
    def nnz(self) -> int:
        return int(self.indices.shape[0])

    def values(self, conductance, diagonal=None) -> np.ndarray:
        """The CSR values for edge conductances ``conductance`` (one per edge of the share) and
        an extra diagonal ``diagonal`` (one per owned node, or None)."""
        c = np.asarray(conductance, dtype=float)
        if c.shape != (self.network.edges.shape[0],):
            raise ValueError(f"conductance must have one value per edge of the share "
                             f"({self.network.edges.shape[0]}), got {c.shape}")
        d = np.zeros(self.n_rows)
        if diagonal is not None:
            d += np.asarray(diagonal, dtype=float)[self.free_owned]
        e = self.network.edges
        for a, on in enumerate(self._on):
            d += np.bincount(self.row_of[e[on, a]], c[on], self.n_rows)
        entries = np.concatenate([d] + [-c[free] for free in self._free])
        return np.bincount(self._slot, entries, self.nnz)

    def fixed_rhs(self, conductance, value) -> np.ndarray:
        """``r_i = sum_j c_ij v_j`` over the fixed neighbours j of each owned unknown i, for the
        values ``value`` of the local nodes (only fixed nodes' entries are read)."""
        c = np.asarray(conductance, dtype=float)
        v = np.asarray(value, dtype=float)
        r = np.zeros(self.n_rows)
        for fe, fr, fnode in self._fixed:
            r += np.bincount(fr, c[fe] * v[fnode], self.n_rows)
        return r
