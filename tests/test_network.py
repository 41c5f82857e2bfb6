"""Kirchhoff solve: exact answers on small networks and lattices, conservation, symmetry,
agreement of the solvers, re-use of the setup, and bad input.

Sign conventions under test (yade_electro.network.conduction):
* ``branch_current[k]`` flows from ``edges[k, 0]`` to ``edges[k, 1]``: w = c (u_i - u_j);
* ``electrode_current[name]`` is fed *into* the network by the external circuit;
* R_eq(a, b) = (V_a - V_b) / I_a.
"""
import warnings

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.sparse.csgraph import connected_components
from scipy.spatial import cKDTree

from yade_electro import (BoundaryConditionError, ContactGraph, Electrode, MaterialError, SolverError,
                          equivalent_resistance, laplacian, make_solver, solve_potential)
from yade_electro.laws.factors import conductance
from yade_electro.network.conduction import ConductionProblem
from yade_electro.solvers.cg import CGSolver
from yade_electro.solvers.base import DirectSolver
from yade_electro.solvers.registry import solver_names

from lattice import cubic_lattice, lattice_index, node_class

try:
    import pyamg  # noqa: F401
    HAVE_PYAMG = True
except ImportError:
    HAVE_PYAMG = False

SOLVERS = ["cg", "cg-deflated", pytest.param("cg-amg", marks=pytest.mark.skipif(not HAVE_PYAMG, reason="pyamg not installed")),
           "direct"]
S3 = np.sqrt(3.0)


def dense_solve(n, edges, c, fixed):
    """Reference: dense numpy solve of K u = 0 on the free nodes with u given on ``fixed``
    (dict node -> V). Returns (u, net current leaving each node into the bonds)."""
    K = np.zeros((n, n))
    for (i, j), ck in zip(edges, c):
        K[i, i] += ck
        K[j, j] += ck
        K[i, j] -= ck
        K[j, i] -= ck
    d = np.array(sorted(fixed))
    f = np.setdiff1d(np.arange(n), d)
    u = np.zeros(n)
    u[d] = [fixed[k] for k in d]
    u[f] = np.linalg.solve(K[np.ix_(f, f)], -K[np.ix_(f, d)] @ u[d])
    return u, K @ u


def two_electrodes(a, b, va=1.0, vb=0.0):
    return [Electrode("a", a, potential=va), Electrode("b", b, potential=vb)]


# -- assembly ---------------------------------------------------------------------------------
def test_laplacian_exact():
    K = laplacian([[0, 1], [1, 2], [0, 2]], [1.0, 2.0, 4.0], 4).toarray()
    np.testing.assert_array_equal(K, [[5, -1, -4, 0], [-1, 3, -2, 0], [-4, -2, 6, 0], [0, 0, 0, 0]])
    g = cubic_lattice((3, 4, 2))
    c = np.arange(1.0, g.n_edges + 1)
    K = laplacian(g.edges, c, g.n_nodes)
    A = g.incidence
    np.testing.assert_allclose(K.toarray(), (A.T @ sp.diags(c) @ A).toarray(), rtol=0, atol=1e-12)
    np.testing.assert_allclose(K.sum(axis=1), 0, atol=1e-12)
    with pytest.raises(ValueError, match="one value per edge"):
        laplacian([[0, 1]], [1.0, 2.0], 2)


# -- series and parallel ------------------------------------------------------------------------
@pytest.mark.parametrize("solver", SOLVERS)
def test_series_resistors(solver):
    # 0 --R1-- 1 --R2-- 2 --R3-- 3, V(0) = 10 V, V(3) = 0; edges given in mixed directions
    R = np.array([2.0, 3.0, 5.0])
    edges = [[1, 0], [1, 2], [3, 2]]
    sol = solve_potential(4, edges, 1.0 / R, two_electrodes([0], [3], 10.0, 0.0), solver=solver)
    I = 10.0 / R.sum()                                   # 1 A flowing 0 -> 1 -> 2 -> 3
    np.testing.assert_allclose(sol.potential, [10.0, 10.0 - 2.0 * I, 5.0 * I, 0.0], rtol=1e-10, atol=1e-12)
    # branch current flows from edges[k, 0] to edges[k, 1]: edge (1, 0) carries -I
    np.testing.assert_allclose(sol.branch_current, [-I, I, -I], rtol=1e-10)
    assert sol.electrode_current["a"] == pytest.approx(I, rel=1e-10)      # fed in at the + electrode
    assert sol.electrode_current["b"] == pytest.approx(-I, rel=1e-10)
    assert sol.electrode_potential == {"a": 10.0, "b": 0.0}
    assert sol.equivalent_resistance("a", "b") == pytest.approx(10.0, rel=1e-10)
    assert sol.equivalent_resistance("b", "a") == pytest.approx(10.0, rel=1e-10)
    assert not sol.floating.any()
    # Joule power w^2 / c = R I^2 per edge, total V I
    np.testing.assert_allclose(sol.joule_power(1.0 / R), R * I ** 2, rtol=1e-10)


