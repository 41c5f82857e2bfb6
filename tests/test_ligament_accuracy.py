"""Accuracy in a ligament a few elements wide (issue 36, item 23), on the numerical core: the
bounded cells leave no gap at a notch's re-entrant edges, every Voronoi face of an intact
solid conducts, and the 'cells' Joule sharing is exact in a uniform field."""
import numpy as np
import pytest

from yade_electro.core.graph import ContactGraph
from yade_electro.geometry.cells import bounded_cells
from yade_electro.geometry.shapes import Box
from yade_electro.geometry.voronoi import VoronoiFaces
from yade_electro.laws.factors import make_law
from yade_electro.packing.dense import dense_packing
from yade_electro.physics.integrator import Integrator
from yade_electro.physics.thermal import cell_joule_sources, joule_sources

L, W, Z = 6e-3, 2e-3, 1e-3
A, B, DEPTH = 2.6e-3, 3.4e-3, 0.7e-3          # two notches, a 0.6 mm ligament


def notched():
    return (Box((0, 0, 0), (L, W, Z)) - Box((A, -W, -Z), (B, DEPTH, 2 * Z))
            - Box((A, W - DEPTH, -Z), (B, 2 * W, 2 * Z)))


@pytest.fixture(scope="module")
def ligament():
    shape = notched()
    pk = dense_packing(shape, n=2500, seed=3)
    graph = ContactGraph(pk.centers, pk.radii, np.zeros((0, 2), np.int64))
    return shape, graph, bounded_cells(pk.centers, pk.radii, shape)


def crossing(cells, pos, x):
    """Sum of |n_x| A over the faces between elements on either side of the plane at x: the
    section there when the faces leave no gap (at least the section, more where the
    separating surface folds)."""
    e = cells.pairs
    d = pos[e[:, 1]] - pos[e[:, 0]]
    cross = (pos[e[:, 0], 0] - x) * (pos[e[:, 1], 0] - x) < 0
    return float(np.sum(cells.area[cross] * np.abs(d[cross, 0]) / np.linalg.norm(d[cross], axis=1)))


def test_no_gap_at_the_notch_edges(ligament):
    """Ghosts mirrored across one face of a notch were nearer to solid beyond the other face
    than any element: that solid belonged to no cell, and the section through the ligament's
    entrance was 2-3.5 % short (0.2 mm ligament, 10,000 elements). Now the faces cover it and
    the cells fill the solid."""
    shape, graph, cells = ligament
    r = float(np.mean(graph.radius))
    section = (W - 2 * DEPTH) * Z
    for x in (A + 0.5 * r, A + r, A + 2 * r, 0.5 * L, B - r):
        assert crossing(cells, graph.pos, x) >= section * (1 - 1e-9), x
    assert crossing(cells, graph.pos, 0.5 * L) == pytest.approx(section, rel=1e-9)
    solid = L * W * Z - 2 * (B - A) * DEPTH * Z
    assert cells.volume.sum() == pytest.approx(solid, rel=1e-3)


def test_every_face_of_an_intact_solid_conducts(ligament):
    """The crack-facet rule kept an unbonded pair only within ``hops`` bonds: in a thin part
    some faces of the intact solid did not conduct (1.2 % of a 0.2 mm ligament's section).
    Now a pair conducts while it is no farther apart along the bonds than in the reference."""
    shape, graph, cells = ligament
    d = np.linalg.norm(graph.pos[cells.pairs[:, 1]] - graph.pos[cells.pairs[:, 0]], axis=1)
    near = d < 1.02 * (graph.radius[cells.pairs[:, 0]] + graph.radius[cells.pairs[:, 1]])
    bonded = graph.with_edges(cells.pairs[near])
    law = make_law("voronoi", container=shape, hops=1)
    net = law.network(bonded)
    every = np.unique(np.concatenate([law.faces(bonded).pairs, np.sort(bonded.edges, axis=1)]), axis=0)
    np.testing.assert_array_equal(net, every)
    # a bond broken: the pairs whose only short path ran through it stop conducting
    cut = law.network(bonded.with_edges(bonded.edges[1:]))
    assert cut.shape[0] < net.shape[0]


