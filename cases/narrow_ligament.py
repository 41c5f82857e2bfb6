"""Joule heating through a ligament a few elements wide (issue 36, item 23): the resistance and
the temperature at the ligament's centre in the first milliseconds, against a finite-element
reference, and where the local error comes from.

Geometry (ours): a bar 6 x 1.1 x 1.1 mm along x with two rectangular notches through the
thickness at mid-length, 0.6 mm long and 0.45 mm deep, one from each side: the ligament is
0.2 mm wide (y) and 1.1 mm thick (z), about two element diameters at 10,000 elements
(r_mean 47 um). 304L with constant properties (rho_e 0.73e-6 ohm m, 7,900 kg/m^3, 500 J/(kg K),
15 W/(m K)), 1 V between the end faces (surface electrodes), adiabatic, from 293.15 K.

* **FEM** (:mod:`yade_electro.fem`: P1 tetrahedra of one layer, nothing varies in z;
  Crank-Nicolson, 0.05 ms steps): R_eq from ``--hs`` meshes with Richardson's extrapolation;
  temperatures recorded at ``--times`` at the ligament's centre and at sample points that fill
  the cells of the DEM elements nearest to it (finest mesh).
* **DEM**: ``ElectroThermalEngine``, law 'voronoi' (cells bounded by the exact container),
  surface electrodes on the end faces, backward Euler of 0.05 ms, ``--n`` elements, seeds
  ``--seeds``. ``--refine F``: a graded packing of the same ``--n``, its elements F times
  smaller within 0.7 mm of the middle (:class:`yade_electro.packing.Refinement`, back to the
  full size over 0.4 mm): the field's singular edges at the notches get finer cells, the
  uniform arms coarser ones, which the Voronoi network carries exactly anyway.

At the recorded times, for the element whose centre is nearest the ligament's centre:

* ``T_rise_vs_point_pct``: its temperature rise against the FEM's at the ligament's centre
  point (what a probe at that point compares);
* ``T_rise_vs_own_point_pct``: against the FEM's at the element's own centre;
* ``T_rise_vs_cell_pct``: against the FEM's mean over the element's Voronoi cell (sample
  points in the solid nearer to its centre than to any other's): the like-for-like
  comparison, since an element's temperature is its cell's heat over its cell's capacity.

Early in the heating conduction has not moved heat yet, so a rise is the source over the
capacity: the DEM's ``P_i / C_i`` against the FEM's ``rho_e |J|^2 / (rho c)`` averaged over
the cell. The ligament's centre is where ``|J|`` is smallest across the ligament (it crowds
to the notches' corners), so a cell's mean there is above the centre's value: a point probe
reads low against any cell average, by an amount that shrinks as the cells do.

Run
---
    yade-electro -n -x cases/narrow_ligament.py [--n 10000] [--seeds 1,2,3,4] [--quick]
    yade-electro -n -x cases/narrow_ligament.py --notch-depth 0.3e-3   # notched_joule's 0.5 mm ligament
    yade-electro -n -x cases/narrow_ligament.py --refine 0.75 --sharing cells   # graded: smaller elements there

Ends with one JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("narrow_ligament.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("narrow_ligament.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

LENGTH, WIDTH, THICKNESS = 6e-3, 1.1e-3, 1.1e-3        # m
NOTCH_WIDTH, NOTCH_DEPTH = 0.6e-3, 0.45e-3              # m: ligament 0.2 mm
RHO_E, DENSITY, SPECIFIC_HEAT, CONDUCTIVITY = 0.73e-6, 7900.0, 500.0, 15.0
T0, VOLTAGE, DT = 293.15, 1.0, 5e-5                     # K, V, s
CENTRE = np.array([0.5 * LENGTH, 0.5 * WIDTH, 0.5 * THICKNESS])


def shape(depth: float = NOTCH_DEPTH):
    """The notched bar, notches ``depth`` [m] deep from each side (the ligament: WIDTH - 2 depth)."""
    from yade_electro.geometry.shapes import Box
    a, b = 0.5 * (LENGTH - NOTCH_WIDTH), 0.5 * (LENGTH + NOTCH_WIDTH)
    L, B, Z, D = LENGTH, WIDTH, THICKNESS, depth
    return (Box((0, 0, 0), (L, B, Z)) - Box((a, -B, -Z), (b, D, 2 * Z)) - Box((a, B - D, -Z), (b, 2 * B, 2 * Z)))


def fem_geometry(depth: float = NOTCH_DEPTH):
    from yade_electro.fem import NotchedBarGeometry
    return NotchedBarGeometry(length=LENGTH, width=WIDTH, thickness=THICKNESS, notch_width=NOTCH_WIDTH,
                              notch_depth=depth, kind="rect", sides="both")


def fem_run(h: float, t_end: float, probes, depth: float = NOTCH_DEPTH):
    """One FEM run: (R_eq [ohm], recorded times [s], probe temperatures (nrec, npts) [K])."""
    from yade_electro import fem
    g = fem_geometry(depth)
    mesh = fem.notched_bar_mesh(g, h, 0.5, 1)
    res = fem.joule_heating(mesh, RHO_E, CONDUCTIVITY, DENSITY * SPECIFIC_HEAT, {"end1": VOLTAGE, "end0": 0.0},
                            t_end=t_end, dt=DT, theta=0.5, T0=T0, probes=probes)
    return float(res.resistance[0]), np.asarray(res.times), np.asarray(res.probe_temperatures), int(res.basis.N)


def cell_samples(centres, radius, k: int, per_cell: int, seed: int = 5, depth: float = NOTCH_DEPTH):
    """Sample points of the cells of element ``k``: uniform in a box of 2.5 radii around its
    centre, kept when inside the solid and nearer to it than to any other centre."""
    from scipy.spatial import cKDTree
    rng = np.random.default_rng(seed)
    c, r = centres[k], 2.5 * float(radius[k])
    pts = c + rng.uniform(-r, r, size=(40 * per_cell, 3))
    pts = pts[shape(depth).sdf(pts) < 0]
    pts = pts[cKDTree(centres).query(pts)[1] == k]
    return pts[:per_cell]


def refinement(factor: float):
    """Smaller elements around the ligament: radius ``factor`` within 0.7 mm of the bar's
    middle along x (the notches and 0.4 mm beyond them), back to the full size over 0.4 mm."""
    from yade_electro.packing import Refinement
    from yade_electro.geometry.shapes import Box
    half, big = 0.7e-3, 10.0 * LENGTH
    return Refinement(Box((0.5 * LENGTH - half, -big, -big), (0.5 * LENGTH + half, big, big)), factor, 0.4e-3)


def dem_run(n: int, seed: int, times, cache_dir=None, sharing: str = "edges", depth: float = NOTCH_DEPTH,
            refine=None) -> dict:
    """The DEM heating; temperatures of every element at ``times`` [s] and R_eq; ``sharing``: the
    Joule heat's ``Integrator(joule_sharing=...)``; ``refine``: a graded packing's Refinement."""
    from yade_electro.yade import ElectroThermalEngine, Electrode, Integrator, Law, Material
    from yade_electro.yade import packing as P
    from yade_electro.yade.runtime import import_yade
    O = import_yade().Omega()
    O.reset()
    sh = shape(depth)
    pk = P.dense_packing(sh, n=n, seed=seed, cache_dir=cache_dir, refine=refine)
    P.add_bonded_packing(pk)
    for e in O.engines:
        if type(e).__name__ == "NewtonIntegrator":
            e.dead = True
    box = P.Box((0, 0, 0), (LENGTH, WIDTH, THICKNESS))
    eng = ElectroThermalEngine(
        material=Material(resistivity=RHO_E, density=DENSITY, specific_heat=SPECIFIC_HEAT, conductivity=CONDUCTIVITY),
        boundaries=[Electrode("end1", surface=box.face("x+"), potential=VOLTAGE),
                    Electrode("end0", surface=box.face("x-"), potential=0.0)],
        temperature=T0, law=Law("voronoi", container=sh),
        integrator=Integrator(theta="backward-euler", dt=DT, joule_sharing=sharing), iterPeriod=1, label="ligament")
    O.engines = O.engines + [eng.runner]
    # the engine's own clock decides when to record: whether YADE's PyRunner calls it at the
    # first step depends on the steps the scene has already run (the packing's bonding ran
    # some), and one step is 10 % of the first recorded time
    T_at = []
    for t in times:
        while eng.coupled.time < t - 0.5 * DT:
            O.run(max(1, int(round((t - eng.coupled.time) / DT))), True)
        if abs(eng.coupled.time - t) > 1e-9 * DT + 1e-15:
            raise RuntimeError(f"the engine is at t = {eng.coupled.time} s, not at the recorded time {t} s")
        T_at.append(eng.temperature.copy())
    g = eng.graph
    out = {"n": int(g.n_nodes), "seed": int(seed), "sharing": sharing, "R_eq": float(eng.equivalent_resistance), "pos": g.pos.copy(),
           "radius": g.radius.copy(), "T": np.array(T_at), "time": float(eng.coupled.time),
           "capacity": eng.coupled.capacity.copy(), "sources": np.asarray(eng.coupled.sources, float).copy()}
    eng.remove()
    return out


def main(argv=None) -> dict:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10000)
    ap.add_argument("--seeds", default="1,2,3,4")
    ap.add_argument("--times", default="0.0005,0.001,0.002,0.005")
    ap.add_argument("--hs", default="0.05e-3,0.025e-3,0.0125e-3", help="FEM mesh sizes [m], coarse to fine")
    ap.add_argument("--per-cell", type=int, default=400, help="FEM sample points per cell")
    ap.add_argument("--sharing", default="edges,cells", help="Integrator(joule_sharing=...) values, each run")
    ap.add_argument("--notch-depth", type=float, default=NOTCH_DEPTH,
                    help="notch depth from each side [m] (0.45e-3: the 0.2 mm ligament; 0.3e-3: notched_joule's 0.5 mm)")
    ap.add_argument("--refine", type=float, default=None,
                    help="a graded packing: elements this factor smaller near the ligament (e.g. 0.75), same --n")
    ap.add_argument("--quick", action="store_true")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    if args.quick:
        args.n, args.seeds, args.hs, args.times, args.per_cell = 3000, "1", "0.1e-3,0.05e-3,0.025e-3", "0.0005,0.002", 150
    seeds = [int(s) for s in args.seeds.split(",")]
    times = [float(t) for t in args.times.split(",")]
    hs = [float(h) for h in args.hs.split(",")]
    t_start = time.perf_counter()
    dems = []
    for seed in seeds:
        for sharing in args.sharing.split(","):
            sys.stderr.write(f"[narrow_ligament] DEM n={args.n} seed={seed} joule_sharing={sharing}\n")
            dems.append(dem_run(args.n, seed, times, args.cache_dir, sharing, args.notch_depth,
                                None if args.refine is None else refinement(args.refine)))
    # the FEM: its points are the ligament's centre, each run's nearest element's centre and
    # the samples of that element's cell
    probes, slices = [CENTRE], []
    for d in dems:
        k = int(np.argmin(np.linalg.norm(d["pos"] - CENTRE, axis=1)))
        d["k"] = k
        samples = cell_samples(d["pos"], d["radius"], k, args.per_cell, depth=args.notch_depth)
        slices.append((len(probes), len(probes) + 1, len(probes) + 1 + len(samples)))
        probes += [d["pos"][k]] + list(samples)
    probes = np.array(probes)
    fem_R, fem_T = [], None
    for h in hs:
        sys.stderr.write(f"[narrow_ligament] FEM h={h:g} m\n")
        R, t_rec, T_rec, ndofs = fem_run(h, max(times), probes, args.notch_depth)
        fem_R.append(R)
        fem_T, fem_t, fem_ndofs = T_rec, t_rec, ndofs
    from yade_electro import fem
    R_ref = fem.richardson(hs, fem_R)
    rec = [int(np.argmin(np.abs(fem_t - t))) for t in times]
    out = {"case": "narrow_ligament", "n": args.n, "seeds": seeds, "times_s": times, "ligament_m": WIDTH - 2 * args.notch_depth,
           "refine_factor": args.refine,
           "fem_R_eq_ohm": fem_R, "fem_R_extrapolated_ohm": float(R_ref.extrapolated), "fem_R_gci_ohm": float(R_ref.gci),
           "fem_ndofs": fem_ndofs, "fem_centre_rise_K": (fem_T[rec, 0] - T0).tolist(), "runs": []}
    for d, (i_own, i_cell, i_end) in zip(dems, slices):
        k = d["k"]
        dem_rise = d["T"][:, k] - T0
        point = fem_T[rec, 0] - T0
        own = fem_T[rec, i_own] - T0
        cell = fem_T[rec][:, i_cell:i_end].mean(axis=1) - T0
        near = np.abs(d["pos"][:, 0] - CENTRE[0]) < 0.3e-3
        run = {"seed": d["seed"], "n": d["n"], "joule_sharing": d["sharing"], "R_eq_ohm": d["R_eq"],
               "r_mean_m": float(d["radius"].mean()), "r_mean_ligament_m": float(d["radius"][near].mean()),
               "R_vs_fem_pct": 100 * (d["R_eq"] / R_ref.extrapolated - 1),
               "element_distance_to_centre_m": float(np.linalg.norm(d["pos"][k] - CENTRE)),
               "element_radius_m": float(d["radius"][k]), "cell_samples": int(i_end - i_cell),
               "dem_rise_K": dem_rise.tolist(),
               "T_rise_vs_point_pct": (100 * (dem_rise / point - 1)).tolist(),
               "T_rise_vs_own_point_pct": (100 * (dem_rise / own - 1)).tolist(),
               "T_rise_vs_cell_pct": (100 * (dem_rise / cell - 1)).tolist(),
               # the source: early in the heating, rise ~ t P_i / C_i against the cell's mean rise
               "source_rate_K_per_s": float(d["sources"][k] / d["capacity"][k]),
               "fem_cell_rate_K_per_s": float(cell[0] / times[0])}
        out["runs"].append(run)
    R = np.array([r["R_vs_fem_pct"] for r in out["runs"]])
    out.update({"R_vs_fem_pct_worst": float(np.max(np.abs(R))), "R_vs_fem_pct_mean": float(np.mean(R))})
    for sharing in sorted({r["joule_sharing"] for r in out["runs"]}):
        runs = [r for r in out["runs"] if r["joule_sharing"] == sharing]
        for key, name in (("T_rise_vs_point_pct", "T_vs_point"), ("T_rise_vs_cell_pct", "T_vs_cell")):
            out[f"{name}_pct_worst_{sharing}"] = float(max(abs(v) for r in runs for v in r[key]))
    out["run_s"] = time.perf_counter() - t_start
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
