"""A rotating drum that mixes hot and cold copper particles and heats them through its wall
(paper 002, cases 6 and 7, in 3D).

Set-up
------
* Drum: diameter 0.1524 m (paper 002, after Chaudhuri et al.'s rotary calciner), axis along z,
  a slice ``SLICE_DIAMETERS`` = 5 particle diameters long (20 mm). Its shell is a facet mesh
  (``geom.facetCylinder``, 48 segments) turned by a ``RotationEngine`` at 10, 20 or 30 rpm,
  isothermal at ``T_WALL``. The slice's two ends are frictionless, adiabatic ``Wall`` planes:
  planes of symmetry of a long drum, so the ends neither drag nor heat the bed.
* Baffles (``--baffles``): four L-shaped baffles (facets, turning with the shell): a radial
  plate 0.2 R deep and a lip 0.1 R long at its inner edge; they conduct like the shell
  (isothermal, a separate wall so that a particle in the corner touches both).
* Particles: copper, r = 2 mm (paper 002 table III.1: k = 385 W/(m K), rho = 8900 kg/m^3,
  c = 172 J/(kg K)), about ``--n`` of them, dropped in and settled, then the left half
  (x < 0) starts at ``T_HOT``, the right half at ``T_COLD``, and the drum starts turning.
  Mechanics: FrictMat with E = 1e7 Pa (softened for the time step, as DEM drums are), friction
  0.5, Cundall damping 0.1.
* Heat: ``HeatEngine(material=Material(), law='contact', reader=Reader(bonds='contacts'))`` (H = 2 k a, the geometric contact
  radius of the overlap, no softened-stiffness correction: paper 002 uses the overlaps as
  they come) every 10 steps on the elapsed time, explicit (forward Euler, sub-cycled if the
  step ever exceeds the stable one C_i / sum G; with these small contacts the 3e-4 s thermal
  step runs as one sub-step), walls as above.

Outputs, sampled every ``--sample`` s
-------------------------------------
* Lacey mixing index of the hot/cold species, M = (s0^2 - s^2) / (s0^2 - sr^2), over square
  cells of 4 particle diameters in the x-y plane holding at least 5 particles (s^2 the
  particle-weighted variance of the hot fraction across cells, s0^2 = p (1 - p), sr^2 = s0^2
  / mean particles per cell);
* bed mean and standard deviation of temperature; the wall heat given (history CSV).
* The time to 90 % of the wall temperature rise: first time T_mean - T_0 >= 0.9 (T_WALL -
  T_0), T_0 the initial bed mean (None if not reached in the run).
* A plot (``rotating_drum_<rpm>rpm_<wall>.png``), VTK of the particles and of the contact
  network (heat flow per contact) at the end, and one JSON line.

Run
---
    yade-electro -n -x cases/rotating_drum.py --rpm 20                # smooth wall
    yade-electro -n -x cases/rotating_drum.py --rpm 20 --baffles
    yade-electro -n -x cases/rotating_drum.py --rpm 20 --overlap      # the engine's overlap=True
    yade-electro batch cases/rotating_drum.table cases/rotating_drum.py   # the 6 combinations
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("rotating_drum.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("rotating_drum.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

DRUM_RADIUS = 0.1524 / 2        # m
PARTICLE_RADIUS = 2e-3          # m
SLICE_DIAMETERS = 5             # slice length in particle diameters
CONDUCTIVITY = 385.0            # W/(m K), copper (paper 002 table III.1)
DENSITY = 8900.0                # kg/m^3
SPECIFIC_HEAT = 172.0           # J/(kg K)
YOUNG = 1e7                     # Pa, softened
T_HOT, T_COLD, T_WALL = 333.15, 293.15, 373.15   # K
ENGINE_PERIOD = 10              # steps


def slice_length():
    return SLICE_DIAMETERS * 2 * PARTICLE_RADIUS


def baffle_triangles(n_baffles=4, depth=0.2, lip=0.1):
    """Vertices (k, 3, 3) of L-shaped baffles on the shell: a radial plate ``depth`` R deep
    and a lip ``lip`` R long at its inner edge, two triangles per plate."""
    R, L = DRUM_RADIUS, slice_length()
    tris = []
    for k in range(n_baffles):
        phi = 2 * math.pi * k / n_baffles
        e_r = np.array([math.cos(phi), math.sin(phi), 0.0])
        e_t = np.array([-math.sin(phi), math.cos(phi), 0.0])
        z0, z1 = np.array([0, 0, -L / 2]), np.array([0, 0, L / 2])
        outer, inner = R * e_r, (1 - depth) * R * e_r
        tip = inner + lip * R * e_t
        for a, b in ((outer, inner), (inner, tip)):
            tris.append([a + z0, b + z0, b + z1])
            tris.append([a + z0, b + z1, a + z1])
    return np.array(tris)


def build_drum(n=2000, seed=1, baffles=False, settle_time=0.4, verbose=True):
    """Reset YADE's scene: the drum, its walls and about ``n`` settled particles. Returns a
    dict of body ids (``spheres``, ``shell``, ``baffles``, ``ends``) and the material ids."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import geom, pack, utils
    from yade import wrapper as W
    O = yade.Omega()
    O.reset()
    R, r, L = DRUM_RADIUS, PARTICLE_RADIUS, slice_length()
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=0.3, density=DENSITY, frictionAngle=math.atan(0.5),
                                        label="copper"))
    smooth = O.materials.append(W.FrictMat(young=YOUNG, poisson=0.3, density=DENSITY, frictionAngle=0.0,
                                           label="smooth"))
    shell = O.bodies.append(geom.facetCylinder((0, 0, 0), R, L, segmentsNumber=48, wallMask=4, material=mat))
    baffle_ids = []
    if baffles:
        baffle_ids = O.bodies.append([utils.facet([tuple(v) for v in tri], material=mat)
                                      for tri in baffle_triangles()])
    ends = O.bodies.append([utils.wall(-L / 2, axis=2, sense=1, material=smooth),
                            utils.wall(L / 2, axis=2, sense=-1, material=smooth)])
    sp = pack.SpherePack()
    box = R - 2 * r
    # a cloud in the square around the drum, kept inside it: about n particles
    n_cloud = int(round(n * 4 * box ** 2 / (math.pi * (R - 1.5 * r) ** 2)))
    sp.makeCloud((-box, -box, -L / 2 + r), (box, box, L / 2 - r), rMean=r, rRelFuzz=0.0, num=n_cloud, seed=seed)
    kept = [(c, rad) for c, rad in sp if c[0] ** 2 + c[1] ** 2 < (R - 1.5 * r) ** 2]
    spheres = O.bodies.append([utils.sphere(c, rad, material=mat) for c, rad in kept])
    from caselib import frictional_bed
    frictional_bed(O, ("Facet", "Wall"), gravity=(0, -9.81, 0), damping=0.1)
    steps = int(settle_time / O.dt)
    t = time.time()
    done = 0
    while done < steps:               # settle, with progress
        k = min(steps - done, max(steps // 10, 1))
        O.run(k, True)
        done += k
        if verbose:
            el = time.time() - t
            print(f"  settling {len(spheres)} particles: {100 * done / steps:.0f} %, {el:.0f} s, about "
                  f"{el * (steps - done) / done:.0f} s left", flush=True)
    return {"spheres": list(spheres), "shell": list(shell), "baffles": list(baffle_ids), "ends": list(ends),
            "material": mat}


def start_rotation(ids, rpm):
    """Turn the shell and baffles about z at ``rpm``."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import wrapper as W
    O = yade.Omega()
    rot = W.RotationEngine(ids=ids["shell"] + ids["baffles"], rotationAxis=(0, 0, 1), rotateAroundZero=True,
                           zeroPoint=(0, 0, 0), angularVelocity=rpm * 2 * math.pi / 60, label="drum_rotation")
    O.engines = O.engines[:-1] + [rot] + O.engines[-1:]          # before the integrator
    return rot


def heat_engine(ids, hot, label="drum_heat", iterPeriod=ENGINE_PERIOD, history=None, skin=None, overlap=False):
    """The bed's HeatEngine: the left half hot, the shell (and baffles) at T_WALL, the ends
    adiabatic (``overlap``: the engine's ``overlap=``)."""
    from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Material, Output, Reader, Wall
    walls = [Wall("shell", bodies=ids["shell"], temperature=T_WALL),
             Wall("ends_minus", bodies=ids["ends"][0], temperature=None),
             Wall("ends_plus", bodies=ids["ends"][1], temperature=None)]
    if ids["baffles"]:
        walls.append(Wall("baffles", bodies=ids["baffles"], temperature=T_WALL))
    return HeatEngine(
        material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=walls,
        temperature=InitialTemperature(T_COLD, by_id={int(i): T_HOT for i in hot}),
        law="contact",
        integrator=Integrator(theta="explicit"),
        reader=Reader(bonds="contacts", overlap=overlap, skin="auto" if skin is None else skin),
        output=Output(history=history),
        iterPeriod=iterPeriod,
        label=label)


def lacey_index(pos, is_a, cell=8 * PARTICLE_RADIUS, min_count=5) -> float:
    """Lacey mixing index of species ``is_a`` over square x-y cells of side ``cell`` [m]."""
    p = float(np.mean(is_a))
    key = np.floor(pos[:, :2] / cell).astype(np.int64)
    _, lab, counts = np.unique(key, axis=0, return_inverse=True, return_counts=True)
    lab = lab.reshape(-1)
    frac = np.bincount(lab, is_a.astype(float)) / counts
    ok = counts >= min_count
    if not np.any(ok) or p in (0.0, 1.0):
        return float("nan")
    w = counts[ok]
    s2 = float(np.sum(w * (frac[ok] - p) ** 2) / np.sum(w))
    s0 = p * (1 - p)
    sr = s0 / float(np.mean(w))
    return (s0 - s2) / (s0 - sr)


def run(n=2000, rpm=20.0, baffles=False, duration=3.0, sample=0.1, seed=1, out="out/rotating_drum", verbose=True,
        overlap=False):
    from yade_electro.yade.runtime import import_yade
    from yade_electro.post.vtk import write_bonds, write_elements
    yade = import_yade()
    O = yade.Omega()
    t0 = time.time()
    ids = build_drum(n, seed, baffles, verbose=verbose)
    t_settle = time.time() - t0
    sph = np.array(ids["spheres"])
    x = np.array([O.bodies[int(i)].state.pos[0] for i in sph])
    hot = sph[x < 0]
    is_hot = np.isin(sph, hot)
    wall = "baffles" if baffles else "smooth"
    tag = f"{int(rpm)}rpm_{wall}"
    os.makedirs(out, exist_ok=True)
    engine = heat_engine(ids, hot, history=os.path.join(out, f"rotating_drum_{tag}.csv"), overlap=overlap)
    O.engines = O.engines + [engine.runner]
    start_rotation(ids, rpm)
    T_init = float(np.mean(engine.temperature))
    samples = []
    steps_per_sample = max(int(round(sample / O.dt)), 1)
    n_samples = int(round(duration / sample))
    t1 = time.time()
    for k in range(n_samples + 1):
        if k:
            O.run(steps_per_sample, True)
        order = engine.reader.graph.index_of(sph)
        pos = engine.reader.graph.pos[order]
        T = engine.temperature[order]
        samples.append({"t": float(O.time), "lacey": lacey_index(pos, is_hot),
                        "T_mean": float(T.mean()), "T_std": float(T.std()),
                        "wall_heat": float(sum(engine.wall_heat().values()))})
        if verbose and k % max(n_samples // 10, 1) == 0:
            el = time.time() - t1
            print(f"  {tag}: t = {O.time:.2f} s, Lacey {samples[-1]['lacey']:.3f}, T mean {T.mean() - 273.15:.2f} "
                  f"degC, std {T.std():.2f} K; {el:.0f} s, about {el * (n_samples - k) / max(k, 1):.0f} s left",
                  flush=True)
    t_run = time.time() - t1
    ts = np.array([s["t"] for s in samples])
    ts -= ts[0]
    Tm = np.array([s["T_mean"] for s in samples])
    rise = Tm - T_init
    reached = np.flatnonzero(rise >= 0.9 * (T_WALL - T_init))
    t90 = float(ts[reached[0]]) if reached.size else None
    g = engine.reader.graph
    pairs, G, q = engine.contact_heat_flow()
    write_elements(os.path.join(out, f"rotating_drum_{tag}_particles.vtu"), g.pos, g.radius,
                   {"temperature": engine.temperature, "hot": np.isin(g.ids, hot).astype(float)})
    write_bonds(os.path.join(out, f"rotating_drum_{tag}_contacts.vtu"), g.pos, g.index_of(pairs.ravel()).reshape(-1, 2),
                {"heat_flow_W": q, "conductance_W_per_K": G})
    png = plot(ts, samples, tag, os.path.join(out, f"rotating_drum_{tag}.png"))
    stored = engine.coupled.heat_content() - float(np.sum(engine.coupled.capacity * (T_init - engine.coupled.T0)))
    wall_heat = float(sum(engine.wall_heat().values()))
    res = {"case": "rotating_drum", "rpm": rpm, "wall": wall, "n": int(sph.size), "duration_s": duration,
           "final_lacey": samples[-1]["lacey"], "t90_wall_s": t90, "T_mean_final_K": float(Tm[-1]),
           "T_std_final_K": samples[-1]["T_std"], "wall_heat_J": wall_heat,
           "balance_rel": abs(stored - wall_heat) / max(abs(wall_heat), 1e-300),
           "settle_s": round(t_settle, 1), "run_s": round(t_run, 1), "dt_s": float(O.dt), "overlap": overlap,
           "samples": samples, "png": png}
    engine.remove()
    return res


def plot(ts, samples, tag, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, (a1, a2) = plt.subplots(1, 2, figsize=(10, 4))
    a1.plot(ts, [s["lacey"] for s in samples], "k-")
    a1.set_xlabel("time [s]")
    a1.set_ylabel("Lacey mixing index")
    a1.set_ylim(0, 1.1)
    Tm = np.array([s["T_mean"] for s in samples]) - 273.15
    Ts = np.array([s["T_std"] for s in samples])
    a2.plot(ts, Tm, "r-", label="bed mean")
    a2.fill_between(ts, Tm - Ts, Tm + Ts, color="r", alpha=0.2, label="+- 1 std")
    a2.axhline(T_WALL - 273.15, color="k", ls=":", label="wall")
    a2.set_xlabel("time [s]")
    a2.set_ylabel("temperature [degC]")
    a2.legend()
    fig.suptitle(f"rotating drum, {tag.replace('_', ', ')}")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--rpm", type=float, default=20.0)
    ap.add_argument("--baffles", action="store_true")
    ap.add_argument("--duration", type=float, default=3.0, help="rotation time [s]")
    ap.add_argument("--sample", type=float, default=0.1)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="out/rotating_drum")
    ap.add_argument("--overlap", action="store_true",
                    help="the engine's overlap=True (its numpy work on a worker thread; the same results)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("rpm", "baffles"))
    res = run(args.n, args.rpm, bool(args.baffles), args.duration, args.sample, args.seed, args.out,
              overlap=args.overlap)
    with open(os.path.join(args.out, f"rotating_drum_{int(res['rpm'])}rpm_{res['wall']}.json"), "w") as fh:
        json.dump(res, fh)
    short = {k: v for k, v in res.items() if k != "samples"}
    print(json.dumps(short))
    return res


if __name__ == "__main__":
    main()
