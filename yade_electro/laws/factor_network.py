"""A conductance law's network kept on a changing graph, with its geometric factors: what
changed between two graphs, and only that recomputed.

Units: m.
"""
from __future__ import annotations

import numpy as np

from ..core.graph import ContactGraph
from .factors import ConductanceLaw

__all__ = ["FactorNetwork"]


class FactorNetwork:
    """A law's network on a changing graph, kept with its geometric factors.

    ``update(graph)`` compares the graph with the previous one and returns what changed:

    * ``None``: nothing (same object, or same elements, bonds and positions);
    * ``'geometry'``: the elements moved (or their periodic images, or their radii changed):
      new factors g on the same edges;
    * ``'topology'``: the bonds changed and the law's new network is a subset of the kept
      edges (bonds broke): the lost edges get g = 0, the edge list stays;
    * ``'structure'``: another element set, or new edges: a new edge list.

    A law whose network depends on the positions (``moves_network``: resolved grains, whose
    links across contacts follow the grains) is asked for its network at every move.

    Attributes
    ----------
    edges : (m, 2) the kept edges (node pairs of ``graph``)
    factor : (m,) g on ``edges`` [m] (0 on edges the law no longer conducts through)
    graph : the graph of the last update
    """

    def __init__(self, law: ConductanceLaw):
        self.law = law
        self.graph: ContactGraph = None
        self.edges = None
        self.factor = None
        self._net = None
        self._slots = None
        self._pos = self._shift = self._radius = None

    def update(self, graph: ContactGraph):
        from ..core.graph import edge_slots
        old = self.graph
        if old is not None and graph is old:
            return None
        self.graph = graph
        if old is None or graph.n_nodes != old.n_nodes or not np.array_equal(graph.ids, old.ids):
            self._rebuild(graph)
            return "structure"
        same_bonds = graph.edges is old.edges or np.array_equal(graph.edges, old.edges)
        moved = not (graph.pos is self._pos or np.array_equal(graph.pos, self._pos)) or not (
            graph.shift is self._shift or (graph.shift is not None and self._shift is not None
                                           and np.array_equal(graph.shift, self._shift))) or not (
            graph.radius is self._radius or np.array_equal(graph.radius, self._radius))
        if same_bonds and not moved:
            return None
        kind = "geometry"
        if not same_bonds or getattr(self.law, "moves_network", False):     # a law whose network moves
            net = self.law.network(graph)
            slots = edge_slots(self.edges, net, graph.n_nodes)
            if slots is None:
                self._rebuild(graph)
                return "structure"
            self._net, self._slots = net, slots
            kind = "topology"
        g = np.zeros(self.edges.shape[0])
        g[self._slots] = self.law.factor(graph, self._net)
        self.factor, self._pos, self._shift, self._radius = g, graph.pos, graph.shift, graph.radius
        return kind

    def _rebuild(self, graph):
        net = self.law.network(graph)
        self.edges, self._net, self._slots = net, net, np.arange(net.shape[0])
        self.factor = self.law.factor(graph, net)
        self._pos, self._shift, self._radius = graph.pos, graph.shift, graph.radius
