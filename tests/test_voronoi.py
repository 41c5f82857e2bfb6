"""The 'voronoi' conductance law: exact for uniform fields, cut by cracks."""
import numpy as np
import pytest

from yade_electro import ContactGraph
from yade_electro.laws.factors import conductance, make_law
from yade_electro.laws.law import Law
from yade_electro.physics.electrical import ElectricalModel
from yade_electro.geometry.shapes import Box
from yade_electro.network.conduction import equivalent_resistance
from yade_electro.geometry.voronoi import VoronoiFaces, voronoi_faces


def test_cubic_lattice_faces_are_the_cube_faces():
    r = 1.0
    g = np.stack(np.meshgrid(*[np.arange(4)] * 3, indexing="ij"), -1).reshape(-1, 3) * 2 * r + r
    box = Box([0, 0, 0], [8, 8, 8])
    pairs, area = voronoi_faces(g, np.full(len(g), r), box)
    d = np.linalg.norm(g[pairs[:, 0]] - g[pairs[:, 1]], axis=1)
    face = np.isclose(d, 2 * r)
    np.testing.assert_allclose(area[face], 4 * r * r, rtol=1e-9)
    assert np.all(area[~face] < 1e-9 * r * r)   # diagonal pairs share at most an edge


def test_uniform_field_is_exact_on_random_points():
    """Random interior points, electrode points on the two end faces (dense enough that the
    electrode cells cover the end faces): a uniform field satisfies Kirchhoff exactly, so
    R_eq = rho L / A to rounding."""
    rng = np.random.default_rng(3)
    L, W, rho = 3.0, 1.0, 2.5
    inner = rng.uniform([0.05, 0.05, 0.1], [W - 0.05, W - 0.05, L - 0.1], size=(400, 3))
    gx = (np.stack(np.meshgrid(np.linspace(0.04, W - 0.04, 12), np.linspace(0.04, W - 0.04, 12),
                               indexing="ij"), -1).reshape(-1, 2))
    bottom = np.column_stack([gx, np.zeros(len(gx))])
    top = np.column_stack([gx, np.full(len(gx), L)])
    pos = np.concatenate([inner, bottom, top])
    radius = np.full(len(pos), 0.05)
    box = Box([0, 0, 0], [W, W, L])
    pairs, area = voronoi_faces(pos, radius, box)
    graph = ContactGraph(pos, radius, pairs)
    c = conductance(graph, rho, "voronoi", container=box, hops=1)
    n_in = len(inner)
    bot = np.arange(n_in, n_in + len(gx))
    topn = np.arange(n_in + len(gx), len(pos))
    R = equivalent_resistance(graph.n_nodes, graph.edges, c, topn, bot, solver="direct")
    assert R == pytest.approx(rho * L / (W * W), rel=1e-9)


def _rod_graph(seed=0, n=1500):
    rng = np.random.default_rng(seed)
    L = 4.0
    pos = rng.uniform([0, 0, 0], [1, 1, L], size=(n, 3))
    radius = np.full(n, 0.08)
    from scipy.spatial import cKDTree
    pairs = cKDTree(pos).query_pairs(0.25, output_type="ndarray")
    return ContactGraph(pos, radius, pairs), Box([0, 0, 0], [1, 1, L]), L


def test_cut_bonds_cut_the_current():
    graph, box, L = _rod_graph()
    z = graph.pos[:, 2]
    el = {"top": dict(select=z > L - 0.2, potential=1.0), "bottom": dict(select=z < 0.2, potential=0.0)}
    m = ElectricalModel(1.0, el, law=Law("voronoi", container=box))
    m.solve(graph)
    assert np.isfinite(m.equivalent_resistance)
    # break every bond crossing the plane z = L/2: no path of bonds crosses it any more
    e = graph.edges
    crossing = (z[e[:, 0]] < L / 2) != (z[e[:, 1]] < L / 2)
    cut = graph.subgraph(~crossing)
    m.solve(cut)
    assert m.equivalent_resistance == float("inf")
    assert not np.any(np.isnan(m.solution.potential))


def test_hops_widen_the_network_and_faces_are_reused():
    graph, box, L = _rod_graph(1)
    law1 = make_law("voronoi", container=box, hops=1)
    n1 = law1.network(graph)
    faces = law1.faces(graph)
    g1 = law1.factor(graph, n1)
    assert law1.faces(graph) is faces and law1.tessellations == 1       # the tessellation is made once
    # the areas of an edge list are looked up once, even when the list comes as a new view
    # (FactorNetwork passes one at every call): a move changes only the lengths
    moved = graph.with_positions(graph.pos * 1.01)
    g2 = law1.factor(moved, n1.reshape(-1, 2))
    assert law1.area_lookups == 1
    np.testing.assert_allclose(g2, g1 / 1.01, rtol=1e-12)
    law3 = make_law("voronoi", container=box, hops=3)
    n3 = law3.network(graph)
    # intact, every face of the solid conducts, whatever hops: pairs farther apart than hops
    # along the bonds conduct while they are no farther than in the reference
    every = np.unique(np.concatenate([faces.pairs, np.sort(graph.edges, axis=1)]), axis=0)
    np.testing.assert_array_equal(n1, every)
    np.testing.assert_array_equal(n3, every)
    # bonds broken: a pair conducts while linked within max(hops, its reference distance), so
    # a larger hops keeps more
    broken = graph.with_edges(graph.edges[::2])
    m1, m3 = law1.network(broken), law3.network(broken)
    assert m3.shape[0] >= m1.shape[0] and m1.shape[0] < faces.pairs.shape[0]


def test_voronoi_needs_a_container():
    graph, box, L = _rod_graph(2, n=200)
    with pytest.raises(ValueError, match="container"):
        conductance(graph, 1.0, "voronoi")


