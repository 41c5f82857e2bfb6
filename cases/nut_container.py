"""Paper 003's multibody case (issue 35): nut-shaped particles poured into a cylinder whose walls
are held at 300 C, heated by conduction only; lumped against resolved clumps, nuts against
spheres of the same volume.

A nut is a clump of 12 spheres (r_m = 1.6 mm) on a ring of radius 4 mm in one plane: a
hexagon-like ring 11.2 mm across with a 4.8 mm hole, its members overlapping by 1.13 mm (the
paper's nut is a meshed hexagonal nut; this is the clumped approximation a DEM user builds).
``--nuts`` of them (default 2,000) are made as a random cloud (``makeClumpCloud``) above a
cylinder (radius 45 mm, facets) and poured in under gravity (Hertz-free linear contacts,
FrictMat, damping 0.4) until 90 % of the particles move slower than 1 mm/s (at most 200,000
steps: a few rattlers keep rolling). Then the side and the bottom of the cylinder
(two ``Wall``s) are held at 573.15 K; the nuts start at 293.15 K. Steel: k = 50 W/(m K),
rho = 7,800 kg/m^3, c = 500 J/(kg K). The heat engine (``HeatEngine``, contact law, backward
Euler, a thermal step of ``--dt`` per call) runs on the still bed in three set-ups:

* ``lumped``: one temperature per nut (``Reader(clumps='lumped')``);
* ``resolved``: one per member, members joined through their lenses (``clumps='resolved'``);
* ``spheres``: the same number of single spheres of the nut's volume (its members' union),
  poured the same way.

Figures (one JSON line): for each set-up the elements, the bed's height, its wall contacts,
the capacity-weighted mean temperature against time and the time at which it reaches half of
the way to 573.15 K (``t_half_s``), the run times (pouring, heat calls); and how far lumped is
from resolved (``lumped_vs_resolved_pct``: the mean over the history of the difference of the
mean temperatures, in per cent of the 280 K span). There is no reference solution: the figures
are the comparison.

Run
---
    yade-electro -n -x cases/nut_container.py [--nuts 2000] [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("nut_container.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("nut_container.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

MEMBER_R, RING_R, MEMBERS = 1.6e-3, 4.0e-3, 12          # m, m, spheres per nut
CONTAINER_R = 45e-3                                      # m
K, RHO, C = 50.0, 7800.0, 500.0                          # W/(m K), kg/m^3, J/(kg K)
T_WALL, T0 = 573.15, 293.15                              # K


def nut_template():
    """The nut's members: (relative centres (12, 3) [m], radii (12,) [m])."""
    a = 2 * np.pi * np.arange(MEMBERS) / MEMBERS
    return np.column_stack([RING_R * np.cos(a), RING_R * np.sin(a), np.zeros(MEMBERS)]), np.full(MEMBERS, MEMBER_R)


def nut_volume() -> float:
    """The union of a nut's members [m^3] (each sphere less half of each lens it shares)."""
    from yade_electro.network.lumping import member_volumes
    c, r = nut_template()
    return float(member_volumes(c, r, np.zeros(MEMBERS, np.int64)).sum())


