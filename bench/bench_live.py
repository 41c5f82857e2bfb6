"""What the engines cost in a live YADE run: bonded rods under slow tension (the positions change
every step), engine and no-engine blocks interleaved in one process.

For each size (the rod case's bonded packings, seed 1) and configuration (ElectricalEngine
every step and every 100 steps, ElectroThermalEngine every 100 steps; 'continuum' and, at the
first size, 'voronoi'), the same simulation runs in alternating blocks (80 steps with the engine every step, 500 every
100 steps at up to 5,000 elements; 20 and 200 above; at 5,000 about 1 s and 6 s on this machine):
``--blocks`` pairs, one block without the engine and one with it (its PyRunner made dead or
alive), the order swapped every pair. At the end a bond is broken in shear and the call that
finds it is timed (``bond_break_call_ms``).
The bottom layer is held, the top layer pulled at a strain rate that gives 1e-4 over the whole
bench (no bond breaks; the engines see new positions at every geometry read).

One JSON line per configuration::

    {"bench": "live", "n", "engine", "law", "period", "ratio": wall_with / wall_without (sums
     over the blocks), "ratio_median_of_pairs" (the median of the block pairs' ratios, less
     sensitive to the machine's noise), "ratio_from_calls": 1 + (time in the engine's calls) /
     wall_without, "rebuild_ms": the call that builds the structure (the first),
     "unchanged_ms": median call that read nothing (no position read, nothing changed),
     "positions_read_ms": median call that read the positions and found no move beyond the
     tolerance, "median_call_ms", "max_call_ms" (a call that moved the values: new geometry,
     warm re-solve, write-back), "max_over_unchanged", "geometry_median_ms" and
     "geometry_median_over_unchanged" (the median of the calls that found moves: the typical
     such call, where the largest is one sample), "max_over_positions_read", "calls",
     "calls_by_kind", "structure_builds", "mech_step_ms", "block_timer", "load_average"}

    yade-electro -n -x bench/bench_live.py [--sizes 5000,20000] [--blocks 4] [--only engine/law/period,...]

Before the configurations of each size, one line ``{"bench": "live_positions_read", ...}``
(:func:`positions_read`): what reading the positions costs, YADE's reader alone and with
either conversion to numpy.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

_SCRIPT = __file__ if __file__.endswith("bench_live.py") else next(
    (a for a in sys.argv if a.endswith("bench_live.py")), __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

import numpy as np  # noqa: E402

from _benchlib import BLOCK_TIMER, bonded_rod, run_steps  # noqa: E402

STRAIN = 1e-4


def setup_pull(O, ids, top, bottom, total_steps, length):
    rate = STRAIN / (total_steps * O.dt)
    for i in ids[bottom]:
        O.bodies[int(i)].state.blockedDOFs = "xyzXYZ"
    for i in ids[top]:
        b = O.bodies[int(i)]
        b.state.blockedDOFs = "xyzXYZ"
        b.state.vel = (0.0, 0.0, rate * length)


def make_engine(kind, law, period, ids, top, bottom):
    import joule_rod as jr
    import rod_resistance as rod
    from yade_electro.yade import ElectricalEngine, ElectroThermalEngine, Integrator, Law, Material, electrodes_from_dict
    from yade_electro.geometry.shapes import Cylinder
    el = {"top": dict(select=ids[top], potential=1.0), "bottom": dict(select=ids[bottom], potential=0.0)}
    lp = {"container": Cylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS)} if law == "voronoi" else None
    if kind == "ElectricalEngine":
        return ElectricalEngine(
            material=Material(resistivity=rod.RHO_304L),
            boundaries=electrodes_from_dict(el),
            law=Law(law, **(lp or {})),
            iterPeriod=period,
            label=f"live_{law}_{period}")
    return ElectroThermalEngine(
        material=Material(resistivity=rod.RHO_304L, density=jr.DENSITY, specific_heat=jr.SPECIFIC_HEAT, conductivity=jr.CONDUCTIVITY),
        boundaries=electrodes_from_dict(el),
        temperature=jr.T0,
        law=Law(law, **(lp or {})),
        integrator=Integrator(dt=1e-5),
        iterPeriod=period,
        label=f"live_thermal_{law}_{period}")


def timed(engine, times, kinds):
    """Wrap the engine's step to record every call's wall time and what changed."""
    step = engine.step

    def wrapper():
        reads, builds = engine.reader.full_reads, engine.model.updates["structure"] if engine.model else 0
        geo = engine.reader.geometry_reads
        t = time.perf_counter()
        out = step()
        times.append(time.perf_counter() - t)
        changed = engine.reader.last_change
        built = (engine.model.updates["structure"] if engine.model else 0) != builds
        read = engine.reader.geometry_reads != geo
        kinds.append("structure" if built else ("full read" if engine.reader.full_reads != reads else
                                                 ("geometry" if changed == "geometry" else
                                                  ("positions read" if read else "unchanged"))))
        return out
    engine.step = wrapper


def bench(n, kind, law, period, steps, blocks):
    from yade_electro.yade import registry
    import rod_resistance as rod
    O, ids, bottom, top = bonded_rod(n)
    setup_pull(O, ids, top, bottom, 2 * blocks * steps + 10, rod.LENGTH)
    O.run(5, True)
    t = time.perf_counter()
    engine = make_engine(kind, law, period, ids, top, bottom)
    t_build = time.perf_counter() - t
    times, kinds = [], []
    timed(engine, times, kinds)
    O.engines = O.engines + [engine.runner]
    engine.runner.dead = True
    wall = {"with": 0.0, "without": 0.0}
    pair_ratios = []
    for b in range(blocks):
        w = {}
        for mode in (("without", "with") if b % 2 == 0 else ("with", "without")):
            engine.runner.dead = mode == "without"
            w[mode] = run_steps(O, steps)
            wall[mode] += w[mode]
        pair_ratios.append(w["with"] / w["without"])
    # a bond broken in shear (its spheres stay together: only the sweep sees it): the call
    # that finds it reads the scene again and takes the bond out of the network (no rebuild)
    engine.runner.dead = True
    mid = next(i for i in O.interactions if i.isReal and abs(O.bodies[i.id1].state.pos[2] - 0.5 * rod.LENGTH) < 2e-4)
    mid.phys.cohesionBroken = True
    n_before = len(times)
    for _ in range(engine.reader.sweep_calls + 1):
        engine.step()
        if kinds[-1] != "unchanged" and engine.reader.last_change == "a bond broke":
            break
    break_ms = 1e3 * times[-1] if engine.reader.last_change == "a bond broke" else float("nan")
    times, kinds = times[:n_before], kinds[:n_before]
    t_all = np.array(times)
    unchanged = t_all[np.array(kinds) == "unchanged"]
    read_only = t_all[np.array(kinds) == "positions read"]
    geometry = t_all[np.array(kinds) == "geometry"]
    first = t_all[0] if len(t_all) else float("nan")
    um = float(np.median(unchanged)) if unchanged.size else float("nan")
    rest = t_all[1:]
    row = {"bench": "live", "n": int(len(ids)), "engine": kind, "law": law, "period": int(period),
           "ratio": round(wall["with"] / wall["without"], 4),
           "ratio_median_of_pairs": round(float(np.median(pair_ratios)), 4),
           "ratio_from_calls": round(1.0 + float(np.sum(t_all)) / wall["without"], 4),
           "build_ms": round(1e3 * t_build, 2), "rebuild_ms": round(1e3 * first, 2),
           "bond_break_call_ms": round(break_ms, 2),
           "unchanged_ms": round(1e3 * um, 3),
           "median_call_ms": round(1e3 * float(np.median(rest)), 3) if rest.size else None,
           "max_call_ms": round(1e3 * float(rest.max()), 3) if rest.size else None,
           "max_over_unchanged": round(float(rest.max()) / um, 2) if rest.size and um > 0 else None,
           "geometry_median_ms": round(1e3 * float(np.median(geometry)), 3) if geometry.size else None,
           "geometry_median_over_unchanged": round(float(np.median(geometry)) / um, 2)
           if geometry.size and um > 0 else None,
           "positions_read_ms": round(1e3 * float(np.median(read_only)), 3) if read_only.size else None,
           "max_over_positions_read": round(float(rest.max()) / float(np.median(read_only)), 2)
           if rest.size and read_only.size else None,
           "calls": int(len(times)), "calls_by_kind": {k: kinds.count(k) for k in set(kinds)},
           "structure_builds": int(engine.model.updates["structure"]) if engine.model else None,
           "steps_per_block": int(steps), "blocks": int(blocks),
           "mech_step_ms": round(1e3 * wall["without"] / (blocks * steps), 3),
           "block_timer": BLOCK_TIMER, "load_average": round(os.getloadavg()[0], 2)}
    engine.remove()
    registry.ENGINES.pop(engine.label, None)
    print(json.dumps(row), flush=True)
    return row


def positions_read(n, repeats=30):
    """What reading every body's centre costs on the bonded rod of ``n`` elements, interleaved
    in one process (medians of ``repeats``): YADE's bulk reader alone (``api_ms``: the three
    ``coordsAndDisplacements`` calls), the engines' read (``array_ms``:
    :func:`yade_electro.yade.scene.bulk_coordinates`, the lists through ``array.array``) and
    the same read with ``numpy.fromiter`` instead (``fromiter_ms``, the read before)."""
    from yade import utils as U
    from yade_electro.yade.scene import bulk_coordinates
    O, ids, _, _ = bonded_rod(n)
    n_bodies = len(O.bodies)

    def api():
        return [U.coordsAndDisplacements(k)[0] for k in range(3)]

    def fromiter():
        return np.column_stack([np.fromiter(c, dtype=float, count=len(c)) for c in api()])

    reads = {"api": api, "array": lambda: bulk_coordinates(n_bodies), "fromiter": fromiter}
    if not np.array_equal(reads["array"](), fromiter()):
        raise RuntimeError("the two conversions of the positions differ")
    times = {name: [] for name in reads}
    for k in range(repeats):
        for name in (list(reads) if k % 2 == 0 else list(reads)[::-1]):
            t = time.perf_counter()
            reads[name]()
            times[name].append(time.perf_counter() - t)
    row = {"bench": "live_positions_read", "n": int(len(ids)), "bodies": n_bodies, "repeats": repeats,
           **{f"{name}_ms": round(1e3 * float(np.median(v)), 3) for name, v in times.items()},
           "load_average": round(os.getloadavg()[0], 2)}
    print(json.dumps(row), flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="5000,20000")
    ap.add_argument("--blocks", type=int, default=12, help="pairs of blocks (with / without the engine)")
    ap.add_argument("--only", default=None,
                    help="run only these configurations, e.g. 'ElectricalEngine/continuum/100,"
                         "ElectroThermalEngine/continuum/100' (engine/law/period, comma separated)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    rows = []
    for k, n in enumerate(int(x) for x in args.sizes.split(",")):
        # blocks of about half a second of mechanics, short so that the machine's noise
        # falls alike on both kinds of block
        rows.append(positions_read(n))
        steps_1, steps_100 = (80, 500) if n <= 5000 else (20, 200)
        configs = [("ElectricalEngine", "continuum", 1, steps_1),
                   ("ElectricalEngine", "continuum", 100, steps_100),
                   ("ElectroThermalEngine", "continuum", 100, steps_100)]
        if k == 0:
            configs += [("ElectricalEngine", "voronoi", 1, steps_1), ("ElectricalEngine", "voronoi", 100, steps_100),
                        ("ElectroThermalEngine", "voronoi", 100, steps_100)]
        if args.only:
            wanted = {tuple(c.split("/")) for c in args.only.split(",")}
            configs = [c for c in configs if (c[0], c[1], str(c[2])) in wanted]
        for kind, law, period, steps in configs:
            rows.append(bench(n, kind, law, period, steps, args.blocks))
    return rows


if __name__ == "__main__":
    main()