@pytest.mark.parametrize("solver", SOLVERS)
def test_parallel_resistors_between_multi_node_electrodes(solver):
    # electrode a = nodes {0, 1, 2} (tied by a perfect conductor), b = {3}:
    # three resistors 0-3, 1-3, 2-3 in parallel, plus two series pairs 0-4-3 and 2-5-3
    edges = [[0, 3], [1, 3], [2, 3], [0, 4], [4, 3], [5, 2], [5, 3]]
    R = np.array([2.0, 4.0, 8.0, 1.0, 3.0, 6.0, 2.0])
    sol = solve_potential(6, edges, 1.0 / R, two_electrodes([0, 1, 2], [3], 2.0, 0.0), solver=solver)
    G = 1 / 2 + 1 / 4 + 1 / 8 + 1 / (1 + 3) + 1 / (6 + 2)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(1 / G, rel=1e-10)
    assert sol.electrode_current["a"] == pytest.approx(2.0 * G, rel=1e-10)
    # divider nodes: u4 = 2 V * 3 / (1 + 3), u5 = 2 V * 2 / (6 + 2)
    np.testing.assert_allclose(sol.potential, [2, 2, 2, 0, 1.5, 0.5], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(sol.branch_current, [1.0, 0.5, 0.25, 0.5, 0.5, -0.25, 0.25], rtol=1e-10)


@pytest.mark.parametrize("solver", SOLVERS)
def test_node_injection_between_two_grounds(solver):
    # 0 --R1-- 1 --R2-- 2, both ends grounded, I injected at node 1
    R1, R2, I = 2.0, 6.0, 0.5
    f = np.array([0.0, I, 0.0])
    sol = solve_potential(3, [[0, 1], [1, 2]], [1 / R1, 1 / R2], two_electrodes([0], [2], 0.0, 0.0),
                          injection=f, solver=solver)
    u1 = I * R1 * R2 / (R1 + R2)
    np.testing.assert_allclose(sol.potential, [0, u1, 0], atol=1e-12)
    np.testing.assert_allclose(sol.branch_current, [-u1 / R1, u1 / R2], rtol=1e-10)
    # the current leaves the network at both grounds: fed-in currents are negative
    assert sol.electrode_current["a"] == pytest.approx(-u1 / R1, rel=1e-10)
    assert sol.electrode_current["b"] == pytest.approx(-u1 / R2, rel=1e-10)
    assert sol.current_imbalance < 1e-12


# -- bridge and irregular network vs a dense solve ------------------------------------------------
BRIDGE_EDGES = [[0, 1], [0, 2], [1, 3], [2, 3], [1, 2]]


@pytest.mark.parametrize("solver", SOLVERS)
def test_wheatstone_bridge_against_dense_solve(solver):
    R = np.array([1.0, 2.0, 3.0, 4.0, 5.0])
    sol = solve_potential(4, BRIDGE_EDGES, 1 / R, two_electrodes([0], [3]), solver=solver)
    u, net = dense_solve(4, BRIDGE_EDGES, 1 / R, {0: 1.0, 3: 0.0})
    np.testing.assert_allclose(sol.potential, u, rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(sol.branch_current, [(u[i] - u[j]) / Rk for (i, j), Rk in zip(BRIDGE_EDGES, R)],
                               rtol=1e-10)
    assert sol.electrode_current["a"] == pytest.approx(net[0], rel=1e-10)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(1.0 / net[0], rel=1e-10)
    # closed form of the bridge (R1 = A-C, R2 = A-D, R3 = C-B, R4 = D-B, R5 = C-D):
    # R_eq = [R1 R2 (R3+R4) + R3 R4 (R1+R2) + R5 (R1+R3)(R2+R4)] / [(R1+R2)(R3+R4) + R5 (R1+R2+R3+R4)]
    #      = (14 + 36 + 120) / (21 + 50) = 170/71
    assert sol.equivalent_resistance("a", "b") == pytest.approx(170.0 / 71.0, rel=1e-10)


def test_balanced_bridge_carries_no_current_in_the_middle():
    R = np.array([1.0, 2.0, 3.0, 6.0, 5.0])          # R1/R3 = R2/R4
    sol = solve_potential(4, BRIDGE_EDGES, 1 / R, two_electrodes([0], [3]), solver="direct")
    assert abs(sol.branch_current[4]) < 1e-15
    assert sol.potential[1] == pytest.approx(sol.potential[2], abs=1e-15)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(4.0 * 8.0 / 12.0, rel=1e-14)


@pytest.mark.parametrize("solver", SOLVERS)
def test_irregular_network_three_electrodes_against_dense_solve(solver):
    rng = np.random.default_rng(7)
    n = 40
    chain = np.stack([np.arange(n - 1), np.arange(1, n)], axis=1)
    extra = rng.integers(0, n, size=(60, 2))
    extra = extra[extra[:, 0] != extra[:, 1]]
    edges = np.unique(np.sort(np.concatenate([chain, extra]), axis=1), axis=0)
    c = 10.0 ** rng.uniform(-2, 2, size=len(edges))
    els = [Electrode("hi", [3, 17, 22], potential=1.5), Electrode("lo", [0, 39], potential=-0.5),
           Electrode("mid", [30], potential=0.2)]
    sol = solve_potential(n, edges, c, els, solver=solver)
    fixed = {k: e.potential for e in els for k in e.nodes}
    u, net = dense_solve(n, edges, c, fixed)
    np.testing.assert_allclose(sol.potential, u, rtol=0, atol=1e-9)
    np.testing.assert_allclose(sol.branch_current, c * (u[edges[:, 0]] - u[edges[:, 1]]),
                               rtol=0, atol=1e-8 * np.abs(net).max())
    for e in els:
        assert sol.electrode_current[e.name] == pytest.approx(net[e.nodes].sum(), rel=1e-8)
    assert abs(sum(sol.electrode_current.values())) < 1e-9 * np.abs(net).max()


# -- simple cubic lattice rods --------------------------------------------------------------------
def test_lattice_rod_2x2_closed_form():
    """A 2 x 2 x L rod with electrodes on the end layers: all four columns are alike (no lateral
    current), every middle element has 4 neighbours, e = sqrt2/2 -> f = 2, S_m = alpha(4)/2 r^2
    = 3 sqrt3 r^2; the end elements have 3 neighbours, e = 2/sqrt3 -> f = 2, S_e = alpha(3)/2 r^2
    = (9 sqrt3 - 2)/2 r^2. One column: 2 end bonds of S = sqrt(S_e S_m) and L-3 bonds of S_m,
    each of length 2r:  R_eq = rho 2r (2 / sqrt(S_e S_m) + (L - 3) / S_m) / 4."""
    r, rho, L = 0.5e-3, 0.73e-6, 9
    shape = (2, 2, L)
    g = cubic_lattice(shape, r=r)
    c = conductance(g, rho)
    S_m, S_e = 3 * S3 * r ** 2, (9 * S3 - 2) / 2 * r ** 2
    R_theory = rho * 2 * r * (2 / np.sqrt(S_e * S_m) + (L - 3) / S_m) / 4
    a, b = np.arange(4), g.n_nodes - 4 + np.arange(4)
    for solver in ("direct", "cg"):
        sol = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver=solver)
        assert sol.equivalent_resistance("a", "b") == pytest.approx(R_theory, rel=1e-10)
        # every layer is at one potential: lateral bonds carry no current
        layer_u = sol.potential.reshape(L, 4)
        np.testing.assert_allclose(layer_u - layer_u[:, :1], 0, atol=1e-10)
        lateral = g.pos[g.edges[:, 0], 2] == g.pos[g.edges[:, 1], 2]
        assert np.abs(sol.branch_current[lateral]).max() < 1e-10 * sol.electrode_current["a"]


def test_lattice_rod_interior_conductivity_is_exactly_one_over_rho():
    """Rod 5 x 5 x 14 of touching spheres, r = 0.4 mm, electrodes on the end layers.

    Interior elements have 6 neighbours and alpha(6) = 4, so S_i = 4 r^2 and an interior bond
    along the rod has conductance 4 r^2 / (rho 2 r): the local conductivity current * l /
    (S dV) of the interior chains is exactly 1/rho. The surface elements do not have S = 4 r^2
    (face: 5 neighbours, e = 0.4 exactly, f = 1, S = alpha(5) r^2 = 7.196 r^2; edge: 4
    neighbours, e = 0.707, f = 2, S = 5.196 r^2; corner: 3, e = 1.155, f = 2, S = 6.794 r^2),
    so the outer chains conduct more per element than the interior and the potential is not
    uniform over a cross-section: there is no exact closed form for this rod, and R_eq is
    checked against a dense solve instead.
    """
    r, rho = 0.4e-3, 0.73e-6
    shape = (5, 5, 14)
    nx, ny, nz = shape
    g = cubic_lattice(shape, r=r)
    c = conductance(g, rho)
    layer = nx * ny
    a, b = np.arange(layer), g.n_nodes - layer + np.arange(layer)
    sol = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver="direct")
    u = sol.potential
    # interior chains (i, j both interior), bond between the two middle layers
    k = nz // 2 - 1
    i, j = np.meshgrid(np.arange(1, nx - 1), np.arange(1, ny - 1), indexing="ij")
    lo, hi = lattice_index(i.ravel(), j.ravel(), k, shape), lattice_index(i.ravel(), j.ravel(), k + 1, shape)
    edge_of = {(int(p), int(q)): e for e, (p, q) in enumerate(g.edges)}
    ks = np.array([edge_of[(int(p), int(q))] for p, q in zip(lo, hi)])
    w, dv = sol.branch_current[ks], u[lo] - u[hi]
    assert np.all(w > 0) and np.all(dv > 0)                   # current flows from a (1 V) to b
    np.testing.assert_allclose(w * (2 * r) / (4 * r ** 2 * dv), 1.0 / rho, rtol=1e-10)
    # every bond across the middle section together carries the electrode current
    zi, zj = g.pos[g.edges[:, 0], 2], g.pos[g.edges[:, 1], 2]
    across = np.isclose(zi, 2 * r * k) & np.isclose(zj, 2 * r * (k + 1))
    assert across.sum() == layer
    assert sol.branch_current[across].sum() == pytest.approx(sol.electrode_current["a"], rel=1e-10)
    # the outer chains (larger S) carry more current than the interior ones
    assert sol.branch_current[across][node_class(shape)[g.edges[across, 0]] == 0].max() < \
        sol.branch_current[across].max()
    # R_eq against the dense solve of the same network
    ud, net = dense_solve(g.n_nodes, g.edges, c, {**{int(p): 1.0 for p in a}, **{int(p): 0.0 for p in b}})
    np.testing.assert_allclose(u, ud, rtol=0, atol=1e-12)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(1.0 / net[a].sum(), rel=1e-10)
    # and it is below the resistance of a prism of 4 r^2 per element (surface S > 4 r^2)
    R_prism = rho * (2 * r * (nz - 1)) / (layer * 4 * r ** 2)
    assert 0.6 * R_prism < sol.equivalent_resistance("a", "b") < R_prism


