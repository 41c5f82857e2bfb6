"""Granular contacts from positions (Verlet lists, sphere-wall overlaps), the contact laws'
wall factors and softened-stiffness correction, and isothermal walls in the heat model: each
against an exact answer (numpy only)."""
import math

import numpy as np
import pytest

from yade_electro.geometry.contacts import (WallGeometry, candidate_pairs, plane_contact_radius, triangle_distance,
                                   wall_candidates, wall_overlaps)
from yade_electro.laws.factors import make_law
from yade_electro import Material
from yade_electro.laws.law import Law
from yade_electro.physics.coupled import ElectroThermalModel
from yade_electro.physics.integrator import Integrator
from yade_electro.core.errors import BoundaryConditionError
from yade_electro.core.graph import ContactGraph
from yade_electro.network.heat_conditions import ThermalWall


def test_candidate_pairs_are_every_close_pair():
    rng = np.random.default_rng(3)
    pos = rng.uniform(0, 0.02, (400, 3))
    rad = rng.uniform(0.5e-3, 1e-3, 400)
    skin = 0.3e-3
    got = candidate_pairs(pos, rad, skin)
    d = np.linalg.norm(pos[:, None] - pos[None], axis=2)
    i, j = np.nonzero(np.triu(d < rad[:, None] + rad[None] + skin, 1))
    assert np.array_equal(got, np.column_stack([i, j]))       # lexicographic, i < j


def test_triangle_distance_against_dense_sampling():
    rng = np.random.default_rng(5)
    tri = np.array([[0, 0, 0], [1, 0, 0], [0.2, 0.8, 0]], float)
    pts = rng.uniform(-1, 2, (300, 3))
    u, v = np.meshgrid(np.linspace(0, 1, 301), np.linspace(0, 1, 301))
    keep = u + v <= 1
    samples = tri[0] + u[keep, None] * (tri[1] - tri[0]) + v[keep, None] * (tri[2] - tri[0])
    brute = np.array([np.min(np.linalg.norm(samples - p, axis=1)) for p in pts])
    got = triangle_distance(pts, np.repeat(tri[None], len(pts), axis=0))
    assert np.all(got <= brute + 1e-12)                   # exact closest point: never farther
    assert np.max(brute - got) < 5e-3                     # the sampling's resolution


def test_compiled_contact_radii_are_the_numpy_ones():
    """The contact radii of native/contact_radii.cpp against the numpy form, both models, on
    overlapping and separated pairs of a polydisperse cloud, with and without periodic image
    shifts: the same a^2 to 1e-14 r_max^2 (a last-bit difference in the centre distance, numpy's
    einsum sums the squares in another order, is amplified in a^2 = r1^2 - x^2 for small
    contacts, to about 1e-13 relative in a); coincident centres are a MaterialError either way,
    and other pairs than a periodic graph's edges (numpy in the package) agree too."""
    import reference_kernels as ref
    from yade_electro.laws.factors import contact_radius, edge_lengths
    from yade_electro.core.errors import MaterialError
    rng = np.random.default_rng(11)
    pos = rng.uniform(0, 0.01, (500, 3))
    rad = rng.uniform(0.4e-3, 1.2e-3, 500)
    edges = candidate_pairs(pos, rad, 0.5e-3)
    shift = rng.uniform(-1e-4, 1e-4, (edges.shape[0], 3))
    for g in (ContactGraph(pos, rad, edges), ContactGraph(pos, rad, edges, shift=shift)):
        for model in ("geometric", "hertz"):
            fast = contact_radius(g, model=model)
            slow = ref.contact_radius(g, model=model)
            assert np.count_nonzero(slow) > 100 and np.count_nonzero(slow == 0) > 100
            assert np.array_equal(fast == 0, slow == 0)
            assert np.allclose(fast ** 2, slow ** 2, rtol=0, atol=1e-14 * rad.max() ** 2)
        # pairs that are not the periodic graph's edges take the package's numpy path
        other = edges[::7].copy()
        assert np.allclose(contact_radius(g, other) ** 2, ref.contact_radius(g, other) ** 2, rtol=0,
                           atol=1e-14 * rad.max() ** 2)
    same = ContactGraph([[0, 0, 0], [0, 0, 0]], [1.0, 1.0], [[0, 1]])
    same_periodic = ContactGraph([[0, 0, 0], [0, 0, 0]], [1.0, 1.0], [[0, 1]], shift=np.zeros((1, 3)))
    for graph, pairs in ((same, same.edges), (same_periodic, same_periodic.edges.copy())):
        with pytest.raises(MaterialError, match="coincident"):
            contact_radius(graph, pairs)
        with pytest.raises(MaterialError, match="coincident"):
            edge_lengths(graph, pairs)
    # the centre distances (native pair_lengths), of the graph's edges and of other pairs
    g = ContactGraph(pos, rad, edges, shift=shift)
    other = np.array([[0, 5], [7, 3], [499, 0]])
    for graph, pairs in ((g, g.edges), (ContactGraph(pos, rad, edges), other), (g, edges[::7].copy())):
        assert np.allclose(edge_lengths(graph, pairs), ref.edge_lengths(graph, pairs), rtol=1e-15, atol=0)


