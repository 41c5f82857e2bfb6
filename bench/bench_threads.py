"""OpenBLAS threads and the solvers, in a plain ``/usr/bin/python3`` (not inside YADE, which
runs one): the same solves with OpenBLAS at 1 and at 2 threads, blocks interleaved.

For each size (the jittered lattice rods of bench_scale.py) and solver ('cg',
'cg-deflated'): best of ``--repeat`` cold solves at each thread count, and
``ratio_2_over_1``. One JSON line per size and solver. The thread count is switched at run
time with ``yade_electro.core.threads.limit_blas_threads`` (OpenBLAS' own call).

    /usr/bin/python3 bench/bench_threads.py [--sizes 5000,20000,100000] [--repeat 5]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

os.environ["YADE_ELECTRO_BLAS_THREADS"] = "0"        # this bench sets the threads itself
_SCRIPT = __file__ if __file__.endswith("bench_threads.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_threads.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--sizes", default="5000,20000,100000")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from bench_scale import RADIUS, RHO, jittered_rod, reduced_rod_system
    from yade_electro.laws.factors import conductance
    from yade_electro.solvers.registry import make_solver
    from yade_electro.core.threads import blas_threads, limit_blas_threads
    start = blas_threads()
    for n in (int(s) for s in args.sizes.split(",")):
        g, top, bottom = jittered_rod(n)
        _, Kuu, _, b, coords = reduced_rod_system(g, top, bottom, conductance(g, RHO, "continuum"))
        for name in ("cg", "cg-deflated"):
            best = {1: np.inf, 2: np.inf}
            for _ in range(args.repeat):
                for threads in (1, 2):
                    limit_blas_threads(threads)
                    s = make_solver(name, Kuu.shape[0])
                    s.set_geometry(coords, 2 * RADIUS)
                    t = time.perf_counter()
                    s.solve(Kuu, b)
                    best[threads] = min(best[threads], 1e3 * (time.perf_counter() - t))
            print(json.dumps({"bench": "threads", "n": int(g.n_nodes), "solver": name, "ms_1_thread": best[1],
                              "ms_2_threads": best[2], "ratio_2_over_1": best[2] / best[1],
                              "openblas_threads_at_start": start, "loadavg": os.getloadavg()[0]}), flush=True)


if __name__ == "__main__":
    main()
