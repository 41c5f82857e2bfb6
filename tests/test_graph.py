"""ContactGraph: validation on construction, derived arrays, exact values on small graphs."""
import numpy as np
import pytest

from yade_electro import ContactGraph, GraphError

from lattice import cubic_lattice, lattice_coords, lattice_edges, lattice_index, node_class


def triangle(**kw):
    pos = [[0.0, 0.0, 0.0], [3.0, 0.0, 0.0], [0.0, 4.0, 0.0]]
    return ContactGraph(pos, [1.0, 1.0, 2.0], [[1, 0], [1, 2], [2, 0]], **kw)


# -- construction ------------------------------------------------------------------------------
def test_edges_are_normalised_and_arrays_read_only():
    g = triangle()
    assert g.edges.tolist() == [[0, 1], [1, 2], [0, 2]]   # each edge as (low, high), order kept
    assert g.ids.tolist() == [0, 1, 2]
    assert (g.n_nodes, g.n_edges, g.revision) == (3, 3, 0)
    for a in (g.pos, g.radius, g.edges, g.ids, g.length, g.degree, g.volume):
        assert not a.flags.writeable
        with pytest.raises(ValueError):
            a[0] = 0


def test_graph_with_no_edges_is_valid():
    g = ContactGraph([[0, 0, 0], [1, 0, 0]], [0.5, 0.5], np.zeros((0, 2), dtype=int))
    assert g.n_edges == 0
    assert g.degree.tolist() == [0, 0]
    assert g.components[0] == 2
    # an isolated node's barycentre is its own position
    np.testing.assert_array_equal(g.neighbour_barycentre(), g.pos)
    ContactGraph([[0, 0, 0]], [1.0], [])   # an empty list of edges too


def test_length_degree_volume_exact():
    g = triangle()
    np.testing.assert_array_equal(g.length, [3.0, 5.0, 4.0])       # 3-4-5 triangle
    assert g.degree.tolist() == [2, 2, 2]
    np.testing.assert_allclose(g.volume, 4.0 / 3.0 * np.pi * np.array([1.0, 1.0, 8.0]), rtol=1e-15)


def test_incidence_sign_convention():
    g = triangle()
    A = g.incidence.toarray()
    # row k: -1 at edges[k, 0], +1 at edges[k, 1]
    np.testing.assert_array_equal(A, [[-1, 1, 0], [0, -1, 1], [-1, 0, 1]])
    u = np.array([5.0, 2.0, 1.0])
    np.testing.assert_array_equal(A @ u, u[g.edges[:, 1]] - u[g.edges[:, 0]])


def test_neighbour_barycentre_exact():
    g = triangle()
    np.testing.assert_allclose(g.neighbour_barycentre(),
                               [[1.5, 2.0, 0.0], [0.0, 2.0, 0.0], [1.5, 0.0, 0.0]], rtol=0, atol=1e-15)


def test_components_and_index_of():
    g = ContactGraph(np.arange(15.0).reshape(5, 3), np.ones(5), [[0, 1], [3, 4]], ids=[10, 42, 7, 3, 99])
    count, label = g.components
    assert count == 3
    assert label[0] == label[1] and label[3] == label[4] and len({label[0], label[2], label[3]}) == 3
    assert g.index_of([99, 10, 7]).tolist() == [4, 0, 2]
    assert g.index_of(42).tolist() == [1]
    with pytest.raises(GraphError, match=r"ids not in the graph: \[5, 1000\]"):
        g.index_of([7, 5, 1000])


def test_with_edges_and_subgraph_bump_revision():
    g = triangle(revision=4)
    h = g.with_edges([[0, 1]])
    assert h.revision == 5 and h.n_edges == 1 and h.pos is g.pos
    assert g.with_edges([[0, 1]], revision=11).revision == 11
    s = g.subgraph([True, False, True])
    assert s.edges.tolist() == [[0, 1], [0, 2]] and s.revision == 5
    assert g.n_edges == 3  # the original is untouched


def test_derived_arrays_are_cached():
    g = triangle()
    assert g.length is g.length
    assert g.incidence is g.incidence


# -- the simple cubic lattice helper ------------------------------------------------------------
def test_cubic_lattice_structure():
    shape = (4, 5, 6)
    g = cubic_lattice(shape, r=0.5)
    n = 4 * 5 * 6
    assert g.n_nodes == n
    assert g.n_edges == 3 * 5 * 6 + 4 * 4 * 6 + 4 * 5 * 5
    np.testing.assert_array_equal(g.length, np.ones(g.n_edges))       # spacing 2 r = 1
    ijk = lattice_coords(shape)
    np.testing.assert_array_equal(g.pos, ijk.astype(float))
    assert lattice_index(3, 4, 5, shape) == n - 1
    assert lattice_index(1, 2, 3, shape) == 1 + 4 * (2 + 5 * 3)
    # degree by class: interior 6, face 5, edge 4, corner 3
    np.testing.assert_array_equal(g.degree, 6 - node_class(shape))
    counts = np.bincount(node_class(shape), minlength=4)
    assert counts.tolist() == [2 * 3 * 4, 2 * (2 * 3 + 2 * 4 + 3 * 4), 4 * (2 + 3 + 4), 8]
    assert g.components[0] == 1
    assert lattice_edges(shape).shape == (g.n_edges, 2)


