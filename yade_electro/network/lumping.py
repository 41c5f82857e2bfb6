"""Clumps of spheres as one thermal node each: the member network restricted to its lumps.

A clump (YADE's ``O.bodies.appendClumped``) is a rigid particle made of overlapping spheres,
its *members*. Two thermal models of it:

* **resolved**: every member keeps its own temperature; members of one clump conduct
  through the lens where they overlap (the contact law's constriction g = 2 a, a the lens
  radius), and each member's heat capacity is its share of the clump's volume (its sphere
  less half of each lens it shares with a member of its clump: :func:`member_volumes`, so
  that the members' volumes sum to the clump's);
* **lumped**: one temperature per clump (the DEM convention, LIGGGHTS' for multisphere
  particles): the member network is restricted to the lumps, ``K_l = P^T K P``,
  ``C_l = P^T C``, ``s_l = P^T s`` with P the member-to-lump incidence (:class:`Lumping`):
  conductances between members of two different clumps add up per clump pair, those inside
  a clump drop out, capacities and sources add up per clump, and a member's temperature is
  its clump's. :class:`LumpedHeatSolver` is a
  :class:`~yade_electro.network.transient.HeatSolver` on the lumps with the member-level
  interface of one (temperatures, capacities, conductances, links and sources per member).

Units: m, m^3, W/K, J/K, K, W, s.
"""
from __future__ import annotations

import dataclasses
from dataclasses import dataclass

import numpy as np

from ..core.errors import ThermalError
from .transient import HeatSolver

__all__ = ["Lumping", "LumpedHeatSolver", "member_volumes", "lens_volume", "member_bonds", "MemberLabels"]


def lens_volume(r1, r2, d) -> np.ndarray:
    """Volume [m^3] of the lens where two spheres of radii ``r1``, ``r2`` [m] whose centres
    are ``d`` [m] apart overlap (0 when they do not; the smaller sphere when one holds the
    other)."""
    r1, r2, d = (np.asarray(a, float) for a in (r1, r2, d))
    out = np.zeros(np.broadcast(r1, r2, d).shape)
    lens = (d < r1 + r2) & (d > np.abs(r1 - r2))
    inside = d <= np.abs(r1 - r2)
    a, b, c = np.broadcast_to(r1, out.shape), np.broadcast_to(r2, out.shape), np.broadcast_to(d, out.shape)
    a, b, c = a[lens], b[lens], c[lens]
    out[lens] = np.pi * (a + b - c) ** 2 * (c ** 2 + 2 * c * (a + b) - 3 * (a - b) ** 2) / (12.0 * c)
    small = np.minimum(np.broadcast_to(r1, out.shape), np.broadcast_to(r2, out.shape))[inside]
    out[inside] = 4.0 / 3.0 * np.pi * small ** 3
    return out


def member_volumes(pos, radius, labels) -> np.ndarray:
    """The volume [m^3] each sphere stands for: its own, less half of each lens it shares with
    a sphere of the same clump (``labels``: the clump of each sphere, -1 for none), so that a
    clump's members sum to the union of two overlapping members (exact when no point lies in
    three members; the lenses of three members overlapping at one point are then counted
    twice)."""
    pos, r = np.asarray(pos, float).reshape(-1, 3), np.asarray(radius, float)
    lab = np.asarray(labels, np.int64)
    v = 4.0 / 3.0 * np.pi * r ** 3
    members = np.flatnonzero(lab >= 0)
    if members.size < 2:
        return v
    from scipy.spatial import cKDTree
    pairs = cKDTree(pos[members]).query_pairs(2.0 * float(r[members].max()), output_type="ndarray")
    i, j = members[pairs[:, 0]], members[pairs[:, 1]]
    same = lab[i] == lab[j]
    i, j = i[same], j[same]
    half = 0.5 * lens_volume(r[i], r[j], np.linalg.norm(pos[i] - pos[j], axis=1))
    return v - np.bincount(i, half, v.size) - np.bincount(j, half, v.size)


def member_bonds(pos, radius, labels, factor: float = 1.0) -> np.ndarray:
    """Pairs (k, 2) of spheres of one clump (``labels``, -1 for none) whose centres are closer
    than ``factor`` times their radii's sum: the bonds of a clump's member geometry in a bonded
    solid (YADE makes no interaction between members of one clump)."""
    pos, r = np.asarray(pos, float).reshape(-1, 3), np.asarray(radius, float)
    lab = np.asarray(labels, np.int64)
    members = np.flatnonzero(lab >= 0)
    if members.size < 2:
        return np.zeros((0, 2), np.int64)
    from scipy.spatial import cKDTree
    pairs = cKDTree(pos[members]).query_pairs(2.0 * factor * float(r[members].max()), output_type="ndarray")
    i, j = members[pairs[:, 0]], members[pairs[:, 1]]
    keep = (lab[i] == lab[j]) & (np.linalg.norm(pos[i] - pos[j], axis=1) < factor * (r[i] + r[j]))
    return np.column_stack([i[keep], j[keep]]).astype(np.int64)


