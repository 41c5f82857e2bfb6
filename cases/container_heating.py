"""A bed of particles heated through the wall of its container (paper 003, section 6).

Paper 003 drops 2,000 metal nuts into a cylindrical container, holds the container at 300
degC and heats the static bed from 0 degC by conduction only. Here:

* Particles: about ``--n`` (2,000) steel spheres, r = 2 mm (spheres, not nuts: the contact
  laws here are for spheres), k = 50 W/(m K), rho = 7850 kg/m^3, c = 470 J/(kg K) (paper
  003's table 4 is not in our copy; these are carbon steel's).
* Container: a cylinder of radius ``CONTAINER_RADIUS`` (25 mm), its side and its bottom two
  facet meshes (``geom.facetCylinder``, 40 segments), two walls of the heat engine so that a
  particle in the corner touches both.
* Filling: the spheres are dropped from a loose cloud and settle under gravity in YADE
  (FrictMat, E = 1e8 Pa, friction 0.5, damping 0.3) until the kinetic energy is below
  1e-8 of its peak or ``--settle`` s. Then the mechanics stop: the bed is static (paper 003
  has no thermal expansion).
* Heat: ``HeatEngine(material=Material(), law='contact', reader=Reader(bonds='contacts'))`` (H = 2 k a, geometric contact radius
  of the settled overlaps), both walls isothermal at 300 degC from t = 0, the particles from
  0 degC, Crank-Nicolson with ``--dt`` (1 s); the engine is stepped from the script
  (``engine.step()``, what its PyRunner calls) while the scene stays still.

Outputs: the temperature at the bed centre (mean of the particles within 2 diameters of the
point on the axis at half the bed height) against time, the time it reaches 90 % of 300
degC, cross-section plots (particles within one diameter of the y = 0 plane) at four
times, VTK of the particles and of the contact network (heat flow per contact) at those
times, and the energy balance: heat given by the walls against heat stored,
|stored - given| / given (target 1e-6). Ends with one JSON line.

    yade-electro -n -x cases/container_heating.py [--n 2000]
    yade-electro batch cases/container_heating.table cases/container_heating.py
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("container_heating.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("container_heating.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

CONTAINER_RADIUS = 0.025        # m
PARTICLE_RADIUS = 2e-3          # m
CONDUCTIVITY = 50.0             # W/(m K), steel
DENSITY = 7850.0                # kg/m^3
SPECIFIC_HEAT = 470.0           # J/(kg K)
YOUNG = 1e8                     # Pa
T_START, T_WALL = 273.15, 573.15  # K (0 and 300 degC)


def fill_container(n=2000, seed=1, settle=1.0, verbose=True):
    """Reset YADE's scene, drop about ``n`` spheres into the container and let them settle.
    Returns dict(spheres=ids, side=ids, bottom=ids, settle_time=s of simulated time)."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import geom, pack, utils
    from yade import wrapper as W
    O = yade.Omega()
    O.reset()
    R, r = CONTAINER_RADIUS, PARTICLE_RADIUS
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=0.3, density=DENSITY, frictionAngle=math.atan(0.5)))
    v_bed = n * 4 / 3 * math.pi * r ** 3
    height = 1.3 * v_bed / 0.25 / (math.pi * (R - 1.5 * r) ** 2)   # a loose cloud (about 25 % solid)
    side = O.bodies.append(geom.facetCylinder((0, 0, height / 2), R, height, segmentsNumber=40, wallMask=4,
                                              material=mat))
    bottom = O.bodies.append(geom.facetCylinder((0, 0, height / 2), R, height, segmentsNumber=40, wallMask=2,
                                                material=mat))
    box = R - 1.5 * r
    sp = pack.SpherePack()
    n_cloud = int(round(1.3 * n * 4 / math.pi))
    sp.makeCloud((-box, -box, r), (box, box, height - r), rMean=r, rRelFuzz=0.0, num=n_cloud, seed=seed)
    kept = [(c, rad) for c, rad in sp if c[0] ** 2 + c[1] ** 2 < box ** 2]
    kept.sort(key=lambda cr: cr[0][2])
    spheres = O.bodies.append([utils.sphere(c, rad, material=mat) for c, rad in kept[:n]])
    from caselib import frictional_bed
    frictional_bed(O, ("Facet",), gravity=(0, 0, -9.81), damping=0.3)
    chunk = max(int(0.02 / O.dt), 1)
    peak, t = 0.0, time.time()
    while O.time < settle:
        O.run(chunk, True)
        ek = utils.kineticEnergy()
        peak = max(peak, ek)
        if verbose:
            el = time.time() - t
            print(f"  filling {len(spheres)} spheres: t = {O.time:.2f} s of {settle:g}, kinetic energy "
                  f"{ek:.2e} J ({ek / max(peak, 1e-300):.1e} of peak), {el:.0f} s, about "
                  f"{el * (settle - O.time) / O.time:.0f} s left", flush=True)
        if O.time > 0.2 and ek < 1e-8 * peak:
            break
    return {"spheres": list(spheres), "side": list(side), "bottom": list(bottom), "settle_time": float(O.time)}


def heat_engine(ids, dt, label="container_heat"):
    from yade_electro.yade import HeatEngine, Integrator, Material, Reader, Wall
    return HeatEngine(
        material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=[
            Wall("side", bodies=ids["side"], temperature=T_WALL),
            Wall("bottom", bodies=ids["bottom"], temperature=T_WALL)],
        temperature=T_START,
        law="contact",
        integrator=Integrator(theta="crank-nicolson", dt=dt),
        reader=Reader(bonds="contacts"),
        label=label)