# -- a random geometric graph: conservation, symmetry, solver agreement --------------------------
@pytest.fixture(scope="module")
def random_network():
    """2,000 random points in a unit box, bonds between points closer than 0.12 (largest
    connected part kept), continuum conductances with r = 0.04 and rho = 1 ohm m;
    electrode 'a' = points with x < 0.1, 'b' = points with x > 0.9."""
    rng = np.random.default_rng(12345)
    pts = rng.random((2000, 3))
    pairs = cKDTree(pts).query_pairs(0.12, output_type="ndarray")
    n = len(pts)
    adj = sp.coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), shape=(n, n))
    ncomp, label = connected_components(adj, directed=False)
    keep = label == np.argmax(np.bincount(label))
    new = np.cumsum(keep) - 1
    pairs = pairs[keep[pairs[:, 0]] & keep[pairs[:, 1]]]
    g = ContactGraph(pts[keep], np.full(keep.sum(), 0.04), new[pairs])
    c = conductance(g, 1.0)
    a = np.flatnonzero(g.pos[:, 0] < 0.1)
    b = np.flatnonzero(g.pos[:, 0] > 0.9)
    ref = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver="direct")
    return g, c, a, b, ref


@pytest.mark.parametrize("solver", SOLVERS)
def test_current_conservation(random_network, solver):
    g, c, a, b, _ = random_network
    sol = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver=solver)
    I = sol.electrode_current["a"]
    assert I > 0
    assert abs(sol.electrode_current["a"] + sol.electrode_current["b"]) <= 1e-9 * I
    assert sol.current_imbalance <= 1e-9
    # Kirchhoff's current law at every node outside the electrodes
    net = laplacian(g.edges, c, g.n_nodes) @ sol.potential
    free = np.setdiff1d(np.arange(g.n_nodes), np.concatenate([a, b]))
    assert np.abs(net[free]).max() <= 1e-9 * I
    # the electrode current is the sum of the branch currents leaving its nodes
    w = sol.branch_current
    out_a = w[np.isin(g.edges[:, 0], a)].sum() - w[np.isin(g.edges[:, 1], a)].sum()
    assert out_a == pytest.approx(I, rel=1e-9)
    # the residual is below the solver's tolerance
    tol = 1e-10 if solver.startswith("cg") else 1e-12
    assert sol.residual <= tol
    assert sol.info["n_unknowns"] == g.n_nodes - len(a) - len(b)
    assert np.all(np.isfinite(sol.potential)) and not sol.floating.any()
    assert np.all((sol.potential >= -1e-9) & (sol.potential <= 1 + 1e-9))   # maximum principle


