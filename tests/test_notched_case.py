"""The notched bar (cases/notched_joule.py, paper 000 section 3.3) in the real YADE, small.

Small run: 1,500 elements (r_mean 85 um, 43 in the notch slab), 20 thermal steps, FEM
reference on coarse P1 meshes (h = 0.2, 0.1, 0.05 mm). Stated tolerances for the 'voronoi'
law (Voronoi-cell capacities) at this size, against the FEM with the electrodes on the end
faces: |R_eq error| < 4 % (measured +1.19 %) and |notch-slab temperature-rise error| < 15 %
(measured +10.1 %: 1,500 elements put only ~3 elements across the 0.5 mm ligament; it is
+3.7 % at 5,000). The paper's model ('continuum') is only checked to run, to conserve
energy and to stay within 40 % (measured +14.4 % and +5.9 %).
"""
import math
import os
import sys

import numpy as np
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "notched_joule.py")
sys.path.insert(0, os.path.join(ROOT, "cases"))
import notched_joule as nj  # noqa: E402

FEM_H = "0.0002,0.0001,0.00005"


def test_geometry_matches_the_paper():
    """Eq. 1 gives the paper's radii within 2 %, and the 4 r_mean slab rule its 100 ... 362
    elements within 15 %."""
    volume = nj.LENGTH * nj.WIDTH * nj.THICKNESS - 2 * nj.NOTCH_WIDTH * nj.NOTCH_DEPTH * nj.THICKNESS
    section = (nj.WIDTH - 2 * nj.NOTCH_DEPTH) * nj.THICKNESS
    for n, r_paper in nj.PAPER_R_MEAN.items():
        r = (0.63 * volume / (4 / 3 * math.pi * n)) ** (1 / 3)
        assert r == pytest.approx(r_paper * 1e-6, rel=0.02)
    slab = lambda n: 1.89 * section / (math.pi * ((0.63 * volume / (4 / 3 * math.pi * n)) ** (1 / 3)) ** 2)  # noqa: E731
    assert slab(5000) == pytest.approx(100, rel=0.15) and slab(40000) == pytest.approx(362, rel=0.15)


def test_layers_and_slabs():
    x = np.array([0.5e-4, 2e-4, 6e-3 - 0.5e-4])
    e0, e1 = nj.end_layers(x, np.full(3, 0.45e-4), 0.5e-4, gap=0.1)
    assert e0.tolist() == [True, False, False] and e1.tolist() == [False, False, True]
    m, cnt = nj.slab_mean(np.array([0.1e-3, 0.15e-3, 5.9e-3]), np.array([1.0, 3.0, 5.0]), nj.bin_edges(3))
    assert m[0] == 2.0 and cnt.tolist() == [2, 0, 1] and np.isnan(m[1])


@pytest.mark.parametrize("law", ["voronoi", "continuum"])
def test_notched_small(run_yade_script, tmp_path, law):
    res = run_yade_script(CASE, "--n", "1500", "--law", law, "--nsteps", "20", "--fem-h", FEM_H,
                          "--no-offset", "--out", str(tmp_path), timeout=300, check=True)
    row = res.result
    assert row["case"] == "notched_joule" and row["law"] == law and row["n"] == 1500
    for k in ("R_eq", "R_eq_fem", "T_slab", "T_slab_fem", "T_notch", "error_R_eq_pct",
              "error_T_slab_pct", "error_T_notch_pct", "profile_T_rms"):
        assert math.isfinite(row[k]), (k, row)
    assert row["t_thermal"] == pytest.approx(0.01)
    assert row["n_slab"] > 10 and row["n_end0"] > 0 and row["n_end1"] > 0
    # adiabatic: the heat stored is the Joule energy
    assert row["heat_content_J"] == pytest.approx(row["joule_energy_J"], rel=1e-8)
    assert nj.T0 < row["T_slab"] < 1000.0
    if law == "voronoi":
        assert abs(row["error_R_eq_pct"]) < 4 and abs(row["error_T_slab_pct"]) < 15, row
    else:
        assert abs(row["error_R_eq_pct"]) < 40 and abs(row["error_T_slab_pct"]) < 40, row
    stem = f"notched_n1500_s1_{law}"
    for suffix in ("_elements.csv", "_history.csv", "_profiles.csv", ".json", ".png"):
        assert (tmp_path / (stem + suffix)).stat().st_size > 0
    prof = np.genfromtxt(tmp_path / (stem + "_profiles.csv"), delimiter=",", names=True)
    assert len(prof) == 60 and np.all(np.isfinite(prof["V_fem"])) and np.all(np.isfinite(prof["T_fem"]))
