"""A granular bed heated in a rigid container: the wall pressure rise against the bed's bulk
modulus, and the contact conductances following the new overlaps (issue 34, item 6).

Glass-like spheres (FrictMat, E = 70 GPa, linear contacts, friction angle 0.4) fill a 10 mm
cube of six rigid, smooth walls (``--wall-friction``, default 0); the packing is jammed without overlaps (``dense_packing``), then every radius is grown
by 0.5 % and YADE relaxes the bed (damping 0.5) to a confining pressure p0. Three runs from that
same state:

``bulk_modulus``
    All six walls moved in at a constant speed by a volumetric strain of 3e-4 in all;
    K = (mean wall pressure rise) / (volumetric strain).
``heating``
    ``ThermalExpansion(mode='radii', alpha=9e-6)``, every sphere heated by dT = 100 K in the
    fixed container. A rigid container blocks the volumetric strain 3 alpha dT, so the wall
    pressure should rise by about K 3 alpha dT (the bed's stiffness at that state; the radii
    grow by 9e-4, three times the strain of the modulus run: the contact network's response is
    not exactly linear). error_pct = 100 |dp - K 3 alpha dT| / (K 3 alpha dT).
    Smooth walls: with friction on the walls, the spheres along a wall slide on it as the other
    walls move in, and the wall friction stiffens the modulus run (K 35 % higher at 2,000
    spheres), but hardly the heating, where the spheres grow in place (dp 2 % lower). The
    estimate is then 27 % high: a property of the compression test, not of the heating.
``conductance``
    The bed's effective conductivity between the floor (303.15 K) and the lid (293.15 K),
    solved steady by ``HeatEngine`` (contacts through the geometric lens of the overlaps)
    before and after the heating: it follows the larger overlaps. With linear contact
    springs the overlaps grow as the pressure, and the lens radius (so the contact
    conductance) as its square root: the mean contact conductance should grow by about
    sqrt(p1 / p0) (``G_ratio_estimate``; the new contacts and the spread of the forces make
    the difference).

Run::

    yade-electro -n -x cases/heated_bed.py            # 2,000 spheres
    yade-electro -n -x cases/heated_bed.py --n 800    # the CI test

Ends with one JSON line (``error_pct``, the pressures, K, the conductivities).
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith("heated_bed.py")
                                       else __file__))
for d in (HERE, os.path.dirname(HERE)):
    if d not in sys.path:
        sys.path.insert(0, d)

import thermal_expansion as TE  # noqa: E402
from yade_electro.geometry.shapes import Box  # noqa: E402
from yade_electro.packing import dense_packing  # noqa: E402

SIDE, ALPHA, DT, T0 = 10e-3, 9e-6, 100.0, 293.15
PRESTRAIN, VOL_STRAIN = 5e-3, 3e-4


def _say(msg):
    sys.stderr.write(f"[heated_bed] {msg}\n")
    sys.stderr.flush()


def new_bed(n, seed=1, cache_dir=None, wall_friction=0.0):
    """A fresh scene: the packing in six walls, radii grown by PRESTRAIN and relaxed. Returns
    (spheres, walls {name: body}, steps)."""
    from yade import O, utils
    from yade.wrapper import (ForceResetter, FrictMat, InsertionSortCollider, InteractionLoop, NewtonIntegrator,
                              Bo1_Sphere_Aabb, Bo1_Wall_Aabb, Ig2_Sphere_Sphere_ScGeom, Ig2_Wall_Sphere_ScGeom,
                              Ip2_FrictMat_FrictMat_FrictPhys, Law2_ScGeom_FrictPhys_CundallStrack)
    from yade_electro.yade import ensure_thermal_state
    from yade_electro.yade.spheres import add_spheres
    O.reset()
    pk = dense_packing(Box((0, 0, 0), (SIDE, SIDE, SIDE)), n=n, seed=seed, cache_dir=cache_dir)
    O.materials.append(FrictMat(young=70e9, poisson=0.22, density=2500, frictionAngle=0.4, label="glass"))
    O.materials.append(FrictMat(young=70e9, poisson=0.22, density=2500, frictionAngle=wall_friction, label="smooth"))
    ids = add_spheres(pk.centers, pk.radii * (1.0 + PRESTRAIN), material="glass")
    walls = {}
    for name, (axis, x, sense) in {"floor": (2, 0.0, 1), "lid": (2, SIDE, -1), "x0": (0, 0.0, 1),
                                   "x1": (0, SIDE, -1), "y0": (1, 0.0, 1), "y1": (1, SIDE, -1)}.items():
        walls[name] = O.bodies[O.bodies.append(utils.wall(x, axis=axis, sense=sense, material="smooth"))]
    O.engines = [ForceResetter(), InsertionSortCollider([Bo1_Sphere_Aabb(), Bo1_Wall_Aabb()]),
                 InteractionLoop([Ig2_Sphere_Sphere_ScGeom(), Ig2_Wall_Sphere_ScGeom()],
                                 [Ip2_FrictMat_FrictMat_FrictPhys()], [Law2_ScGeom_FrictPhys_CundallStrack()]),
                 NewtonIntegrator(damping=0.5)]
    O.dt = 0.5 * utils.PWaveTimeStep()
    spheres = [O.bodies[i] for i in ids]
    ensure_thermal_state(spheres)
    for b in spheres:
        b.state.temp = T0
    steps = relax(lambda: pressure(walls))
    return spheres, walls, steps


def pressure(walls):
    """Mean normal stress on the six walls [Pa] (compression positive), on the box's current
    faces."""
    from yade import O
    lo = {a: walls[n].state.pos[a] for n, a in (("x0", 0), ("y0", 1), ("floor", 2))}
    hi = {a: walls[n].state.pos[a] for n, a in (("x1", 0), ("y1", 1), ("lid", 2))}
    size = [hi[a] - lo[a] for a in range(3)]
    total = 0.0
    for name, axis in (("x0", 0), ("x1", 0), ("y0", 1), ("y1", 1), ("floor", 2), ("lid", 2)):
        area = size[(axis + 1) % 3] * size[(axis + 2) % 3]
        total += abs(O.forces.f(walls[name].id)[axis]) / area
    return total / 6.0


def relax(figure):
    """Run until ``figure()`` settles (``cases/thermal_expansion.py``'s rule; no unbalanced
    force test: the walls are held). Returns the steps."""
    return TE.relax(figure, unbalanced=None)[1]


def bulk_modulus(n, cache_dir, wall_friction=0.0):
    from yade import O
    spheres, walls, _ = new_bed(n, cache_dir=cache_dir, wall_friction=wall_friction)
    p0 = pressure(walls)
    ramp = 2000
    v = VOL_STRAIN / 3.0 * SIDE / (ramp * O.dt)            # each wall in by a third of the strain / 2
    for name, (axis, sign) in {"floor": (2, 1), "lid": (2, -1), "x0": (0, 1), "x1": (0, -1), "y0": (1, 1),
                               "y1": (1, -1)}.items():
        vel = [0.0, 0.0, 0.0]
        vel[axis] = 0.5 * sign * v
        walls[name].state.vel = tuple(vel)
    O.run(ramp, True)
    for w in walls.values():
        w.state.vel = (0.0, 0.0, 0.0)
    steps = relax(lambda: pressure(walls))
    size = np.array([walls["x1"].state.pos[0] - walls["x0"].state.pos[0],
                     walls["y1"].state.pos[1] - walls["y0"].state.pos[1],
                     walls["lid"].state.pos[2] - walls["floor"].state.pos[2]])
    eps_v = 1.0 - float(np.prod(size)) / SIDE ** 3
    p1 = pressure(walls)
    return {"p0_Pa": p0, "dp_Pa": p1 - p0, "volumetric_strain": eps_v, "K_Pa": (p1 - p0) / eps_v, "steps": steps,
            "spheres": len(spheres)}


def conductivity(spheres, walls):
    """The bed's effective conductivity [W/(m K)] between the floor and the lid, steady, from
    the heat flow through the contacts that cross mid-height; and the mean contact
    conductance [W/K]."""
    from yade_electro.yade import HeatEngine, Material, Reader, Wall
    heat = HeatEngine(material=Material(density=2500.0, specific_heat=800.0, conductivity=1.0),
                      boundaries=[Wall("floor", bodies=walls["floor"].id, temperature=T0 + 10.0),
                                  Wall("lid", bodies=walls["lid"].id, temperature=T0)],
                      temperature=T0, reader=Reader(bonds="contacts"), label="probe")
    heat.steady_state()
    pairs, G, q = heat.contact_heat_flow()
    from yade import O
    z = {b.id: b.state.pos[2] for b in spheres}
    zm = 0.5 * SIDE
    flow = 0.0
    for (a, b), qq in zip(pairs.tolist(), q.tolist()):
        za, zb = z.get(a), z.get(b)
        if za is not None and zb is not None and (za - zm) * (zb - zm) < 0:
            flow += qq if za < zm else -qq             # upwards
    heat.remove()
    O.engines = [e for e in O.engines if getattr(e, "label", "") != "probe"]
    return flow * SIDE / (SIDE * SIDE * 10.0), float(np.mean(G))


def heating(n, cache_dir, wall_friction=0.0):
    from yade import O
    from yade_electro.yade import ThermalExpansion
    spheres, walls, _ = new_bed(n, cache_dir=cache_dir, wall_friction=wall_friction)
    k0, g0 = conductivity(spheres, walls)
    for b in spheres:                                   # the probe wrote its field: back to T0
        b.state.temp = T0
    p0 = pressure(walls)
    e = ThermalExpansion(alpha=ALPHA, mode="radii", iterPeriod=500)
    O.engines = O.engines + [e.runner]
    for b in spheres:
        b.state.temp = T0 + DT
    e.step()
    steps = relax(lambda: pressure(walls))
    p1 = pressure(walls)
    e.remove()                                          # the radii stay grown
    k1, g1 = conductivity(spheres, walls)
    return {"p0_Pa": p0, "dp_Pa": p1 - p0, "steps": steps, "k_before_W_mK": k0, "k_after_W_mK": k1,
            "mean_G_before_W_K": g0, "mean_G_after_W_K": g1, "spheres": len(spheres)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--cache-dir", default=None)
    ap.add_argument("--wall-friction", type=float, default=0.0, help="the walls' friction angle [rad]")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    t0 = time.time()
    _say(f"bulk modulus: {args.n} spheres")
    K = bulk_modulus(args.n, args.cache_dir, args.wall_friction)
    _say("heating")
    H = heating(args.n, args.cache_dir, args.wall_friction)
    estimate = K["K_Pa"] * 3.0 * ALPHA * DT
    out = {"case": "heated_bed", "spheres": H["spheres"], "wall_friction": args.wall_friction, "p0_Pa": H["p0_Pa"], "K_Pa": K["K_Pa"],
           "dp_Pa": H["dp_Pa"], "dp_estimate_Pa": estimate,
           "error_pct": 100.0 * abs(H["dp_Pa"] - estimate) / estimate,
           "k_before_W_mK": H["k_before_W_mK"], "k_after_W_mK": H["k_after_W_mK"],
           "conductivity_ratio": H["k_after_W_mK"] / H["k_before_W_mK"],
           "mean_G_ratio": H["mean_G_after_W_K"] / H["mean_G_before_W_K"],
           "G_ratio_estimate": float(np.sqrt((H["p0_Pa"] + H["dp_Pa"]) / H["p0_Pa"])),
           "bulk_modulus_run": K, "wall_s": round(time.time() - t0, 1)}
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
