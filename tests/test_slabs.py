"""The slabs of a plain-mpiexec run (yade_electro.yade.distributed.Slabs), without MPI: the
region a rank reads, and the error when bonds reach beyond every halo it tries."""
import numpy as np
import pytest

from yade_electro.core.errors import BoundaryConditionError
from yade_electro.core.graph import ContactGraph
from yade_electro.yade.distributed import Slabs


def _chain(n=40, r=0.5):
    pos = np.column_stack([np.arange(n, dtype=float), np.zeros(n), np.zeros(n)])
    edges = np.column_stack([np.arange(n - 1), np.arange(1, n)])
    return ContactGraph(pos, np.full(n, r), edges, ids=np.arange(n))


class _Reader:
    """A bonded reader whose region leaves out the far end of one long bond (``cut``); it
    calls the slabs' region hook at each read, as the scene readers' ``keep`` does."""

    def __init__(self, graph, cut, slabs):
        self.graph, self.cut_nodes, self.last_coordinates = graph, np.asarray(cut, np.int64), None
        self.slabs, self.reads, self.invalidated, self.halos = slabs, 0, 0, []

    def read(self):
        self.reads += 1
        self.slabs.region(self.graph.ids, self.graph.pos, self.graph.radius)
        self.halos.append(self.slabs.halo)
        return self.graph

    def invalidate(self):
        self.invalidated += 1


def test_region_is_the_slab_and_a_halo():
    g = _chain()
    s = Slabs(0, 2)
    keep = s.region(g.ids, g.pos, g.radius)
    own = s.owner(g.ids, g.pos) == 0
    assert own.sum() == 20 and np.all(keep[own])
    # halo: two largest diameters (contacts and bonds) plus one of margin = 3 m on this chain
    assert s.halo == pytest.approx(3.0)
    assert np.flatnonzero(keep & ~own).tolist() == [20, 21]          # within the halo, strictly
    wide = Slabs(0, 2, hops=3)                        # the voronoi law looks hops + 2 diameters far
    wide.region(g.ids, g.pos, g.radius)
    assert wide.halo == pytest.approx(6.0)


def test_bonds_beyond_every_halo_raise_naming_the_halo():
    g = _chain()
    s = Slabs(0, 2)
    s.region(g.ids, g.pos, g.radius)
    reader = _Reader(g, cut=[3], slabs=s)             # an owned element keeps a bond out of the region
    with pytest.raises(BoundaryConditionError, match="beyond a halo of 24 m"):
        s.read(reader)
    assert reader.halos == [3.0, 6.0, 12.0, 24.0] and reader.invalidated == 4   # doubled after each try


def test_a_cut_at_another_ranks_element_is_not_this_ranks_business():
    g = _chain()
    s = Slabs(0, 2)
    s.region(g.ids, g.pos, g.radius)
    reader = _Reader(g, cut=[30], slabs=s)            # owned by rank 1
    assert s.read(reader) is g and reader.reads == 1
