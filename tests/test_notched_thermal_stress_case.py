"""cases/notched_thermal_stress.py in the real YADE at 3,000 elements, FEM with 2 layers
through the thickness (about 2 min): the Joule-heated notched bar's elongation and ligament
stress, DEM against the thermo-elastic FEM on the same temperature field. Measured at this
size: elongation 0.52 %, ligament stress differences 0.05 / 0.72 / 1.6 % of E alpha dT
(xx / yy / zz); the 10,000-element figures with the FEM refined through the thickness are in
docs/guide/thermal-expansion.md."""
import pytest

pytestmark = pytest.mark.yade


def test_notched_bar_thermal_stress_against_fem(run_yade_script, tmp_path):
    out = run_yade_script("cases/notched_thermal_stress.py", "--n", "3000", "--layers", "2", timeout=900,
                          cwd=tmp_path, check=True).result
    assert out["T_ligament_K"] > out["T_max_K"] - 20 > 320            # heated, hottest in the ligament
    assert out["elongation_error_pct"] < 2.0
    for comp, diff in out["ligament_stress_diff_over_E_alpha_dT_pct"].items():
        assert abs(diff) < 5.0, comp
    assert out["ligament_stress_fem_Pa"]["zz"] < 0 and out["ligament_stress_dem_Pa"]["zz"] < 0
