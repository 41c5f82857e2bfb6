"""Reliability on real YADE (issue 36): what a demanding user hit, each provoked."""
import re

from yade_snippets import BONDED_ROD

RIGID = BONDED_ROD + r'''
import json, math
import numpy as np
from yade_electro.yade import ElectroThermalEngine, Electrode, Material, Integrator, FixedTemperature
def build_engine():
    build()
    eng = ElectroThermalEngine(material=Material(resistivity=7.3e-7, density=7900.0, specific_heat=500.0, conductivity=16.2),
        boundaries=[Electrode("top", surface=rod.face("top"), potential=0.05), Electrode("bottom", surface=rod.face("bottom"), potential=0.0),
                    FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0)],
        temperature=300.0, integrator=Integrator(dt=1e-3))
    O.engines = O.engines + [eng.runner]
    O.run(3, True)
    return eng
def restructure(eng, moved):
    if moved:
        q = Quaternion((1, 0.3, 0.2), 0.5)
        for b in O.bodies:
            b.state.pos = q * b.state.pos + Vector3(1e-3, -2e-3, 0.7e-3)
            b.state.ori = q * b.state.ori
    O.run(3, True)
    R_moved = eng.equivalent_resistance
    b = O.bodies[17]; pos, r = Vector3(b.state.pos), b.shape.radius
    O.bodies.erase(17)
    O.run(3, True)
    R_erased = eng.equivalent_resistance
    O.bodies.append(sphere(pos, r))
    O.run(3, True)
    return R_moved, R_erased, eng.equivalent_resistance, float(eng.history.rows[-1]["T_max"])
e = build_engine(); still = restructure(e, False)
e = build_engine(); moved = restructure(e, True)
print(json.dumps({"still": still, "moved": moved}))
'''


def test_a_rigid_motion_then_a_restructure_keeps_the_resistance(run_yade_script):
    """Item 1: a bonded rod turned and moved as a whole, then a body erased and one added: the
    tessellation is made in the container's frame, so R_eq and the heat are those of the rod
    left in place (before: +1.5 % after a 0.3 mm shift, inf after 1 mm)."""
    out = run_yade_script(RIGID, check=True, timeout=600).result
    still, moved = out["still"], out["moved"]
    for a, b in zip(still, moved):
        assert abs(a / b - 1) < 1e-9, out


SURFACES = r'''
import json
import numpy as np
from yade_electro.yade import ElectricalEngine, Electrode, Material
from yade_electro.yade import packing as P
from yade_electro.geometry.surfaces import Plane
L, RAD = 2e-3, 0.5e-3
rod = P.Cylinder((0, 0, 0), (0, 0, L), RAD)
P.add_bonded_packing(P.dense_packing(rod, n=400, seed=3))
out = {}
for name, surf in (("mid", Plane((0, 0, L / 2), (0, 0, 1), 1e-6 * L)), ("mid_wide", Plane((0, 0, L / 2), (0, 0, 1), 0.05 * L)),
                   ("twice", None), ("face_layer", None), ("adjacent", None)):
    try:
        if name == "twice":
            b = [Electrode("top", surface=rod.face("top"), potential=1.0), Electrode("top2", surface=rod.face("top"), potential=0.0),
                 Electrode("bottom", surface=rod.face("bottom"), potential=0.0)]
        elif name == "face_layer":
            b = [Electrode("top", surface=rod.face("top"), potential=1.0),
                 Electrode("layer", select=lambda pos, r: pos[:, 2] > L - 0.3e-3, potential=0.0),
                 Electrode("bottom", surface=rod.face("bottom"), potential=0.0)]
        elif name == "adjacent":
            b = [Electrode("top", surface=rod.face("top"), potential=1.0), Electrode("side", surface=rod.face("side"), potential=0.0)]
        else:
            b = [Electrode("top", surface=surf, potential=1.0), Electrode("bottom", surface=rod.face("bottom"), potential=0.0)]
        el = ElectricalEngine(material=Material(resistivity=7.3e-7), boundaries=b, label=name)
        O.engines = O.engines + [el.runner]
        O.run(2, True)
        out[name] = el.equivalent_resistance
        el.remove()
    except Exception as exc:
        out[name] = "REFUSED " + str(exc)[:200]
print(json.dumps(out))
'''


