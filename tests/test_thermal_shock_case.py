"""cases/thermal_shock.py in the real YADE, at 2,500 elements (--quick): a hot alumina strip
quenched at its two long faces by 4 times Hasselman's dT_c.

What must hold (measured at this size in brackets; the 8,000-element figures are in
docs/guide/thermal-expansion.md): the pull gives E_x (328 GPa) and a strength (142 MPa); before
the first crack the stress across the strip follows Timoshenko's strip formula on the DEM's own
temperatures to 15 % (6.2 %: the check falls 0.33 ms into the quench, when the cooled layer is
less than one element deep); every relaxation ends quasi-static (the elements' mean |force|
below 1 % of the bonds'); the surface layers break at 0.64 of the strength (their mean is below
the face's stress); cracks grow from both quenched faces, of unequal depths (7 + 8 cracks,
0.81 mm apart, 5 long and 10 short); the heat ledger closes (1e-14).
"""
import pytest

pytestmark = pytest.mark.yade


def test_thermal_shock_cracks_both_faces(run_yade_script, tmp_path):
    run = run_yade_script("cases/thermal_shock.py", "--quick", "--out", str(tmp_path / "out"), timeout=900,
                          cwd=tmp_path, check=True)
    r = run.result
    assert r["case"] == "thermal_shock"
    assert 250e9 < r["E_x_Pa"] < 550e9 and r["strength_Pa"] > 0 and r["dT_c_K"] > 0
    (q,) = r["quenches"]
    assert abs(q["dT_over_dT_c"] - 4.0) < 1e-9
    assert q["stress_error_pct"] < 15.0
    assert q["max_unbalanced"] <= 0.0101 or q["relax_chunks"] > q["calls"]
    assert q["onset_time_s"] is not None and 0.3 < q["surface_stress_at_onset_over_strength"] < 1.3
    assert min(q["cracks_per_face"]) >= 2 and q["short_cracks"] >= 1 and q["long_cracks"] >= 1
    assert 0.05 < q["spacing_over_width"] < 2.0
    assert q["ledger_error"] < 1e-9
