"""ElectroThermalEngine in the real YADE (each case a fresh ``yade-electro -n -x`` process)."""
import csv
import io

import pytest

pytestmark = pytest.mark.yade

SCENE = r'''
import json, math
import numpy as np
from yade import pack, utils
from yade_electro.yade import ElectroThermalEngine, Electrode, Integrator, Material, Output
from yade_electro.yade import Convection
O.materials.append(CohFrictMat(young=210e9, poisson=0.3, density=7900, normalCohesion=1e8, shearCohesion=1e8,
                               momentRotationLaw=True, label="steel"))
r = 1e-4
O.bodies.append(pack.regularHexa(pack.inAlignedBox((0, 0, 0), (1e-3, 1e-3, 3e-3)), radius=r, gap=0, material="steel"))
O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(aabbEnlargeFactor=1.1, label="bo")]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=1.1, label="ig")],
                             [Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True, setCohesionOnNewContacts=False)],
                             [Law2_ScGeom6D_CohFrictPhys_CohesionMoment()]),
             NewtonIntegrator(damping=0.4)]
O.dt = 1e-9
O.step()
bo.aabbEnlargeFactor = -1
ig.interactionDetectionFactor = -1
zs = [b.state.pos[2] for b in O.bodies]
TOP = pack.inAlignedBox((-1, -1, max(zs) - 0.5 * r), (1, 1, 1))
BOTTOM = pack.inAlignedBox((-1, -1, -1), (1, 1, min(zs) + 0.5 * r))
'''

HEATING = SCENE + r'''
e = ElectroThermalEngine(
    material=Material(resistivity=0.73e-6, density=7900, specific_heat=500, conductivity=15),
    boundaries=[Electrode("top", select=TOP, potential=VOLTAGE), Electrode("bottom", select=BOTTOM, potential=0.0)],
    temperature=293.15,
    integrator=Integrator(theta=THETA, dt=1e-3),
    output=Output(history="heat.csv"),
    iterPeriod=1)
O.engines = O.engines + [e.runner]
out = {}
try:
    O.run(STEPS_BEFORE, True)
    if BLOWUP:
        e.set_electrode("top", 1e160)   # the Joule power overflows from the next call on
    O.run(5 - STEPS_BEFORE, True)
except Exception as exc:
    out["error"] = str(exc)
rows = e.history.rows
out.update(n_rows=len(rows), iters=[r["iter"] for r in rows])
if rows:
    last = rows[-1]
    out.update(time=last["time"], joule_energy=last["joule_energy"], heat=last["heat_content"], T_mean=last["T_mean"],
               power=last["joule_power"], T_max=last["T_max"])
    temps = [b.state.temp for b in O.bodies]
    out.update(state_type=type(O.bodies[0].state).__name__, body_T_min=min(temps), body_T_max=max(temps),
               model_T_max=float(max(e.temperature)), potential_written=hasattr(O.bodies[0], "potential"))
    if "error" not in out:
        import meshio
        files = e.write_vtk("vtk/rod")
        parts, lines = meshio.read(files["particles"]), meshio.read(files["contacts"])
        out.update(vtk_points=len(parts.points), vtk_lines=len(lines.cells_dict["line"]),
                   bonds=int(np.sum(e.coupled.heat.conductance > 0)), n_bodies=len(O.bodies),
                   vtk_T_max=float(parts.point_data["temperature"].max()),
                   vtk_V_max=float(parts.point_data["potential"].max()))
print(json.dumps(out))
'''


def _run(run_yade_script, tmp_path, voltage, theta="backward-euler", blowup=False):
    src = (HEATING.replace("VOLTAGE", repr(voltage)).replace("THETA", repr(theta))
           .replace("STEPS_BEFORE", "2").replace("BLOWUP", repr(blowup)))
    return run_yade_script(src, timeout=120, cwd=tmp_path, check=True).result


@pytest.mark.parametrize("theta", ["backward-euler", "explicit"])
def test_adiabatic_heating_writes_temperatures(run_yade_script, tmp_path, theta):
    out = _run(run_yade_script, tmp_path, 0.1, theta)
    assert "error" not in out
    assert out["n_rows"] == 5 and out["time"] == pytest.approx(5e-3)
    # adiabatic: the heat gained is the Joule energy (the thermal core checks 1e-9 on its own)
    assert out["heat"] == pytest.approx(out["joule_energy"], rel=1e-9)
    assert out["T_mean"] > 293.15
    assert out["state_type"] == "ThermalState" and out["potential_written"]
    assert out["body_T_max"] == pytest.approx(out["model_T_max"], rel=1e-12)
    assert out["body_T_min"] >= 293.15
    # write_vtk: every body a point, every conducting bond a line, the fields of the model
    assert out["vtk_points"] == out["n_bodies"] and out["vtk_lines"] == out["bonds"] > 0
    assert out["vtk_T_max"] == pytest.approx(out["model_T_max"], rel=1e-12)
    assert out["vtk_V_max"] == pytest.approx(0.1, rel=1e-9)
    rows = list(csv.DictReader(io.StringIO((tmp_path / "heat.csv").read_text())))
    assert len(rows) == 5 and float(rows[-1]["joule_energy"]) == pytest.approx(out["joule_energy"])