def test_electrodes_that_would_short_or_sit_inside_the_solid_are_refused(run_yade_script):
    """Items 2 and 3: a face given twice, a face and the layer of elements under it, a plane
    inside the solid (also with a tolerance wide enough to catch side-wall slivers: before,
    R_eq 290x off) are refused when the engine is built; two adjacent faces are not."""
    out = run_yade_script(SURFACES, check=True, timeout=600).result
    assert "holds none of the packing's boundary faces" in out["mid"], out
    assert "crosses the container's surface only where that faces another way" in out["mid_wide"], out
    assert re.search(r"electrodes 'top' and 'top2' hold the same \d+ boundary face\(s\)", out["twice"]), out
    assert "are also on surface electrode 'top'" in out["face_layer"], out
    assert isinstance(out["adjacent"], float) and 1e-4 < out["adjacent"] < 1e-2, out


BUILD = BONDED_ROD + r'''
import json
from yade_electro.yade import HeatEngine, ElectricalEngine, ElectroThermalEngine, Electrode, Material, Integrator, FixedTemperature, HeatSource, Reader, Law
heat_mat = Material(density=7900.0, specific_heat=500.0, conductivity=16.2)
out = {}
def attempt(name, make):
    try:
        e = make()
        O.engines = O.engines + [e.runner]
        O.run(2, True)
        out[name] = ["ran", e.history.rows[-1].get("T_max"), e.body_ids.size]
        e.remove()
    except Exception as exc:
        out[name] = "REFUSED " + type(exc).__name__ + ": " + str(exc)
cold = FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0)
# 4: a loose sphere outside the container
build(); O.bodies.append(sphere((0, 0, 5e-3), 0.05e-3))
attempt("outside", lambda: HeatEngine(material=heat_mat, boundaries=[cold], temperature=300.0, integrator=Integrator(dt=1e-3)))
attempt("outside_left_out", lambda: HeatEngine(material=heat_mat, boundaries=[cold], temperature=300.0, integrator=Integrator(dt=1e-3), reader=Reader(isolated="leave out")))
# 21 + 13: a particle with no bond inside, steady with a source
build()
for i in list(O.interactions):
    if 17 in (i.id1, i.id2): O.interactions.erase(i.id1, i.id2)
attempt("unbonded_steady", lambda: HeatEngine(material=heat_mat, boundaries=[cold, HeatSource("q", density=1e8)], temperature=300.0, integrator=Integrator(steady=True), law=Law("continuum", container=rod)))
attempt("unbonded_left_out", lambda: HeatEngine(material=heat_mat, boundaries=[cold, HeatSource("q", density=1e8)], temperature=300.0, integrator=Integrator(steady=True), law=Law("continuum", container=rod), reader=Reader(isolated="leave out")))
attempt("unbonded_voronoi", lambda: HeatEngine(material=heat_mat, boundaries=[cold, HeatSource("q", density=1e8)], temperature=300.0, integrator=Integrator(steady=True)))
# 13: steady Joule heating with no thermal sink
build()
attempt("joule_no_sink", lambda: ElectroThermalEngine(material=Material(resistivity=7.3e-7, density=7900.0, specific_heat=500.0, conductivity=16.2),
        boundaries=[Electrode("top", surface=rod.face("top"), potential=0.05), Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
        temperature=300.0, integrator=Integrator(steady=True)))
# 5: the bonding step forgotten
O.reset()
pk = P.dense_packing(rod, n=400, seed=3)
for c, r in zip(pk.centers, pk.radii):
    O.bodies.append(sphere(tuple(c), float(r)))
attempt("no_bonds_before_run", lambda: ElectricalEngine(material=Material(resistivity=7.3e-7), boundaries=[Electrode("top", surface=rod.face("top"), potential=1.0), Electrode("bottom", surface=rod.face("bottom"), potential=0.0)], law=Law("continuum", container=rod)))
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb()]), InteractionLoop([Ig2_Sphere_Sphere_ScGeom()], [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]), NewtonIntegrator(dead=True)]
O.dt = 1e-9
O.step()
attempt("no_bonds", lambda: ElectricalEngine(material=Material(resistivity=7.3e-7), boundaries=[Electrode("top", surface=rod.face("top"), potential=1.0), Electrode("bottom", surface=rod.face("bottom"), potential=0.0)], law=Law("continuum", container=rod)))
print(json.dumps(out))
'''


