"""Paper 003's multibody case on real YADE, small: nuts (clumps of 12 spheres) poured into a
cylinder whose walls are held at 573 K, lumped, resolved, and spheres of the nut's volume."""
import numpy as np


def test_nut_container_quick(run_yade_script):
    res = run_yade_script("cases/nut_container.py", "--quick", check=True, timeout=900)
    out = res.result
    lum, rsv, sph = out["lumped"], out["resolved"], out["spheres"]
    assert out["nuts"] == 150 and lum["elements"] == rsv["elements"] == 1800 and sph["elements"] == 150, out
    for r in (lum, rsv, sph):
        T = np.array(r["T_mean_K"])
        assert r["wall_contacts"] > 50 and np.all(np.diff(T) > 0) and 293.15 < T[-1] < 573.15, r
        assert r["ledger_error"] < 1e-9, r
    assert 0.0 < out["lumped_vs_resolved_pct"] < 5.0, out       # the nuts conduct well inside
    assert lum["T_mean_K"][-1] > rsv["T_mean_K"][-1], out        # lumping skips the members' own resistance
