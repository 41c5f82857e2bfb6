"""Transmission surfaces, volume fractions, eccentricity (paper 000 eq. 3-5) and the
conductance-law registry, against exact values."""
import numpy as np
import pytest

from yade_electro import ContactGraph, MaterialError, conductance_laws, register_conductance_law
from yade_electro.laws.factors import ConductanceLaw, conductance, contact_radius, unregister_conductance_law
from yade_electro.laws.transmission import (POLYHEDRON_ALPHA, POLYHEDRON_FACES, POLYHEDRON_FV,
                                   eccentricity, eccentricity_factor, edge_transmission_surface,
                                   polyhedron_alpha, polyhedron_volume_fraction,
                                   transmission_surface, volume_fraction)

from lattice import cubic_lattice, lattice_index, node_class

S3 = np.sqrt(3.0)
# exact face areas of the Platonic solids with unit inscribed sphere
ALPHA4, ALPHA6, ALPHA8 = 6.0 * S3, 4.0, 1.5 * S3
# alpha by lattice node class (interior, face, edge, corner), S_i / r^2 in a simple cubic lattice:
# interior n=6 e=0 f=1; face n=5 e=0.4 f=1; edge n=4 e=sqrt2/2 f=2; corner n=3 e=2/sqrt3 f=2
S_BY_CLASS = np.array([ALPHA6, (ALPHA4 + ALPHA6) / 2, ALPHA4 / 2, (1.5 * ALPHA4 - 0.5 * ALPHA6) / 2])


# -- polyhedron table ------------------------------------------------------------------------------
def test_polyhedron_table_values():
    assert POLYHEDRON_FACES.tolist() == [4, 6, 8, 12, 20]
    np.testing.assert_allclose(POLYHEDRON_ALPHA, [10.392, 4.000, 2.598, 1.388, 0.758], atol=5e-4)
    np.testing.assert_allclose(POLYHEDRON_FV, [0.302, 0.524, 0.605, 0.755, 0.829], atol=1.5e-3)
    # exact values where they are simple
    np.testing.assert_allclose(POLYHEDRON_ALPHA[:3], [ALPHA4, ALPHA6, ALPHA8], rtol=1e-14)
    np.testing.assert_allclose(POLYHEDRON_FV[:3], [np.pi / (6 * S3), np.pi / 6, np.pi / (3 * S3)], rtol=1e-14)
    # fv = sphere volume / polyhedron volume, polyhedron volume = n alpha / 3 for unit inradius
    np.testing.assert_allclose(POLYHEDRON_FV, (4 * np.pi / 3) / (POLYHEDRON_FACES * POLYHEDRON_ALPHA / 3),
                               rtol=1e-14)
    # the tabulated arrays cannot be changed by accident
    with pytest.raises(ValueError):
        POLYHEDRON_ALPHA[0] = 1.0


def test_alpha_and_fv_at_the_table_points():
    np.testing.assert_allclose(polyhedron_alpha(POLYHEDRON_FACES), POLYHEDRON_ALPHA, rtol=1e-15)
    np.testing.assert_allclose(polyhedron_volume_fraction(POLYHEDRON_FACES), POLYHEDRON_FV, rtol=1e-15)


def test_alpha_interpolation_and_extrapolation():
    a = POLYHEDRON_ALPHA
    np.testing.assert_allclose(polyhedron_alpha([5, 7, 10]),
                               [(a[0] + a[1]) / 2, (a[1] + a[2]) / 2, (a[2] + a[3]) / 2], rtol=1e-14)
    assert polyhedron_alpha(5) == pytest.approx(3 * S3 + 2, rel=1e-14)         # 7.196
    assert polyhedron_alpha(7) == pytest.approx(2 + 0.75 * S3, rel=1e-14)      # 3.299
    assert polyhedron_alpha(16) == pytest.approx((a[3] + a[4]) / 2, rel=1e-14)
    # below 4: linear with the 4-6 slope; the paper's alpha(3) = 13.59
    assert polyhedron_alpha(3) == pytest.approx(9 * S3 - 2, rel=1e-14)
    assert round(float(polyhedron_alpha(3)), 2) == 13.59
    assert polyhedron_alpha(1) == pytest.approx(15 * S3 - 6, rel=1e-14)        # 19.98
    # above 20: held
    assert polyhedron_alpha(30) == pytest.approx(a[4], rel=1e-15)
    # float n (mean degrees) and arrays keep their shape
    assert polyhedron_alpha(np.array([[4.5]])).shape == (1, 1)
    assert polyhedron_alpha(4.5) == pytest.approx(a[0] * 0.75 + a[1] * 0.25, rel=1e-14)


