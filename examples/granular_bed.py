"""A granular bed heated through its contacts and a hot floor.

Copper spheres fall into a box onto a floor held at 100 degC; the side walls are adiabatic.
The heat engine follows the contacts YADE makes and loses as the bed settles, and the heat the
floor gives is what the bed stores. Run: ``yade-electro -n -x examples/granular_bed.py``.
"""
import json

import numpy as np
from yade import pack, utils

from yade_electro.yade import HeatEngine, Integrator, Law, Material, Output, Reader, Wall

T_BED, T_FLOOR, SIDE = 293.15, 373.15, 0.012                       # K, K, box side [m]
O.materials.append(FrictMat(young=1e7, poisson=0.3, density=8900, frictionAngle=0.5, label="copper"))
sp = pack.SpherePack()
sp.makeCloud((0, 0, 0), (SIDE, SIDE, 2 * SIDE), rMean=0.8e-3, rRelFuzz=0.2, seed=1)
sp.toSimulation(material="copper")
floor = O.bodies.append(utils.wall(0, axis=2, sense=1))
sides = [O.bodies.append(utils.wall(x, axis=a, sense=s)) for a in (0, 1) for x, s in ((0, 1), (SIDE, -1))]
O.engines = [ForceResetter(),
             InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
             InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                             [Ip2_FrictMat_FrictMat_MindlinPhys(en=MatchMaker(algo="val", val=0.3))],
                             [Law2_ScGeom_MindlinPhys_Mindlin()]),
             NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.3)]
O.dt = 0.5 * utils.PWaveTimeStep()

heat = HeatEngine(
    material=Material(density=8900.0, specific_heat=385.0, conductivity=400.0),
    boundaries=[Wall("floor", bodies=floor, temperature=T_FLOOR)],      # walls not named: adiabatic
    temperature=T_BED,
    # the contact radius a of g = 2 a: the lens where the two spheres' surfaces cross (the
    # default; for equal spheres sqrt(2) times Hertz's a = sqrt(R* delta)); radius="hertz" for Hertz
    law=Law("contact", radius="geometric"),
    integrator=Integrator(theta="explicit"),               # sub-cycled to its stable step by itself
    reader=Reader(bonds="contacts"),
    output=Output(history="bed.csv"),
    iterPeriod=20)
O.engines = O.engines + [heat.runner]
O.run(20000, True)

row, T = heat.history.rows[-1], heat.temperature
stored = row["heat_content"]
print(f"{T.size} spheres, {heat.contact_heat_flow()[1].size} contacts after {O.time:.3f} s: "
      f"bed mean {np.mean(T) - 273.15:.2f} degC, hottest {np.max(T) - 273.15:.2f} degC; "
      f"the floor gave {heat.wall_heat()['floor']:.4f} J, the bed stored {stored:.4f} J")
print(json.dumps({"example": "granular_bed", "n": int(T.size), "time_s": O.time, "T_mean": float(np.mean(T)),
                  "T_max": float(np.max(T)), "floor_heat_J": heat.wall_heat()["floor"], "heat_stored_J": stored,
                  "particle_heat_J": row["particle_heat"], "contacts": int(heat.contact_heat_flow()[1].size)}))