def test_cells_joule_sharing_is_exact_in_a_uniform_field(ligament):
    """A uniform field: each element's heat is its cell's volume times |E|^2 / rho (the
    edges' half-and-half shares are off by up to tens of percent per element), and the total is
    the network's."""
    shape, graph, cells = ligament
    pos, e = graph.pos, cells.pairs
    E, rho = np.array([300.0, -40.0, 10.0]), 2e-6
    u = pos @ E
    dvec = pos[e[:, 1]] - pos[e[:, 0]]
    c = cells.area / np.linalg.norm(dvec, axis=1) / rho
    w = c * (u[e[:, 1]] - u[e[:, 0]])                    # branch currents
    edges = joule_sources(e, w, c, pos.shape[0])
    out = cell_joule_sources(pos, e, u, cells.volume, rho, edges)
    assert out.sum() == pytest.approx(edges.sum(), rel=1e-12)
    exact = cells.volume * (E @ E) / rho
    inner = shape.sdf(pos) < -2.0 * graph.radius              # whole cells: the network is exact
    np.testing.assert_allclose(out[inner] / exact[inner], out.sum() / exact.sum(), rtol=1e-9)
    spread = edges[inner] / exact[inner]
    assert spread.max() - spread.min() > 0.1                 # what 'edges' does per element
    # an electrode's own elements (held) and their neighbours keep their edge share, the others
    # share the rest alike
    held = pos[:, 0] < pos[:, 0].min() + 2.0 * graph.radius
    near = held.copy()
    near[e[held[e[:, 0]], 1]] = near[e[held[e[:, 1]], 0]] = True
    assert near.sum() > held.sum() > 0
    kept = cell_joule_sources(pos, e, u, cells.volume, rho, edges, held=held)
    np.testing.assert_array_equal(kept[near], edges[near])
    assert kept.sum() == pytest.approx(edges.sum(), rel=1e-12)
    free = inner & ~near
    np.testing.assert_allclose(kept[free] / exact[free], (kept.sum() - edges[near].sum()) / exact[~near].sum(),
                               rtol=1e-9)
    # an element with one neighbour keeps its edge share; the others share the rest
    lone = np.array([[0, 1]])
    got = cell_joule_sources(pos[:2], lone, u[:2], np.ones(2), rho, np.array([1.0, 1.0]))
    np.testing.assert_array_equal(got, [1.0, 1.0])
    with pytest.raises(ValueError, match="joule_sharing must be 'auto'"):
        Integrator(joule_sharing="faces")


def test_the_default_joule_sharing_is_cells_for_a_bonded_voronoi_solid_only():
    """'auto' (the default) reads a Voronoi solid as a continuum (cells) and keeps a contact's
    heat at the contact under every other law; an explicit choice is kept under any law."""
    default = Integrator()
    assert default.joule_sharing == "auto"
    assert default.joule_sharing_for("voronoi") == "cells"
    for law in ("continuum", "contact", "liggghts", "pipe", "grains"):
        assert default.joule_sharing_for(law) == "edges"
    assert Integrator(joule_sharing="edges").joule_sharing_for("voronoi") == "edges"
    assert Integrator(joule_sharing="cells").joule_sharing_for("contact") == "cells"