def test_volume_fraction_interpolation_and_extrapolation():
    f = POLYHEDRON_FV
    np.testing.assert_allclose(polyhedron_volume_fraction([5, 7, 10]),
                               [(f[0] + f[1]) / 2, (f[1] + f[2]) / 2, (f[2] + f[3]) / 2], rtol=1e-14)
    fv3 = 1.5 * f[0] - 0.5 * f[1]
    assert fv3 == pytest.approx(0.1917, abs=1e-4)
    np.testing.assert_allclose(polyhedron_volume_fraction([3, 2, 1, 0]), fv3, rtol=1e-14)  # held below 3
    assert polyhedron_volume_fraction(25) == pytest.approx(f[4], rel=1e-15)


# -- eccentricity -------------------------------------------------------------------------------
def test_eccentricity_factor_is_strict_with_tolerance():
    e = np.array([0.0, 0.39, 0.4, 0.4 * (1 + 1e-12), 0.4 * (1 - 1e-12), 0.4 * (1 + 1e-6), 0.41, 3.0])
    np.testing.assert_array_equal(eccentricity_factor(e), [1, 1, 1, 1, 1, 2, 2, 2])
    np.testing.assert_array_equal(eccentricity_factor([0.2, 0.6], threshold=0.5, factor=3.0), [1, 3])


def test_eccentricity_of_simple_shapes():
    # node 0 with one neighbour at distance d: e = d / r
    g = ContactGraph([[0, 0, 0], [2, 0, 0]], [1.0, 0.5], [[0, 1]])
    np.testing.assert_allclose(eccentricity(g), [2.0, 4.0], rtol=1e-15)
    # symmetric neighbours: e = 0; isolated node: e = 0
    g = ContactGraph([[0, 0, 0], [1, 0, 0], [-1, 0, 0], [5, 5, 5]], [1.0] * 4, [[0, 1], [0, 2]])
    np.testing.assert_allclose(eccentricity(g), [0.0, 1.0, 1.0, 0.0], atol=1e-15)


@pytest.mark.parametrize("r, origin", [(1.0, (0, 0, 0)), (0.37e-3, (0.123e-3, -4.56e-3, 7.89e-3)),
                                       (0.1, (1e3, 0, 0))])
def test_lattice_eccentricity_and_surfaces_by_class(r, origin):
    """Simple cubic lattice, every element a touching sphere bonded to its nearest neighbours:

    - interior: 6 neighbours, e = 0, f = 1, S = alpha(6) r^2 = 4 r^2;
    - face: 5 neighbours, barycentre 2r/5 inwards, e = 0.4 exactly -> f = 1 (strict
      inequality, with a relative tolerance against the rounding of the coordinates), so
      S = alpha(5) r^2 = 7.196 r^2 (larger than the interior: the face element has lost a bond);
    - edge: 4 neighbours, e = sqrt(2)/2 = 0.707 -> f = 2, S = alpha(4)/2 r^2 = 5.196 r^2;
    - corner: 3 neighbours, e = 2/sqrt(3) = 1.155 -> f = 2, S = alpha(3)/2 r^2 = 6.794 r^2.
    """
    shape = (4, 5, 3)
    g = cubic_lattice(shape, r=r, origin=origin)
    cls = node_class(shape)
    e = eccentricity(g)
    np.testing.assert_allclose(e, np.array([0.0, 0.4, np.sqrt(0.5), 2 / S3])[cls], rtol=1e-9, atol=1e-9)
    np.testing.assert_array_equal(eccentricity_factor(e), np.array([1, 1, 2, 2])[cls])
    s = transmission_surface(g)
    np.testing.assert_allclose(s, S_BY_CLASS[cls] * r ** 2, rtol=1e-12)
    np.testing.assert_allclose(S_BY_CLASS, [4.000, 7.196, 5.196, 6.794], atol=5e-4)
    fv = volume_fraction(g)
    fv_by_class = [np.pi / 6, (POLYHEDRON_FV[0] + POLYHEDRON_FV[1]) / 2, 2 * POLYHEDRON_FV[0],
                   2 * (1.5 * POLYHEDRON_FV[0] - 0.5 * POLYHEDRON_FV[1])]
    np.testing.assert_allclose(fv, np.array(fv_by_class)[cls], rtol=1e-12)
    # edge surface: geometric mean of the two end nodes'
    i, j = g.edges.T
    np.testing.assert_allclose(edge_transmission_surface(g), np.sqrt(s[i] * s[j]), rtol=1e-15)
    np.testing.assert_allclose(edge_transmission_surface(g, node_surface=s), np.sqrt(s[i] * s[j]), rtol=1e-15)


