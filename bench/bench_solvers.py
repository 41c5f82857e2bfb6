"""Linear solvers on the rod's Kirchhoff problem: cold solve, and re-solve after a 1 % change of
the conductances with the kept structure and solver setup. Picks the default ('auto') by size.

For each size (the bonded rods of the rod case, continuum law, end layers at 1 V / 0 V) and
each solver ('cg' = Jacobi-CG, 'cg-deflated', 'cg-amg', 'direct'):

* ``cold_ms``: a new ConductionProblem on the changed conductances (structure: reduced
  indexing, parts, patterns) and its first solve (solver setup included): what every call
  cost before the structure was kept;
* ``cold_solve_ms``: the first solve alone (setup + iterations from zero), structure built;
* ``resolve_ms``: ``update_conductance`` (values in place, solver ``update``) + the solve,
  warm-started from the previous potentials;
* ``resolve_ratio = resolve_ms / cold_ms``, ``resolve_over_cold_solve = resolve_ms /
  cold_solve_ms``; iteration counts of both.

Blocks of the solvers are interleaved, best of ``--repeat``; OpenBLAS limited to one thread
(threadpoolctl when present; YADE runs one). One JSON line per size and solver, then a summary
line naming the fastest re-solve per size.

    python3 bench/bench_solvers.py [--sizes 1000,5000,20000] [--repeat 5]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("bench_solvers.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_solvers.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, os.path.join(os.path.dirname(HERE), "cases"))

import numpy as np  # noqa: E402

SOLVERS = ("cg", "cg-deflated", "cg-amg", "direct")


def rod_problem(n, seed=1):
    """(graph, conductances, electrodes) of the rod case's bonded packing (no YADE)."""
    import rod_resistance as rod
    from yade_electro.laws.factors import conductance
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.core.graph import ContactGraph
    from yade_electro.network.kirchhoff import Electrode
    from yade_electro.packing import bond_pairs, dense_packing
    pk = dense_packing(Cylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS), n=n, seed=seed)
    g = ContactGraph(pk.centers, pk.radii, bond_pairs(pk.centers, pk.radii))
    bottom, top = rod.end_layers(pk.centers[:, 2], pk.radii, float(np.mean(pk.radii)))
    el = [Electrode("top", np.flatnonzero(top), potential=1.0), Electrode("bottom", np.flatnonzero(bottom), potential=0.0)]
    return g, conductance(g, rod.RHO_304L), el


def bench_size(n, repeat):
    from yade_electro.network.conduction import ConductionProblem
    g, c, el = rod_problem(n)
    rng = np.random.default_rng(0)
    best = {s: {} for s in SOLVERS}
    for _ in range(repeat):
        for solver in SOLVERS:                     # interleaved blocks
            if solver == "direct" and g.n_nodes > 50000:
                continue
            b = best[solver]
            c1 = c * (1 + 0.01 * rng.standard_normal(c.size))
            t = time.perf_counter()
            p = ConductionProblem(g.n_nodes, g.edges, c1, el, solver=solver, coords=g.pos)
            t_struct = time.perf_counter() - t
            s0 = p.solve()
            t_cold = time.perf_counter() - t
            c2 = c1 * (1 + 0.01 * rng.standard_normal(c.size))
            t = time.perf_counter()
            p.update_conductance(c2)
            s1 = p.solve()
            t_re = time.perf_counter() - t
            for k, v in (("cold_ms", t_cold), ("cold_solve_ms", t_cold - t_struct), ("resolve_ms", t_re)):
                b[k] = min(b.get(k, np.inf), 1e3 * v)
            b["cold_iterations"] = int(s0.info["iterations"])
            b["resolve_iterations"] = int(s1.info["iterations"])
            b["setups"] = int(getattr(p.solver, "n_setups", 0))
    rows = []
    for solver in SOLVERS:
        b = best[solver]
        if not b:
            continue
        row = {"bench": "solvers", "n": int(g.n_nodes), "n_unknowns": int(p.system.n_unknowns), "solver": solver,
               **{k: (round(v, 3) if isinstance(v, float) else v) for k, v in b.items()},
               "resolve_ratio": round(b["resolve_ms"] / b["cold_ms"], 3),
               "resolve_over_cold_solve": round(b["resolve_ms"] / b["cold_solve_ms"], 3),
               "load_average": os.getloadavg()[0]}
        print(json.dumps(row), flush=True)
        rows.append(row)
    return rows


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="1000,5000,20000")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(argv)
    try:
        from threadpoolctl import threadpool_limits
        threadpool_limits(1)
    except ImportError:
        pass
    summary = {}
    for n in (int(x) for x in args.sizes.split(",")):
        rows = bench_size(n, args.repeat)
        fastest = min(rows, key=lambda r: r["resolve_ms"])
        cold = min(rows, key=lambda r: r["cold_ms"])
        summary[str(rows[0]["n"])] = {"fastest_resolve": fastest["solver"], "fastest_cold": cold["solver"]}
    print(json.dumps({"bench": "solvers_summary", "by_size": summary}))


if __name__ == "__main__":
    main()
