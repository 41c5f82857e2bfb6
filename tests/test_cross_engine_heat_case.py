"""cases/cross_engine_heat.py on the real YADE and LIGGGHTS: the two spheres, a small settled
packing and the same packing on an isothermal floor agree particle by particle at every dump
(< 0.5 % of the range), with the same contacts and conductances; the floor's heat is what the
particles stored; the contact law's decay time is sqrt(pi) times LIGGGHTS'."""
import math
import os

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "cross_engine_heat.py")


def test_cross_engine_heat_small(run_yade_script, liggghts_exe, tmp_path):
    res = run_yade_script(CASE, "--n", "300", "--out", str(tmp_path), timeout=900, check=True)
    row = res.result
    assert row["case"] == "cross_engine_heat" and row["problem"] == "two_spheres,packing,floor"
    assert row["max_rel_diff_pct"] < 0.5
    for name, p in row["problems"].items():
        assert p["max_rel_diff_pct"] < 0.5 and len(p["rel_diff_pct_per_dump"]) == p["dumps"] > 5, name
        assert p["contacts_liggghts_only"] == 0 and p["contacts_yade_only"] == 0, name
        assert p["conductance_max_rel_diff"] < 1e-5, name       # the dump's 6 digits of the area
    two = row["problems"]["two_spheres"]
    assert abs(two["h_c_ratio"] / math.sqrt(math.pi) - 1) < 1e-5
    assert abs(two["tau_ratio_contact_over_liggghts"] / math.sqrt(math.pi) - 1) < 1e-3
    pack = row["problems"]["packing"]
    assert pack["n"] == 300 and pack["settled"] and pack["liggghts_contacts"] > 300
    floor = row["problems"]["floor"]
    assert floor["floor_contacts"] > 20 and abs(floor["heat_rel_diff"]) < 5e-3
    assert abs(floor["wall_heat_yade_J"] / floor["heat_stored_yade_J"] - 1) < 1e-9     # all of it from the floor
    assert os.path.exists(row["png"])
