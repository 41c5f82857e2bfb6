"""Torsion closed forms, the reading of a twist test, and the VTK writer (numpy only)."""
import math

import numpy as np
import pytest

from yade_electro.post.torsion import (crack_summary, elastic_slope, elastic_torque, first_crossing, polar_moment,
                                  ratio_at, surface_shear_stress, yield_angle)
from yade_electro.post.vtk import write_bonds, write_elements


def test_closed_forms_of_the_pin():
    # paper 000 section 4: r = 1 mm, h = 5 mm, G = 48.062 GPa, tau_y = 400 MPa
    assert polar_moment(1e-3) == pytest.approx(math.pi * 1e-12 / 2)
    assert yield_angle(400e6, 48.062e9, 1e-3, 5e-3) == pytest.approx(0.041613, rel=1e-4)
    # with d = 1 mm (r = 0.5 mm) it would be twice that, not the paper's 0.043
    assert yield_angle(400e6, 48.062e9, 0.5e-3, 5e-3) == pytest.approx(0.083226, rel=1e-4)
    T = elastic_torque(48.062e9, 1e-3, 5e-3, 0.041613)
    assert surface_shear_stress(T, 1e-3) == pytest.approx(400e6, rel=1e-4)


def test_elastic_slope_ignores_an_offset_and_the_range_outside():
    th = np.linspace(0, 0.1, 101)
    tq = 3.0 * th + 0.2
    tq[th > 0.05] = 0.0                      # cracked: outside the fit range
    assert elastic_slope(th, tq, theta_max=0.04, theta_min=0.01) == pytest.approx(3.0, rel=1e-12)
    with pytest.raises(ValueError, match="fewer than 3 points"):
        elastic_slope(th, tq, theta_max=0.0105, theta_min=0.01)


def test_first_crossing_interpolates_and_counts_inf():
    th = np.array([0.0, 0.1, 0.2, 0.3])
    assert first_crossing(th, [1.0, 1.0, 1.2, 2.0], 1.1) == pytest.approx(0.15)
    assert first_crossing(th, [1.0, 1.0, 1.05, np.inf], 1.1) == pytest.approx(0.3)
    assert first_crossing(th, [1.0, 1.0, 1.0, 1.0], 1.1) is None


def test_ratio_at_gives_inf_after_separation_and_nan_beyond_an_unseparated_test():
    th = np.array([0.0, 0.02, 0.04, 0.06, 0.08])
    r = np.array([1.0, 1.0, 1.5, np.inf, np.inf])
    out = ratio_at(th, r, (0.03, 0.05, 0.07, 0.09))
    assert out["0.03"] == pytest.approx(1.25)
    assert out["0.05"] == pytest.approx(1.5)      # separated between the records: last finite value
    assert out["0.07"] == math.inf
    assert out["0.09"] == math.inf                # ended separated: still separated there
    assert math.isnan(ratio_at(th, [1.0, 1.0, 1.1, 1.2, 1.3], (0.09,))["0.09"])   # ended whole


def test_crack_summary():
    th = np.array([0.0, 0.01, 0.02, 0.03, 0.04, 0.05])
    r = np.array([1.0, 1.0, 1.005, 1.2, 2.5, np.inf])
    nb = np.array([0, 0, 2, 30, 90, 200])
    s = crack_summary(th, r, nb)
    assert s["theta_first_break"] == 0.02
    assert s["theta_R_rise"]["1%"] == pytest.approx(0.02 + 0.01 * (0.005 / 0.195))
    assert s["theta_R_rise"]["100%"] == pytest.approx(0.03 + 0.01 * (0.8 / 1.3))
    assert s["theta_separation"] == 0.05
    assert s["broken_at_separation"] == 200
    never = crack_summary(th, np.ones(6), np.zeros(6))
    assert never["theta_first_break"] is None and never["theta_separation"] is None
    with pytest.raises(ValueError, match="one shape"):
        crack_summary(th, r[:3], nb)


def test_vtk_files_round_trip(tmp_path):
    import meshio
    x = np.array([[0, 0, 0], [1e-3, 0, 0], [0, 2e-3, 0]], float)
    p = write_elements(str(tmp_path / "e.vtu"), x, [1e-4, 2e-4, 3e-4], {"potential": [0.0, 0.5, np.nan]})
    m = meshio.read(p)
    assert np.allclose(m.points, x)
    assert np.allclose(m.point_data["radius"], [1e-4, 2e-4, 3e-4])
    assert np.allclose(m.point_data["potential"], [0.0, 0.5, 0.0])          # nan written as 0
    assert m.cells[0].type == "vertex" and m.cells[0].data.ravel().tolist() == [0, 1, 2]
    q = write_bonds(str(tmp_path / "b.vtu"), x, [[0, 1], [1, 2]], {"broken": [0, 1]})
    m = meshio.read(q)
    assert m.cells[0].type == "line" and m.cells[0].data.tolist() == [[0, 1], [1, 2]]
    assert m.cell_data["broken"][0].tolist() == [0.0, 1.0]
    with pytest.raises(ValueError, match="shape"):
        write_elements(str(tmp_path / "x.vtu"), x, [1, 2, 3], {"potential": [1.0]})
    with pytest.raises(ValueError, match="bond indices"):
        write_bonds(str(tmp_path / "y.vtu"), x, [[0, 3]])
    # periodic: bond (0, 2) crosses a face (its vector is to 2's image), bond (0, 1) does not
    v = [[1e-3, 0, 0], [0, -1e-3, 0]]
    m = meshio.read(write_bonds(str(tmp_path / "p.vtu"), x, [[0, 1], [0, 2]], {"q": [1.0, 2.0]}, vectors=v))
    assert m.cells[0].data.tolist() == [[0, 1], [0, 3]] and np.allclose(m.points[3], [0, -1e-3, 0])
    assert m.cell_data["q"][0].tolist() == [1.0, 2.0]
    with pytest.raises(ValueError, match="vectors"):
        write_bonds(str(tmp_path / "z.vtu"), x, [[0, 1]], vectors=[[0, 0, np.nan]])
