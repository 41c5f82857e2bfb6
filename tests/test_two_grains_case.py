"""Paper 003's two-particle test (numpy, scikit-fem and gmsh; no YADE): resolved grains and the
lumped model against the finite-element reference, and the pieces they are made of."""
import os
import sys

import numpy as np
import pytest

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases"))

from yade_electro.core.errors import BoundaryConditionError  # noqa: E402
from yade_electro.network.grain_contact import mikic_resistance, plane_contact_links  # noqa: E402


def test_two_grains_resolved_within_one_percent_of_fem_and_lumped_misses_at_low_conductivity():
    pytest.importorskip("gmsh")
    import two_grains
    out = two_grains.main(["--n", "1000"])
    assert out["resolved_vs_fem_pct"] < 1.0 and out["resolved_vs_fem_pct_high_k"] < 1.0, out
    assert out["lumped_vs_fem_pct_low_k"] > 3.0 > 1.0 > out["lumped_vs_fem_pct_high_k"], out   # paper 003's effect
    low = out["low_k"]
    assert abs(low["contact_area_sampled_m2"] - out["contact_area_m2"]) < 1e-3 * out["contact_area_m2"]
    assert abs(low["volume_over_exact"] - 1.0) < 1e-4 and low["heat_ledger"] < 1e-10
    assert np.all(np.diff(low["fem_mean_B_K"]) > 0) and low["fem_mean_B_K"][-1] < 350.0


def test_fem_two_discs_conserve_heat_and_converge():
    pytest.importorskip("gmsh")
    from yade_electro.fem.two_discs import TwoDiscs, two_discs_transient
    g = TwoDiscs(0.5, 0.1, 0.0202)
    assert g.contact_area == pytest.approx(0.02, rel=2e-3)
    t = np.array([2e5, 8e5])
    coarse = two_discs_transient(g, 1.0, 2e6, 0.2, 400.0, 300.0, t, h=0.05, dt=2e4)
    fine = two_discs_transient(g, 1.0, 2e6, 0.2, 400.0, 300.0, t, h=0.025, dt=1e4)
    assert np.allclose(coarse["mean_A"] + coarse["mean_B"], 700.0, atol=1e-9)     # insulated: the sum is kept
    assert np.max(np.abs(coarse["mean_B"] - fine["mean_B"])) < 0.1                 # K, of a 100 K span
    assert np.all(fine["jump"] > 0)


def test_plane_contact_links_of_mirror_lattices_are_the_series_conductances():
    """Two cubic lattices facing across a plane: each face element pairs with its mirror, G =
    a^2 / (2 (a/2) / k + R_c), and the areas add up to the contact's."""
    a, k, Rc = 0.01, 2.0, 1e-3
    xs = (np.arange(4) + 0.5) * a
    A = np.array([(x, y, z) for x in -xs for y in xs for z in xs])       # x < 0
    B = A * np.array([-1, 1, 1])
    pairs, G, area = plane_contact_links(A, B, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 4 * a), (0, 4 * a), Rc, k,
                                         samples=40_000)
    assert pairs.shape == (16, 2) and area == pytest.approx(16 * a * a)
    assert np.all(np.abs(A[pairs[:, 0]] - B[pairs[:, 1]] * np.array([-1, 1, 1])).max(axis=1) < 1e-12)
    assert np.allclose(G, a * a / (a / k + Rc), rtol=1e-12)
    with pytest.raises(BoundaryConditionError, match="finite and >= 0"):
        plane_contact_links(A, B, (0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 1), (0, 1), -1.0, k)


def test_rough_contact_resistance_falls_with_pressure():
    R1, R2 = mikic_resistance([1e6, 1e7], roughness=1e-6, slope=0.1, hardness=1e9, conductivity=20.0)
    assert R2 < R1 and R1 / R2 == pytest.approx(10 ** 0.95)
    assert 1 / R1 == pytest.approx(1.25 * 20.0 * 0.1 / 1e-6 * (1e-3) ** 0.95)
    with pytest.raises(BoundaryConditionError, match="pressures"):
        mikic_resistance(0.0, 1e-6, 0.1, 1e9, 20.0)
