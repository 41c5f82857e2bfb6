"""A bonded rod solved with ``solver='petsc'`` on the ranks of ``mpiexec``.

The rod of ``rod_resistance.py`` (R = 1 mm, L = 5 mm, 304L, 1 V between its end layers) is
built on every rank (the same seed, so the same scene); the electrical engine solves it
with PETSc's CG + GAMG distributed over the ranks, and then, for comparison, with the
serial ``cg-deflated`` on each rank. Rank 0 prints the figures: R_eq of both, the largest
potential difference (in V, for 1 V applied), iterations and solve times.

Run
---
    mpiexec -n 2 yade-electro -n -x cases/mpi_rod.py --n 20000
    yade-electro -n -x cases/mpi_rod.py --n 20000            # one rank (MPI singleton)

As root, OpenMPI needs ``--allow-run-as-root`` (or ``OMPI_ALLOW_RUN_AS_ROOT=1
OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1``). YADE 2023.02a notices ``mpiexec`` and prints
"mpy already disconnected" at exit: its own MPI module (``yade.mpy``) is loaded but not
used; see docs/benchmarks.md for what works with it.

Ends with one JSON line (rank 0 only).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("mpi_rod.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("mpi_rod.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)
from rod_resistance import RHO_304L, build_rod  # noqa: E402

from yade_electro.yade.runtime import import_yade  # noqa: E402


def _solve(spec, law, solver, label):
    from yade_electro.yade import ElectricalEngine, Material, electrodes_from_dict
    yade = import_yade()
    O = yade.Omega()
    engine = ElectricalEngine(
        material=Material(resistivity=RHO_304L),
        boundaries=electrodes_from_dict(spec),
        law=law,
        solver=solver,
        iterPeriod=1,
        label=label)
    O.engines = O.engines + [engine.runner]
    t = time.perf_counter()
    O.step()
    dt = time.perf_counter() - t
    info = engine.solution.info
    out = {"R_eq": float(engine.equivalent_resistance), "potential": engine.potential.copy(),
           "ids": engine.body_ids.copy(), "t_step_s": dt, "solver": info.get("solver"),
           "iterations": int(info.get("iterations", 0)), "residual": float(engine.solution.residual)}
    engine.remove()
    return out


def run_mpi_rod(n=20000, seed=1, law="continuum", cache_dir=None):
    """Build the rod, solve it with 'petsc' (all ranks) and 'cg-deflated' (each rank); return
    the figures (the same on every rank)."""
    from yade_electro.solvers.petsc import import_petsc
    comm = import_petsc().COMM_WORLD
    rod = build_rod(n, seed, cache_dir=cache_dir)
    ids, bottom, top = rod["ids"], rod["bottom"], rod["top"]
    t_pack = rod["t_packing_s"] + rod["t_bonding_s"]
    spec = {"top": dict(select=ids[top], potential=1.0), "bottom": dict(select=ids[bottom], potential=0.0)}
    par = _solve(spec, law, "petsc", "rod_petsc")
    ser = _solve(spec, law, "cg-deflated", "rod_serial")
    if not np.array_equal(par["ids"], ser["ids"]):
        raise RuntimeError("the two engines saw different bodies")
    dphi = float(np.max(np.abs(par["potential"] - ser["potential"])))
    # every rank must have built the same scene and got the same potentials
    digest = comm.tompi4py().allgather((int(ids.size), float(np.sum(par["potential"]))))
    return {"case": "mpi_rod", "ranks": comm.getSize(), "n": int(ids.size), "seed": int(seed), "law": law,
            "R_eq_petsc": par["R_eq"], "R_eq_serial": ser["R_eq"],
            "R_rel_diff": abs(par["R_eq"] - ser["R_eq"]) / ser["R_eq"],
            "max_potential_diff_V": dphi,
            "ranks_agree": all(d == digest[0] for d in digest),
            "solvers": [par["solver"], ser["solver"]], "iterations": [par["iterations"], ser["iterations"]],
            "residuals": [par["residual"], ser["residual"]],
            "t_step_petsc_s": par["t_step_s"], "t_step_serial_s": ser["t_step_s"], "t_packing_s": t_pack}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--law", default="continuum")
    args = ap.parse_args(argv)
    row = run_mpi_rod(args.n, args.seed, args.law)
    from yade_electro.solvers.petsc import import_petsc
    if import_petsc().COMM_WORLD.getRank() == 0:
        print(f"{row['ranks']} rank(s), {row['n']} elements: R_eq {row['R_eq_petsc']:.6e} ohm (petsc), "
              f"{row['R_eq_serial']:.6e} ohm (cg-deflated); max |dphi| {row['max_potential_diff_V']:.2e} V; "
              f"step {row['t_step_petsc_s']:.3f} s against {row['t_step_serial_s']:.3f} s")
        print(json.dumps(row))
    return row


if __name__ == "__main__":
    main(sys.argv[1:])
