"""An electrical engine in your own YADE script, on a packing YADE made.

YADE packs a rod (``pack.randomDensePack``), yade-electro bonds it as a solid and one engine
in ``O.engines`` gives the potentials, the currents and the equivalent resistance while
YADE runs. Run it with ``yade-electro -n -x examples/electrical_engine.py``.
"""
import json

import numpy as np
from yade import pack

from yade_electro import Cylinder
from yade_electro.yade import ElectricalEngine, Electrode, Material, Output
from yade_electro.yade import packing as P

R, L, RHO = 1e-3, 5e-3, 0.73e-6                  # rod radius and length [m], 304L steel [ohm m]
rod = Cylinder((0, 0, 0), (0, 0, L), R)
sp = pack.randomDensePack(pack.inCylinder((0, 0, 0), (0, 0, L), R), radius=0.1e-3, rRelFuzz=0.25,
                          spheresInCell=500, returnSpherePack=True, seed=1)
centers = np.array([c for c, _ in sp])
radii = np.array([r for _, r in sp])
ids = P.add_bonded_packing(P.bonded_packing(centers, radii, rod))   # CohFrictMat bonds, rod kept

electro = ElectricalEngine(
    material=Material(resistivity=RHO),
    boundaries=[Electrode("top", surface=rod.face("top"), potential=1.0),
                Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
    output=Output(history="electro.csv"),
    iterPeriod=100)
O.engines = O.engines + [electro.runner]
O.run(300, True)

R_eq, R_nominal = electro.equivalent_resistance, RHO * L / (np.pi * R ** 2)
print(f"{len(ids)} elements: R_eq = {R_eq:.5e} ohm, rho L / (pi R^2) = {R_nominal:.5e} ohm "
      f"({100 * (R_eq / R_nominal - 1):+.2f} %); I = {electro.electrode_currents['top']:.2f} A")
print(json.dumps({"example": "electrical_engine", "n": len(ids), "R_eq": R_eq, "R_nominal": R_nominal,
                  "I_top": electro.electrode_currents["top"], "I_bottom": electro.electrode_currents["bottom"],
                  "V_body0": O.bodies[ids[0]].potential, "history_rows": len(electro.history)}))