def test_compiled_contacts_are_the_numpy_ones():
    """The compiled helpers (native/wall_contacts.cpp, the cell grid of fire_steps.cpp) against
    the numpy / cKDTree forms: triangle distances in every closest-point region (the same to
    1e-15 relative; exactly on the degenerate cases), the Verlet list and a facet mesh's
    candidates identical; the deepest overlaps the same from sorted or shuffled candidates; a
    sparse box (a sphere far away) goes to the tree."""
    import reference_kernels as ref
    import yade_electro.geometry.contacts as C
    rng = np.random.default_rng(8)
    k = 4000
    tri = rng.uniform(-1, 1, (k, 3, 3))
    tri[:50, 2] = tri[:50, 1]                                   # degenerate: two equal corners
    pts = rng.uniform(-2, 2, (k, 3))
    pts[50:100] = tri[50:100, 0]                                # exactly on a corner
    fast = C.triangle_distance(pts, tri)
    slow = ref.triangle_distance(pts, tri)
    ok = np.isfinite(slow)
    assert np.all(ok[100:]) and np.allclose(fast[ok], slow[ok], rtol=1e-14, atol=1e-15)
    assert np.all(fast[50:100] == 0.0)
    # a drum-like facet mesh and a bed of spheres: the same candidates, tree or compiled
    ang = np.linspace(0, 2 * np.pi, 25)
    ring = np.column_stack([np.cos(ang), np.sin(ang)]) * 0.05
    mesh = []
    for a, b in zip(ring[:-1], ring[1:]):
        p0, p1, p2, p3 = [np.array([*xy, z]) for xy, z in ((a, 0), (b, 0), (b, 0.02), (a, 0.02))]
        mesh += [[p0, p1, p2], [p0, p2, p3]]
    wall = WallGeometry("triangles", vertices=np.array(mesh))
    r = np.full(1500, 2e-3)
    rho = 0.05 * np.sqrt(rng.uniform(0, 1, 1500))
    phi = rng.uniform(0, 2 * np.pi, 1500)
    pos = np.column_stack([rho * np.cos(phi), rho * np.sin(phi), rng.uniform(0, 0.02, 1500)])
    got_w = C.wall_candidates(wall, pos, r, 1e-3)
    got_p = C.candidate_pairs(pos, r, 1e-3)
    tree = C.sphere_tree(pos)                       # given a tree, both searches query it
    ref_w = C.wall_candidates(wall, pos, r, 1e-3, tree=tree)
    ref_p = C.candidate_pairs(pos, r, 1e-3, tree=tree)
    assert got_w[0].size > 100 and all(np.array_equal(a, b) for a, b in zip(got_w, ref_w))
    assert got_p.shape[0] > 1000 and np.array_equal(got_p, ref_p)
    # the deepest overlap per sphere: sorted candidates (reduceat) or not (np.unique) alike
    pos_in = pos * (1 + 2.5e-3 / 0.05)                            # some spheres pressed into the shell
    touching = C.wall_overlaps(wall, pos_in, r, *ref_w)
    shuffle = rng.permutation(ref_w[0].size)
    assert touching[0].size > 10
    assert all(np.array_equal(a, b) for a, b in zip(touching, C.wall_overlaps(wall, pos_in, r, ref_w[0][shuffle],
                                                                                 ref_w[1][shuffle])))
    far = np.vstack([pos, [[100.0, 0, 0]]])
    assert C._cell_pairs(far, 5e-3) is None
    assert np.array_equal(C.candidate_pairs(far, np.append(r, 2e-3), 1e-3), ref_p)


