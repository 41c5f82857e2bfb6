"""Bed figures (yade_electro.packing.beds) on a simple cubic lattice of overlapping spheres,
whose coordination, overlaps, volume fraction and effective conductivity are known exactly,
and the comparison of two beds."""
import math

import numpy as np
import pytest

from yade_electro.packing.beds import bed_statistics, compare_beds, contact_pairs, volume_fraction_samples

A, S = 1e-3, 1.98e-3            # radius, lattice spacing (overlap 0.02 mm)


def lattice(layers=14, half=6):
    g = np.arange(-half, half + 1) * S
    X, Y, Z = np.meshgrid(g, g, np.arange(layers) * S + A, indexing="ij")
    c = np.column_stack([X.ravel(), Y.ravel(), Z.ravel()])
    R = (half + 0.2) * S
    c = c[np.hypot(c[:, 0], c[:, 1]) < R - A]
    return c, np.full(len(c), A), R


def test_lattice_figures_are_exact():
    c, r, R = lattice()
    st = bed_statistics(c, r, R, conductivity=2.0, samples=100_000)
    assert st["coordination_core"] == 6.0
    assert st["overlap_mean"] == pytest.approx((2 * A - S) / (2 * A), rel=1e-9)
    assert st["bed_height_m"] == pytest.approx(2 * np.mean(c[:, 2]), rel=1e-12)
    h = A - S / 2                                  # height of each of the six lens caps cut off a cell
    phi = (4 / 3 * math.pi * A ** 3 - 6 * math.pi * h * h * (3 * A - h) / 3) / S ** 3
    assert st["volume_fraction_core"] == pytest.approx(phi, abs=4 * math.sqrt(phi * (1 - phi) / 100_000) + 2e-3)
    # k_eff: parallel chains along z, each contact 2 sqrt(pi) a_c k (liggghts law)
    d, H = 2 * A, st["bed_height_m"]
    z_lo, z_hi = 2 * d, H - 2 * d
    zs = np.unique(c[:, 2])
    band = zs[(zs > z_lo) & (zs < z_hi)]
    bottom, top = band[band < z_lo + d], band[band > z_hi - d]
    links = round((top.min() - bottom.max()) / S)
    columns = len({(round(x / S), round(y / S)) for x, y in c[:, :2]})
    G = 2.0 * 2 * math.sqrt(math.pi) * math.sqrt(A ** 2 - (S / 2) ** 2)
    length = top.mean() - bottom.mean()
    k = length / (links / (columns * G) * math.pi * R ** 2) / 2.0
    assert st["k_eff_over_k"] == pytest.approx(k, rel=1e-8)
    prof = st["profile_phi"]
    assert prof.size == 50 and np.all(np.isfinite(prof))


def test_points_inside_spheres():
    c = np.array([[0.0, 0, 0], [1.0, 0, 0]])
    pts = np.array([[0.0, 0, 0.49], [0.0, 0, 0.51], [0.45, 0, 0], [1.2, 0.1, 0]])
    assert volume_fraction_samples(c, np.array([0.5, 0.3]), pts).tolist() == [True, False, True, True]
    assert contact_pairs(c, np.array([0.5, 0.6])).tolist() == [[0, 1]]
    assert contact_pairs(c, np.array([0.5, 0.5])).shape == (0, 2)        # touching is not a contact


def test_compare_beds():
    c, r, R = lattice()
    a = bed_statistics(c, r, R, samples=20_000)
    same = compare_beds(a, a)
    assert all(v == 0.0 for v in same["relative_difference"].values())
    assert same["ks_pvalue"] == 1.0 and not same["overlaps_differ"]
    b = dict(a, overlaps=a["overlaps"] * 1.5 + 1e-4 * np.random.default_rng(0).random(a["overlaps"].size))
    assert compare_beds(a, b)["overlaps_differ"]
    with pytest.raises(ValueError, match="diameters high"):
        bed_statistics(c[c[:, 2] < 4 * S], r[c[:, 2] < 4 * S], R)
