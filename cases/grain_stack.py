"""Resolved grains moved by YADE (issue 35, item 2 in the engine): grains as clumps of their
template's spheres, conducting inside through their Voronoi cells and across contacts through a
contact resistance, constant or from the contact pressure the DEM gives.

Two parts, one JSON line:

* ``two_discs``: paper 003's two thin cylinders (:mod:`two_grains`'s geometry, its values: r =
  0.5 m, w = 0.1 m, k = 1 W/(m K), rho c = 2e6 J/(m^3 K), R_c = 0.2 m^2 K/W; A at 400 K, B at
  300 K), each a grain of ``--n`` elements (a primitive shape: a cylinder cut at the chord),
  pressed together by 2 % of an element radius, as two YADE clumps under ``HeatEngine`` with
  ``grain_law`` (backward Euler, tau / 100 per call). Against the same network made without
  YADE (:func:`~yade_electro.network.grains.grain_network`: ``engine_vs_network_K``, the
  engine's plumbing) and against the finite-element answer (``engine_vs_fem_pct``, the mean
  error of B's mean temperature in per cent of the 100 K span, as :mod:`two_grains`).
* ``stack``: ``--grains`` hexagonal prisms (20 mm across the flats, 6 mm high, steel: k = 50
  W/(m K), 7,800 kg/m^3, 500 J/(kg K)) read from an STL surface written here (a closed mesh),
  each turned by a random angle about its axis, dropped one onto the other under gravity onto a
  fixed base grain (until every grain is slower than 0.01 mm/s); the heat engine runs during the fall (the contacts are found as the grains
  land). The contact resistance is Mikic's plastic law (Yovanovich's correlation; sigma = 2
  um, m = 0.12, H = 2 GPa) of the pressure: the normal force YADE's contacts carry between two
  grains over their contact's patch area. At rest the base is held at 400 K and the top grain
  at 300 K, and the steady state solved. The closed form: each contact carries the weight of
  the grains above it (their clumps' masses, g = 9.81 m/s^2), so with the same heat flow Q
  through each the temperature step at contact k is ``Q R_c(W_k / A_k) / A_k``; the
  ``step_ratios`` (each step over the lowest's) are compared with
  ``(W_k / W_1)^-0.95 (A_k / A_1)^-0.05`` (``step_ratio_error_pct``, which also holds the
  grains' own conduction, 0.1 % of a step here, and the DEM's settling: each contact's force
  over its weight is ``force_over_weight``); with the forces the engine read from YADE in
  place of the weights, ``step_ratio_vs_dem_forces_pct`` (the engine's plumbing of the
  pressure law). Also how many contact geometries were computed during the fall.

Run
---
    yade-electro -n -x cases/grain_stack.py [--n 1000] [--grains 4] [--quick]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import tempfile
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("grain_stack.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("grain_stack.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

ACROSS, HEIGHT = 20e-3, 6e-3                       # m
K, RHO, C = 50.0, 7800.0, 500.0                    # W/(m K), kg/m^3, J/(kg K)
SIGMA, SLOPE, HARDNESS = 2e-6, 0.12, 2e9           # m, -, Pa
G = 9.81                                           # m/s^2
T_HOT, T_COLD = 400.0, 300.0                       # K


def hex_prism_stl(path: str) -> str:
    """Write the prism's closed surface (ASCII STL, outward normals) to ``path``."""
    rc = ACROSS / np.sqrt(3.0)
    a = np.pi / 6 + np.arange(6) * np.pi / 3
    ring = np.column_stack([rc * np.cos(a), rc * np.sin(a)])
    lo = np.column_stack([ring, np.full(6, -0.5 * HEIGHT)])
    hi = np.column_stack([ring, np.full(6, 0.5 * HEIGHT)])
    tris = []
    for k in range(6):
        m = (k + 1) % 6
        tris += [(lo[k], lo[m], hi[m]), (lo[k], hi[m], hi[k])]
        tris += [(np.array([0, 0, -0.5 * HEIGHT]), lo[m], lo[k]), (np.array([0, 0, 0.5 * HEIGHT]), hi[k], hi[m])]
    with open(path, "w") as f:
        f.write("solid hexprism\n")
        for p, q, r in tris:
            n = np.cross(q - p, r - p)
            n = n / np.linalg.norm(n)
            f.write(f" facet normal {n[0]:.9e} {n[1]:.9e} {n[2]:.9e}\n  outer loop\n")
            for v in (p, q, r):
                f.write(f"   vertex {v[0]:.9e} {v[1]:.9e} {v[2]:.9e}\n")
            f.write("  endloop\n endfacet\n")
        f.write("endsolid hexprism\n")
    return path


