"""A run under MPI: every rank runs the whole scene and the ranks share the electrical solve
(``solver='petsc'``: PETSc's CG + GAMG distributed over them); rank 0 prints.

Run: ``mpiexec -n 2 yade-electro -n -x examples/mpi_petsc.py`` (as root, add
``--allow-run-as-root``). YADE's own domain decomposition (``yade.mpy``) is not used here: the
engines refuse its subdomains, which would each see part of the packing.
"""
import json

from yade_electro import Cylinder
from yade_electro.solvers.petsc import import_petsc
from yade_electro.yade import ElectricalEngine, Electrode, Material
from yade_electro.yade import packing as P

comm = import_petsc().COMM_WORLD
R, L, RHO = 1e-3, 5e-3, 0.73e-6
rod = Cylinder((0, 0, 0), (0, 0, L), R)
ids = P.add_bonded_packing(P.dense_packing(rod, n=3000, seed=1))    # the same scene on every rank

electro = ElectricalEngine(
    material=Material(resistivity=RHO),
    boundaries=[Electrode("top", surface=rod.face("top"), potential=1.0),
                Electrode("bottom", surface=rod.face("bottom"), potential=0.0)],
    solver="petsc",
    iterPeriod=10)
O.engines = O.engines + [electro.runner]
O.run(20, True)

info = electro.solution.info
if comm.getRank() == 0:
    print(f"{comm.getSize()} rank(s), {len(ids)} elements: R_eq = {electro.equivalent_resistance:.5e} ohm "
          f"({info.get('solver')}, {info.get('iterations')} iterations)")
    print(json.dumps({"example": "mpi_petsc", "ranks": comm.getSize(), "n": len(ids),
                      "R_eq": electro.equivalent_resistance, "solver": info.get("solver"),
                      "iterations": int(info.get("iterations", 0)), "residual": electro.solution.residual}))