# -- bad input: each a GraphError saying what is wrong ------------------------------------------
def test_no_spheres_is_a_graph_error():
    with pytest.raises(GraphError, match="no elements.*spheres"):
        ContactGraph(np.zeros((0, 3)), np.zeros(0), np.zeros((0, 2), dtype=int))


@pytest.mark.parametrize("bad", [0.0, -1e-3, np.nan, np.inf])
def test_bad_radius_is_a_graph_error(bad):
    with pytest.raises(GraphError, match=r"radius must be finite and > 0; bad at nodes \[1\]"):
        ContactGraph(np.zeros((3, 3)) + np.arange(3)[:, None], [1.0, bad, 1.0], [[0, 1]])


@pytest.mark.parametrize("kw, message", [
    (dict(pos=np.zeros((3, 2))), r"pos must have shape \(n, 3\)"),
    (dict(pos=[[0, 0, 0], [np.nan, 0, 0], [2, 0, 0]]), r"non-finite positions at nodes \[1\]"),
    (dict(radius=[1.0, 1.0]), r"radius must have shape \(3,\)"),
    (dict(edges=[0, 1, 2]), r"edges must have shape \(m, 2\)"),
    (dict(edges=[[0, 3]]), r"edge node index out of range 0..2"),
    (dict(edges=[[-1, 2]]), r"edge node index out of range"),
    (dict(edges=[[1, 1]]), "self loops"),
    (dict(edges=[[0, 1], [1, 0]]), "duplicate bonds"),
    (dict(ids=[1, 2]), r"ids must have shape \(3,\)"),
    (dict(ids=[5, 6, 5]), "ids must be unique"),
])
def test_malformed_graph_is_a_graph_error(kw, message):
    args = dict(pos=[[0, 0, 0], [1, 0, 0], [2, 0, 0]], radius=[0.5, 0.5, 0.5], edges=[[0, 1], [1, 2]])
    args.update(kw)
    with pytest.raises(GraphError, match=message):
        ContactGraph(**args)


def test_graph_error_is_a_value_error():
    # callers that only know ValueError still catch it
    with pytest.raises(ValueError):
        ContactGraph(np.zeros((1, 3)), [-1.0], [])


def test_periodic_shift_follows_the_edges():
    # a chain 0-1-2 whose bond (2, 0) closes through the cell's face (period 3 along x)
    pos = np.array([[0.0, 0, 0], [1.0, 0, 0], [2.0, 0, 0]])
    edges = [[0, 1], [1, 2], [2, 0]]
    shift = [[0, 0, 0], [0, 0, 0], [3.0, 0, 0]]          # node 0's image next to node 2
    g = ContactGraph(pos, np.full(3, 0.6), edges, shift=shift)
    assert g.edges.tolist() == [[0, 1], [1, 2], [0, 2]]
    assert g.shift.tolist() == [[0, 0, 0], [0, 0, 0], [-3.0, 0, 0]]     # negated with the swap
    assert g.length.tolist() == [1.0, 1.0, 1.0]
    assert g.edge_vectors([[2, 0], [1, 2]]).tolist() == [[1.0, 0, 0], [1.0, 0, 0]]
    assert np.allclose(g.neighbour_barycentre(), pos)    # each node between its two neighbours
    moved = g.with_positions(pos + 0.5)                  # the shifts kept
    assert moved.length.tolist() == [1.0, 1.0, 1.0] and moved.shift is g.shift
    stretched = g.with_positions(pos * 1.1, shift=np.array(g.shift) * 1.1)
    assert np.allclose(stretched.length, 1.1)
    sub = g.subgraph([False, True, True])
    assert sub.edges.tolist() == [[1, 2], [0, 2]] and sub.length.tolist() == [1.0, 1.0]
    with pytest.raises(GraphError, match="shift="):
        g.with_edges([[0, 1]])
    with pytest.raises(GraphError, match="not edges of this periodic graph"):
        g.edge_vectors([[0, 0]])
    with pytest.raises(GraphError, match="shift must be a finite"):
        ContactGraph(pos, np.full(3, 0.6), edges, shift=[[0, 0, 0]])
    with pytest.raises(GraphError, match="no periodic shifts"):
        ContactGraph(pos, np.full(3, 0.6), edges).with_positions(pos, shift=np.zeros((3, 3)))