def _scene(young: float, density: float, gravity=(0.0, 0.0, 0.0)):
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    O = yade.Omega()
    O.reset()
    O.materials.append(yade.FrictMat(young=young, poisson=0.3, frictionAngle=0.5, density=density, label="grain"))
    newton = yade.NewtonIntegrator(gravity=gravity, damping=0.4)
    O.engines = [yade.ForceResetter(), yade.InsertionSortCollider([yade.Bo1_Sphere_Aabb()]),
                 yade.InteractionLoop([yade.Ig2_Sphere_Sphere_ScGeom()], [yade.Ip2_FrictMat_FrictMat_FrictPhys()],
                                      [yade.Law2_ScGeom_FrictPhys_CundallStrack()]), newton]
    return yade, O, newton


def two_discs(n: int, cache_dir=None) -> dict:
    import two_grains as tg
    from yade_electro.fem.two_discs import two_discs_transient
    from yade_electro.geometry.shapes import Box, Cylinder, Intersection
    from yade_electro.network.grain_law import GrainSet
    from yade_electro.network.grains import grain_network
    from yade_electro.network.transient import HeatSolver
    from yade_electro.packing.grains import grain_template
    from yade_electro.yade import HeatEngine, Integrator, Material, Reader
    from yade_electro.yade.grains import add_grain, grain_law
    g = tg.geometry()
    shape = Intersection(Cylinder((0, 0, 0), (0, 0, g.w), g.r),
                         Box((-2 * g.r, -2 * g.r, -g.w), (0.5 * g.d, 2 * g.r, 2 * g.w)))
    tmpl = grain_template(shape, n, seed=1, cache_dir=cache_dir)
    flip = np.diag([-1.0, -1.0, 1.0])
    poses = [(np.eye(3), np.zeros(3)), (flip, np.array([g.d - 0.02 * tmpl.radii.mean(), 0.0, 0.0]))]
    tau, t = tg.times(g)
    dt = (t[1] - t[0]) / 10.0
    yade, O, newton = _scene(1e7, 1000.0)
    newton.dead = True                              # held in place: the heat only
    grains = GrainSet()
    clumps = [add_grain(grains, tmpl, tr, R) for R, tr in poses]
    eng = HeatEngine(material=Material(density=tg.RHO_C, specific_heat=1.0, conductivity=tg.K_LOW),
                     law=grain_law(grains, tg.R_C), reader=Reader(bonds="contacts", clumps="resolved"),
                     temperature=tg.T_B0, integrator=Integrator(theta="backward-euler", dt=dt), iterPeriod=1)
    eng.set_temperatures({clumps[0]: tg.T_A0})
    O.engines = O.engines + [eng.runner]
    O.dt = 1e-6
    B = np.isin(eng.body_ids if eng.coupled.heat is not None else np.zeros(0), grains.members[1])
    mean_B = []
    t0 = time.perf_counter()
    O.run(1, True)                                  # YADE's PyRunner: its first call at the second step
    for _ in range(t.size):
        O.run(10, True)
        ids = eng.body_ids
        B = np.isin(ids, grains.members[1])
        Cap = eng.coupled.capacity
        mean_B.append(float(Cap[B] @ eng.temperature[B] / Cap[B].sum()))
    engine_s = time.perf_counter() - t0
    e, Gc, Cn, first, contacts = grain_network([tmpl, tmpl], poses, tg.K_LOW, tg.RHO_C, tg.R_C,
                                               samples=eng.coupled.network.law.samples)
    heat = HeatSolver(Cn, e, Gc, np.repeat([tg.T_A0, tg.T_B0], tmpl.n), theta="backward-euler", solver="direct")
    for _ in range(10 * t.size):
        heat.advance(dt)
    by_id = eng.temperature_by_id
    T_engine = np.array([by_id[int(i)] for m in grains.members for i in m])
    fem = two_discs_transient(g, tg.K_LOW, tg.RHO_C, tg.R_C, tg.T_A0, tg.T_B0, t, h=0.025, dt=tau / 100)["mean_B"]
    eng.remove()
    return {"elements_per_grain": tmpl.n, "contact_area_m2": eng.coupled.network.law.contacts.get((0, 1)),
            "engine_vs_network_K": float(np.max(np.abs(T_engine - heat.temperature))),
            "engine_vs_fem_pct": tg.error_pct(mean_B, fem), "engine_s": engine_s,
            "mean_B_K": np.round(mean_B, 4).tolist()}


