"""Contact graph of a particle assembly: spherical elements (nodes) and bonds (edges).

The graph is the only thing the numerical core knows about a packing. It is a frozen
dataclass of numpy arrays, validated on construction, so every model downstream can
rely on finite positions, positive radii and well-formed, duplicate-free edges.

Units: positions and radii in metres.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components

from .errors import GraphError

__all__ = ["ContactGraph", "connected_parts"]


def connected_parts(n_nodes: int, edges) -> tuple:
    """(count, label per node) of the connected parts of ``n_nodes`` nodes joined by ``edges``
    ((m, 2) node indices); a node with no edge is a part of its own."""
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    adj = sp.coo_matrix((np.ones(e.shape[0]), (e[:, 0], e[:, 1])), shape=(n_nodes, n_nodes))
    return connected_components(adj, directed=False)


def _readonly(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


@dataclass(frozen=True, eq=False)
class ContactGraph:
    """Spherical elements and the bonds between them.

    Parameters
    ----------
    pos : (n, 3) float array
        Element centres [m].
    radius : (n,) float array
        Element radii [m], all > 0.
    edges : (m, 2) int array
        Node indices (0..n-1) of each bond; stored with ``i < j``, no duplicates and
        no self loops (duplicates raise, order is normalised).
    ids : (n,) int array, optional
        The caller's identifier of every node (YADE body ids). Defaults to ``arange(n)``.
    revision : int
        A counter the producer bumps when the graph changes; consumers use it, with
        ``key``, to reuse work done on an unchanged graph.
    shift : (m, 3) float array, optional
        In a periodic cell, the vector [m] added to ``pos[j] - pos[i]`` to get the
        separation of the bond (i, j) (the periodic image of j next to i); None: no images.
        It follows the edges: an edge given as (j, i) is stored as (i, j) with its shift
        negated.
    """

    pos: np.ndarray
    radius: np.ndarray
    edges: np.ndarray
    ids: np.ndarray = None  # type: ignore[assignment]
    revision: int = 0
    shift: np.ndarray = None  # type: ignore[assignment]
    _cache: dict = field(default_factory=dict, repr=False, compare=False)

    def __post_init__(self):
        pos = np.asarray(self.pos, dtype=float)
        if pos.ndim != 2 or pos.shape[1] != 3:
            raise GraphError(f"pos must have shape (n, 3), got {pos.shape}")
        n = pos.shape[0]
        if n == 0:
            raise GraphError("the graph has no elements: the simulation has no spheres "
                             "(or the selection kept none); add spherical bodies first")
        radius = np.asarray(self.radius, dtype=float).reshape(-1)
        if radius.shape != (n,):
            raise GraphError(f"radius must have shape ({n},), got {radius.shape}")
        if not np.all(np.isfinite(pos)):
            bad = np.flatnonzero(~np.all(np.isfinite(pos), axis=1))
            raise GraphError(f"non-finite positions at nodes {bad[:10].tolist()}")
        if not np.all(np.isfinite(radius)) or np.any(radius <= 0):
            bad = np.flatnonzero(~(np.isfinite(radius) & (radius > 0)))
            raise GraphError(f"radius must be finite and > 0; bad at nodes {bad[:10].tolist()} "
                             f"(values {radius[bad[:5]].tolist()})")
        edges = np.asarray(self.edges, dtype=np.int64)
        if edges.size == 0:
            edges = edges.reshape(0, 2)
        if edges.ndim != 2 or edges.shape[1] != 2:
            raise GraphError(f"edges must have shape (m, 2), got {edges.shape}")
        if edges.size and (edges.min() < 0 or edges.max() >= n):
            raise GraphError(f"edge node index out of range 0..{n - 1}")
        if np.any(edges[:, 0] == edges[:, 1]):
            raise GraphError("edges contain self loops (a node bonded to itself)")
        shift = None
        if self.shift is not None:
            shift = np.array(self.shift, dtype=float).reshape(-1, 3) if np.size(self.shift) else np.zeros((0, 3))
            if shift.shape != (edges.shape[0], 3) or not np.all(np.isfinite(shift)):
                raise GraphError(f"shift must be a finite ({edges.shape[0]}, 3) array (m), one vector per edge")
            shift[edges[:, 0] > edges[:, 1]] *= -1.0
        edges = np.sort(edges, axis=1)
        key = edges[:, 0] * n + edges[:, 1]
        if np.unique(key).size != key.size:
            raise GraphError("edges contain duplicate bonds")
        ids = np.arange(n) if self.ids is None else np.asarray(self.ids, dtype=np.int64)
        if ids.shape != (n,):
            raise GraphError(f"ids must have shape ({n},), got {ids.shape}")
        if np.unique(ids).size != n:
            raise GraphError("ids must be unique")
        object.__setattr__(self, "pos", _readonly(pos))
        object.__setattr__(self, "radius", _readonly(radius))
        object.__setattr__(self, "edges", _readonly(edges))
        object.__setattr__(self, "ids", _readonly(ids))
        object.__setattr__(self, "shift", None if shift is None else _readonly(shift))

    # -- sizes ---------------------------------------------------------------------------
    @property
    def n_nodes(self) -> int:
        return self.pos.shape[0]

    @property
    def n_edges(self) -> int:
        return self.edges.shape[0]

    # -- derived quantities (cached: the graph is immutable) ------------------------------
    def _cached(self, name, make):
        c = self._cache
        if name not in c:
            v = make()
            if isinstance(v, np.ndarray):
                v.setflags(write=False)
            c[name] = v
        return c[name]

    @property
    def length(self) -> np.ndarray:
        """Centre-to-centre distance l_ij of each edge [m]."""
        def make():
            d = self.edge_vectors()
            return np.sqrt(np.einsum("ij,ij->i", d, d))
        return self._cached("length", make)

    @property
    def degree(self) -> np.ndarray:
        """Number of bonds n_i of each node."""
        return self._cached("degree", lambda: np.bincount(self.edges.ravel(), minlength=self.n_nodes))

    @property
    def volume(self) -> np.ndarray:
        """Sphere volume 4/3 pi r^3 of each node [m^3]."""
        return self._cached("volume", lambda: 4.0 / 3.0 * np.pi * self.radius ** 3)

    @property
    def incidence(self) -> sp.csr_matrix:
        """Incidence matrix A (m x n): row k has -1 at edges[k,0] and +1 at edges[k,1]."""
        def make():
            m, n = self.n_edges, self.n_nodes
            rows = np.repeat(np.arange(m), 2)
            cols = self.edges.ravel()
            vals = np.tile([-1.0, 1.0], m)
            return sp.csr_matrix((vals, (rows, cols)), shape=(m, n))
        return self._cached("incidence", make)

    @property
    def components(self) -> tuple:
        """(count, label per node) of the connected components of the bond graph."""
        return self._cached("components", lambda: connected_parts(self.n_nodes, self.edges))

    def index_of(self, ids) -> np.ndarray:
        """Node indices of the given caller ids (e.g. YADE body ids); unknown ids raise."""
        ids = np.atleast_1d(np.asarray(ids, dtype=np.int64))
        order = self._cached("id_order", lambda: np.argsort(self.ids))
        sorted_ids = self.ids[order]
        pos = np.searchsorted(sorted_ids, ids)
        pos = np.clip(pos, 0, self.n_nodes - 1)
        found = sorted_ids[pos] == ids
        if not np.all(found):
            raise GraphError(f"ids not in the graph: {ids[~found][:10].tolist()}")
        return order[pos]

    def neighbour_barycentre(self) -> np.ndarray:
        """Mean position of the bonded neighbours of each node [m]; a node with no
        neighbour gets its own position."""
        def make():
            n = self.n_nodes
            i, j = self.edges[:, 0], self.edges[:, 1]
            d = self.edge_vectors()             # the neighbour's image next to the node
            s = np.stack([np.bincount(i, self.pos[i, k] + d[:, k], n) + np.bincount(j, self.pos[j, k] - d[:, k], n)
                          for k in range(3)], axis=1)
            deg = self.degree
            out = self.pos.copy()
            has = deg > 0
            out[has] = s[has] / deg[has, None]
            return out
        return self._cached("barycentre", make)

    def edge_vectors(self, edges=None) -> np.ndarray:
        """Separation x_j - x_i [m] of each edge (i, j) (``edges``: node pairs of this graph,
        default all), with the periodic image's shift when the graph has one."""
        e = self.edges if edges is None else np.asarray(edges, dtype=np.int64).reshape(-1, 2)
        d = self.pos[e[:, 1]] - self.pos[e[:, 0]]
        if self.shift is None:
            return d
        if e is self.edges or (e.shape == self.edges.shape and np.array_equal(e, self.edges)):
            return d + self.shift
        key = self.edges[:, 0] * self.n_nodes + self.edges[:, 1]
        order = np.argsort(key)
        lo, hi = np.minimum(e[:, 0], e[:, 1]), np.maximum(e[:, 0], e[:, 1])
        want = lo * self.n_nodes + hi
        at = np.clip(np.searchsorted(key[order], want), 0, key.size - 1) if key.size else np.zeros(0, np.int64)
        if not key.size or not np.array_equal(key[order][at], want):
            raise GraphError("edge_vectors: some node pairs are not edges of this periodic graph (their image is "
                             "unknown)")
        sign = np.where(e[:, 0] < e[:, 1], 1.0, -1.0)[:, None]
        return d + sign * self.shift[order][at]

    def with_positions(self, pos, revision=None, shift=None) -> "ContactGraph":
        """A new graph of the same elements and bonds at other positions [m] (the elements
        moved); ``shift``: the edges' new periodic shifts (default: the kept ones). The
        bonds and ids, validated already, are shared, not checked again."""
        pos = np.asarray(pos, dtype=float)
        if pos.shape != self.pos.shape:
            raise GraphError(f"pos must have shape {self.pos.shape}, got {pos.shape}")
        if not np.all(np.isfinite(pos)):
            bad = np.flatnonzero(~np.all(np.isfinite(pos), axis=1))
            raise GraphError(f"non-finite positions at nodes {bad[:10].tolist()}")
        if shift is None:
            shift = self.shift
        else:
            if self.shift is None:
                raise GraphError("with_positions: this graph has no periodic shifts to replace")
            shift = np.asarray(shift, dtype=float)
            if shift.shape != self.shift.shape or not np.all(np.isfinite(shift)):
                raise GraphError(f"shift must be a finite {self.shift.shape} array (m)")
            shift = _readonly(shift)
        g = object.__new__(ContactGraph)
        for name, value in (("pos", _readonly(pos)), ("radius", self.radius), ("edges", self.edges),
                            ("ids", self.ids), ("revision", self.revision + 1 if revision is None else revision),
                            ("shift", shift),
                            ("_cache", {k: v for k, v in self._cache.items() if k in ("degree", "volume",
                                                                                     "incidence", "components",
                                                                                     "id_order")})):
            object.__setattr__(g, name, value)
        return g

    def with_edges(self, edges, revision=None, shift=None) -> "ContactGraph":
        """A new graph with the same elements and other bonds (e.g. after bonds broke);
        ``shift``: their periodic shifts, required when this graph has some."""
        if self.shift is not None and shift is None:
            raise GraphError("with_edges: this graph is periodic; give the new edges' shift= too")
        return ContactGraph(self.pos, self.radius, edges, self.ids,
                            self.revision + 1 if revision is None else revision, shift)

    def subgraph(self, keep_edges) -> "ContactGraph":
        """A new graph with the same elements and only the edges where ``keep_edges`` is true."""
        keep = np.asarray(keep_edges, dtype=bool)
        return self.with_edges(self.edges[keep], shift=None if self.shift is None else self.shift[keep])


def edge_slots(candidates, edges, n_nodes: int):
    """Positions of the node pairs ``edges`` among ``candidates`` (both (m, 2), any order within a
    pair), or None when some pair is not a candidate."""
    c = np.sort(np.asarray(candidates, dtype=np.int64).reshape(-1, 2), axis=1)
    e = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
    if e.shape[0] == 0:
        return np.zeros(0, dtype=np.int64)
    if c.shape[0] == 0:
        return None
    kc = c[:, 0] * n_nodes + c[:, 1]
    ke = e[:, 0] * n_nodes + e[:, 1]
    order = np.argsort(kc)
    pos = np.clip(np.searchsorted(kc[order], ke), 0, kc.size - 1)
    if not np.all(kc[order][pos] == ke):
        return None
    return order[pos]