def test_facet_vertices_compiled_numpy_and_scipy_rotation_agree():
    """The facets' world vertices from their poses: the compiled pass, the numpy form and
    scipy's Rotation (a reference we did not write) on random unit quaternions."""
    from scipy.spatial.transform import Rotation
    import reference_kernels as ref
    import yade_electro.geometry.contacts as C
    rng = np.random.default_rng(11)
    k = 500
    q = rng.normal(size=(k, 4))
    q /= np.linalg.norm(q, axis=1)[:, None]
    pos = rng.uniform(-0.1, 0.1, (k, 3))
    local = rng.uniform(-0.01, 0.01, (k, 3, 3))
    fast = C.facet_vertices(pos, q, local)
    slow = ref.facet_vertices(pos, q, local)
    ref = pos[:, None, :] + np.stack([Rotation.from_quat(q).apply(local[:, v]) for v in range(3)], axis=1)
    assert fast.shape == (k, 3, 3)
    assert np.abs(fast - slow).max() <= 4e-17, np.abs(fast - slow).max()      # a few ulps of 0.1 m
    assert np.abs(slow - ref).max() <= 1e-16, np.abs(slow - ref).max()
    assert np.abs(C.quaternion_matrices(q) - Rotation.from_quat(q).as_matrix()).max() <= 2e-15   # 1.1e-15 found


def test_plane_box_and_triangle_overlaps():
    r = 1e-3
    pos = np.array([[0, 0, 0.9e-3], [0, 0, -0.5e-3], [0, 0, 2e-3]])
    rad = np.full(3, r)
    plane = WallGeometry("plane", point=(0, 0, 0), normal=(0, 0, 1), two_sided=False)
    nodes, dl = wall_overlaps(plane, pos, rad, *wall_candidates(plane, pos, rad, 1e-4))
    assert nodes.tolist() == [0] and dl[0] == pytest.approx(0.1e-3)          # one-sided: not the one below
    both = WallGeometry("plane", point=(0, 0, 0), normal=(0, 0, 1))
    nodes, dl = wall_overlaps(both, pos, rad, *wall_candidates(both, pos, rad, 1e-4))
    assert nodes.tolist() == [0, 1] and dl.tolist() == pytest.approx([0.1e-3, 0.5e-3])
    box = WallGeometry("box", center=(0, 0, -1), axes=np.eye(3), extents=(1, 1, 1))   # top face at z = 0
    out = pos[[0, 2]]                                   # spheres touch a box from outside
    nodes, dl = wall_overlaps(box, out, rad[:2], *wall_candidates(box, out, rad[:2], 1e-4))
    assert nodes.tolist() == [0] and dl[0] == pytest.approx(0.1e-3)
    # a square of two triangles under the spheres: a sphere over their shared edge counts once
    sq = np.array([[[-1, -1, 0], [1, -1, 0], [1, 1, 0]], [[-1, -1, 0], [1, 1, 0], [-1, 1, 0]]], float)
    tris = WallGeometry("triangles", vertices=sq)
    nodes, dl = wall_overlaps(tris, pos, rad, *wall_candidates(tris, pos, rad, 1e-4))
    assert nodes.tolist() == [0, 1] and dl.tolist() == pytest.approx([0.1e-3, 0.5e-3])


def test_plane_contact_radius_and_wall_factors():
    r, dl = 2e-3, 1e-5
    assert plane_contact_radius(r, dl)[()] == pytest.approx(math.sqrt(2 * r * dl - dl ** 2), rel=1e-12)
    assert plane_contact_radius(r, dl, "hertz")[()] == pytest.approx(math.sqrt(r * dl), rel=1e-12)
    assert plane_contact_radius(r, -1.0)[()] == 0.0
    a = math.sqrt(2 * r * dl - dl ** 2)
    assert make_law("contact").wall_factor(np.array([r]), np.array([dl]))[0] == pytest.approx(2 * a)
    assert make_law("liggghts").wall_factor(np.array([r]), np.array([dl]))[0] == pytest.approx(
        2 * math.sqrt(math.pi) * a)
    with pytest.raises(ValueError, match="no sphere-wall contacts"):
        make_law("continuum").wall_factor(np.array([r]), np.array([dl]))