def test_threshold_and_factor_are_parameters():
    g = cubic_lattice((3, 3, 3), r=1.0)
    face = lattice_index(1, 1, 0, (3, 3, 3))
    # with threshold 0.3 the face elements (e = 0.4) become eccentric
    assert transmission_surface(g, threshold=0.3)[face] == pytest.approx((3 * S3 + 2) / 2, rel=1e-14)
    assert transmission_surface(g, factor=4.0)[0] == pytest.approx(polyhedron_alpha(3) / 4, rel=1e-14)


# -- conductance laws ------------------------------------------------------------------------------
def test_registry_lists_the_laws():
    assert {"continuum", "contact", "liggghts"} <= set(conductance_laws())
    assert list(conductance_laws()) == sorted(conductance_laws())


def test_continuum_conductance_on_lattice():
    r, rho = 0.5e-3, 0.73e-6
    shape = (3, 3, 4)
    g = cubic_lattice(shape, r=r)
    c = conductance(g, rho)
    s = transmission_surface(g)
    i, j = g.edges.T
    np.testing.assert_allclose(c, np.sqrt(s[i] * s[j]) / (rho * 2 * r), rtol=1e-14)
    # the central node (1, 1, 1..2) is interior: its bond to (1, 1, 2) has S = 4 r^2, c = 2 r / rho
    k = np.flatnonzero((i == lattice_index(1, 1, 1, shape)) & (j == lattice_index(1, 1, 2, shape)))
    assert c[k[0]] == pytest.approx(4 * r ** 2 / (rho * 2 * r), rel=1e-14)
    # per-node resistivity: an edge is two half-rods in series, rho_ij = (rho_i + rho_j)/2
    rho_n = np.linspace(1e-6, 3e-6, g.n_nodes)
    np.testing.assert_allclose(conductance(g, rho_n), np.sqrt(s[i] * s[j]) / ((rho_n[i] + rho_n[j]) / 2 * 2 * r),
                               rtol=1e-14)
    # law parameters are passed through
    np.testing.assert_allclose(conductance(g, rho, threshold=10.0),
                               edge_transmission_surface(g, threshold=10.0) / (rho * 2 * r), rtol=1e-14)


def test_contact_and_liggghts_laws_exact():
    # equal spheres r = 1 at d = 1.5: a^2 = 1 - 0.75^2; r = 2 and 1 at d = 2.5: a^2 = 4 - 1.85^2
    # (= 1 - 0.65^2 from the other sphere); touching-only and separated pairs: a = 0
    pos = [[0, 0, 0], [1.5, 0, 0], [10, 0, 0], [12.5, 0, 0], [20, 0, 0], [22, 0, 0], [30, 0, 0], [33, 0, 0]]
    rad = [1, 1, 2, 1, 1, 1, 1, 1]
    g = ContactGraph(pos, rad, [[0, 1], [2, 3], [4, 5], [6, 7]])
    a = np.array([np.sqrt(0.4375), np.sqrt(4 - 1.85 ** 2), 0.0, 0.0])
    np.testing.assert_allclose(contact_radius(g), a, rtol=1e-14, atol=1e-15)
    rho = 2.0
    np.testing.assert_allclose(conductance(g, rho, "contact"), 2 * a / rho, rtol=1e-14)
    np.testing.assert_allclose(conductance(g, rho, "liggghts"), 2 * np.sqrt(np.pi) * a / rho, rtol=1e-14)
    # liggghts with two materials: 4 k1 k2 / (k1 + k2) sqrt(pi) a
    rho_n = np.array([1.0, 3.0] + [1.0] * 6)
    k1, k2 = 1.0, 1.0 / 3.0
    assert conductance(g, rho_n, "liggghts")[0] == pytest.approx(4 * k1 * k2 / (k1 + k2) * np.sqrt(np.pi) * a[0],
                                                                   rel=1e-14)


def test_unknown_law_lists_the_known_ones():
    g = cubic_lattice((2, 2, 2))
    with pytest.raises(KeyError) as exc:
        conductance(g, 1.0, "ohmic")
    msg = str(exc.value)
    assert "unknown conductance law 'ohmic'" in msg
    for name in ("continuum", "contact", "liggghts"):
        assert name in msg


