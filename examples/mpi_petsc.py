"""A run distributed over the ranks of ``mpiexec``: each rank owns a slab of the rod and holds,
assembles and solves only its share of the network (``solver='petsc'``: PETSc's CG on a
partitioned matrix, preconditioned by our deflation); rank 0 prints. The same script runs
serially (``yade-electro -n -x examples/mpi_petsc.py``: PETSc's CG + GAMG on one rank).

Run: ``mpiexec -n 2 yade-electro -n -x examples/mpi_petsc.py`` (as root, add
``--allow-run-as-root``). Inside YADE's MPI mode (``yade.mpy``) the same engine keeps YADE's
subdomains: see docs/guide/large-runs-and-mpi.md.
"""
import json

import numpy as np

from yade_electro import Cylinder
from yade_electro.yade import ElectricalEngine, Electrode, Material
from yade_electro.yade import packing as P
from yade_electro.yade.distributed import world_rank, world_size

R, L, RHO = 1e-3, 5e-3, 0.73e-6
rod = Cylinder((0, 0, 0), (0, 0, L), R)
packing = P.dense_packing(rod, n=3000, seed=1)
ids = np.asarray(P.add_bonded_packing(packing))       # the same scene on every rank
z, r = packing.centers[:, 2], packing.radii

electro = ElectricalEngine(
    material=Material(resistivity=RHO),
    boundaries=[Electrode("top", select=ids[z + r >= L - 0.1 * r.mean()], potential=1.0),
                Electrode("bottom", select=ids[z - r <= 0.1 * r.mean()], potential=0.0)],
    law="continuum",
    solver="petsc",
    iterPeriod=10)
O.engines = O.engines + [electro.runner]
O.run(20, True)

if world_rank() == 0:
    print(f"{world_size()} rank(s), {len(ids)} elements: R_eq = {electro.equivalent_resistance:.5e} ohm "
          f"({'distributed' if electro.distributed else 'one rank'})")
    print(json.dumps({"example": "mpi_petsc", "ranks": world_size(), "n": len(ids), "distributed": electro.distributed,
                      "R_eq": electro.equivalent_resistance}))