@pytest.mark.parametrize("correction, k", [("hertz", 1 / 3), ("hooke", 1 / 2), ("lethe", 1 / 5)])
def test_softened_stiffness_correction(correction, k):
    r, delta = 1e-3, 1e-6
    g = ContactGraph(np.array([[0, 0, 0], [2 * r - delta, 0, 0]], float), np.array([r, r]), np.array([[0, 1]]))
    plain = make_law("contact", radius="hertz").factor(g)[0]
    soft = make_law("contact", radius="hertz", stiffness_ratio=1e-3, correction=correction).factor(g)[0]
    assert soft / plain == pytest.approx(1e-3 ** k, rel=1e-12)
    with pytest.raises(ValueError, match="stiffness_ratio must be in"):
        make_law("contact", stiffness_ratio=2.0)
    with pytest.raises(ValueError, match="correction must be one of"):
        make_law("liggghts", stiffness_ratio=0.5, correction="jkr")


def _sphere_on_hot_plane(theta, dt, steps, wall_conductivity=None):
    r, k, rho, c = 2e-3, 385.0, 8900.0, 172.0
    g = ContactGraph(np.zeros((1, 3)), [r], np.zeros((0, 2)))
    m = ElectroThermalModel(None, Material(density=rho, specific_heat=c, conductivity=k), 0.0,
                            law=Law("contact", volume_fraction=1.0), integrator=Integrator(theta=theta),
                            boundaries=[ThermalWall("plate", 100.0, wall_conductivity), ThermalWall("lid")])
    dl = 0.1e-3
    m.set_wall_contacts("plate", [0], [dl])
    m.set_wall_contacts("lid", [0], [dl])          # adiabatic: conducts nothing
    for _ in range(steps):
        row = m.step(g, dt)
    a = math.sqrt(2 * r * dl - dl ** 2)
    k_e = k if wall_conductivity is None else 2 * k * wall_conductivity / (k + wall_conductivity)
    tau = rho * c * 4 / 3 * math.pi * r ** 3 / (2 * k_e * a)
    return row, tau


def test_sphere_on_an_isothermal_wall_follows_the_exponential():
    row, tau = _sphere_on_hot_plane("crank-nicolson", 1e-3, 400)
    exact = 100.0 * (1 - math.exp(-row["time"] / tau))
    assert row["T_mean"] == pytest.approx(exact, rel=1e-6)
    # the wall's heat is the heat stored, and it is in boundary_heat
    assert row["wall_heat:plate"] == pytest.approx(row["heat_content"], rel=1e-12)
    assert row["boundary_heat"] == pytest.approx(row["heat_content"], rel=1e-12)
    assert "wall_heat:lid" not in row and row["wall_contacts:plate"] == 1
    # a steel wall under a copper sphere: the harmonic mean of the conductivities
    row, tau = _sphere_on_hot_plane("crank-nicolson", 1e-3, 400, wall_conductivity=50.0)
    assert row["T_mean"] == pytest.approx(100.0 * (1 - math.exp(-row["time"] / tau)), rel=1e-6)


def test_wall_inputs_are_checked():
    with pytest.raises(BoundaryConditionError, match="conductivity must be > 0"):
        ThermalWall("w", 300.0, conductivity=-1.0)
    with pytest.raises(BoundaryConditionError, match="names must be non-empty"):
        ThermalWall("", 300.0)
    with pytest.raises(BoundaryConditionError, match=r"walls \(ThermalWall\) given with law 'continuum'"):
        ElectroThermalModel(None, Material(density=1.0, specific_heat=1.0, conductivity=1.0), 0.0, law=Law("continuum"),
                            boundaries=[ThermalWall("w", 1.0)])
    m = ElectroThermalModel(None, Material(density=1.0, specific_heat=1.0, conductivity=1.0), 0.0, law=Law("contact"),
                            boundaries=[ThermalWall("w", 1.0)])
    with pytest.raises(BoundaryConditionError, match="no wall named"):
        m.set_wall_contacts("x", [0], [1e-6])
    with pytest.raises(ValueError, match="overlaps must be finite"):
        m.set_wall_contacts("w", [0], [-1e-6])