class MemberLabels:
    """The clump of each sphere, by body id, as at a reader's last full read."""

    def __init__(self):
        self._ids = self._of = np.zeros(0, np.int64)       # body ids (sorted) -> clump ids

    def update(self, ids, clump) -> None:
        """Keep ``clump`` (the clump body id of each sphere of body ids ``ids``, -1: none)."""
        ids = np.asarray(ids, np.int64)
        order = np.argsort(ids)
        self._ids, self._of = ids[order], np.asarray(clump, np.int64)[order]

    @property
    def any(self) -> bool:
        """True when some sphere is a clump's member."""
        return bool(np.any(self._of >= 0))

    def of(self, ids) -> np.ndarray:
        """The clump body id of each sphere of body ids ``ids`` (-1: not in a clump)."""
        ids = np.asarray(ids, np.int64)
        out = np.full(ids.shape, -1, np.int64)
        if self._ids.size:
            at = np.minimum(np.searchsorted(self._ids, ids), self._ids.size - 1)
            found = self._ids[at] == ids
            out[found] = self._of[at[found]]
        return out


@dataclass(frozen=True, eq=False)
class Lumping:
    """Which lump each of ``n`` member nodes belongs to: ``group[i]`` in 0 .. n_lumps - 1.

    Make it with :meth:`of` from each node's clump label (-1: a node of its own); lumps are
    numbered in the order of their first node (nodes with no clump keep their order)."""

    group: np.ndarray
    n_lumps: int

    @classmethod
    def of(cls, labels) -> "Lumping":
        lab = np.asarray(labels, np.int64).ravel()
        key = np.where(lab >= 0, lab, -1 - np.arange(lab.size))      # a node alone is its own lump
        _, first, inv = np.unique(key, return_index=True, return_inverse=True)
        rank = np.empty(first.size, np.int64)                        # lumps in the order of their first node
        rank[np.argsort(first, kind="stable")] = np.arange(first.size)
        group = rank[inv]
        group.setflags(write=False)
        return cls(group, int(group.max()) + 1 if group.size else 0)

    @property
    def n(self) -> int:
        return int(self.group.size)

    def sum(self, values) -> np.ndarray:
        """Per lump, the sum of its members' ``values``."""
        return np.bincount(self.group, np.asarray(values, float), self.n_lumps)

    def spread(self, lump_values) -> np.ndarray:
        """Per member, its lump's value."""
        return np.asarray(lump_values)[self.group]

    def mean(self, values, weights) -> np.ndarray:
        """Per lump, the ``weights``-weighted mean of its members' ``values``."""
        w = np.asarray(weights, float)
        return self.sum(w * np.asarray(values, float)) / self.sum(w)

    def nodes(self, member_nodes) -> np.ndarray:
        """The lumps of the member nodes ``member_nodes``, each once, sorted."""
        return np.unique(self.group[np.asarray(member_nodes, np.int64)])

    def node_sums(self, member_nodes, values):
        """(lumps, per lump the sum of ``values`` over its nodes among ``member_nodes``)."""
        lumps = self.group[np.asarray(member_nodes, np.int64)]
        out, inv = np.unique(lumps, return_inverse=True)
        return out, np.bincount(inv, np.asarray(values, float), out.size)

    def edges(self, member_edges):
        """(lump edges (k, 2), slot (m,)): the pairs of different lumps the member edges join,
        each once, and the lump edge of each member edge (-1 inside a lump)."""
        e = self.group[np.asarray(member_edges, np.int64).reshape(-1, 2)]
        a, b = np.minimum(e[:, 0], e[:, 1]), np.maximum(e[:, 0], e[:, 1])
        between = a != b
        slot = np.full(e.shape[0], -1, np.int64)
        if not np.any(between):
            return np.zeros((0, 2), np.int64), slot
        key = a[between] * self.n_lumps + b[between]
        uniq, inv = np.unique(key, return_inverse=True)
        slot[between] = inv
        return np.column_stack([uniq // self.n_lumps, uniq % self.n_lumps]), slot


def _slots_onto(edges, slot, kept, n: int) -> np.ndarray:
    """``slot`` (member edge -> row of ``edges``, -1 inside a lump) made to point at the same
    lump pairs in ``kept`` (a superset of ``edges``, in its own order)."""
    key = lambda e: np.minimum(e[:, 0], e[:, 1]) * n + np.maximum(e[:, 0], e[:, 1])   # noqa: E731
    kk = key(np.asarray(kept, np.int64).reshape(-1, 2))
    order = np.argsort(kk)
    rows = order[np.searchsorted(kk[order], key(edges))]
    out = slot.copy()
    out[slot >= 0] = rows[slot[slot >= 0]]
    return out


class LumpedHeatSolver:
    """A :class:`~yade_electro.network.transient.HeatSolver` on the lumps of a member network,
    spoken to member by member (see the module doc): the arguments are the member-level ones
    of HeatSolver (capacities, edges and conductances, temperatures, the conditions' node
    sets, areas and link conductances, sources, positions), plus ``lumping``; ``area`` (the
    default exposed areas) per member. A condition holds every lump one of its members is
    in; a member's temperature is its lump's; setting members' temperatures sets their
    lumps' capacity-weighted means. Everything not per node (time, energies, the ledger, the
    stable step, fixed values) is the lump solver's (:attr:`lumped`)."""

    def __init__(self, lumping: Lumping, capacity, edges, conductance, temperature, *, nodes_of=None, area_of=None,
                 link_of=None, area=None, power=None, coords=None, graph=None, **options):
        self.lumping = lumping
        self.n = lumping.n
        self.capacity = np.asarray(capacity, float)
        self.edges = np.asarray(edges, np.int64).reshape(-1, 2)
        self.conductance = np.asarray(conductance, float)
        if area is None and graph is not None:
            from ..laws.transmission import exposed_area
            area = exposed_area(graph)
        T = np.broadcast_to(np.asarray(temperature, float), (self.n,))
        nodes_l, area_l, link_l = {}, {}, {}
        for name, nd in (nodes_of or {}).items():
            nodes_l[name] = lumping.nodes(nd)
            for given, out in ((area_of, area_l), (link_of, link_l)):
                if given and name in given:
                    out[name] = lumping.node_sums(nd, given[name])[1]
        self._edges_l, self._slot = lumping.edges(self.edges)
        w = self.capacity
        self.lumped = HeatSolver(
            lumping.sum(w), self._edges_l, self._lump_conductance(self.conductance), lumping.mean(T, w),
            nodes_of=nodes_l, area_of=area_l, link_of=link_l,
            area=None if area is None else lumping.sum(area), power=None if power is None else lumping.sum(power),
            coords=None if coords is None else np.column_stack([lumping.mean(np.asarray(coords)[:, k], w)
                                                                for k in range(3)]), **options)

    def _lump_conductance(self, G) -> np.ndarray:
        s = self._slot
        return np.bincount(s[s >= 0], np.asarray(G, float)[s >= 0], self._edges_l.shape[0])

    def __getattr__(self, name):                  # time, energy, link_energy, steady's ledger, ...
        if name == "lumped":
            raise AttributeError(name)
        return getattr(self.lumped, name)

    @property
    def time(self) -> float:
        return self.lumped.time

    @time.setter
    def time(self, value):
        self.lumped.time = float(value)

    @property
    def temperature(self) -> np.ndarray:
        """Temperature [K] of every member: its lump's."""
        return self.lumping.spread(self.lumped.temperature)

    def set_temperature(self, temperature):
        T = np.broadcast_to(np.asarray(temperature, float), (self.n,))
        if not np.all(np.isfinite(T)):
            raise ThermalError("non-finite temperatures; the state is unchanged")
        self.lumped.set_temperature(self.lumping.mean(T, self.capacity))

    def update_values(self, conductance=None, capacity=None):
        if conductance is not None:
            self.conductance = np.asarray(conductance, float)
        if capacity is not None:
            self.capacity = np.asarray(capacity, float)
        self.lumped.update_values(None if conductance is None else self._lump_conductance(self.conductance),
                                  None if capacity is None else self.lumping.sum(self.capacity))

    def update_edges(self, edges, conductance, capacity=None) -> str:
        self.edges = np.asarray(edges, np.int64).reshape(-1, 2)
        self.conductance = np.asarray(conductance, float)
        if capacity is not None:
            self.capacity = np.asarray(capacity, float)
        self._edges_l, self._slot = self.lumping.edges(self.edges)
        kind = self.lumped.update_edges(self._edges_l, self._lump_conductance(self.conductance),
                                        None if capacity is None else self.lumping.sum(self.capacity))
        if kind != "structure":                 # a subset: the lump solver keeps its edges (0 on those gone)
            self._slot = _slots_onto(self._edges_l, self._slot, self.lumped.edges, self.lumping.n_lumps)
            self._edges_l = np.asarray(self.lumped.edges)
        return kind

    def set_links(self, name: str, nodes, conductance, assemble: bool = True):
        lumps, G = self.lumping.node_sums(nodes, conductance)
        self.lumped.set_links(name, lumps, G, assemble=assemble)

    def link_flows(self, temperature=None) -> dict:
        T = None if temperature is None else self.lumping.mean(temperature, self.capacity)
        return self.lumped.link_flows(T)

    def _sources(self, sources):
        return None if sources is None else self.lumping.sum(sources)

    def advance(self, dt: float, sources=None):
        return self.lumped.advance(dt, self._sources(sources))

    def trial(self, dt: float, sources=None):
        T, step = self.lumped.trial(dt, self._sources(sources))
        return self.lumping.spread(T), step

    def steady(self, sources=None, apply: bool = True, rtol: float = 1e-12):
        st = self.lumped.steady(self._sources(sources), apply=apply, rtol=rtol)
        return dataclasses.replace(st, temperature=self.lumping.spread(st.temperature),
                                   floating=None if st.floating is None else self.lumping.spread(st.floating))
