"""ThermalExpansion in the real YADE (each case a fresh ``yade-electro -n -x`` process)."""
import pytest

pytestmark = pytest.mark.yade

SCENE = r'''
import json, sys
import numpy as np
from yade import pack, utils
from yade_electro.yade import ThermalExpansion, ensure_thermal_state
O.materials.append(CohFrictMat(young=210e9, poisson=0.3, density=7900, normalCohesion=1e9, shearCohesion=1e9,
                               momentRotationLaw=True, label="steel"))
r = 1e-4
O.bodies.append(pack.regularHexa(pack.inAlignedBox((0, 0, 0), (1e-3, 1e-3, 3e-3)), radius=r, gap=0, material="steel"))
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=1.05, label="bo")]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=1.05, label="ig")],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True, setCohesionOnNewContacts=False)],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment()]),
             NewtonIntegrator(damping=0.5)]
O.dt = 0.5 * utils.PWaveTimeStep()
if BONDED:
    O.step()
    bo.aabbEnlargeFactor = -1
    ig.interactionDetectionFactor = -1
bodies = list(O.bodies)
if TEMPERATURE is not None:
    ensure_thermal_state(bodies)
    for b in bodies:
        b.state.temp = TEMPERATURE
x0 = np.array([tuple(b.state.pos) for b in bodies])

def strain():
    x = np.array([tuple(b.state.pos) for b in bodies])
    return [float(np.polyfit(x0[:, a], x[:, a] - x0[:, a], 1)[0]) for a in range(3)]

def heat(T):
    for b in bodies:
        b.state.temp = T
'''


def script(body, bonded=True, temperature=293.0):
    return f"BONDED = {bonded}\nTEMPERATURE = {temperature!r}\n" + SCENE + body


FREE = r'''
e = ThermalExpansion(alpha=1.2e-5, mode=MODE, iterPeriod=50, history="exp.csv")
O.engines = O.engines + [e.runner]
m0 = [b.state.mass for b in bodies]; r0 = [b.shape.radius for b in bodies]; I0 = [b.state.inertia[0] for b in bodies]
heat(393.0)
O.run(4000, True)
fn, fs = e.bond_forces()
print(json.dumps({"strain": strain(), "max_force": float(abs(fn).max()), "rows": len(e.history.rows),
                  "mass_kept": all(b.state.mass == m for b, m in zip(bodies, m0)),
                  "radius_ratio": float(np.mean([b.shape.radius / q for b, q in zip(bodies, r0)])),
                  "inertia_ratio": float(np.mean([b.state.inertia[0] / q for b, q in zip(bodies, I0)])),
                  "s_zz": e.history.rows[-1]["s_zz_Pa"]}))
'''


@pytest.mark.parametrize("mode", ["bonds", "radii"])
def test_free_expansion_strain_is_alpha_dT(run_yade_script, tmp_path, mode):
    res = run_yade_script(script(f"MODE = {mode!r}\n" + FREE), timeout=300, cwd=tmp_path, check=True).result
    for e in res["strain"]:
        assert e == pytest.approx(1.2e-3, rel=5e-3)
    assert res["rows"] >= 40 and abs(res["s_zz"]) < 1e3       # Pa: no stress in a free body
    assert res["mass_kept"]
    if mode == "radii":
        assert res["radius_ratio"] == pytest.approx(1.0012, rel=1e-12)
        assert res["inertia_ratio"] == pytest.approx(1.0012 ** 2, rel=1e-12)
    else:
        assert res["radius_ratio"] == 1.0


SAVE = r'''
e = ThermalExpansion(alpha=1.2e-5, iterPeriod=50)
O.engines = O.engines + [e.runner]
heat(343.0)
O.run(3000, True)
first = strain()
np.save("x0.npy", x0)
O.save("half.yade.gz")
print(json.dumps({"strain": first}))
'''

LOAD = r'''
import json
import numpy as np
from yade_electro.yade import ThermalExpansion
O.load("half.yade.gz")
x0 = np.load("x0.npy")
bodies = [b for b in O.bodies]
for b in bodies:
    b.state.temp = 393.0
O.run(4000, True)
x = np.array([tuple(b.state.pos) for b in bodies])
print(json.dumps({"strain": [float(np.polyfit(x0[:, a], x[:, a] - x0[:, a], 1)[0]) for a in range(3)]}))
'''


def test_expansion_goes_on_after_save_and_load(run_yade_script, tmp_path):
    half = run_yade_script(script(SAVE), timeout=300, cwd=tmp_path, check=True).result
    assert half["strain"][2] == pytest.approx(0.6e-3, rel=5e-3)
    full = run_yade_script(LOAD, timeout=300, cwd=tmp_path, check=True)
    assert "re-attaching engine 'expansion'" in full.stderr
    for e in full.result["strain"]:
        assert e == pytest.approx(1.2e-3, rel=5e-3)


ERRORS = r'''
from yade_electro.core.errors import MaterialError, ThermalError
out = {}
def trial(name, **kw):
    try:
        ThermalExpansion(**kw)
        out[name] = "built"
    except (MaterialError, ThermalError, ValueError) as exc:
        out[name] = type(exc).__name__ + ": " + str(exc)
trial("negative", alpha=-1e-5)
trial("nan", alpha=float("nan"))
trial("mode", alpha=1e-5, mode="volume")
trial("material", alpha={"copper": 1e-5})
trial("reference", alpha=1e-5, reference_temperature=0.0)
print(json.dumps(out))
'''


def test_bad_input_is_refused_when_built(run_yade_script, tmp_path):
    res = run_yade_script(script(ERRORS), timeout=120, cwd=tmp_path, check=True).result
    assert res["negative"].startswith("MaterialError") and ">= 0" in res["negative"]
    assert res["nan"].startswith("MaterialError") and "finite" in res["nan"]
    assert res["mode"].startswith("ValueError") and "bonds, radii" in res["mode"]
    assert res["material"].startswith("MaterialError") and "copper" in res["material"]
    assert res["reference"].startswith("MaterialError") and "> 0 K" in res["reference"]


def test_no_temperature_and_no_bonds_are_refused(run_yade_script, tmp_path):
    src = script(ERRORS.replace('trial("negative"', 'trial("plain", alpha=1e-5)\ntrial("negative"'),
                 temperature=None)
    res = run_yade_script(src, timeout=120, cwd=tmp_path, check=True).result
    assert res["plain"].startswith("ThermalError") and "no temperature" in res["plain"]
    src = script(ERRORS.replace('trial("negative"', 'trial("loose", alpha=1e-5)\ntrial("negative"'), bonded=False)
    res = run_yade_script(src, timeout=120, cwd=tmp_path, check=True).result
    assert res["loose"].startswith("MaterialError") and "cohesive bonds" in res["loose"]