def pour(nuts: int, shape: str, seed: int = 1):
    """A fresh scene with the container and ``nuts`` particles (``shape`` 'nut' or 'sphere')
    poured in until still; returns (side wall ids, bottom wall ids, seconds)."""
    from yade import geom, pack
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    O = yade.Omega()
    O.reset()
    O.materials.append(yade.FrictMat(young=5e7, poisson=0.3, frictionAngle=0.4, density=RHO, label="steel"))
    height = 0.02 + nuts * nut_volume() / (0.3 * np.pi * CONTAINER_R ** 2)     # room to pour
    side = O.bodies.append(geom.facetCylinder((0, 0, 0.5 * height), CONTAINER_R, height, wallMask=4,
                                              segmentsNumber=36, material="steel"))
    bottom = O.bodies.append(geom.facetCylinder((0, 0, 0.5 * height), CONTAINER_R, height, wallMask=2,
                                                segmentsNumber=36, material="steel"))
    half = 0.68 * CONTAINER_R
    # a cloud tall enough for the particles' bounding spheres (makeClumpCloud places them apart)
    top = 0.01 + max(3 * height, 1.5 * nuts * (2.4 * (RING_R + MEMBER_R)) ** 3 / (2 * half) ** 2)
    sp = pack.SpherePack()
    if shape == "nut":
        c, r = nut_template()
        tmpl = pack.SpherePack([(tuple(p), float(q)) for p, q in zip(c, r)])
        made = sp.makeClumpCloud((-half, -half, 0.01), (half, half, top), [tmpl], num=nuts, seed=seed)
    else:
        r_eq = (3 * nut_volume() / (4 * np.pi)) ** (1 / 3)
        made = sp.makeCloud((-half, -half, r_eq), (half, half, top), rMean=r_eq, rRelFuzz=0.0, num=nuts, seed=seed)
    if made < nuts:
        raise RuntimeError(f"only {made} of {nuts} {shape}s fit in the pouring region")
    sp.toSimulation(material="steel")
    O.engines = [yade.ForceResetter(), yade.InsertionSortCollider([yade.Bo1_Sphere_Aabb(), yade.Bo1_Facet_Aabb()]),
                 yade.InteractionLoop([yade.Ig2_Sphere_Sphere_ScGeom(), yade.Ig2_Facet_Sphere_ScGeom()],
                                      [yade.Ip2_FrictMat_FrictMat_FrictPhys()],
                                      [yade.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 yade.NewtonIntegrator(gravity=(0, 0, -9.81), damping=0.4)]
    O.dt = 0.5 * yade.utils.PWaveTimeStep()
    t0 = time.perf_counter()
    for chunk in range(400):                      # pour until still: 90 % of the particles under 1 mm/s
        O.run(500, True)
        v = float(np.percentile([b.state.vel.norm() for b in O.bodies if b.isClump or (
            shape == "sphere" and b.isStandalone and isinstance(b.shape, yade.Sphere))], 90))
        if chunk % 10 == 0:
            sys.stderr.write(f"[nut_container] pouring {shape}s: {O.iter} steps, 90th percentile speed {v:.3g} m/s, "
                             f"{time.perf_counter() - t0:.0f} s\n")
        if chunk > 4 and v < 1e-3:
            break
    return list(side), list(bottom), time.perf_counter() - t0


def heat(side, bottom, mode, calls: int, dt: float) -> dict:
    """The heat engine on the still bed: ``calls`` calls of ``dt`` [s]; the mean temperature history."""
    from yade_electro.yade import HeatEngine, Integrator, Material, Reader, Wall
    from yade_electro.yade.runtime import import_yade
    O = import_yade().Omega()
    eng = HeatEngine(material=Material(density=RHO, specific_heat=C, conductivity=K), law="contact",
                     reader=Reader(bonds="contacts", clumps=mode if mode != "spheres" else None),
                     boundaries=[Wall("side", bodies=side, temperature=T_WALL),
                                 Wall("bottom", bodies=bottom, temperature=T_WALL)],
                     temperature=T0, integrator=Integrator(theta="backward-euler", dt=dt), iterPeriod=1,
                     label=f"heat_{mode}")
    O.engines = O.engines + [eng.runner]
    newton = [e for e in O.engines if type(e).__name__ == "NewtonIntegrator"][0]
    newton.dead = True                            # the bed is still: heat only
    t0 = time.perf_counter()
    O.run(calls + 1, True)
    wall = time.perf_counter() - t0
    rows = eng.history.rows
    t = np.array([r["time"] for r in rows])
    Tm = np.array([r["T_mean"] for r in rows])
    g = eng.reader.graph
    half = 0.5 * (T0 + T_WALL)
    t_half = float(np.interp(half, Tm, t)) if Tm[-1] >= half else None
    out = {"elements": int(g.n_nodes), "bed_height_m": float(g.pos[:, 2].max() + g.radius.max()),
           "wall_contacts": int(rows[-1]["wall_contacts:side"] + rows[-1]["wall_contacts:bottom"]),
           "time_s": t.tolist(), "T_mean_K": Tm.round(4).tolist(), "t_half_s": t_half,
           "heat_call_ms": 1e3 * wall / max(calls, 1),
           "ledger_error": abs(rows[-1]["heat_content"] - rows[-1]["boundary_heat"] - rows[-1]["particle_heat"])
           / abs(rows[-1]["heat_content"])}
    newton.dead = False
    eng.remove()
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--nuts", type=int, default=2000)
    ap.add_argument("--calls", type=int, default=60)
    ap.add_argument("--dt", type=float, default=20.0, help="thermal step per call [s]")
    ap.add_argument("--quick", action="store_true", help="150 nuts, 30 calls (the CI test)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    nuts, calls = (150, 30) if args.quick else (args.nuts, args.calls)
    out = {"case": "nut_container", "nuts": nuts, "members_per_nut": MEMBERS, "nut_volume_m3": nut_volume(),
           "calls": calls, "dt_s": args.dt}
    side, bottom, t_pour = pour(nuts, "nut")
    out["pour_nuts_s"] = t_pour
    for mode in ("lumped", "resolved"):
        out[mode] = heat(side, bottom, mode, calls, args.dt)
    side, bottom, t_pour = pour(nuts, "sphere")
    out["pour_spheres_s"] = t_pour
    out["spheres"] = heat(side, bottom, "spheres", calls, args.dt)
    lum, res = np.array(out["lumped"]["T_mean_K"]), np.array(out["resolved"]["T_mean_K"])
    out["lumped_vs_resolved_pct"] = float(100 * np.mean(np.abs(lum - res)) / (T_WALL - T0))
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
