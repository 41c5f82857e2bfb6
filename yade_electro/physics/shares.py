"""One MPI rank's share of a packing: the elements it owns, the ghosts they touch, the edges
with an owned end (numpy only, no MPI call, no YADE).

:func:`carve_share` carves it from a graph of the elements a rank has (the whole packing, or
its own and mirrored ones); :func:`carve_region_share` from a rank's *region* (its own
elements and a halo around them) for a law whose network and factors need a neighbourhood
wider than the pairs (the 'voronoi' law's tessellation).

Units: m.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

from ..core.graph import ContactGraph
from ..network.partition import LocalNetwork, split_network

__all__ = ["Share", "carve_share", "carve_region_share"]


@dataclass(frozen=True, eq=False)
class Share:
    """One rank's share of the packing: ``graph`` (owned nodes first, then ghosts; None when
    the rank owns nothing) and its ``network`` (the same nodes and edges, with the ghosts'
    owners)."""

    graph: Optional[ContactGraph]
    network: LocalNetwork
    #: the geometric factors [m] of the edges when the carving computed them (the 'voronoi'
    #: law, on the rank's region), else None (computed on the share)
    factor: Optional[np.ndarray] = None
    #: the owned elements' cell volumes [m^3] when the law has cells ('voronoi'), else None
    volume: Optional[np.ndarray] = None

    @property
    def n_owned(self) -> int:
        return self.network.n_owned

    @property
    def owned_ids(self) -> np.ndarray:
        return self.network.owned_key

    def conducting(self, keep) -> "Share":
        """The share with only the edges ``keep`` (a mask): contacts that touch; the nodes stay."""
        keep = np.asarray(keep, dtype=bool)
        if self.graph is None or np.all(keep):
            return self
        net = self.network
        graph = self.graph.with_edges(self.graph.edges[keep])
        return Share(graph, LocalNetwork(net.owned_key, net.ghost_key, net.ghost_owner, graph.edges))


def _carve(graph, owner, rank):
    owner = np.asarray(owner, dtype=np.int64)
    network, held = split_network(graph.n_nodes, graph.edges, owner, rank, keys=graph.ids)
    if network.n_owned == 0:
        return Share(None, network), held, None
    nodes = np.concatenate([np.flatnonzero(owner == rank), graph.index_of(network.ghost_key)])
    sub = ContactGraph(graph.pos[nodes], graph.radius[nodes], network.edges, ids=graph.ids[nodes],
                       revision=graph.revision)
    return Share(sub, LocalNetwork(network.owned_key, network.ghost_key, network.ghost_owner, sub.edges)), held, nodes


def carve_share(graph: Optional[ContactGraph], owner, rank: int) -> Share:
    """The share of rank ``rank`` of a graph of the elements it has (the whole packing, or its
    own and mirrored ones), ``owner[i]`` the rank owning node i. The share's edges are the
    graph's edges with an owned end, in the graph's order."""
    if graph is None:
        return Share(None, LocalNetwork([], [], [], np.zeros((0, 2), np.int64)))
    return _carve(graph, owner, rank)[0]


def carve_region_share(graph: Optional[ContactGraph], owner, rank: int, law) -> Share:
    """The share of rank ``rank`` for a law whose network and factors need a neighbourhood
    wider than the pairs (the 'voronoi' law: a tessellation): ``graph`` is the rank's region
    (the elements it owns and a halo around them, with their bonds), ``law`` the rank's law
    object, which keeps the region's tessellation. The share's edges are the law's conducting
    pairs with an owned end; its ``factor`` and ``volume`` are the region's values, exact for
    the owned elements when the halo holds every element their cells and crack rule see."""
    if graph is None:
        return carve_share(None, None, rank)
    pairs = np.asarray(law.network(graph), dtype=np.int64).reshape(-1, 2)
    factor = law.factor(graph, pairs)
    share, held, nodes = _carve(graph.with_edges(pairs), owner, rank)
    if share.graph is None:
        return share
    volume = law.cell_volumes(graph)[nodes[:share.n_owned]] if hasattr(law, "cell_volumes") else None
    return Share(share.graph, share.network, factor=np.asarray(factor, float)[held], volume=volume)