def test_what_fails_later_is_refused_when_the_engine_is_built_naming_the_bodies(run_yade_script):
    """Items 4, 5, 13, 21: a loose sphere outside the container, a particle with no bond under a
    steady heat source (a bond law), steady Joule heating with no sink and a packing never bonded
    are refused in the script, naming the bodies; Reader(isolated='leave out') leaves the lone
    ones out. Under the Voronoi law a particle that never had a bond is part of the intact solid:
    it conducts through its cell faces and the steady run goes."""
    out = run_yade_script(BUILD, check=True, timeout=600).result
    assert "GraphError" in out["outside"] and "bodies [400] lie outside the solid" in out["outside"], out
    assert out["outside_left_out"][0] == "ran" and out["outside_left_out"][2] == 400, out
    assert "ThermalError" in out["unbonded_steady"] and "Bodies: [17]" in out["unbonded_steady"], out
    assert "Reader(isolated='leave out')" in out["unbonded_steady"], out
    assert out["unbonded_left_out"][0] == "ran" and out["unbonded_left_out"][2] == 399, out
    assert out["unbonded_voronoi"][0] == "ran" and out["unbonded_voronoi"][2] == 400, out
    assert 300.0 < out["unbonded_voronoi"][1] < 1e4, out
    assert "ThermalError" in out["joule_no_sink"] and "400 element(s) in 1 part(s)" in out["joule_no_sink"], out
    assert out["no_bonds_before_run"][0] == "ran", out          # bonds may come from the first steps: a warning
    assert "none of the 400 spheres is bonded" in out["no_bonds"], out


KELVIN = r'''
import json
from yade_electro.yade import HeatEngine, Material, Integrator, FixedTemperature, Convection, InitialTemperature, Reader, Wall
from yade_electro.yade import packing as P
L, RAD = 2e-3, 0.5e-3
rod = P.Cylinder((0, 0, 0), (0, 0, L), RAD)
P.add_bonded_packing(P.dense_packing(rod, n=200, seed=3))
mat = Material(density=7900.0, specific_heat=500.0, conductivity=16.2)
out = []
def attempt(**kw):
    base = dict(material=mat, boundaries=[FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0)], temperature=300.0)
    base.update(kw)
    try:
        HeatEngine(**base).remove()
        out.append("accepted")
    except Exception as exc:
        out.append(type(exc).__name__ + ": " + str(exc))
attempt(temperature=0.0)
attempt(temperature=-20.0)
attempt(boundaries=[FixedTemperature("cold", surface=rod.face("bottom"), temperature=0.0)])
attempt(boundaries=[Convection("air", surface=rod.face("side"), h=10.0, t_inf=-5.0)])
attempt(temperature=InitialTemperature(300.0, by_id={3: -1.0}))
e = HeatEngine(**dict(material=mat, boundaries=[FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0)], temperature=300.0))
for call in (lambda: e.set_temperatures({3: 0.0}), lambda: e.set_fixed_temperature("cold", -3.0)):
    try:
        call(); out.append("accepted")
    except Exception as exc:
        out.append(type(exc).__name__ + ": " + str(exc))
print(json.dumps(out))
'''


def test_temperatures_at_or_below_zero_kelvin_are_refused(run_yade_script):
    """Item 12: the engine's temperature, a fixed temperature, a convection's ambient, initial
    values by id, set_temperatures and set_fixed_temperature: each at or below 0 K refused."""
    out = run_yade_script(KELVIN, check=True, timeout=600).result
    assert len(out) == 7 and all(("ValueError" in o or "MaterialError" in o) and "is not an absolute temperature" in o
                                 for o in out), out


