"""Two spheres in contact (paper 002 case 4) in the real YADE with the granular heat engine:
every law within 0.1 % of the closed form (measured 4e-5 % with Crank-Nicolson at tau/200,
0.05 % explicit), and the engine's per-body starting temperatures refused when wrong."""
import os
import sys

import pytest

pytestmark = pytest.mark.yade

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
CASE = os.path.join(ROOT, "cases", "two_spheres.py")
sys.path.insert(0, os.path.join(ROOT, "cases"))
import two_spheres  # noqa: E402


def test_closed_form_numbers():
    assert two_spheres.contact_circle_radius() == pytest.approx(6.2450e-4, rel=1e-4)
    t1, t2 = two_spheres.closed_form([0.0, 1e3], "contact")
    assert t1[0] == pytest.approx(373.15) and t2[0] == pytest.approx(273.15)
    assert t1[1] == pytest.approx(323.15) and t2[1] == pytest.approx(323.15)


@pytest.mark.parametrize("theta, tol", [("crank-nicolson", 1e-3), ("explicit", 0.1)])
def test_two_spheres_every_law(run_yade_script, tmp_path, theta, tol):
    res = run_yade_script(CASE, "--theta", theta, "--out", str(tmp_path), timeout=600, check=True)
    row = res.result
    assert row["case"] == "two_spheres" and row["law"] == "contact,liggghts"
    for law, d in row["laws"].items():
        assert d["max_error_pct"] < tol, (law, d)
        assert d["mean_drift_K"] < 1e-9, law
        g = {"contact": 2.0, "liggghts": 2.0 * 3.141592653589793 ** 0.5}[law] * d["contact_radius_m"]
        assert d["engine_factor_m"] == pytest.approx(g, rel=1e-12), law
    assert row["max_error_pct"] < 0.1


BAD = r'''
import json
from yade_electro.yade.runtime import import_yade
yade = import_yade()
from yade import utils
from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Material, Reader
O = yade.Omega()
O.bodies.append([utils.sphere((0, 0, 0), 1e-3), utils.sphere((1.9e-3, 0, 0), 1e-3)])
out = {}
for name, table in (("unknown_id", {7: 300.0}), ("not_a_number", {0: "hot"}), ("nan", {0: float("nan")}),
                    ("not_a_dict", [300.0])):
    try:
        HeatEngine(
            material=Material(density=8900, specific_heat=172, conductivity=385),
            temperature=InitialTemperature(273.15, by_id=table),
            law="contact",
            integrator=Integrator(dt=1e-3),
            reader=Reader(bonds="contacts"),
            label="bad_" + name)
        out[name] = "accepted"
    except Exception as exc:
        out[name] = type(exc).__name__ + ": " + str(exc)
print(json.dumps(out))
'''


def test_bad_initial_temperatures_are_refused_in_the_script(run_yade_script):
    out = run_yade_script(BAD, timeout=300, check=True).result
    assert "not the id of a body" in out["unknown_id"]
    assert "initial_temperature[0]" in out["not_a_number"] and "real number" in out["not_a_number"]
    assert "finite" in out["nan"]
    assert "must be a dict" in out["not_a_dict"]
