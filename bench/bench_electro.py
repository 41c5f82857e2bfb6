"""Electrical benchmark on the bonded rods of the rod case (5,000 and 20,000 elements).

Prints, per size: graph extraction from YADE (full read, and the cheap unchanged check),
assembly (conductances + reduced Kirchhoff system), the ``continuum`` law's factors after a
move (compiled and numpy, interleaved), solve time cold (first solve, solver
setup included) and re-solve with an unchanged graph, for each solver, and the time of one
YADE mechanical step on the same bonded packing. Ends with one JSON line.

    yade-electro -n -x bench/bench_electro.py [--sizes 5000,20000] [--repeat 5]
"""
from __future__ import annotations

import os
import sys
import time

import numpy as np


# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("bench_electro.py") else (sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_electro.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))

sys.path.insert(0, HERE)
from _benchlib import best, bonded_rod, run_sizes, to_ms  # noqa: E402
from yade_electro.yade.runtime import import_yade  # noqa: E402


def bench_size(n, repeat=5, seed=1):
    yade = import_yade()
    from yade import pack
    from yade_electro.laws.factors import conductance
    from yade_electro.network.conduction import ConductionProblem
    from yade_electro.network.kirchhoff import Electrode
    from yade_electro.yade import SceneReader
    from yade_electro.yade import packing as P
    import rod_resistance as rod

    O, ids, bottom, top = bonded_rod(n, seed)
    out = {"n": int(len(ids))}

    def full_read():
        reader = SceneReader(O, geometry_every=0)
        return reader, reader.read()
    out["extract_full_ms"], (reader, graph) = best(full_read, repeat)
    out["n_edges"] = int(graph.n_edges)
    out["extract_unchanged_ms"], _ = best(reader.read, repeat)
    reader_count = SceneReader(O, geometry_every=0, bond_check="count")
    reader_count.read()
    out["extract_unchanged_count_only_ms"], _ = best(reader_count.read, repeat)
    reader_geo = SceneReader(O, geometry_every=1)
    reader_geo.read()
    out["extract_unchanged_with_positions_ms"], _ = best(reader_geo.read, repeat)

    def assemble():
        c = conductance(graph, rod.RHO_304L)
        el = [Electrode("top", graph.index_of(ids[top]), potential=1.0),
              Electrode("bottom", graph.index_of(ids[bottom]), potential=0.0)]
        return ConductionProblem(graph.n_nodes, graph.edges, c, el, solver="direct")
    out["assembly_ms"], _ = best(assemble, repeat)

    # the continuum law's factors after a move (a new graph object: nothing cached), compiled
    # and numpy (the form a periodic graph's bonds take), interleaved
    from yade_electro.laws.factors import make_law
    law = make_law("continuum")
    times = {True: [], False: []}
    for rep in range(4 * repeat):
        for native in (True, False):
            moved = graph.with_positions(graph.pos + 0.0, rep + 1)
            t = time.perf_counter()
            law.factor(moved) if native else law.periodic_factor(moved, moved.edges)
            times[native].append(time.perf_counter() - t)
    out["continuum_factors_ms"], out["continuum_factors_numpy_ms"] = min(times[True]), min(times[False])

    c = conductance(graph, rod.RHO_304L)
    el_nodes = [Electrode("top", graph.index_of(ids[top]), potential=1.0),
                Electrode("bottom", graph.index_of(ids[bottom]), potential=0.0)]
    for name in ("cg", "cg-deflated", "cg-amg", "direct"):
        def cold():
            p = ConductionProblem(graph.n_nodes, graph.edges, c, el_nodes, solver=name, coords=graph.pos)
            return p, p.solve()
        t_cold, (p, sol) = best(cold, repeat)
        values = iter(np.linspace(1.1, 2.0, 10 * repeat))
        t_val, _ = best(lambda: p.solve({"top": next(values)}), repeat)   # a new electrode value: no solve
        out[f"{name}_cold_ms"] = t_cold
        out[f"{name}_new_value_ms"] = t_val
        out[f"{name}_iterations_cold"] = int(sol.info.get("iterations", 0))
        out[f"{name}_R_eq"] = sol.equivalent_resistance("top", "bottom")
        out[f"{name}_residual"] = sol.residual

    # the 'voronoi' law: its first solve (one bounded tessellation: faces, cell volumes and
    # boundary faces), then the update after a bond broke (the structure is kept)
    from yade_electro.laws.law import Law
    from yade_electro.physics.electrical import ElectricalModel
    el = {"top": dict(select=graph.index_of(ids[top]), potential=1.0),
          "bottom": dict(select=graph.index_of(ids[bottom]), potential=0.0)}
    model = ElectricalModel(rod.RHO_304L, el,
                            law=Law("voronoi", container=P.as_shape(
                                 pack.inCylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS))))
    t = time.perf_counter()
    model.solve(graph)
    out["voronoi_first_solve_ms"] = time.perf_counter() - t
    broken = graph.with_edges(graph.edges[1:])
    t = time.perf_counter()
    model.solve(broken)
    out["voronoi_after_bond_break_ms"] = time.perf_counter() - t
    out["voronoi_R_eq"] = model.equivalent_resistance
    out["voronoi_structure_builds"] = model.updates["structure"]

    O.dt = 0.5 * yade.utils.PWaveTimeStep()
    O.step()
    out["yade_step_ms"], _ = best(O.step, repeat)
    return to_ms(out)


def main(argv=None):
    return run_sizes(bench_size, "electro", argv)


if __name__ == "__main__":
    main()
