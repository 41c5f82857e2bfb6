"""Electrodes and a fixed temperature on the faces of a rod, with Joule heating.

A bonded steel rod carries 50 mV between its end faces; its bottom face is held at room
temperature, its side loses heat to the air. The engine heats it step by step while YADE
runs, and its energy ledger closes. Run: ``yade-electro -n -x examples/joule_heating_faces.py``.
"""
import json

from yade_electro import Cylinder
from yade_electro.yade import (Convection, ElectroThermalEngine, Electrode, FixedTemperature, Integrator, Material,
                               Output)
from yade_electro.yade import packing as P

R, L, T_ROOM = 1e-3, 5e-3, 293.15                     # m, m, K
rod = Cylinder((0, 0, 0), (0, 0, L), R)
ids = P.add_bonded_packing(P.dense_packing(rod, n=1500, seed=1))

heat = ElectroThermalEngine(
    material=Material(resistivity=0.73e-6, density=7900.0, specific_heat=500.0, conductivity=15.0),   # 304L
    boundaries=[Electrode("top", surface=rod.face("top"), potential=0.05),
                Electrode("bottom", surface=rod.face("bottom"), potential=0.0),
                FixedTemperature("clamp", surface=rod.face("bottom"), temperature=T_ROOM),
                Convection("air", surface=rod.face("side"), h=25.0, t_inf=T_ROOM)],
    temperature=T_ROOM,
    integrator=Integrator(theta="backward-euler", dt=2e-3),          # 2 ms of heating per call
    output=Output(history="joule.csv"),
    iterPeriod=10)
O.engines = O.engines + [heat.runner]
O.run(500, True)                                     # 50 calls: 0.1 s of heating

row = heat.history.rows[-1]
T = heat.temperature
stored = row["heat_content"]
inputs = (row["joule_energy"] - row["absorbed_heat"] + row["boundary_heat"] + row["convection_heat"]
          + row["flux_heat"] + row["particle_heat"])
print(f"{len(ids)} elements, R_eq = {heat.equivalent_resistance:.4e} ohm, P = {row['joule_power']:.2f} W; "
      f"after {heat.coupled.time:.2f} s: T max {T.max():.2f} K, mean {T.mean():.2f} K; "
      f"heat stored {stored:.4f} J = inputs {inputs:.4f} J")
print(json.dumps({"example": "joule_heating_faces", "n": len(ids), "R_eq": heat.equivalent_resistance,
                  "power_W": row["joule_power"], "time_s": heat.coupled.time, "T_max": float(T.max()),
                  "T_min": float(T.min()), "heat_stored_J": stored, "heat_inputs_J": inputs,
                  "T_body0": O.bodies[ids[0]].state.temp}))