@pytest.mark.parametrize("solver", SOLVERS)
def test_solvers_agree(random_network, solver):
    g, c, a, b, ref = random_network
    sol = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver=solver)
    assert np.abs(sol.potential - ref.potential).max() <= 1e-8
    assert np.abs(sol.branch_current - ref.branch_current).max() <= 1e-8 * np.abs(ref.branch_current).max()
    assert sol.equivalent_resistance("a", "b") == pytest.approx(ref.equivalent_resistance("a", "b"), rel=1e-8)
    assert sol.info["solver"] == solver


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_swapping_the_electrodes(random_network, solver):
    g, c, a, b, ref = random_network
    tol = 1e-8 if solver == "cg" else 1e-12          # ref is the direct solve
    swapped = solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b, 0.0, 1.0), solver=solver)
    np.testing.assert_allclose(swapped.potential, 1.0 - ref.potential, rtol=0, atol=tol)
    np.testing.assert_allclose(swapped.branch_current, -ref.branch_current, rtol=0,
                               atol=tol * np.abs(ref.branch_current).max())
    assert swapped.equivalent_resistance("b", "a") == pytest.approx(ref.equivalent_resistance("a", "b"), rel=1e-9)
    # the same with the names exchanged as well
    renamed = solve_potential(g.n_nodes, g.edges, c, two_electrodes(b, a), solver=solver)
    assert renamed.equivalent_resistance("a", "b") == pytest.approx(ref.equivalent_resistance("a", "b"), rel=1e-9)
    assert renamed.electrode_current["a"] == pytest.approx(ref.electrode_current["a"], rel=1e-9)


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_imposed_current_gives_v_equal_i_r(random_network, solver):
    g, c, a, b, ref = random_network
    R = ref.equivalent_resistance("a", "b")
    I = 2.5e-3
    els = [Electrode("a", a, current=I), Electrode("b", b, potential=0.0)]
    sol = solve_potential(g.n_nodes, g.edges, c, els, solver=solver)
    assert sol.electrode_potential["a"] == pytest.approx(I * R, rel=1e-9)
    assert sol.electrode_current["a"] == I
    assert sol.electrode_current["b"] == pytest.approx(-I, rel=1e-9)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(R, rel=1e-9)
    # all nodes of the current electrode share its potential; the field is the scaled 1 V one
    np.testing.assert_array_equal(sol.potential[a], sol.electrode_potential["a"])
    np.testing.assert_allclose(sol.potential, I * R * ref.potential, rtol=0, atol=1e-9 * I * R)
    # a grounded electrode at another potential just shifts everything
    els = [Electrode("a", a, current=I), Electrode("b", b, potential=0.5)]
    sol = solve_potential(g.n_nodes, g.edges, c, els, solver=solver)
    assert sol.electrode_potential["a"] == pytest.approx(0.5 + I * R, rel=1e-9)


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_resolve_reuses_the_setup(random_network, solver):
    g, c, a, b, ref = random_network
    problem = ConductionProblem(g.n_nodes, g.edges, c, two_electrodes(a, b), solver=solver)
    s1 = problem.solve()
    solves, setups = problem.basis_solves, problem.solver.n_setups
    assert solves == 1 and setups == 1                      # two electrodes: one characteristic potential
    if solver == "cg":
        assert s1.info["iterations"] > 0
    assert problem.solve() is s1                            # nothing changed: the same solution
    # new electrode values: no linear solve at all, linear response
    s3 = problem.solve({"a": 3.0})
    assert (problem.basis_solves, problem.solver.n_setups) == (solves, setups)
    np.testing.assert_allclose(s3.potential, 3.0 * s1.potential, rtol=0, atol=1e-8)
    assert s3.electrode_current["a"] == pytest.approx(3.0 * s1.electrode_current["a"], rel=1e-8)
    # the electrodes themselves are unchanged
    assert problem.solve().electrode_potential["a"] == 1.0


