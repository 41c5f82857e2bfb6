"""cases/heated_bed.py in the real YADE at 800 spheres (about 10 s): a bed heated in a rigid,
smooth container. Measured at 800 (2,000 in docs/guide/thermal-expansion.md): the wall
pressure rise within 0.2 % (0.003 %) of K 3 alpha dT, with K from the case's own compression
of the box; the mean contact conductance up by 13.3 % (13.0 %) against sqrt(p1 / p0) = 13.7 %
(13.5 %), the bed's conductivity by 14.5 % (14.2 %)."""
import pytest

pytestmark = pytest.mark.yade


def test_heated_bed_pressure_and_conductance(run_yade_script, tmp_path):
    out = run_yade_script("cases/heated_bed.py", "--n", "800", timeout=600, cwd=tmp_path, check=True).result
    assert out["spheres"] == 800 and out["p0_Pa"] > 0 and out["dp_Pa"] > 0
    assert out["error_pct"] < 2.0
    assert out["conductivity_ratio"] > 1.05                          # conductances follow the overlaps
    assert out["mean_G_ratio"] == pytest.approx(out["G_ratio_estimate"], rel=0.02)