def test_area_lookup_of_non_neighbours_is_zero():
    pairs = np.array([[0, 1], [1, 2]])
    f = VoronoiFaces(pairs, np.array([2.0, 3.0]), 4)
    np.testing.assert_array_equal(f.area_of(np.array([[1, 0], [2, 1], [0, 3]])), [2.0, 3.0, 0.0])


def test_cells_at_a_re_entrant_corner_are_not_cut_away():
    """An L-shaped solid (a box minus a box): tangent planes of the concave corner must not
    cut solid away; every cell keeps a volume and the cells fill the solid."""
    from yade_electro.geometry.voronoi import voronoi_cell_volumes
    solid = Box((0, 0, 0), (2, 2, 1)) - Box((1, 1, -1), (3, 3, 2))
    rng = np.random.default_rng(5)
    pts = rng.uniform([0, 0, 0], [2, 2, 1], size=(3000, 3))
    pts = pts[np.asarray(solid.sdf(pts)) < -0.02][:600]
    vol, info = voronoi_cell_volumes(pts, np.full(len(pts), 0.02), solid, return_info=True)
    assert vol.min() > 0
    assert vol.sum() == pytest.approx(3.0, rel=2e-3)        # exact L volume: 4 - 1
    pairs, area = voronoi_faces(pts, np.full(len(pts), 0.02), solid)
    assert np.all(area >= 0) and np.isfinite(area).all()


def test_coupled_model_takes_voronoi_cell_capacities_by_default():
    """With the voronoi law the heat capacities are rho c V_cell, from the law's own
    tessellation: they add up to rho c times the solid's volume."""
    from yade_electro import Material
    from yade_electro.physics.coupled import ElectroThermalModel
    graph, box, L = _rod_graph(3, n=800)
    z = graph.pos[:, 2]
    el = ElectricalModel(1.0, {"top": dict(select=z > L - 0.2, potential=1.0),
                               "bottom": dict(select=z < 0.2, potential=0.0)}, law=Law("voronoi", container=box))
    m = ElectroThermalModel(el, Material(density=2.0, specific_heat=3.0, conductivity=1.0), 0.0)
    m.step(graph, 1e-3)
    assert m.capacity.sum() == pytest.approx(2.0 * 3.0 * (1 * 1 * L), rel=1e-9)
    assert el.law.tessellations == 1                          # the capacities came from the law's tessellation


def _crossing_point(pos, pairs, zc):
    """Where each pair's segment crosses z = zc (nan where it does not)."""
    a, b = pos[pairs[:, 0]], pos[pairs[:, 1]]
    across = (a[:, 2] - zc) * (b[:, 2] - zc) < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(across, (zc - a[:, 2]) / (b[:, 2] - a[:, 2]), np.nan)
    return a + (b - a) * t[:, None]


def test_crack_facets_stop_the_leak_through_a_half_section_crack():
    """A crack over half the section (x < 1/2 at z = L/2): by the facet rule almost none of the
    Voronoi area across the cracked half conducts (what does: faces of never-bonded pairs, a
    documented failure mode); the path rule lets several times more leak near the front;
    the ligament (x > 1/2) keeps all of its faces by both rules."""
    graph, box, L = _rod_graph(2)
    zc, x = L / 2, graph.pos[:, 0]
    e, z = graph.edges, graph.pos[:, 2]
    x_mid = 0.5 * (x[e[:, 0]] + x[e[:, 1]])
    broken = ((z[e[:, 0]] < zc) != (z[e[:, 1]] < zc)) & (x_mid < 0.5)
    cracked = graph.subgraph(~broken)
    leak = {}
    for crack in ("facets", "paths"):
        law = make_law("voronoi", container=box, hops=3, crack=crack)
        faces = law.faces(graph)                              # the reference: nothing broken
        on = np.zeros(faces.pairs.shape[0], bool)
        at = faces.index_of(law.network(cracked))
        on[at[at >= 0]] = True
        hit = _crossing_point(graph.pos, faces.pairs, zc)
        deep = hit[:, 0] < 0.5 - 0.1                           # across the crack, off its front
        ligament = hit[:, 0] > 0.5 + 0.1
        leak[crack] = faces.area[deep & on].sum() / faces.area[deep].sum()
        assert faces.area[ligament & ~on].sum() == 0.0, crack
    assert leak["facets"] < 0.07            # 0.049 here (random points, many unbonded neighbours)
    assert leak["paths"] > 2 * leak["facets"]   # 0.155
    with pytest.raises(ValueError, match="crack must be"):
        make_law("voronoi", container=box, crack="none")


@pytest.mark.parametrize("hops", [1, 2, 3, 4])
def test_compiled_hop_test_agrees_with_the_sparse_matrix_powers(hops):
    """VoronoiFaces.linked by the compiled breadth-first helper against the reference (powers of
    the adjacency matrix), on random graphs with isolated nodes and long chains."""
    import reference_kernels as ref
    from yade_electro.geometry.voronoi import VoronoiFaces
    rng = np.random.default_rng(hops)
    n = 3000
    b = np.sort(rng.integers(0, n, (4000, 2)), axis=1)
    b = np.unique(b[b[:, 0] != b[:, 1]], axis=0)
    pairs = np.sort(rng.integers(0, n, (20000, 2)), axis=1)
    pairs = np.unique(pairs[pairs[:, 0] != pairs[:, 1]], axis=0)
    pairs = np.concatenate([pairs, b])            # bonded pairs too: linked at every hops >= 1
    faces = VoronoiFaces(pairs, np.ones(len(pairs)), n)
    fast = faces.linked(b, hops)
    slow = ref.hops_linked(n, b, faces.pairs, hops)
    assert 0 < slow.sum() < slow.size
    np.testing.assert_array_equal(fast, slow)