def test_solver_objects_keep_their_setup_per_matrix():
    K = laplacian([[0, 1], [1, 2]], [1.0, 1.0], 3).tocsr()[:2, :2].tocsr()   # node 2 grounded
    b = np.array([1.0, 0.0])
    for solver in (DirectSolver(), CGSolver(rtol=1e-12)):
        x, info = solver.solve(K, b)
        np.testing.assert_allclose(x, [2.0, 1.0], rtol=1e-12)
        assert info["setup"] is True
        x, info = solver.solve(K, 2 * b)
        np.testing.assert_allclose(x, [4.0, 2.0], rtol=1e-12)
        assert info["setup"] is False
        x, info = solver.solve(K.copy(), b)          # another matrix object: a new setup
        assert info["setup"] is True
    x, info = CGSolver().solve(K, np.zeros(2))
    assert info["iterations"] == 0 and not x.any()


def test_make_solver_and_names():
    assert set(solver_names()) == {"auto", "cg", "cg-amg", "cg-deflated", "cg-jacobi", "direct", "petsc", "petsc-hypre",
                                   "petsc-gamg", "petsc-auto"}
    assert isinstance(make_solver("direct"), DirectSolver)
    assert make_solver("cg").preconditioner == "jacobi"
    assert make_solver("cg", rtol=1e-6).rtol == 1e-6
    s = DirectSolver()
    assert make_solver(s) is s


# -- bad input ---------------------------------------------------------------------------------
def chain(n=5):
    return np.stack([np.arange(n - 1), np.arange(1, n)], axis=1), np.ones(n - 1)


def test_electrode_selecting_nothing():
    with pytest.raises(BoundaryConditionError, match="electrode 'top' selects no element"):
        Electrode("top", [], potential=1.0)


@pytest.mark.parametrize("kw, message", [
    (dict(), "give exactly one of potential="),
    (dict(potential=1.0, current=1.0), "give exactly one of potential="),
    (dict(potential=np.nan), "value must be finite, got nan"),
    (dict(current=np.inf), "value must be finite, got inf"),
])
def test_electrode_values(kw, message):
    with pytest.raises(BoundaryConditionError, match=message):
        Electrode("a", [0], **kw)


def test_same_body_in_two_electrodes():
    edges, c = chain()
    with pytest.raises(BoundaryConditionError,
                       match=r"1 element\(s\) belong to both electrodes 'a' and 'b' \(e\.g\. node 2\); "
                             "make the selections disjoint"):
        solve_potential(5, edges, c, two_electrodes([0, 1, 2], [2, 4]))


