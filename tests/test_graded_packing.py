"""Graded packings (yade_electro.packing.grading), numpy only: smaller elements in a region,
the same number in all, no overlaps, each element the size of its place."""
import numpy as np
import pytest

from yade_electro.packing import Refinement, dense_packing
from yade_electro.geometry.shapes import Box

BAR = Box((0, 0, 0), (3e-3, 1e-3, 1e-3))
MIDDLE = Box((1.2e-3, -1.0, -1.0), (1.8e-3, 1.0, 1.0))        # |x - 1.5 mm| < 0.3 mm


def test_a_graded_packing_has_the_smaller_elements_where_it_was_asked(tmp_path):
    refine = Refinement(MIDDLE, factor=0.7, width=0.3e-3)
    pk = dense_packing(BAR, n=1500, seed=2, cache_dir=tmp_path, refine=refine)
    uniform = dense_packing(BAR, n=1500, seed=2, cache_dir=tmp_path)
    assert pk.n == 1500 and pk.max_overlap <= 1e-6
    assert np.all(BAR.sdf(pk.centers) + pk.radii <= 1e-9 * pk.r_mean)       # inside the bar
    assert pk.volume_fraction > 0.55
    x = pk.centers[:, 0]
    inner, outer = np.abs(x - 1.5e-3) < 0.25e-3, np.abs(x - 1.5e-3) > 0.95e-3
    ratio = pk.radii[inner].mean() / pk.radii[outer].mean()
    assert ratio == pytest.approx(0.7, abs=0.05), ratio
    # each element keeps the size of its place: the radius follows the size there (+-12.5 %
    # drawn); a few drift across the region's edge as the cloud relaxes (2.8 % by > 15 %)
    rel = pk.radii / refine.size(pk.centers)
    rel /= np.median(rel)
    assert np.mean((rel > 0.85) & (rel < 1.15)) > 0.95
    # the number density follows size^-3: 0.7^-3 = 2.9 times as many per volume in the middle
    dens = inner.sum() / outer.sum() * (2 * 0.55e-3) / (2 * 0.25e-3)
    assert 2.2 < dens < 3.6, dens
    # a graded packing is its own cache entry, and read back the same
    assert not np.array_equal(pk.radii, uniform.radii)
    again = dense_packing(BAR, n=1500, seed=2, cache_dir=tmp_path, refine=refine)
    assert again.from_cache and np.array_equal(again.centers, pk.centers)
    assert pk.params["refine"]["factor"] == 0.7


def test_a_refinement_is_checked_when_it_is_made():
    with pytest.raises(ValueError, match="factor must be in"):
        Refinement(MIDDLE, factor=1.5)
    with pytest.raises(ValueError, match="factor must be in"):
        Refinement(MIDDLE, factor=0.0)
    with pytest.raises(ValueError, match="width must be"):
        Refinement(MIDDLE, factor=0.5, width=-1e-3)
    with pytest.raises(ValueError, match="region must be a shape"):
        Refinement("the middle", factor=0.5)
    with pytest.raises(ValueError, match="takes n"):
        dense_packing(BAR, r_mean=0.1e-3, refine=Refinement(MIDDLE, 0.5), cache_dir=False)
    with pytest.raises(ValueError, match="dispersion"):
        dense_packing(BAR, n=100, dispersion=3, refine=Refinement(MIDDLE, 0.5), cache_dir=False)
    with pytest.raises(ValueError, match="refine must be a Refinement"):
        dense_packing(BAR, n=100, refine=0.5, cache_dir=False)
    step = Refinement(MIDDLE, factor=0.5)                      # width 0: a step at the region's surface
    np.testing.assert_array_equal(step.size(np.array([[1.5e-3, 0, 0], [2.5e-3, 0, 0]])), [0.5, 1.0])
    ramp = Refinement(MIDDLE, factor=0.5, width=0.2e-3)
    np.testing.assert_allclose(ramp.size(np.array([[1.9e-3, 0, 0]])), [0.75])


def test_the_narrow_ligament_case_refines_around_its_notches():
    """cases/narrow_ligament.py --refine F: F inside 0.7 mm of the middle, the full size from
    1.1 mm on (its graded figures, 10,000 elements on the 0.2 mm ligament, are in
    docs/guide/reliability-and-security.md: R_eq +0.73 to +0.87 %)."""
    import os
    import sys
    sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "cases"))
    import narrow_ligament as nl
    refine = nl.refinement(0.75)
    mid = 0.5 * nl.LENGTH
    pts = np.array([[mid, 0.5e-3, 0.5e-3], [mid + 0.69e-3, 0, 0], [mid + 0.9e-3, 0, 1e-3], [mid - 1.2e-3, 0, 0],
                    [0.0, 0.0, 0.0]])
    np.testing.assert_allclose(refine.size(pts), [0.75, 0.75, 0.875, 1.0, 1.0])