def test_non_finite_temperatures_stop_and_keep_the_history(run_yade_script, tmp_path):
    # two good steps, then 1e160 V: the Joule power overflows; the run must stop with a clear
    # error, the bodies keep finite temperatures and the two rows already written stay in the CSV
    out = _run(run_yade_script, tmp_path, 0.1, blowup=True)
    assert "non-finite heat sources" in out["error"] and "state is unchanged" in out["error"]
    assert out["n_rows"] == 2 and out["iters"] == [1, 2]
    rows = list(csv.DictReader(io.StringIO((tmp_path / "heat.csv").read_text())))
    assert len(rows) == 2
    assert all(float(v) == float(v) and abs(float(v)) != float("inf")
               for r in rows for k, v in r.items() if k not in ("graph_revision",))
    assert 293.15 <= out["body_T_min"] <= out["body_T_max"] < 1e4


BCS = SCENE + r'''
from yade_electro.yade import FixedTemperature, Convection
e = ElectroThermalEngine(
    material=Material(resistivity=0.73e-6, density=7900, specific_heat=500, conductivity=15),
    boundaries=[
        Electrode("top", select=TOP, potential=0.05),
        Electrode("bottom", select=BOTTOM, potential=0.0),
        FixedTemperature("cold end", BOTTOM, 293.15),
        Convection("air", pack.inAlignedBox((-1, -1, -1), (1, 1, 1)), h=1e5, t_inf=293.15)],
    temperature=293.15,
    integrator=Integrator(dt=1e-3),
    output=Output(history="bcs.csv"),
    iterPeriod=1)
O.engines = O.engines + [e.runner]
O.run(20, True)
bottom_T = [b.state.temp for b in O.bodies if BOTTOM(tuple(b.state.pos), 0)]
last = e.history.rows[-1]
print(json.dumps(dict(bottom=[min(bottom_T), max(bottom_T)], joule=last["joule_energy"], heat=last["heat_content"],
                      absorbed=last["absorbed_heat"], boundary=last["boundary_heat"],
                      convection=last["convection_heat"], flux=last["flux_heat"], T_max=last["T_max"])))
'''


def test_boundary_conditions_selected_by_predicates(run_yade_script, tmp_path):
    out = run_yade_script(BCS, timeout=120, cwd=tmp_path, check=True).result
    assert out["bottom"] == [293.15, 293.15]                 # held by the fixed-temperature set
    assert out["heat"] < out["joule"]                        # heat leaves through both conditions
    # the history closes the energy balance: stored = Joule - absorbed by the thermostat
    # + received from the fixed elements + from the ambient + from fluxes (received < 0 here)
    assert out["heat"] == pytest.approx(out["joule"] - out["absorbed"] + out["boundary"] + out["convection"]
                                        + out["flux"], rel=1e-9)
    assert out["convection"] < 0 and out["boundary"] < 0 and out["absorbed"] > 0 and out["flux"] == 0


STATE_REPLACED = SCENE + r'''
e = ElectroThermalEngine(
    material=Material(resistivity=0.73e-6, density=7900, specific_heat=500, conductivity=15),
    boundaries=[Electrode("top", select=TOP, potential=0.1), Electrode("bottom", select=BOTTOM, potential=0.0)],
    temperature=293.15,
    integrator=Integrator(dt=1e-3),
    iterPeriod=1)
import meshio
early = meshio.read(e.write_vtk("vtk/early")["particles"]).point_data["temperature"]   # before any call
early = [float(early.min()), float(early.max()), int(early.size)]
O.engines = O.engines + [e.runner]
O.run(3, True)
w = e._temperature_writer
refreshes = w.refreshes
k = e.body_ids.tolist().index(len(O.bodies) // 2)
b = O.bodies[int(e.body_ids[k])]
st = State()                    # a plain State: no temp of YADE's
st.pos, st.mass, st.inertia, st.blockedDOFs = b.state.pos, b.state.mass, b.state.inertia, b.state.blockedDOFs
b.state = st
calls = 0
while calls < 20 and not (isinstance(b.state, ThermalState) and b.state.temp == float(e.temperature[k])):
    O.run(1, True)
    calls += 1
out = dict(calls=calls, thermal=isinstance(b.state, ThermalState), temp=b.state.temp if isinstance(b.state, ThermalState) else None,
           model=float(e.temperature[k]), sweep=w.sweep_calls, refreshes=w.refreshes - refreshes, replaced=w.replaced_states,
           others=max(abs(x.state.temp - t) for x, t in zip(e.reader.bodies, e.temperature.tolist())), early=early)
print(json.dumps(out))
'''


def test_a_state_replaced_by_the_script_gets_the_temperatures(run_yade_script, tmp_path):
    """The engine keeps the bodies' State handles between calls (TemperatureWriter); a state a
    script replaces, here by a plain State without YADE's temp, is found by the sweep within
    sweep_calls calls, made a ThermalState and given the model's temperature. Also: write_vtk
    before the engine's first call writes the starting state."""
    out = run_yade_script(STATE_REPLACED, timeout=120, cwd=tmp_path, check=True).result
    assert out["thermal"] and out["temp"] == out["model"] > 293.15
    assert 1 <= out["calls"] <= out["sweep"]
    assert out["refreshes"] == 1 and out["replaced"] == 1
    assert out["others"] == 0.0
    # write_vtk before the first call: the starting state (the engine reads the scene when built)
    assert out["early"][:2] == [293.15, 293.15] and out["early"][2] > 100