def test_other_electrode_mistakes():
    edges, c = chain()
    with pytest.raises(BoundaryConditionError, match="names node 7 but the network has 5 nodes"):
        solve_potential(5, edges, c, two_electrodes([0], [7]))
    # a negative index must not wrap around to the last nodes
    with pytest.raises(BoundaryConditionError, match=r"names node -1 but the network has 5 nodes \(indices 0..4\)"):
        solve_potential(5, edges, c, two_electrodes([0], [-1]))
    with pytest.raises(BoundaryConditionError, match="names must be unique"):
        solve_potential(5, edges, c, [Electrode("a", [0], potential=1.0), Electrode("a", [4], potential=0.0)])
    with pytest.raises(BoundaryConditionError, match="no electrode given"):
        solve_potential(5, edges, c, [])
    problem = ConductionProblem(5, edges, c, two_electrodes([0], [4]))
    with pytest.raises(BoundaryConditionError, match=r"no electrode named 'c'; have \['a', 'b'\]"):
        problem.solve({"c": 1.0})
    with pytest.raises(BoundaryConditionError, match="must be finite"):
        problem.solve({"a": np.nan})
    with pytest.raises(BoundaryConditionError, match="no electrode named 'x'"):
        problem.solve().equivalent_resistance("a", "x")
    with pytest.raises(BoundaryConditionError, match=r"injection must be a finite array of shape \(5,\)"):
        solve_potential(5, edges, c, two_electrodes([0], [4]), injection=np.ones(4))


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_electrodes_in_disconnected_parts_give_infinite_resistance(solver):
    # two separate chains 0-1-2 and 3-4-5, a on the first, b on the second
    edges = [[0, 1], [1, 2], [3, 4], [4, 5]]
    sol = solve_potential(6, edges, np.ones(4), two_electrodes([0], [5]), solver=solver)
    assert sol.equivalent_resistance("a", "b") == np.inf
    assert equivalent_resistance(6, edges, np.ones(4), [0], [5], solver=solver) == np.inf
    for arr in (sol.potential, sol.branch_current, list(sol.electrode_current.values()),
                list(sol.electrode_potential.values()), [sol.residual, sol.current_imbalance]):
        assert np.all(np.isfinite(arr))
    np.testing.assert_array_equal(sol.potential, [1, 1, 1, 0, 0, 0])
    np.testing.assert_array_equal(sol.branch_current, 0)
    assert sol.electrode_current == {"a": 0.0, "b": 0.0}
    assert not sol.floating.any()


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_floating_clusters_warn_and_stay_finite(solver):
    # chain 0-1-2-3 (R = 1 each) between the electrodes, a triangle 4-5-6 and a lone node 7,
    # and node 8 bonded to the chain by a zero conductance only
    edges = [[0, 1], [1, 2], [2, 3], [4, 5], [5, 6], [4, 6], [2, 8]]
    c = [1.0, 1.0, 1.0, 2.0, 2.0, 2.0, 0.0]
    with pytest.warns(UserWarning, match=r"5 element\(s\) in 3 part\(s\) are connected to no "
                                         r"electrode: they carry nothing to the rest and keep a potential of 0 V"):
        sol = solve_potential(9, edges, c, two_electrodes([0], [3], 3.0, 0.0), solver=solver)
    np.testing.assert_array_equal(sol.floating, [0, 0, 0, 0, 1, 1, 1, 1, 1])
    assert np.all(np.isfinite(sol.potential)) and np.all(np.isfinite(sol.branch_current))
    np.testing.assert_allclose(sol.potential, [3, 2, 1, 0, 0, 0, 0, 0, 0], rtol=1e-10, atol=1e-12)
    np.testing.assert_allclose(sol.branch_current, [1, 1, 1, 0, 0, 0, 0], rtol=1e-10, atol=1e-12)
    assert sol.equivalent_resistance("a", "b") == pytest.approx(3.0, rel=1e-10)


@pytest.mark.parametrize("solver", ["cg", "direct"])
def test_no_warning_without_floating_clusters(solver):
    edges, c = chain()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        solve_potential(5, edges, c, two_electrodes([0], [4]), solver=solver)


def test_imposed_current_with_no_grounded_electrode():
    edges, c = chain()
    with pytest.raises(BoundaryConditionError, match=r"no return path.*electrodes \['a', 'b'\].*ground one"):
        solve_potential(5, edges, c, [Electrode("a", [0], current=1.0), Electrode("b", [4], current=-1.0)])
    # grounded, but in another part of the network
    edges2 = [[0, 1], [2, 3], [3, 4]]
    with pytest.raises(BoundaryConditionError, match=r"no return path.*electrodes \['a'\]"):
        solve_potential(5, edges2, np.ones(3), [Electrode("a", [0], current=1.0), Electrode("b", [4], potential=0.0)])
    # a node injection without a ground
    with pytest.raises(BoundaryConditionError, match="no return path.*node injections"):
        solve_potential(5, edges2, np.ones(3), [Electrode("b", [4], potential=0.0)],
                        injection=np.array([0, 1.0, 0, 0, 0]))


@pytest.mark.parametrize("bad", [-1.0, np.nan, np.inf])
def test_bad_conductances(bad):
    edges, c = chain()
    c[1] = bad
    with pytest.raises(MaterialError, match="conductances must be finite and >= 0"):
        solve_potential(5, edges, c, two_electrodes([0], [4]))
    with pytest.raises(ValueError, match=r"one value per edge \(4\)"):
        solve_potential(5, edges, np.ones(3), two_electrodes([0], [4]))


def test_unknown_solver():
    edges, c = chain()
    with pytest.raises(ValueError, match=r"unknown solver 'gmres'; known: auto, cg, cg-amg, cg-deflated, cg-jacobi, direct"):
        solve_potential(5, edges, c, two_electrodes([0], [4]), solver="gmres")
    with pytest.raises(ValueError, match="preconditioner must be"):
        CGSolver(preconditioner="ilu")
    with pytest.raises(ValueError, match=r"rtol must be in \(0, 1\)"):
        CGSolver(rtol=0)


def test_cg_that_cannot_converge_raises(random_network):
    g, c, a, b, _ = random_network
    with pytest.raises(SolverError, match="did not converge.*solver='direct'"):
        solve_potential(g.n_nodes, g.edges, c, two_electrodes(a, b), solver=CGSolver(maxiter=2))


