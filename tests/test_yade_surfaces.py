"""Surface boundary conditions, the heat-only engine and steady states in real YADE (issue 7).

A bonded rod (R = 0.5 mm, L = 2 mm, 400 elements) made by ``dense_packing`` and
``add_bonded_packing``, which leave the container in the scene: the engines then default
to the 'voronoi' law and take ``rod.face(...)`` surfaces without being told the container.
"""
import pytest

from yade_snippets import BONDED_ROD

COMMON = BONDED_ROD + r'''
import json, math
import numpy as np
from yade_electro.yade import ElectricalEngine, ElectroThermalEngine, HeatEngine, attach, Electrode, Integrator, Law, Material
from yade_electro.yade import FixedTemperature, Convection
from yade_electro.yade import HeatSource
RHO, LAM = 7.3e-7, 16.2
'''

STEADY = COMMON + r'''
build()
el = ElectricalEngine(
    material=Material(resistivity=RHO),
    boundaries=[
        Electrode("top", surface=rod.face("top"), potential=1.0),
        Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
    label="el")
heat = HeatEngine(
    material=Material(density=7900.0, specific_heat=500.0, conductivity=LAM),
    boundaries=[
        FixedTemperature("cold", surface=rod.face("bottom"), temperature=300.0),
        FixedTemperature("hot", surface=rod.face("top"), temperature=400.0)],
    temperature=300.0,
    integrator=Integrator(steady=True),
    label="heat")
O.engines = O.engines + [el.runner, heat.runner]
O.run(3, True)
z = np.array([O.bodies[int(i)].state.pos[2] for i in heat.body_ids])
T = heat.temperature
out = dict(law=el.model.law.name, heat_law=heat.coupled.network.law.name,
           R=el.equivalent_resistance, R_nominal=RHO * L / (math.pi * RAD ** 2),
           lin_err=float(np.max(np.abs(T - (300.0 + 100.0 * z / L))) / 100.0),
           body_T=float(O.bodies[int(heat.body_ids[0])].state.temp), T0=float(T[0]), time=heat.coupled.time)
# Joule heating to a steady state, the end faces held at 300 K: the parabola
# T = 300 + q z (L - z) / (2 lambda), q = V^2 / (rho L^2)
V = 0.05
et = ElectroThermalEngine(
    material=Material(resistivity=RHO, density=7900.0, specific_heat=500.0, conductivity=LAM),
    boundaries=[
        Electrode("top", surface=rod.face("top"), potential=V),
        Electrode("bottom", surface=rod.face("bottom"), potential=0.0),
        FixedTemperature("a", surface=rod.face("bottom"), temperature=300.0),
        FixedTemperature("b", surface=rod.face("top"), temperature=300.0)],
    temperature=300.0,
    label="et")
row = et.steady_state()
q = V ** 2 / (RHO * L ** 2)
exact = q * z * (L - z) / (2 * LAM)
rise = et.temperature - 300.0
out.update(parabola_rms=float(np.sqrt(np.mean((rise - exact) ** 2)) / exact.max()),
           joule=row["joule_power"], joule_exact=V ** 2 / (RHO * L / (math.pi * RAD ** 2)),
           balance=row["steady_balance_error"])
O.save("steady.yade.gz")
print(json.dumps(out))
'''

RELOAD = COMMON + r'''
O.load("steady.yade.gz")
el, heat = attach("el"), attach("heat")
O.run(2, True)
print(json.dumps(dict(R=el.equivalent_resistance, T0=float(heat.temperature[0]),
                      surfaces=sorted(heat.coupled.bc_surfaces), law=el.model.law.name)))
'''

BAD = COMMON + r'''
build()
from yade_electro.core.errors import BoundaryConditionError
out = {}
from yade_electro.geometry.surfaces import Plane
inside = Plane((0, 0, L / 2), (0, 0, 1), tol=1e-9)
for name, make in (
        ("electrode", lambda: ElectricalEngine(
            material=Material(resistivity=RHO),
            boundaries=[
                Electrode("a", surface=inside, potential=1.0),
                Electrode("b", surface=rod.face("bottom"), potential=0.0)])),
        ("convection", lambda: HeatEngine(
            material=Material(density=7900.0, specific_heat=500.0, conductivity=LAM),
            boundaries=[Convection("air", surface=inside, h=10.0, t_inf=300.0)],
            temperature=300.0)),
        ("steady", lambda: HeatEngine(
            material=Material(density=7900.0, specific_heat=500.0, conductivity=LAM),
            boundaries=[HeatSource("q", density=1e6)],
            temperature=300.0).steady_state()),
        ("crack", lambda: ElectricalEngine(
            material=Material(resistivity=RHO),
            boundaries=[
                Electrode("a", surface=rod.face("top"), potential=1.0),
                Electrode("b", surface=rod.face("bottom"), potential=0.0)],
            law=Law("continuum", crack="facets")))):
    try:
        make()
        out[name] = "no error"
    except Exception as exc:
        out[name] = f"{type(exc).__name__}: {exc}"
print(json.dumps(out))
'''


def test_surfaces_heat_only_and_steady_states(run_yade_script, tmp_path):
    out = run_yade_script(STEADY, cwd=tmp_path, check=True).result
    assert out["law"] == out["heat_law"] == "voronoi"               # the scene's container: the default law
    assert out["R"] == pytest.approx(out["R_nominal"], rel=0.01)     # end faces: no L - 2 r_mean
    assert out["lin_err"] < 0.01                                    # T linear between the two held faces
    assert out["body_T"] == out["T0"] and out["time"] == 0.0        # written back; steady: no clock
    assert out["parabola_rms"] < 0.01
    assert out["joule"] == pytest.approx(out["joule_exact"], rel=0.01)
    assert out["balance"] < 1e-8
    again = run_yade_script(RELOAD, cwd=tmp_path, check=True).result
    assert again["R"] == pytest.approx(out["R"], rel=1e-12)
    assert again["T0"] == pytest.approx(out["T0"], rel=1e-12)
    assert again["surfaces"] == ["cold", "hot"] and again["law"] == "voronoi"


def test_bad_surface_input_is_refused_when_the_engine_is_built(run_yade_script, tmp_path):
    out = run_yade_script(BAD, cwd=tmp_path, check=True).result
    assert out["electrode"].startswith("BoundaryConditionError") and "boundary faces" in out["electrode"]
    assert out["convection"].startswith("BoundaryConditionError") and "boundary faces" in out["convection"]
    assert out["steady"].startswith("ThermalError") and "no fixed temperature and no convection" in out["steady"]
    assert out["crack"].startswith("ValueError") and "no Voronoi faces" in out["crack"]
