"""Thermal stress of a Joule-heated notched bar: the DEM against a thermo-elastic FEM (issue
34, item 4).

The notched bar of ``cases/notched_joule.py`` (6 x 1.1 x 1.1 mm, two 0.6 x 0.3 mm notches at
mid-length) heats adiabatically for 0.01 s under ``--voltage`` (0.5 V: the ligament rises by
about 75 K, the bonds stay far from their strength). The temperature field is the FEM's
(scikit-fem, P1, Crank-Nicolson: ``yade_electro.fem.thermal.joule_heating``), given to both
sides, so that the comparison isolates the thermo-mechanics:

* FEM: ``yade_electro.fem.thermoelastic.thermal_stress`` (P2 displacements) with the packing's
  own E and nu (measured first by ``cases/thermal_expansion.py``'s ``moduli`` on a straight bar
  of the same section and mean radius) and alpha = 1.7e-5 1/K;
* DEM: the bonded notched bar, each element at the FEM temperature of its centre,
  ``ThermalExpansion(mode='bonds')``, relaxed by YADE.

Both hold the end x = 0 on rollers (the DEM: its end layer's centres, x <= 1.2 r_mean, held
in x) and remove the rigid-body modes the same way (one point held in x, y, z, one in x and z).
Figures: the elongation (mean x displacement of the end layer at x = L minus that at x = 0,
the FEM interpolated at the DEM layers' centres) and the mean stress of the ligament slab
(|x - L/2| < 0.3 mm; FEM volume average over its elements, DEM Love-Weber over its
elements), component by component.

Run::

    yade-electro -n -x cases/notched_thermal_stress.py              # 10,000 elements
    yade-electro -n -x cases/notched_thermal_stress.py --n 3000     # the CI test

Ends with one JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith("notched_thermal_stress.py")
                                       else __file__))
for d in (HERE, os.path.dirname(HERE)):
    if d not in sys.path:
        sys.path.insert(0, d)

import notched_joule as NJ  # noqa: E402
import thermal_expansion as TE  # noqa: E402

ALPHA = 1.7e-5          # 1/K, 304L


def _say(msg):
    sys.stderr.write(f"[notched_thermal_stress] {msg}\n")
    sys.stderr.flush()


def fem_temperature(voltage, h, layers):
    """The FEM's notched-bar mesh and its temperature at t = 0.01 s (P1, at the vertices)."""
    from yade_electro.fem.meshes import notched_bar_mesh
    from yade_electro.fem.thermal import joule_heating
    mesh = notched_bar_mesh(NJ.bar_geometry(), h, 0.5, layers)
    res = joule_heating(mesh, NJ.RHO_E, NJ.CONDUCTIVITY, NJ.DENSITY * NJ.SPECIFIC_HEAT, {"end1": voltage, "end0": 0.0},
                        t_end=NJ.T_END, dt=NJ.T_END / 20, theta=0.5, T0=NJ.T0, order=1)
    return mesh, res