def test_deflation_caps_its_clusters():
    """With more clusters than max_clusters the clusters grow until there are about that many;
    the solution stays the same to the tolerance; a bad cap is refused."""
    from yade_electro.network.kirchhoff import laplacian
    from yade_electro.solvers.deflation import DeflatedCGSolver
    g = cubic_lattice((12, 12, 48), 0.5e-3)
    A = (laplacian(g.edges, np.ones(len(g.edges)), g.n_nodes) + 1e-3 * sp.eye(g.n_nodes)).tocsr()   # SPD
    b = np.random.default_rng(0).random(g.n_nodes)
    out = {}
    for cap in (None, 50):
        s = DeflatedCGSolver(max_clusters=cap)
        s.set_geometry(g.pos, 1e-3)
        out[cap] = s.solve(A, b)
    assert out[None][1]["clusters"] > 50 and out[None][1]["cluster_size"] == 3.0
    assert out[50][1]["clusters"] <= 2 * 50 and out[50][1]["cluster_size"] > 3.0
    np.testing.assert_allclose(out[50][0], out[None][0], rtol=1e-7)
    with pytest.raises(ValueError, match="max_clusters must be >= 1"):
        DeflatedCGSolver(max_clusters=0)


@pytest.mark.parametrize("repeats", [False, True])
@pytest.mark.parametrize("with_groups", [False, True])
def test_reduced_system_is_the_condensed_laplacian(repeats, with_groups):
    """ReducedSystem's K_uu and K_ud against a dense Laplacian, for distinct and repeated
    edges (the scatter and the bincount paths), assembled twice in place."""
    from yade_electro.network.condensation import ReducedSystem
    rng = np.random.default_rng(7 + 2 * repeats + with_groups)
    n = 80
    e = np.sort(rng.integers(0, n, (300, 2)), axis=1)
    e = np.unique(e[e[:, 0] != e[:, 1]], axis=0)
    if repeats:
        e = np.concatenate([e, e[::7]])
    groups = [np.arange(0, 5), np.arange(10, 13)] if with_groups else []
    rs = ReducedSystem(n, e, groups)
    u = rs.unknown_nodes
    for _ in range(2):
        c = rng.random(len(e))
        L = np.zeros((n, n))
        np.add.at(L, (e[:, 0], e[:, 0]), c)
        np.add.at(L, (e[:, 1], e[:, 1]), c)
        np.add.at(L, (e[:, 0], e[:, 1]), -c)
        np.add.at(L, (e[:, 1], e[:, 0]), -c)
        Kuu, Kud = rs.assemble(c)
        np.testing.assert_allclose(Kuu.toarray(), L[np.ix_(u, u)], rtol=1e-13, atol=1e-13)
        if groups:
            np.testing.assert_allclose(Kud.toarray(), np.column_stack([L[np.ix_(u, g)].sum(axis=1) for g in groups]),
                                       rtol=1e-13, atol=1e-13)
        else:           # no group: empty blocks (a shortcut path), nothing leaves through a group
            assert Kud.shape == (n, 0) and rs.Kdd.shape == (0, 0) and rs.Kdu is None
            assert rs.group_flux(rng.random(n), np.zeros(0)).shape == (0,)
            assert np.array_equal(rs.expand(np.arange(n, dtype=float), []), np.arange(n))


@pytest.mark.parametrize("repeats", [False, True])
def test_compiled_laplacian_fill_is_the_numpy_one(repeats, monkeypatch):
    """ReducedSystem's compiled K_uu pattern and fill (native/csr_pattern.cpp,
    laplacian_fill.cpp) give scipy's pattern and numpy's values to the last bit, with and
    without an extra diagonal, for distinct and repeated edges;
    K_ud and K_dd are the same; a kernel that is not built raises (no silent fallback)."""
    from yade_electro.network.condensation import ReducedSystem
    import yade_electro.native as native
    rng = np.random.default_rng(3 + repeats)
    n = 400
    e = np.sort(rng.integers(0, n, (1500, 2)), axis=1)
    e = np.unique(e[e[:, 0] != e[:, 1]], axis=0)
    if repeats:
        e = np.concatenate([e, e[::5]])
    groups = [np.arange(0, 7), np.arange(50, 60)]
    fast, slow = ReducedSystem(n, e, groups), ReducedSystem(n, e, groups, native=False)
    # the compiled patterns (native/csr_pattern.cpp; repeated edges go to scipy) are scipy's
    a, b = fast.Kuu, slow.Kuu
    assert np.array_equal(a.indptr, b.indptr) and np.array_equal(a.indices, b.indices)
    assert a.indices.dtype == b.indices.dtype and a.has_sorted_indices
    assert np.array_equal(fast.diagonal_slots, slow.diagonal_slots)
    for extra in (None, rng.random(fast.n_unknowns), 2.5):
        c = rng.random(len(e))
        fast.assemble(c, extra)
        slow.assemble(c, extra)
        assert fast.compiled is True and slow.compiled is None
        assert np.array_equal(fast.Kuu.data, slow.Kuu.data)
        assert np.array_equal(fast.Kud.data, slow.Kud.data) and np.array_equal(fast.Kdd.data, slow.Kdd.data)
    with pytest.raises(ValueError, match="one value per edge"):
        fast.assemble(np.ones(len(e) + 1))

    # a kernel that is not built is an error that says so, never a silent numpy fallback
    def unavailable(*a, **k):
        raise native.NativeError("the compiled kernel 'laplacian_fill' is not built: reinstall yade-electro")
    monkeypatch.setattr(native, "laplacian_fill", unavailable)
    other = ReducedSystem(n, e, groups)
    with pytest.raises(native.NativeError, match="reinstall"):
        other.assemble(c)


