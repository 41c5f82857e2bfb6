"""A rod heated by its own current expands: ElectroThermalEngine writes the temperatures,
ThermalExpansion turns them into longer bonds, YADE moves the rod.

A bonded steel rod carries 0.2 V between its end faces with no heat loss, so it heats almost
uniformly. After 0.1 s of heating the current is switched off and YADE lets the free rod
settle; its elongation is alpha times its mean temperature rise times its length.
Run: ``yade-electro -n -x examples/thermal_expansion.py``.
"""
import json

import numpy as np

from yade_electro import Cylinder
from yade_electro.yade import ElectroThermalEngine, Electrode, Integrator, Material, ThermalExpansion
from yade_electro.yade import packing as P

R, L, T_ROOM, ALPHA = 1e-3, 5e-3, 293.15, 1.7e-5          # m, m, K, 1/K (304L)
rod = Cylinder((0, 0, 0), (0, 0, L), R)
ids = P.add_bonded_packing(P.dense_packing(rod, n=1500, seed=1), damping=0.5)
bodies = [O.bodies[i] for i in ids]
z0 = np.array([b.state.pos[2] for b in bodies])

heat = ElectroThermalEngine(
    material=Material(resistivity=0.73e-6, density=7900.0, specific_heat=500.0, conductivity=15.0),
    boundaries=[Electrode("top", surface=rod.face("top"), potential=0.2),
                Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
    temperature=T_ROOM, integrator=Integrator(theta="backward-euler", dt=2e-3), iterPeriod=10)
# the heat engine writes the temperatures at its first call: the reference is given here
expansion = ThermalExpansion(alpha=ALPHA, mode="bonds", reference_temperature=T_ROOM, iterPeriod=10,
                             history="expansion.csv")
O.engines = O.engines + [heat.runner, expansion.runner]     # temperatures first, then expansion
O.run(500, True)                                  # 50 calls: 0.1 s of heating
heat.remove()                                     # current off; the rod keeps its temperatures
O.run(3000, True)                                 # the free rod settles

z = np.array([b.state.pos[2] for b in bodies])
strain = float(np.polyfit(z0, z - z0, 1)[0])
dT = float(np.mean([b.state.temp for b in bodies]) - T_ROOM)
row = expansion.history.rows[-1]
print(f"{len(ids)} elements heated by {dT:.2f} K: axial strain {strain:.4e} against alpha dT = {ALPHA * dT:.4e}; "
      f"mean stress s_zz {row['s_zz_Pa']:.3g} Pa, largest bond tension {row['bond_tension_max_N']:.3g} N")
print(json.dumps({"example": "thermal_expansion", "n": len(ids), "dT_K": dT, "strain": strain,
                  "alpha_dT": ALPHA * dT, "s_zz_Pa": row["s_zz_Pa"], "rows": len(expansion.history.rows)}))