ENGINES = r'''
import json, warnings
from yade_electro.yade import HeatEngine, Material, Integrator, FixedTemperature, Reader, Output
from yade_electro.yade import packing as P
L, RAD = 2e-3, 0.5e-3
rod = P.Cylinder((0, 0, 0), (0, 0, L), RAD)
P.add_bonded_packing(P.dense_packing(rod, n=200, seed=3))
mat = Material(density=7900.0, specific_heat=500.0, conductivity=16.2)
cold = FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0)
out = {}
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    a = HeatEngine(material=mat, boundaries=[cold], temperature=300.0, label="a")
    b = HeatEngine(material=mat, boundaries=[cold], temperature=300.0, label="b")
out["same_bodies"] = [str(x.message) for x in w if "both write" in str(x.message)]
a.remove(); b.remove()
for bd in O.bodies:
    bd.mask = 2 if bd.state.pos[2] > L / 2 else 4
with warnings.catch_warnings(record=True) as w:
    warnings.simplefilter("always")
    a = HeatEngine(material=mat, boundaries=[FixedTemperature("t", nodes=lambda p, r: p[:, 2] > 0.9 * L, temperature=300.0)], temperature=300.0, label="a", reader=Reader(mask=2))
    b = HeatEngine(material=mat, boundaries=[cold], temperature=300.0, label="b", reader=Reader(mask=4))
out["masks_apart"] = [str(x.message) for x in w if "both write" in str(x.message)]
a.remove(); b.remove()
for bd in O.bodies:
    bd.mask = 1
try:
    HeatEngine(material=mat, boundaries=[cold], temperature=300.0, output=Output(write_back="T"))
    out["write_back"] = "accepted"
except ValueError as exc:
    out["write_back"] = str(exc)
# 18: steady_state() raising on an engine not in O.engines removes it
e = HeatEngine(material=mat, boundaries=[cold], temperature=300.0, integrator=Integrator(steady=True), label="s")
bottom = [int(i) for i in e.body_ids if O.bodies[int(i)].state.pos[2] < 0.25e-3]
for i in bottom:
    O.bodies.erase(i)
try:
    e.steady_state()
    out["steady"] = "ran"
except Exception as exc:
    out["steady"] = str(exc) + " | " + " ".join(getattr(exc, "__notes__", []))
from yade_electro.yade.registry import live_engines
out["live_after"] = sorted(live_engines())
e2 = HeatEngine(material=mat, boundaries=[FixedTemperature("hot", surface=rod.face("top"), temperature=350.0)], temperature=300.0, label="s")
out["label_reused"] = e2.label
print(json.dumps(out))
'''


def test_two_heat_engines_write_back_and_a_failed_steady_state(run_yade_script):
    """Items 17 and 18: two heat engines on the same bodies are warned with advice that applies
    (bodies apart), not when their masks keep them apart; a HeatEngine refuses write_back= (it
    writes no potential) instead of ignoring it; an engine not in O.engines whose steady_state()
    raised is removed, its label free again."""
    out = run_yade_script(ENGINES, check=True, timeout=600).result
    assert len(out["same_bodies"]) == 1 and "Reader(mask=...)" in out["same_bodies"][0], out
    assert out["masks_apart"] == [], out
    assert "writes no potential" in out["write_back"], out
    assert "none of its elements is left" in out["steady"] and "is removed" in out["steady"], out
    assert out["live_after"] == [] and out["label_reused"] == "s", out


EVIL = r'''
import base64, json, os, pickle
from yade_electro.yade import ElectricalEngine, Electrode, Material, attach, Law
from yade_electro.yade import packing as P
L, RAD = 2e-3, 0.5e-3
rod = P.Cylinder((0, 0, 0), (0, 0, L), RAD)
P.add_bonded_packing(P.dense_packing(rod, n=200, seed=3))
class Evil:
    def __reduce__(self):
        return (os.system, ("touch PWNED",))
payload = base64.b64encode(pickle.dumps([(Evil(), (0, 1, 2))])).decode()
O.tags["yade_electro:containers"] = payload
O.tags["yade_electro:evil:config"] = base64.b64encode(pickle.dumps({"engine": Evil()})).decode()
O.save("evil.yade.gz")
O.load("evil.yade.gz")
out = {}
try:
    e = ElectricalEngine(material=Material(resistivity=7.3e-7), boundaries=[
        Electrode("top", surface=rod.face("top"), potential=1.0), Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
        law=Law("voronoi", container=rod))
    out["built"] = e.equivalent_resistance if e.model.solution is not None else "built"
except Exception as exc:
    out["built"] = type(exc).__name__ + ": " + str(exc)
try:
    attach("evil")
    out["attach"] = "attached"
except Exception as exc:
    out["attach"] = type(exc).__name__ + ": " + str(exc)
# a config written now is data, and a saved engine comes back
e.remove() if "built" in out and not str(out["built"]).startswith(("ValueError", "Type")) else None
out["pwned"] = os.path.exists("PWNED")
print(json.dumps(out))
'''


def test_a_crafted_scene_file_runs_no_code(run_yade_script, tmp_path):
    """Item 7: a scene whose yade-electro tags hold pickles that run a command when read: an
    engine built on it and attach() read them as data only (the old tags are refused with a
    message), and nothing runs."""
    res = run_yade_script(EVIL, check=True, timeout=600, cwd=tmp_path)
    out = res.result
    assert out["pwned"] is False and not (tmp_path / "PWNED").exists(), out
    assert out["built"] == "built", out
    assert out["attach"].startswith("ValueError") and "no longer read" in out["attach"], out
