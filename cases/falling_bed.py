"""A block of particles, hot half and cold half, falls onto a plate and settles (paper 002,
case 5); then the settled bed's effective conductivity between two isothermal walls.

Stage 1, the fall. A loose block of about ``--n`` copper spheres (r = 1 mm +- 20 %, paper 002
table III.1: k = 385 W/(m K), rho = 8900 kg/m^3, c = 172 J/(kg K)), its left half (x < 0) at
``T_HOT`` and its right half at ``T_COLD``, falls 10 mm onto a plate and settles, inside a
square box whose frictionless side walls keep it a slab (paper 002's 2D block falls on an
open plate and forms a heap; the box makes the slab that stage 2 needs). The plate and the
sides are adiabatic walls, so the heat in the bed must stay what it was while the contacts
are made and lost at every call: ``energy_drift`` = max |sum C_i (T_i - T_0) - initial| /
initial over the run (target 1e-9). The engine (``HeatEngine``, ``bonds='contacts'``,
``law='contact'``, explicit, every 10 steps on the elapsed time) writes ``b.state.temp``;
side views of positions and temperatures (plot) and VTK at four times.

Stage 2, the settled bed between two walls. A lid (a ``Wall``) comes down on the bed until it
presses it with the bed's weight, then holds still while the bed relaxes (nudged down again
until it still carries at least half that weight: 0.39 N of 0.76 N at 2,000 spheres); the
mechanics then stop. The plate is held at ``T_HOT``,
the lid at ``T_COLD``, the sides adiabatic; the engine's ``steady_state()`` gives the
temperatures. In the core (the middle 60 % of the bed height, away from the walls' contact
resistance) the temperature is fitted linearly in z, and

* ``k_network`` = Q / (A dT/dz), Q the heat through the plate, A the box's cross-section;
* ``k_affine`` = (1/V) sum_c H_c l_cz^2 over the contacts c whose midpoint is in the core
  (the conductivity of the same contacts if every one saw the uniform gradient: an upper
  bound of the network's, which relaxes the gradient where contacts are weak);
* ``k_affine_formula`` = phi Z H / (2 pi r), the isotropic form of the same with the core's
  solid fraction phi, coordination Z, mean contact conductance H and mean radius r.

Ends with one JSON line ``{"case": "falling_bed", "energy_drift": ..., "k_network": ...,
"k_affine": ..., "ratio": k_network / k_affine, ...}``.

    yade-electro -n -x cases/falling_bed.py [--n 2000]
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("falling_bed.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("falling_bed.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

RADIUS = 1e-3                   # m, mean
CONDUCTIVITY = 385.0            # W/(m K)
DENSITY = 8900.0                # kg/m^3
SPECIFIC_HEAT = 172.0           # J/(kg K)
YOUNG = 1e7                     # Pa (softened)
T_HOT, T_COLD = 373.15, 273.15  # K
PERIOD = 10                     # engine period, steps


def build(n=2000, seed=1):
    """Reset YADE: the box (plate + four frictionless sides) and the loose block above it.
    Returns dict(spheres, floor, sides, width [m])."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import pack, utils
    from yade import wrapper as W
    O = yade.Omega()
    O.reset()
    r = RADIUS
    width = 2 * r * round((n / 0.6 * 4 / 3 * math.pi * r ** 3 / (24 * r)) ** 0.5 / (2 * r))   # bed ~ 12 d high
    mat = O.materials.append(W.FrictMat(young=YOUNG, poisson=0.3, density=DENSITY, frictionAngle=math.atan(0.5)))
    smooth = O.materials.append(W.FrictMat(young=YOUNG, poisson=0.3, density=DENSITY, frictionAngle=0.0))
    floor = O.bodies.append(utils.wall(0, axis=2, sense=1, material=mat))
    h = width / 2
    sides = O.bodies.append([utils.wall(-h, axis=0, sense=1, material=smooth), utils.wall(h, axis=0, sense=-1,
                             material=smooth), utils.wall(-h, axis=1, sense=1, material=smooth),
                             utils.wall(h, axis=1, sense=-1, material=smooth)])
    height = n * 4 / 3 * math.pi * r ** 3 / 0.2 / (width - 2.4 * r) ** 2       # a loose cloud
    sp = pack.SpherePack()
    sp.makeCloud((-h + 1.2 * r, -h + 1.2 * r, 10e-3), (h - 1.2 * r, h - 1.2 * r, 10e-3 + height), rMean=r,
                 rRelFuzz=0.2, num=n, seed=seed)
    spheres = O.bodies.append([utils.sphere(c, rad, material=mat) for c, rad in sp])
    from caselib import frictional_bed
    frictional_bed(O, ("Wall",), gravity=(0, 0, -9.81), damping=0.2)
    return {"spheres": list(spheres), "floor": floor, "sides": list(sides), "width": width, "material": mat}