def test_deflated_cg_after_value_updates_on_a_lattice_whose_cluster_sums_cancel():
    """Uniform conductances on a lattice make many entries of the deflation's W^T A exactly 0
    (a cluster's column sum of the Laplacian); after value updates the solver must still
    refill every entry: the re-solves match the direct solution and converge as fast as a
    cold solve."""
    from lattice import cubic_lattice
    g = cubic_lattice((12, 12, 30), r=1e-4)
    el = [Electrode("top", np.arange(g.n_nodes - 144, g.n_nodes), potential=1.0),
          Electrode("bottom", np.arange(144), potential=0.0)]
    p = ConductionProblem(g.n_nodes, g.edges, np.full(len(g.edges), 2.5), el, solver="cg-deflated", coords=g.pos)
    cold = p.solve().info["iterations"]
    rng = np.random.default_rng(4)
    for _ in range(3):
        c2 = rng.uniform(0.5, 2.0, len(g.edges))
        assert p.update_conductance(c2) == "values"
        sol = p.solve()
        ref = ConductionProblem(g.n_nodes, g.edges, c2, el, solver="direct").solve()
        np.testing.assert_allclose(sol.potential, ref.potential, rtol=0, atol=1e-8)
        assert sol.info["iterations"] <= cold + 10


def test_compiled_deflated_cg_is_the_numpy_one(monkeypatch):
    """cg-deflated's compiled iterations (native/deflated_cg.cpp, Eigen's Cholesky of the
    coarse matrix) against its numpy form: the same iterations (+-1), the same solution to
    the tolerance, cold and after value updates (dense- and sparse-coarse sizes); a matrix
    that is not positive definite is refused as by numpy; without the helper, numpy."""
    from yade_electro.network.kirchhoff import laplacian
    from yade_electro.solvers.deflation import DeflatedCGSolver
    import yade_electro.native as native
    rng = np.random.default_rng(11)
    for shape in ((6, 6, 24), (14, 14, 40)):        # 54 and 720 clusters: dense and sparse coarse in numpy
        g = cubic_lattice(shape, 0.5e-3)
        c = rng.uniform(0.5, 2.0, len(g.edges))
        L = laplacian(g.edges, c, g.n_nodes).tocsr()
        # ground the bottom layer: the SPD reduced matrix on the rest
        keep = np.arange(shape[0] * shape[1], g.n_nodes)
        A = L[keep][:, keep].tocsr()
        b = rng.random(keep.size)
        sol = {}
        for compiled in (True, False):
            s = DeflatedCGSolver(native=compiled)
            s.set_geometry(g.pos[keep], 1e-3)
            A1 = A.copy()
            x, info = s.solve(A1, b)
            assert info["compiled"] is compiled and info["setup"] is True
            its = [info["iterations"]]
            xs = [x]
            for k in range(2):                           # value updates in place, warm re-solves
                c2 = c * np.random.default_rng(k).uniform(0.99, 1.01, c.size)
                A2 = laplacian(g.edges, c2, g.n_nodes).tocsr()[keep][:, keep].tocsr()
                assert np.array_equal(A2.indices, A1.indices)
                A1.data[:] = A2.data
                s.update(A1)
                x, info = s.solve(A1, b, x0=x)
                its.append(info["iterations"])
                xs.append(x)
            sol[compiled] = (its, xs)
        for a, bb in zip(sol[True][0], sol[False][0]):
            assert abs(a - bb) <= 1
        for xa, xb in zip(sol[True][1], sol[False][1]):
            np.testing.assert_allclose(xa, xb, rtol=0, atol=1e-8 * np.abs(xb).max())
    # not positive definite: refused like numpy's
    bad = A.copy()
    bad.data[bad.indices == np.repeat(np.arange(bad.shape[0]), np.diff(bad.indptr))] *= -1.0
    s = DeflatedCGSolver()
    s.set_geometry(g.pos[keep], 1e-3)
    with pytest.raises(SolverError):
        s.solve(bad, b)

    class Missing:
        def __init__(self, *a, **k):
            raise native.NativeError("not built")
    monkeypatch.setattr(native, "DeflatedCG", Missing)
    s = DeflatedCGSolver()
    s.set_geometry(g.pos[keep], 1e-3)
    with pytest.raises(native.NativeError, match="not built"):     # said, not a silent numpy run
        s.solve(A, b)


def test_compiled_deflated_cg_refuses_an_indefinite_matrix():
    """A symmetric matrix with a positive diagonal that is not positive definite: the compiled
    deflated CG says so (coarse factor or breakdown), as numpy's does, instead of a NaN."""
    from yade_electro.solvers.deflation import DeflatedCGSolver
    n = 200
    rng = np.random.default_rng(3)
    coords = rng.random((n, 3))
    # 1 on the diagonal, -2 between neighbours in a chain: eigenvalues down to 1 - 4 < 0
    A = sp.diags([np.full(n - 1, -2.0), np.ones(n), np.full(n - 1, -2.0)], [-1, 0, 1], format="csr")
    for native in (True, False):
        s = DeflatedCGSolver(native=native, cluster_size=1.0)
        s.set_geometry(coords, 0.05)
        with pytest.raises(SolverError, match="not positive definite"):
            s.solve(A, rng.random(n))