def fem_mesh(h, layers):
    from yade_electro.fem.meshes import notched_bar_mesh
    return notched_bar_mesh(NJ.bar_geometry(), h, 0.5, layers)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10000, help="elements of the notched bar")
    ap.add_argument("--voltage", type=float, default=0.5)
    ap.add_argument("--h", type=float, default=0.1e-3, help="FEM mesh size [m]")
    ap.add_argument("--layers", default="2,4,6", help="FEM element layers through the thickness, coarse to fine")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    t0 = time.time()
    from yade import O
    from yade_electro.fem.thermoelastic import thermal_stress
    from yade_electro.yade import ThermalExpansion, ensure_thermal_state
    from yade_electro.yade import packing as P

    _say(f"FEM Joule heating, h = {args.h * 1e3:.3f} mm")
    layers = [int(k) for k in args.layers.split(",")]
    mesh, heat = fem_temperature(args.voltage, args.h, layers[0])
    # the straight bar of the same section and mean radius, for E and nu
    V_notched = NJ.LENGTH * NJ.WIDTH * NJ.THICKNESS - 2 * NJ.NOTCH_WIDTH * NJ.NOTCH_DEPTH * NJ.THICKNESS
    n_bar = int(round(args.n * NJ.LENGTH * NJ.WIDTH * NJ.THICKNESS / V_notched))
    _say(f"moduli: straight bar of {n_bar} elements")
    mod = TE.moduli(n_bar, (NJ.WIDTH, NJ.THICKNESS, NJ.LENGTH), args.cache_dir)
    E, nu = mod["E_Pa"], mod["nu"]

    _say(f"DEM: notched bar of {args.n} elements")
    O.reset()
    pk = P.dense_packing(NJ.bar_shape(), n=args.n, seed=1, cache_dir=args.cache_dir)
    ids = P.add_bonded_packing(pk, damping=0.5)
    bodies = [O.bodies[i] for i in ids]
    ensure_thermal_state(bodies)
    x0 = TE.positions(bodies)
    T = heat.probe(x0)
    if not np.all(np.isfinite(T)):
        raise RuntimeError("some element centres are outside the FEM mesh")
    for b in bodies:
        b.state.temp = NJ.T0
    r_mean = float(pk.radii.mean())
    end0 = x0[:, 0] <= x0[:, 0].min() + 1.2 * r_mean
    end1 = x0[:, 0] >= x0[:, 0].max() - 1.2 * r_mean
    k_a, k_b = NJ.hold_on_rollers(bodies, x0, end0)
    e = ThermalExpansion(alpha=ALPHA, mode="bonds", reference_temperature=NJ.T0, iterPeriod=500)
    O.engines = O.engines + [e.runner]
    for b, t in zip(bodies, T.tolist()):
        b.state.temp = t
    e.step()

    def elongation():
        x = TE.positions(bodies)
        return float(np.mean(x[end1, 0] - x0[end1, 0]) - np.mean(x[end0, 0] - x0[end0, 0]))
    _, steps = TE.relax(elongation, unbalanced=None, rtol=1e-4)
    dem_elong = elongation()
    lig = np.abs(x0[:, 0] - 0.5 * NJ.LENGTH) < 0.5 * NJ.NOTCH_WIDTH
    s = e.element_stress()
    V = e.element_volumes()
    dem_sigma = np.einsum("n,nij->ij", V[lig], s[lig]) / V[lig].sum()

    # FEM: the same rollers and pins (the nodes nearest the two held elements, on x = 0), on
    # meshes refined through the thickness (the heating does not vary with z: the temperature
    # of the first mesh is taken, interpolated to the others)
    fems = []
    for k in layers:
        _say(f"FEM thermo-elasticity (P2), {k} layers")
        m, _ = (mesh, None) if k == layers[0] else (fem_mesh(args.h, k), None)
        Tm = heat.T if k == layers[0] else heat.probe(m.p.T)
        face = np.flatnonzero(np.abs(m.p[0]) < 1e-12)

        def nearest(p):
            return int(face[np.argmin(np.sum((m.p[1:, face].T - p[1:]) ** 2, axis=1))])
        fem = thermal_stress(m, Tm, NJ.T0, E, nu, ALPHA, {"end0": (0,)},
                             pins=((nearest(x0[k_a]), (1, 2)), (nearest(x0[k_b]), (2,))))
        u0, u1 = fem.displacement_at(x0[end0]), fem.displacement_at(x0[end1])
        c = fem.centroids()
        fems.append((k, int(m.p.shape[1]), float(u1[:, 0].mean() - u0[:, 0].mean()),
                     fem.mean_stress_where(np.abs(c[:, 0] - 0.5 * NJ.LENGTH) < 0.5 * NJ.NOTCH_WIDTH)))
    _, nodes, fem_elong, fem_sigma = fems[-1]
    T_lig = float(np.mean(T[lig]))
    scale = E * ALPHA * (T_lig - NJ.T0)
    names = ("xx", "yy", "zz")
    out = {"case": "notched_thermal_stress", "elements": len(bodies), "voltage": args.voltage, "E_Pa": E, "nu": nu,
           "T_ligament_K": T_lig, "T_max_K": float(np.max(heat.T)),
           "elongation_dem_m": dem_elong, "elongation_fem_m": fem_elong,
           "elongation_error_pct": 100.0 * abs(dem_elong - fem_elong) / abs(fem_elong),
           "ligament_stress_dem_Pa": {a: float(dem_sigma[i, i]) for i, a in enumerate(names)},
           "ligament_stress_fem_Pa": {a: float(fem_sigma[i, i]) for i, a in enumerate(names)},
           "ligament_stress_diff_over_E_alpha_dT_pct": {a: float(100 * (dem_sigma[i, i] - fem_sigma[i, i]) / scale)
                                                         for i, a in enumerate(names)},
           "E_alpha_dT_ligament_Pa": scale, "fem_nodes": nodes, "fem_h_m": args.h,
           "fem_by_layers": [{"layers": k, "nodes": nn, "elongation_m": el,
                              "ligament_stress_Pa": {a: float(sg[i, i]) for i, a in enumerate(names)}}
                             for k, nn, el, sg in fems],
           "steps": steps, "wall_s": round(time.time() - t0, 1)}
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