def test_register_a_law_and_refuse_a_duplicate_name():
    name = "test-constant"
    try:
        @register_conductance_law(name)
        class Constant(ConductanceLaw):
            def __init__(self, value=1.0):
                self.value = value

            def factor(self, graph, edges=None):
                return np.full(len(self._edges(graph, edges)), self.value)
        constant = Constant
        assert name in conductance_laws()
        g = cubic_lattice((2, 2, 2))
        np.testing.assert_array_equal(conductance(g, 2.0, name, value=3.0), np.full(12, 1.5))
        with pytest.raises(ValueError, match="already registered"):
            register_conductance_law(name)(constant)
        with pytest.raises(ValueError, match="already registered"):
            register_conductance_law("continuum")(constant)
    finally:
        unregister_conductance_law(name)


def test_a_law_returning_negative_values_is_refused():
    name = "test-negative"

    class Negative(ConductanceLaw):
        def factor(self, graph, edges=None):
            return -np.ones(len(self._edges(graph, edges)))
    try:
        register_conductance_law(name)(Negative)
        with pytest.raises(MaterialError, match="non-finite or negative"):
            conductance(cubic_lattice((2, 2, 2)), 1.0, name)
    finally:
        unregister_conductance_law(name)


@pytest.mark.parametrize("rho", [0.0, -1e-6, np.nan, np.inf, -np.inf])
def test_bad_resistivity_is_a_material_error(rho):
    g = cubic_lattice((2, 2, 2))
    with pytest.raises(MaterialError, match="resistivity must be finite and > 0"):
        conductance(g, rho)
    rho_n = np.ones(g.n_nodes)
    rho_n[3] = rho
    with pytest.raises(MaterialError, match="resistivity must be finite and > 0"):
        conductance(g, rho_n, "contact")


def test_resistivity_of_the_wrong_shape_is_a_material_error():
    g = cubic_lattice((2, 2, 2))
    with pytest.raises(MaterialError, match=r"one value per element \(8\)"):
        conductance(g, np.ones(7))
    with pytest.raises(MaterialError, match="scalar or one value per element"):
        conductance(g, np.ones((8, 1)))


def test_coincident_bonded_centres_are_a_material_error():
    g = ContactGraph([[0, 0, 0], [0, 0, 0]], [1.0, 1.0], [[0, 1]])
    with pytest.raises(MaterialError, match="coincident centres"):
        conductance(g, 1.0)


def test_compiled_continuum_factors_are_the_numpy_ones():
    """The continuum law's factors by native/continuum_factors.cpp against the numpy form: a
    simple-cubic lattice (the face nodes' eccentricity is exactly the threshold 0.4, so f
    must agree there too) and a jittered random bond graph, g the same to 1e-13 relative and
    the same eccentricity factors; coincident centres a MaterialError either way."""
    import reference_kernels as ref
    from yade_electro.laws.factors import make_law
    law = make_law("continuum")
    rng = np.random.default_rng(5)
    lat = cubic_lattice((6, 5, 7), r=1e-3)
    pos = rng.uniform(0, 0.01, (600, 3))
    edges = np.array([(i, j) for i in range(600) for j in range(i + 1, 600)
                      if np.linalg.norm(pos[i] - pos[j]) < 1.6e-3])
    cloud = ContactGraph(pos, rng.uniform(0.5e-3, 0.8e-3, 600), edges)
    for g in (lat, cloud, lat.with_positions(lat.pos + rng.normal(0, 1e-5, lat.pos.shape))):
        fast = law.factor(g)
        slow = ref.continuum_factor(g)
        assert np.allclose(fast, slow, rtol=1e-13, atol=0) and np.all(slow > 0)
        # the package's numpy path (a periodic graph's bonds) is the same form
        assert np.allclose(law.periodic_factor(g, g.edges), slow, rtol=1e-15, atol=0)
    # both kinds of eccentricity factor occur in the cloud and the lattice
    assert len(set(np.round(eccentricity_factor(eccentricity(cloud)), 6))) == 2
    same = ContactGraph([[0, 0, 0], [0, 0, 0]], [1.0, 1.0], [[0, 1]])
    with pytest.raises(MaterialError, match="coincident"):
        law.factor(same)
    with pytest.raises(MaterialError, match="coincident"):
        law.factor(ContactGraph([[0, 0, 0], [0, 0, 0]], [1.0, 1.0], [[0, 1]], shift=np.zeros((1, 3))))