def fall(ids, duration=0.35, snapshots=4, out="out/falling_bed", verbose=True):
    """Stage 1: the block falls with the heat engine; returns figures and snapshots."""
    from yade_electro.yade import HeatEngine, InitialTemperature, Integrator, Material, Output, Reader, walls_from_dict
    from yade_electro.yade.runtime import import_yade
    from yade_electro.post.vtk import write_elements
    O = import_yade().Omega()
    sph = ids["spheres"]
    hot = {int(i): T_HOT for i in sph if O.bodies[int(i)].state.pos[0] < 0}
    walls = {"floor": dict(bodies=ids["floor"], temperature=None)}
    walls.update({f"side{k}": dict(bodies=b, temperature=None) for k, b in enumerate(ids["sides"])})
    e = HeatEngine(
        material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=walls_from_dict(walls),
        temperature=InitialTemperature(T_COLD, by_id=hot),
        law="contact",
        integrator=Integrator(theta="explicit"),
        reader=Reader(bonds="contacts"),
        output=Output(history=os.path.join(out, "falling_bed_history.csv")),
        iterPeriod=PERIOD,
        label="falling_bed")
    O.engines = O.engines + [e.runner]
    heat0 = e.coupled.heat_content()
    steps = int(duration / O.dt)
    chunk = max(steps // 40, PERIOD)
    drift, snaps, t1, done = 0.0, [], time.time(), 0
    snap_every = max(steps // max(snapshots - 1, 1), 1)
    contacts = []
    g = e.reader.graph
    snaps.append((float(O.time), g.pos.copy(), e.temperature.copy()))
    write_elements(os.path.join(out, "falling_bed_t0ms.vtu"), g.pos, g.radius, {"temperature": e.temperature})
    while done < steps:
        k = min(chunk, steps - done)
        O.run(k, True)
        done += k
        drift = max(drift, abs(e.coupled.heat_content() - heat0) / abs(heat0))
        contacts.append(int(np.sum(e.coupled.heat.conductance > 0)))
        if done % snap_every < chunk or done == steps:
            g = e.reader.graph
            snaps.append((float(O.time), g.pos.copy(), e.temperature.copy()))
            write_elements(os.path.join(out, f"falling_bed_t{1e3 * O.time:.0f}ms.vtu"), g.pos, g.radius,
                           {"temperature": e.temperature})
        if verbose and done % (10 * chunk) < chunk:
            el = time.time() - t1
            print(f"  falling: t = {O.time:.3f} s of {duration:g}, contacts {contacts[-1]}, energy drift {drift:.1e}; "
                  f"{el:.0f} s, about {el * (steps - done) / done:.0f} s left", flush=True)
    res = {"energy_drift": drift, "heat_J": heat0, "list_builds": e.reader.list_builds, "calls": e.reader.calls,
           "contacts_final": contacts[-1], "fall_s": round(time.time() - t1, 1)}
    e.remove()
    return res, snaps


def press_lid(ids, verbose=True):
    """Lower a lid onto the bed until it carries the bed's weight, let it settle, return its id."""
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    from yade import utils
    from yade import wrapper as W
    O = yade.Omega()
    sph = [O.bodies[int(i)] for i in ids["spheres"]]
    top = max(b.state.pos[2] + b.shape.radius for b in sph)
    weight = sum(b.state.mass for b in sph) * 9.81
    lid = O.bodies.append(utils.wall(top + 0.2 * RADIUS, axis=2, sense=-1, material=ids["material"]))
    mover = W.TranslationEngine(ids=[lid], translationAxis=(0, 0, -1), velocity=0.005, label="lid_mover")
    O.engines = O.engines[:-1] + [mover] + O.engines[-1:]
    for _ in range(10000):
        O.run(50, True)
        f = abs(O.forces.f(lid)[2])
        if f >= weight:
            break
    mover.velocity = 0.0
    for _ in range(20):                 # let the bed take the load; push again while it relaxes
        O.run(int(0.01 / O.dt), True)
        if abs(O.forces.f(lid)[2]) >= 0.5 * weight:
            break
        mover.velocity = 0.002
        O.run(int(0.002 / O.dt), True)
        mover.velocity = 0.0
    if verbose:
        print(f"  lid pressed: force {abs(O.forces.f(lid)[2]):.3g} N against the bed's weight {weight:.3g} N",
              flush=True)
    return lid


def conductivity(ids, lid):
    """Stage 2: steady temperatures between the plate (T_HOT) and the lid (T_COLD)."""
    from yade_electro.yade import HeatEngine, Material, Reader, Wall
    e = HeatEngine(
        material=Material(density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=[
            Wall("floor", bodies=ids["floor"], temperature=T_HOT),
            Wall("lid", bodies=lid, temperature=T_COLD)],
        temperature=0.5 * (T_HOT + T_COLD),
        law="contact",
        reader=Reader(bonds="contacts"),
        label="falling_bed_k")
    row = e.steady_state()
    g = e.reader.graph
    T = e.temperature
    z = g.pos[:, 2]
    z_lo, z_hi = float(np.min(z - g.radius)), float(np.max(z + g.radius))
    H = z_hi - z_lo
    core_lo, core_hi = z_lo + 0.2 * H, z_hi - 0.2 * H
    core = (z > core_lo) & (z < core_hi)
    slope = float(np.polyfit(z[core], T[core], 1)[0])
    A = ids["width"] ** 2
    Q = row["wall_power:floor"]
    k_net = -Q / (A * slope)
    pairs, G, _ = e.contact_heat_flow()
    idx = g.index_of(pairs.ravel()).reshape(-1, 2)
    mid = 0.5 * (z[idx[:, 0]] + z[idx[:, 1]])
    in_core = (mid > core_lo) & (mid < core_hi)
    lz = z[idx[:, 1]] - z[idx[:, 0]]
    V = A * (core_hi - core_lo)
    k_aff = float(np.sum(G[in_core] * lz[in_core] ** 2) / V)
    phi = float(np.sum(g.volume[core]) / V)
    both_core = core[idx[:, 0]] & core[idx[:, 1]]
    Z = 2.0 * int(np.sum(both_core)) / max(int(np.sum(core)), 1)
    H_mean = float(np.mean(G[in_core]))
    r_mean = float(np.mean(g.radius[core]))
    k_formula = phi * Z * H_mean / (2 * math.pi * r_mean)
    res = {"k_network": k_net, "k_affine": k_aff, "ratio": k_net / k_aff, "k_affine_formula": k_formula,
           "phi_core": phi, "Z_core": Z, "H_mean_W_per_K": H_mean, "Q_W": Q, "lid_Q_W": row["wall_power:lid"],
           "steady_balance": abs(Q + row["wall_power:lid"]) / abs(Q), "bed_height_m": H,
           "k_over_solid": k_net / CONDUCTIVITY}
    e.remove()
    return res


def plot(snaps, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, len(snaps), figsize=(4 * len(snaps), 4), sharey=True)
    for ax, (t, pos, T) in zip(np.atleast_1d(axes), snaps):
        sc = ax.scatter(pos[:, 0] * 1e3, pos[:, 2] * 1e3, c=T - 273.15, s=4, vmin=0, vmax=100, cmap="coolwarm")
        ax.set_title(f"t = {1e3 * t:.0f} ms")
        ax.set_xlabel("x [mm]")
        ax.set_aspect("equal")
    np.atleast_1d(axes)[0].set_ylabel("z [mm]")
    fig.colorbar(sc, ax=axes, label="degC")
    fig.suptitle("falling bed: positions and temperatures (side view)")
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def run(n=2000, seed=1, duration=0.35, out="out/falling_bed", verbose=True):
    os.makedirs(out, exist_ok=True)
    t0 = time.time()
    ids = build(n, seed)
    fall_res, snaps = fall(ids, duration, out=out, verbose=verbose)
    lid = press_lid(ids, verbose)
    k_res = conductivity(ids, lid)
    png = plot(snaps, os.path.join(out, f"falling_bed_n{n}.png"))
    return {"case": "falling_bed", "n": len(ids["spheres"]), **fall_res, **k_res, "png": png,
            "wall_s": round(time.time() - t0, 1)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--duration", type=float, default=0.35, help="fall and settling time [s]")
    ap.add_argument("--out", default="out/falling_bed")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    from caselib import apply_batch_table
    args = apply_batch_table(args, columns=("n", "seed"))
    res = run(args.n, args.seed, args.duration, args.out)
    with open(os.path.join(args.out, f"falling_bed_n{res['n']}.json"), "w") as fh:
        json.dump(res, fh)
    print(json.dumps(res))
    return res


if __name__ == "__main__":
    main()
