"""Thermal expansion and thermal stress as pure functions (numpy only, exact answers)."""
import numpy as np
import pytest
from scipy.integrate import quad

from yade_electro.core.errors import MaterialError
from yade_electro.physics.expansion import (AlphaTable, bond_rest_increments, check_alpha, contact_points,
                                            element_stress, radius_growth, thermal_strain, von_mises)


def test_constant_alpha_strain():
    assert thermal_strain(393.0, 293.0, 1.2e-5) == pytest.approx(1.2e-3, rel=1e-15)
    np.testing.assert_allclose(thermal_strain([293.0, 193.0], 293.0, 2e-5), [0.0, -2e-3])


def test_alpha_table_is_integrated_exactly():
    t = AlphaTable(((300.0, 1e-5), (500.0, 2e-5), (800.0, 2.5e-5)))

    def alpha(x):                      # constant beyond the ends
        return float(np.interp(x, [300, 500, 800], [1e-5, 2e-5, 2.5e-5]))
    for T in (250.0, 300.0, 420.0, 500.0, 650.0, 900.0):
        exact = quad(alpha, 350.0, T, points=[300, 500, 800], epsabs=1e-16)[0]
        assert thermal_strain(T, 350.0, t) == pytest.approx(exact, rel=1e-12, abs=1e-18)
    assert t(400.0) == pytest.approx(1.5e-5)
    assert AlphaTable(((300.0, 1e-5),)).integral(400.0) == pytest.approx(1e-3)


@pytest.mark.parametrize("bad", [-1e-5, float("nan"), float("inf"), "1e-5", None, True])
def test_bad_alpha_is_refused(bad):
    with pytest.raises(MaterialError, match="alpha"):
        check_alpha("alpha", bad)


@pytest.mark.parametrize("points, match", [(((300, 1e-5), (200, 1e-5)), "increase"),
                                           (((300, -1e-5),), ">= 0"), (((0, 1e-5),), "> 0 K"),
                                           (((300, float("nan")),), "finite"), ((1, 2, 3), "pairs")])
def test_bad_alpha_table_is_refused(points, match):
    with pytest.raises(MaterialError, match=match):
        AlphaTable(points)


def test_a_uniform_strain_scales_every_rest_length():
    pairs = np.array([[0, 1], [1, 2], [0, 2]])
    r = np.array([1.0, 2.0, 0.5])
    L = np.array([2.9, 2.4, 1.6])
    inc = bond_rest_increments(pairs, r, L, np.full(3, 1e-3), np.zeros(3))
    np.testing.assert_allclose(inc, 1e-3 * L, rtol=1e-14)


def test_rest_lengths_do_not_depend_on_the_path():
    rng = np.random.default_rng(0)
    pairs = np.array([[0, 1], [1, 2], [2, 3], [0, 3]])
    r = rng.uniform(0.5, 1.5, 4)
    L0 = r[pairs].sum(axis=1) * 0.98
    e_mid, e_end = rng.uniform(-1e-3, 2e-3, 4), rng.uniform(-1e-3, 3e-3, 4)
    L1 = L0 + bond_rest_increments(pairs, r, L0, e_mid, np.zeros(4))
    L2 = L1 + bond_rest_increments(pairs, r, L1, e_end, e_mid)
    direct = L0 + bond_rest_increments(pairs, r, L0, e_end, np.zeros(4))
    np.testing.assert_allclose(L2, direct, rtol=1e-14)
    # each half with its own element's strain
    w = r[pairs]
    np.testing.assert_allclose(direct, L0 * (w[:, 0] * (1 + e_end[pairs[:, 0]]) + w[:, 1] * (1 + e_end[pairs[:, 1]]))
                               / w.sum(axis=1), rtol=1e-14)


def test_radius_growth_is_path_independent():
    r0 = np.array([1e-4, 2e-4])
    r1 = radius_growth(r0, [1e-3, 2e-3], [0.0, 0.0])
    np.testing.assert_allclose(radius_growth(r1, [3e-3, -1e-3], [1e-3, 2e-3]), r0 * [1.003, 0.999], rtol=1e-14)


def test_love_weber_stress_of_a_pressed_pair_and_its_sum():
    # two spheres pressed along x with 10 N: each carries sigma_xx = -F l / (2 V)
    pos = np.array([[0.0, 0, 0], [1.8, 0, 0]])
    r = np.array([1.0, 1.0])
    pairs = np.array([[0, 1]])
    pts = contact_points(pos, r, pairs)
    np.testing.assert_allclose(pts, [[0.9, 0, 0]])
    f = np.array([[10.0, 0, 0]])                 # on the second: pushed away (compression)
    s = element_stress(pos, pairs, pts, f, 2.0)
    np.testing.assert_allclose(s[:, 0, 0], [-10 * 0.9 / 2.0] * 2)
    assert np.count_nonzero(s[:, 1:, 1:]) == 0
    # the elements' V sigma sum to the Love-Weber sum -l (x) f over the interactions
    rng = np.random.default_rng(1)
    pos = rng.uniform(0, 5, (30, 3))
    pairs = np.array([(i, j) for i in range(30) for j in range(i + 1, 30) if np.linalg.norm(pos[i] - pos[j]) < 2])
    r = np.full(30, 0.9)
    pts = contact_points(pos, r, pairs)
    f = rng.normal(size=(pairs.shape[0], 3))
    V = rng.uniform(1, 2, 30)
    total = np.einsum("n,nij->ij", V, element_stress(pos, pairs, pts, f, V))
    l = pos[pairs[:, 1]] - pos[pairs[:, 0]]
    lw = -np.einsum("mi,mj->ij", l, f)
    np.testing.assert_allclose(total, 0.5 * (lw + lw.T), atol=1e-12)


def test_von_mises():
    s = np.zeros((2, 3, 3))
    s[0, 0, 0] = -5.0
    s[1] = np.eye(3) * 7.0
    np.testing.assert_allclose(von_mises(s), [5.0, 0.0], atol=1e-12)


def test_element_volumes_must_be_positive():
    with pytest.raises(ValueError, match="volumes"):
        element_stress(np.zeros((2, 3)), np.array([[0, 1]]), np.zeros((1, 3)), np.zeros((1, 3)), [1.0, 0.0])