def test_feng_pipe_law():
    from yade_electro.laws.factors import PipeLaw
    r, w, a = 1e-3, 5e-3, 0.2e-3
    d = 2 * math.sqrt(r ** 2 - a ** 2)                    # half chord a
    g = ContactGraph(np.array([[0, 0, 0], [d, 0, 0]], float), np.array([r, r]), np.array([[0, 1]]))
    alpha = math.asin(a / r)
    f = -math.log(alpha) + 1.5 + alpha ** 2 / 36
    assert PipeLaw.pipe_bracket(alpha) == pytest.approx(f, rel=1e-15)
    # two pipes in series, each (f / (pi k)) per unit length, over the width w: G = k pi w / (2 f)
    assert make_law("pipe", width=w).factor(g)[0] == pytest.approx(math.pi * w / (2 * f), rel=1e-9)
    apart = ContactGraph(np.array([[0, 0, 0], [3 * r, 0, 0]], float), np.array([r, r]), np.array([[0, 1]]))
    assert make_law("pipe", width=w).factor(apart)[0] == 0.0
    with pytest.raises(ValueError, match="needs width="):
        make_law("pipe")


def _periodic_brute_force(pos, radius, skin, H):
    """Every (i < j, image) within r_i + r_j + skin, over the images around the nearest one."""
    import itertools
    s = pos @ np.linalg.inv(H).T
    ds = s[None, :, :] - s[:, None, :]
    base = -np.round(ds)
    out = set()
    for k in itertools.product((-1, 0, 1), repeat=3):
        c = base + np.array(k)
        d = (ds + c) @ H.T
        close = np.triu(np.sqrt((d ** 2).sum(-1)) < radius[:, None] + radius[None, :] + skin, 1)
        for a, b in zip(*np.nonzero(close)):
            out.add((int(a), int(b), *c[a, b].astype(int).tolist()))
    return out


@pytest.mark.parametrize("sheared", [False, True])
def test_periodic_candidate_pairs_are_every_close_image(sheared):
    # centres anywhere (YADE does not wrap them): up to 3 cells away from the reference one
    from yade_electro.geometry.contacts import periodic_candidate_pairs
    rng = np.random.default_rng(7 + sheared)
    H = np.diag([0.02, 0.015, 0.018])
    if sheared:
        H = H + np.array([[0, 0.004, 0.001], [0, 0, 0.002], [0, 0, 0]])
    n = 300
    pos = (rng.random((n, 3)) + rng.integers(-3, 4, size=(n, 3))) @ H.T
    radius = rng.uniform(0.0008, 0.0012, n)
    pairs, images = periodic_candidate_pairs(pos, radius, 3e-4, H)
    got = {(int(a), int(b), *c.tolist()) for (a, b), c in zip(pairs, images)}
    assert len(got) == len(pairs) > 300 and got == _periodic_brute_force(pos, radius, 3e-4, H)
    key = pairs[:, 0] * n + pairs[:, 1]
    assert np.all(np.diff(key) > 0)                          # lexicographic, one image per pair
    d = pos[pairs[:, 1]] - pos[pairs[:, 0]] + images @ H.T   # the image is the contact's
    assert np.all(np.linalg.norm(d, axis=1) < radius[pairs[:, 0]] + radius[pairs[:, 1]] + 3e-4)


def test_periodic_cell_too_small_is_refused():
    from yade_electro.geometry.contacts import periodic_candidate_pairs
    from yade_electro.core.errors import GraphError
    pos = np.array([[0.001, 0.001, 0.001], [0.003, 0.001, 0.001]])
    with pytest.raises(GraphError, match="periodic cell is too small"):
        periodic_candidate_pairs(pos, np.full(2, 1e-3), 1e-4, np.eye(3) * 0.004)
    with pytest.raises(GraphError, match="independent base vectors"):
        periodic_candidate_pairs(pos, np.full(2, 1e-3), 1e-4, np.zeros((3, 3)))