def stack(grains_n: int, n: int, cache_dir=None, seed: int = 3) -> dict:
    from yade_electro.geometry.surface_mesh import MeshShape, read_stl
    from yade_electro.network.grain_contact import mikic_resistance
    from yade_electro.network.grain_law import GrainSet
    from yade_electro.packing.grains import grain_template
    from yade_electro.yade import FixedTemperature, HeatEngine, Integrator, Material, Reader
    from yade_electro.yade.grains import GrainForces, add_grain, grain_law
    with tempfile.TemporaryDirectory() as work:
        shape = MeshShape(*read_stl(hex_prism_stl(os.path.join(work, "hexprism.stl"))), name="hexprism.stl")
    tmpl = grain_template(shape, n, seed=1, cache_dir=cache_dir)
    yade, O, newton = _scene(2e8, RHO, gravity=(0.0, 0.0, -G))
    grains = GrainSet()
    rng = np.random.default_rng(seed)
    clumps = []
    for k in range(grains_n):
        a = rng.uniform(0, np.pi / 3) if k else 0.0
        R = np.array([[np.cos(a), -np.sin(a), 0], [np.sin(a), np.cos(a), 0], [0, 0, 1]])
        clumps.append(add_grain(grains, tmpl, (0.0, 0.0, k * (HEIGHT + 1e-3)), R))
    O.bodies[clumps[0]].state.blockedDOFs = "xyzXYZ"
    O.bodies[clumps[0]].state.vel = (0, 0, 0)

    def rc(pressure):
        return mikic_resistance(pressure, SIGMA, SLOPE, HARDNESS, K)

    law = grain_law(grains, rc)
    eng = HeatEngine(material=Material(density=RHO, specific_heat=C, conductivity=K), law=law,
                     reader=Reader(bonds="contacts", clumps="resolved"),
                     boundaries=[FixedTemperature("base", nodes=[int(i) for i in grains.members[0]],
                                                  temperature=T_HOT)],
                     temperature=T_COLD, integrator=Integrator(theta="backward-euler", dt=0.5), iterPeriod=200)
    O.engines = O.engines + [eng.runner]
    O.dt = 0.5 * yade.utils.PWaveTimeStep()
    t0 = time.perf_counter()
    for chunk in range(200):                        # fall and settle: every grain slower than 0.1 mm/s
        O.run(2000, True)
        v = max(O.bodies[c].state.vel.norm() for c in clumps[1:])
        if chunk % 5 == 0:
            sys.stderr.write(f"[grain_stack] settling: {O.iter} steps, fastest grain {v:.3g} m/s, "
                             f"{len(eng.coupled.network.law.contacts)} contacts, {time.perf_counter() - t0:.0f} s\n")
        if chunk > 2 and v < 1e-5:
            break
    settle_s = time.perf_counter() - t0
    calls_falling = len(eng.history.rows)
    computed_falling = eng.coupled.network.law.contact_computations
    # at rest: the base hot, the top cold, steady
    top = [int(i) for i in grains.members[-1]]
    eng.remove()
    newton.dead = True
    eng = HeatEngine(material=Material(density=RHO, specific_heat=C, conductivity=K), law=law,
                     reader=Reader(bonds="contacts", clumps="resolved"),
                     boundaries=[FixedTemperature("base", nodes=[int(i) for i in grains.members[0]],
                                                  temperature=T_HOT),
                                 FixedTemperature("top", nodes=top, temperature=T_COLD)],
                     temperature=T_COLD, integrator=Integrator(steady=True, solver="direct"), iterPeriod=1)
    eng.steady_state()
    contacts = eng.coupled.network.law.contacts
    by_id = eng.temperature_by_id
    Cap = dict(zip(eng.body_ids.tolist(), eng.coupled.capacity.tolist()))
    mean = [float(sum(Cap[int(i)] * by_id[int(i)] for i in m) / sum(Cap[int(i)] for i in m)) for m in grains.members]
    pairs = [(k, k + 1) for k in range(grains_n - 1)]
    area = np.array([contacts.get(p, np.nan) for p in pairs])
    weight = np.array([G * sum(O.bodies[c].state.mass for c in clumps[k + 1:]) for k in range(grains_n - 1)])
    force = GrainForces(grains)(np.array(pairs))
    steps = -np.diff(mean)
    ratio = steps / steps[0]
    closed = (weight / weight[0]) ** -0.95 * (area / area[0]) ** -0.05
    closed_dem = (force / force[0]) ** -0.95 * (area / area[0]) ** -0.05      # with the forces the engine read
    eng.remove()
    return {"grains": grains_n, "elements_per_grain": tmpl.n, "template_volume_over_mesh": float(
                tmpl.volume.sum() / shape.exact_volume),
            "contacts": {f"{i}-{j}": a for (i, j), a in contacts.items()},
            "contact_area_m2": area.tolist(), "weight_N": weight.tolist(), "force_over_weight": (force / weight).tolist(),
            "pressure_Pa": (weight / area).tolist(), "mean_T_K": np.round(mean, 5).tolist(),
            "steps_K": steps.tolist(), "step_ratios": ratio.tolist(), "closed_form_ratios": closed.tolist(),
            "step_ratio_error_pct": float(100 * np.max(np.abs(ratio - closed) / closed)),
            "closed_form_ratios_dem_forces": closed_dem.tolist(),
            "step_ratio_vs_dem_forces_pct": float(100 * np.max(np.abs(ratio - closed_dem) / closed_dem)),
            "heat_calls_falling": calls_falling, "contact_computations_falling": computed_falling,
            "settle_s": settle_s}


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=1000, help="elements per disc (two_discs)")
    ap.add_argument("--grains", type=int, default=4, help="grains in the stack")
    ap.add_argument("--stack-n", type=int, default=200, help="elements per prism")
    ap.add_argument("--quick", action="store_true", help="small grains (a test's run)")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(argv)
    if args.quick:
        args.n, args.stack_n, args.grains = 300, 120, 3
    out = {"case": "grain_stack"}
    t0 = time.perf_counter()
    out["two_discs"] = two_discs(args.n, args.cache_dir)
    out["stack"] = stack(args.grains, args.stack_n, args.cache_dir)
    out["engine_vs_network_K"] = out["two_discs"]["engine_vs_network_K"]
    out["engine_vs_fem_pct"] = out["two_discs"]["engine_vs_fem_pct"]
    out["step_ratio_error_pct"] = out["stack"]["step_ratio_error_pct"]
    out["step_ratio_vs_dem_forces_pct"] = out["stack"]["step_ratio_vs_dem_forces_pct"]
    out["run_s"] = time.perf_counter() - t0
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