def centre_nodes(pos, r=PARTICLE_RADIUS):
    """Particles within 2 diameters of the axis point at half the bed height."""
    top = np.percentile(pos[:, 2], 98)
    c = np.array([0.0, 0.0, 0.5 * top])
    return np.flatnonzero(np.linalg.norm(pos - c, axis=1) < 4 * r)


def run(n=2000, dt=1.0, t_max=8000.0, seed=1, settle=1.0, out="out/container_heating", verbose=True):
    from yade_electro.post.vtk import write_bonds, write_elements
    t0 = time.time()
    ids = fill_container(n, seed, settle, verbose)
    t_fill = time.time() - t0
    engine = heat_engine(ids, dt)
    g = engine.reader.read()
    pos = g.pos
    centre = centre_nodes(pos)
    C = engine.coupled.capacity
    times, T_centre = [0.0], [T_START]
    kept = {0.0: engine.temperature.copy()}            # every 10th step, for the snapshots
    t90, t1 = None, time.time()
    steps = int(round(t_max / dt))
    os.makedirs(out, exist_ok=True)
    tag = f"n{n}"
    for k in range(1, steps + 1):
        engine.step()
        T = engine.temperature
        times.append(k * dt)
        T_centre.append(float(T[centre].mean()))
        if k % 10 == 0:
            kept[k * dt] = T.copy()
        if t90 is None and T_centre[-1] - T_START >= 0.9 * (T_WALL - T_START):
            t90 = k * dt
        if verbose and k % max(steps // 40, 1) == 0:
            el = time.time() - t1
            print(f"  heating: t = {k * dt:.0f} s, centre {T_centre[-1] - 273.15:.1f} degC, bed mean "
                  f"{np.sum(C * T) / np.sum(C) - 273.15:.1f} degC; {el:.0f} s", flush=True)
        if t90 is not None and k * dt >= 1.2 * t90:
            break
    kept[times[-1]] = engine.temperature.copy()
    stored_times = np.array(sorted(kept))
    snaps = {}
    for frac in (0.1, 0.3, 0.6, 1.0):
        t_s = float(stored_times[np.argmin(np.abs(stored_times - frac * times[-1]))])
        snaps[t_s] = kept[t_s]
    t_heat = time.time() - t1
    row = engine.coupled.summary()
    given = sum(engine.wall_heat().values())
    stored = row["heat_content"]                     # relative to T_START (= T_0)
    balance = abs(stored - given) / abs(given)
    pairs, G, q = engine.contact_heat_flow()
    vtus = []
    for t_s, T in sorted(snaps.items()):
        vtus.append(write_elements(os.path.join(out, f"container_{tag}_t{int(t_s)}s_particles.vtu"), pos, g.radius,
                                   {"temperature_C": T - 273.15}))
    vtus.append(write_bonds(os.path.join(out, f"container_{tag}_contacts.vtu"), pos,
                            g.index_of(pairs.ravel()).reshape(-1, 2), {"heat_flow_W": q, "conductance_W_per_K": G}))
    png = plot(np.array(times), np.array(T_centre), t90, pos, snaps, os.path.join(out, f"container_{tag}.png"))
    res = {"case": "container_heating", "n": int(len(ids["spheres"])), "dt_s": dt, "t90_centre_s": t90,
           "T_centre_final_C": T_centre[-1] - 273.15, "balance_rel": balance, "wall_heat_J": given,
           "stored_J": stored, "contacts": int(G.size),
           "wall_contacts": {k: int(row[f"wall_contacts:{k}"]) for k in ("side", "bottom")},
           "mean_contacts_per_particle": 2 * int(G.size) / len(ids["spheres"]),
           "fill_s": round(t_fill, 1), "heat_s": round(t_heat, 1), "settled_at_s": ids["settle_time"],
           "png": png, "vtk": vtus}
    engine.remove()
    return res


def plot(times, T_centre, t90, pos, snaps, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 1 + len(snaps), figsize=(4 * (1 + len(snaps)), 4))
    a = axes[0]
    a.plot(times, T_centre - 273.15, "r-", label="bed centre")
    a.axhline(T_WALL - 273.15, color="k", ls=":", label="wall")
    a.axhline(T_START - 273.15 + 0.9 * (T_WALL - T_START), color="g", ls="--", label="90 %")
    if t90:
        a.axvline(t90, color="g", ls=":")
    a.set_xlabel("time [s]")
    a.set_ylabel("temperature [degC]")
    a.legend()
    sl = np.abs(pos[:, 1]) < 2 * PARTICLE_RADIUS
    for ax, (t_s, T) in zip(axes[1:], sorted(snaps.items())):
        sc = ax.scatter(pos[sl, 0] * 1e3, pos[sl, 2] * 1e3, c=T[sl] - 273.15, s=12, vmin=0, vmax=300, cmap="inferno")
        ax.set_aspect("equal")
        ax.set_title(f"t = {t_s:.0f} s")
        ax.set_xlabel("x [mm]")
    axes[1].set_ylabel("z [mm]")
    fig.colorbar(sc, ax=axes[-1], label="degC")
    fig.suptitle("container heated at 300 degC: cross-section |y| < 1 diameter")
    fig.tight_layout()
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--dt", type=float, default=1.0, help="thermal step [s]")
    ap.add_argument("--t-max", type=float, default=8000.0)
    ap.add_argument("--settle", type=float, default=1.0, help="longest filling time [s, simulated]")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", default="out/container_heating")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("n", "seed"))
    res = run(args.n, args.dt, args.t_max, args.seed, args.settle, args.out)
    with open(os.path.join(args.out, f"container_heating_n{res['n']}.json"), "w") as fh:
        json.dump(res, fh)
    print(json.dumps(res))
    return res


if __name__ == "__main__":
    main()