def test_periodic_graph_lengths_and_contact_factors():
    # two spheres touching through the cell's face: the shift gives their contact
    from yade_electro.geometry.contacts import periodic_candidate_pairs
    H = np.eye(3) * 0.02
    pos = np.array([[0.0005, 0.01, 0.01], [0.0195 + 0.04, 0.01, 0.01]])    # the second two periods away
    radius = np.array([1e-3, 1e-3])
    pairs, images = periodic_candidate_pairs(pos, radius, 1e-4, H)
    assert pairs.tolist() == [[0, 1]] and images.tolist() == [[-3, 0, 0]]
    g = ContactGraph(pos, radius, pairs, shift=images @ H.T)
    assert g.length == pytest.approx([1e-3], rel=1e-12)
    law = make_law("contact")
    a = math.sqrt(1e-3 ** 2 - 0.5e-3 ** 2)                   # lens of the 1 mm overlap
    assert law.factor(g) == pytest.approx([2 * a], rel=1e-12)


def test_heat_carried_by_particles_closes_the_balance():
    # a chain of four touching copper spheres, heat only, the first hot: then the hot one
    # leaves, one grows, one is added at the reference temperature; the history's
    # particle_heat is the heat each change took or brought, and the balance closes
    r = 1e-3
    C = 8900 * 172 * 4 / 3 * math.pi * r ** 3
    pos = np.array([[i * 1.9e-3, 0, 0] for i in range(4)])
    g = ContactGraph(pos, np.full(4, r), [[0, 1], [1, 2], [2, 3]], ids=[10, 11, 12, 13])
    m = ElectroThermalModel(None, Material(density=8900, specific_heat=172, conductivity=385), 300.0,
                            law=Law("contact", volume_fraction=1.0))
    m.restore_temperatures(lambda graph: np.array([400.0, 300.0, 300.0, 300.0]))
    start = m.refresh(g)["heat_content"]
    for _ in range(5):
        m.step(g, 1e-3)
    T_hot = m.temperature[0]
    g2 = ContactGraph(pos[1:], np.full(3, r), [[0, 1], [1, 2]], ids=[11, 12, 13])
    row = m.step(g2, 1e-3)
    assert row["particle_heat"] == pytest.approx(-C * (T_hot - 300.0), rel=1e-12)
    T_grow = m.temperature[2]
    g3 = ContactGraph(pos[1:], [r, r, 1.2 * r], [[0, 1], [1, 2]], ids=[11, 12, 13])
    row3 = m.step(g3, 1e-3)
    assert row3["particle_heat"] - row["particle_heat"] == pytest.approx(C * (1.2 ** 3 - 1) * (T_grow - 300.0),
                                                                         rel=1e-9)
    g4 = ContactGraph(np.vstack([pos[1:], [[7.6e-3, 0, 0]]]), [r, r, 1.2 * r, r], [[0, 1], [1, 2], [2, 3]],
                      ids=[11, 12, 13, 14])
    row4 = m.step(g4, 1e-3)
    assert row4["particle_heat"] == row3["particle_heat"]        # added at the reference temperature
    assert row4["heat_content"] - start == pytest.approx(row4["particle_heat"], rel=1e-12, abs=1e-15)


def test_candidate_pairs_over_a_wide_size_spread():
    # radii spread over a factor 25 (size classes): the same pairs as the brute force, plain
    # and periodic
    from yade_electro.geometry.contacts import SIZE_CLASS_RATIO, periodic_candidate_pairs
    rng = np.random.default_rng(11)
    n = 500
    rad = np.exp(rng.uniform(np.log(0.2e-3), np.log(5e-3), n))
    assert rad.max() / rad.min() > 10 * SIZE_CLASS_RATIO
    pos = rng.uniform(0, 0.05, (n, 3))
    skin = 0.1e-3
    got = candidate_pairs(pos, rad, skin)
    d = np.linalg.norm(pos[:, None] - pos[None], axis=2)
    i, j = np.nonzero(np.triu(d < rad[:, None] + rad[None] + skin, 1))
    assert len(got) > 200 and np.array_equal(got, np.column_stack([i, j]))
    H = np.diag([0.05, 0.05, 0.05]) + np.array([[0, 0.01, 0], [0, 0, 0], [0, 0, 0]])
    pos = (rng.random((n, 3)) + rng.integers(-2, 3, size=(n, 3))) @ H.T
    pairs, images = periodic_candidate_pairs(pos, rad, skin, H)
    assert {(int(a), int(b), *c.tolist()) for (a, b), c in zip(pairs, images)} == \
        _periodic_brute_force(pos, rad, skin, H)