def test_far_pairs_stop_conducting_once_a_crack_cuts_the_part_in_two():
    """A face whose elements are linked only by a long way round (20 bonds, beyond FAR_HOPS)
    conducts while the bonds link them at all, and stops once one bond on that way breaks (a
    separated bar carries no current through such faces); an element that never had a bond is
    not held to the reference distance (it keeps its one neighbour, whose part it is in)."""
    chain = np.column_stack([np.arange(20), np.arange(1, 21)])
    faces = VoronoiFaces(np.array([[0, 20], [5, 21]]), np.ones(2), 22)
    pos = np.zeros((22, 3))
    key = {tuple(p) for p in faces.cracked(pos, chain, chain)}
    assert {(0, 20), (5, 21)} <= key
    cut = np.delete(chain, 10, axis=0)
    key = {tuple(p) for p in faces.cracked(pos, cut, chain)}
    assert (0, 20) not in key and (5, 21) in key and (10, 11) not in key


def test_an_element_that_never_had_a_bond_does_not_bridge_a_crack():
    """A rattler between two parts of a chain conducts with both while the chain is intact; once
    the bond between the parts breaks it conducts with the part it has most face area with
    only (it bridged the separated halves of a cracked bar: R_eq finite where it is infinite)."""
    chain = np.column_stack([np.arange(9), np.arange(1, 10)])
    faces = VoronoiFaces(np.array([[3, 10], [6, 10]]), np.array([1.0, 2.0]), 11)
    pos = np.zeros((11, 3))
    key = {tuple(p) for p in faces.cracked(pos, chain, chain)}
    assert {(3, 10), (6, 10)} <= key
    key = {tuple(p) for p in faces.cracked(pos, np.delete(chain, 4, axis=0), chain)}
    assert (6, 10) in key and (3, 10) not in key


def test_cells_joule_sharing_split_over_ranks_is_the_serial_one():
    """A distributed rank computes its owned elements' cell sources from its share (owned
    elements first, then ghosts) and the ranks' sums: two ranks give the serial sources."""
    rng = np.random.default_rng(3)
    pos = rng.uniform(0, 1e-3, size=(300, 3))
    from scipy.spatial import Delaunay
    tri = Delaunay(pos).simplices
    edges = np.unique(np.sort(np.concatenate([tri[:, [a, b]] for a in range(4) for b in range(a + 1, 4)]), axis=1),
                      axis=0)
    u = 3.0 * pos[:, 0] + 50.0 * pos[:, 1] ** 2 + rng.normal(0, 1e-5, 300)
    volume, rho = rng.uniform(1, 2, 300) * 1e-12, rng.uniform(1, 3, 300) * 1e-6
    p_edge = rng.uniform(0.5, 1.5, 300)
    # held elements (an electrode's) on both sides of the ranks' border: an owned element next to
    # a ghost that is held keeps its edge share as in the serial run
    pinned = np.abs(pos[:, 2] - 0.5e-3) < 0.08e-3
    for hold in (None, pinned):
        serial = cell_joule_sources(pos, edges, u, volume, rho, p_edge, held=hold)
        owner = (pos[:, 2] > 0.5e-3).astype(int)
        shares = []
        for rank in (0, 1):
            own = np.flatnonzero(owner == rank)
            held = edges[(owner[edges[:, 0]] == rank) | (owner[edges[:, 1]] == rank)]
            ghosts = np.setdiff1d(np.unique(held), own)
            nodes = np.concatenate([own, ghosts])
            local = np.full(300, -1)
            local[nodes] = np.arange(nodes.size)
            shares.append((own, nodes, local[held]))
        sums = []
        for own, nodes, e in shares:          # each rank's two sums, then every rank's with the total
            cell_joule_sources(pos[nodes], e, u[nodes], volume[own], rho[own], p_edge[own], owned=own.size,
                               reduce=lambda v: sums.append(v) or v, held=None if hold is None else hold[nodes])
        total = sum(sums)
        for own, nodes, e in shares:
            got = cell_joule_sources(pos[nodes], e, u[nodes], volume[own], rho[own], p_edge[own], owned=own.size,
                                     reduce=lambda v: total, held=None if hold is None else hold[nodes])
            np.testing.assert_allclose(got, serial[own], rtol=1e-12)
