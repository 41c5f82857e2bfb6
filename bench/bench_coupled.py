"""Cost of one coupled electro-thermal step on the bonded rods of the rod case (5,000 and
20,000 elements, seed 1, the cached packings), next to one YADE mechanical step.

One coupled step = potential (solve or re-use) + Joule sources + heat advance, by
``ElectroThermalModel.step(graph, dt)`` on a graph read once from YADE, dt = 1 ms (the
Joule-rod case's thermal step), 304L, 1 V between the end layers, law 'continuum':

* ``be_unchanged`` / ``explicit_unchanged``: constant resistivity and an unchanged graph,
  so the potential of the first step is re-used; backward Euler (the factorisation is kept)
  or explicit sub-cycled to the stable step (the number of sub-steps is printed);
* ``be_rho_T`` / ``explicit_rho_T``: rho_e(T) with beta = 1e-3 /K: conductances updated in
  place every step, the potential re-solved warm with the kept solver setup;
* ``rho_T_step_ratio`` (and ``_voronoi``): one backward-Euler step with beta = 1e-3 over one
  with beta = 0, same packing, the two models stepped in turn after ``WARMUP`` (10) steps
  (target <= 1.5);
* ``cells_over_edges_step_ratio_voronoi``: under 'voronoi', the rho_e(T) step with the default
  Joule sharing ('cells': a least-squares field per cell at each re-solve) over the same step
  with ``Integrator(joule_sharing='edges')``, stepped in turn with the others;
* ``*_first``: the first step (assembly, potential solve, capacities, factorisation);
* ``engine_call``: the whole PyRunner call of an ``ElectroThermalEngine`` (scene read with
  the unchanged-graph check, coupled step, temperatures written to ``b.state.temp`` and
  potentials to ``b.potential``, history row), backward Euler, constant resistivity;
* ``engine_scene_read``: the scene-read part of that call (bond flags and positions);
* ``yade_step``: one ``O.step()`` of YADE's mechanics on the same bonded packing, without
  the engine.

Times are the best of ``--repeat`` (default 5), in ms; the voronoi law's figures end in
``_voronoi``. Ends with one JSON line.

    yade-electro -n -x bench/bench_coupled.py [--sizes 5000,20000] [--repeat 5]
"""
from __future__ import annotations

import os
import sys
import time


# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("bench_coupled.py") else (sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_coupled.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))

sys.path.insert(0, HERE)
from _benchlib import best, bonded_rod, run_sizes, to_ms  # noqa: E402
from yade_electro.yade.runtime import import_yade  # noqa: E402

DT = 1e-3           # s, thermal step
BETA = 1e-3         # 1/K, for the rho_e(T) variant
WARMUP = 10         # steps before the timed ones: a live run's steady state, where the projected warm
                    # start of the rho_e(T) re-solve has its history of earlier solutions


def bench_size(n, repeat=5, seed=1):
    yade = import_yade()
    from yade_electro.physics.coupled import ElectroThermalModel
    from yade_electro.laws.law import Law
    from yade_electro.physics.electrical import ElectricalModel
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.yade import ElectroThermalEngine, SceneReader, Electrode, Integrator, Material
    import joule_rod as jr
    import rod_resistance as rod

    O, ids, bottom, top = bonded_rod(n, seed)
    graph = SceneReader(O, geometry_every=0).read()
    out = {"n": int(graph.n_nodes), "n_edges": int(graph.n_edges)}
    electrodes = {"top": dict(select=graph.index_of(ids[top]), potential=1.0),
                  "bottom": dict(select=graph.index_of(ids[bottom]), potential=0.0)}
    container = Cylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS)

    def model(theta, beta, law="continuum", sharing="auto"):
        el = ElectricalModel(rod.RHO_304L, electrodes, law=Law(law, container=container if law == "voronoi" else None))
        material = Material(density=jr.DENSITY, specific_heat=jr.SPECIFIC_HEAT, conductivity=jr.CONDUCTIVITY,
                            beta=beta, reference_temperature=jr.T0)
        return ElectroThermalModel(el, material, jr.T0, integrator=Integrator(theta=theta, joule_sharing=sharing))

    for law in ("continuum", "voronoi"):
        suffix = "" if law == "continuum" else "_voronoi"   # put before "_ms": to_ms converts "*_ms"
        for tag, theta in (("be", "backward-euler"), ("explicit", "explicit")):
            if law == "voronoi" and tag == "explicit":
                continue
            models = {}
            variants = [("unchanged", 0.0, "auto"), ("rho_T", BETA, "auto")]
            if law == "voronoi":            # the default 'cells' Joule sharing against the links' 'edges'
                variants.append(("rho_T_edges", BETA, "edges"))
            for var, beta, sharing in variants:
                t = time.perf_counter()
                m = model(theta, beta, law, sharing)
                m.step(graph, DT)
                out[f"{tag}_{var}_first{suffix}_ms"] = time.perf_counter() - t
                for _ in range(WARMUP):
                    m.step(graph, DT)
                models[var] = m
            # interleaved: one step of each in turn, best of repeat
            times = {var: [] for var in models}
            solves0 = {var: m.n_potential_solves for var, m in models.items()}
            for _ in range(repeat):
                for var, m in models.items():
                    t = time.perf_counter()
                    row = m.step(graph, DT)
                    times[var].append(time.perf_counter() - t)
                    out[f"{tag}_{var}_substeps{suffix}"] = int(row["n_substeps"])
            for var, m in models.items():
                out[f"{tag}_{var}{suffix}_ms"] = min(times[var])
                out[f"{tag}_{var}_potential_solves_per_step{suffix}"] = (m.n_potential_solves - solves0[var]) / repeat
            if tag == "be":
                out[f"rho_T_step_ratio{suffix}"] = round(min(times["rho_T"]) / min(times["unchanged"]), 3)
            if "rho_T_edges" in times:
                out[f"cells_over_edges_step_ratio{suffix}"] = round(min(times["rho_T"]) / min(times["rho_T_edges"]), 3)
    out["dt_critical_ms"] = models["unchanged"].time_steps()["critical"] * 1e3

    # the engine's whole PyRunner call
    engine = ElectroThermalEngine(
        material=Material(resistivity=rod.RHO_304L, density=jr.DENSITY, specific_heat=jr.SPECIFIC_HEAT, conductivity=jr.CONDUCTIVITY),
        boundaries=[
            Electrode("top", select=ids[top], potential=1.0),
            Electrode("bottom", select=ids[bottom], potential=0.0)],
        temperature=jr.T0,
        integrator=Integrator(theta="backward-euler", dt=DT),
        label="bench_coupled")
    t = time.perf_counter()
    engine.step()
    out["engine_call_first_ms"] = time.perf_counter() - t
    engine.step()
    out["engine_call_ms"], _ = best(engine.step, repeat)
    out["engine_scene_read_ms"], _ = best(engine.reader.read, repeat)     # part of the call
    engine.remove()

    O.dt = 0.5 * yade.utils.PWaveTimeStep()
    O.step()
    out["yade_step_ms"], _ = best(O.step, repeat)
    return to_ms(out, keep=("dt_critical_ms",))


def main(argv=None):
    return run_sizes(bench_size, "coupled", argv, dt_s=DT, beta=BETA)


if __name__ == "__main__":
    main()
