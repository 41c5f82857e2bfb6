"""cases/cross_engine_packing.py on the real YADE and LIGGGHTS at a small size: both engines
settle the same spheres in the same cylinder, every figure is there for both, and the
comparison can be made again from the saved packings."""
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "cross_engine_packing.py")


def test_cross_engine_packing_small(run_yade_script, liggghts_exe, tmp_path):
    args = ("--n", "300", "--radius", "0.006", "--out", str(tmp_path))
    row = run_yade_script(CASE, *args, timeout=900, check=True).result
    assert row["case"] == "cross_engine_packing" and row["n"] == 300
    for engine in ("liggghts", "yade"):
        f = row[engine]
        assert f["n"] == 300 and f["settle"]["settled"], engine
        assert 0.5 < f["volume_fraction_core"] < 0.7 and 3.0 < f["coordination"] < 7.0, engine
        assert 0 < f["overlap_mean"] < 0.02 and 0 < f["k_eff_over_k"] < 1, engine
    assert row["yade"]["settle"]["lost"] == 0
    # the same spheres: same count and volume; the beds are alike within a few per cent
    assert abs(row["relative_difference"]["bed_height_m"]) < 0.1
    assert abs(row["relative_difference"]["volume_fraction_core"]) < 0.05
    assert 0 <= row["ks_pvalue"] <= 1 and isinstance(row["overlaps_differ"], bool)
    assert os.path.exists(row["png"])
    again = run_yade_script(CASE, *args, "--reuse", timeout=300, check=True).result
    assert again["relative_difference"] == row["relative_difference"]
