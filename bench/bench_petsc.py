"""``solver='petsc'`` (CG + GAMG) on 1 and 2 MPI ranks against the serial default, same systems.

    /usr/bin/python3 bench/bench_petsc.py [--sizes 20000,100000,500000] [--repeat 2]

The driver starts ``mpiexec -n 1`` and ``mpiexec -n 2`` runs of this script (``--worker``) in
interleaved blocks. Each worker builds the jittered lattice rod of ``bench_scale.py`` on every
rank (the assembly is replicated), then times on the reduced system:
- the cold PETSc solve (matrix hand-over, GAMG setup, CG iterations) and a re-solve after a
  +-1 % change of every conductance (values in place, GAMG's interpolation kept, warm start);
- on one rank, the serial default (``cg-deflated``) on the same system, and the largest
  difference between the two solutions (potentials in V for 1 V applied).
One JSON line per size, with the best of ``--repeat`` blocks, the load average and the
speed-up of 2 ranks over 1. OpenMPI runs as root here, so the driver sets
``OMPI_ALLOW_RUN_AS_ROOT``; OpenBLAS and OpenMP are held to one thread per rank.
"""
from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.dirname(HERE))


def log(msg):
    print(f"[bench_petsc] {msg}", file=sys.stderr, flush=True)


def worker(sizes):
    from bench_scale import RADIUS, jittered_rod, reduced_rod_system
    from yade_electro.laws.factors import conductance
    from yade_electro.solvers.petsc import PETScSolver, import_petsc
    from yade_electro.solvers.registry import make_solver
    PETSc = import_petsc()
    comm = PETSc.COMM_WORLD
    rank, size = comm.getRank(), comm.getSize()
    for n in sizes:
        g, top, bottom = jittered_rod(n)
        c = conductance(g, 0.73e-6, "continuum")
        rs, Kuu, Kud, b, coords = reduced_rod_system(g, top, bottom, c)
        row = {"n": int(g.n_nodes), "unknowns": int(Kuu.shape[0]), "ranks": size}
        comm.barrier()
        t = time.perf_counter()
        s = PETScSolver()
        x, info = s.solve(Kuu, b)
        comm.barrier()
        row["petsc_cold_ms"] = 1e3 * (time.perf_counter() - t)
        row["petsc_setup_ms"] = 1e3 * info["setup_time"]
        row["petsc_iterations"] = info["iterations"]
        rng = np.random.default_rng(2)
        c2 = c * (1.0 + 0.01 * rng.uniform(-1.0, 1.0, c.size))
        comm.barrier()
        t = time.perf_counter()
        rs.assemble(c2)
        b2 = -(Kud @ np.array([1.0, 0.0]))
        s.update(Kuu)
        x2, info2 = s.solve(Kuu, b2, x0=x)
        comm.barrier()
        row["petsc_resolve_ms"] = 1e3 * (time.perf_counter() - t)
        row["petsc_resolve_iterations"] = info2["iterations"]
        if size == 1:
            d = make_solver("auto", Kuu.shape[0])
            d.set_geometry(coords, 2.0 * RADIUS)
            t = time.perf_counter()
            y, dinfo = d.solve(Kuu, b2)
            row["serial_ms"] = 1e3 * (time.perf_counter() - t)
            row["serial_solver"], row["serial_iterations"] = dinfo["solver"], dinfo["iterations"]
            row["max_potential_diff_V"] = float(np.max(np.abs(y - x2)))
        if rank == 0:
            print(json.dumps(row), flush=True)


def run_worker(ranks, sizes):
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1",
               OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1")
    cmd = ["mpiexec", "-n", str(ranks), sys.executable, os.path.abspath(__file__), "--worker",
           "--sizes", ",".join(map(str, sizes))]
    from yade_electro.core.mpi_network import private_network
    out = subprocess.run(private_network(cmd), env=env, check=True, capture_output=True, text=True)
    return [json.loads(line) for line in out.stdout.splitlines() if line.startswith("{")]


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="20000,100000,500000")
    ap.add_argument("--repeat", type=int, default=2)
    ap.add_argument("--worker", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    sizes = [int(s) for s in args.sizes.split(",")]
    if args.worker:
        worker(sizes)
        return
    best = {}
    for k in range(args.repeat):
        for ranks in (1, 2):
            t = time.perf_counter()
            for row in run_worker(ranks, sizes):
                key = (row["n"], ranks)
                old = best.get(key)
                if old is None:
                    best[key] = row
                else:
                    for f in ("petsc_cold_ms", "petsc_resolve_ms", "serial_ms"):
                        if f in row:
                            old[f] = min(old[f], row[f])
            log(f"block {k + 1}/{args.repeat}, {ranks} rank(s): {time.perf_counter() - t:.0f} s")
    for n in sorted({key[0] for key in best}):
        one, two = best[(n, 1)], best[(n, 2)]
        print(json.dumps({
            "bench": "petsc", "n": n, "unknowns": one["unknowns"],
            "serial_solver": one["serial_solver"], "serial_ms": one["serial_ms"],
            "serial_iterations": one["serial_iterations"],
            "petsc_1rank_cold_ms": one["petsc_cold_ms"], "petsc_2rank_cold_ms": two["petsc_cold_ms"],
            "petsc_1rank_setup_ms": one["petsc_setup_ms"], "petsc_2rank_setup_ms": two["petsc_setup_ms"],
            "petsc_iterations": [one["petsc_iterations"], two["petsc_iterations"]],
            "petsc_1rank_resolve_ms": one["petsc_resolve_ms"], "petsc_2rank_resolve_ms": two["petsc_resolve_ms"],
            "speedup_2_ranks_cold": one["petsc_cold_ms"] / two["petsc_cold_ms"],
            "speedup_2_ranks_resolve": one["petsc_resolve_ms"] / two["petsc_resolve_ms"],
            "petsc_2rank_cold_vs_serial": two["petsc_cold_ms"] / one["serial_ms"],
            "max_potential_diff_V": one["max_potential_diff_V"],
            "repeat": args.repeat, "loadavg": os.getloadavg()[0]}))


if __name__ == "__main__":
    main()
