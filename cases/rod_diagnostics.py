"""Where the paper-000 continuum model loses conductance on a random packing (rod case).

For one rod packing (same recipe and electrode layers as ``rod_resistance.py``) this prints,
for the 'continuum' law:

* the error on R_eq;
* the conductivity measured in the core (elements more than 2.5 r_mean from the lateral
  surface and 3 r_mean from the ends): current density across the mid plane over the fitted
  potential gradient, relative to 1/rho_e;
* the affine (uniform-field) estimate of the same core conductivity,
  sum_edges c_ij dz_ij^2 / V_core, and their ratio (the non-affine relaxation);
* the share of the current the surface layer carries against its share of the area;
* the share of core elements with e > 0.4 (whose surfaces the model halves) and the model's
  volume fraction fv(n) next to the local packing fraction.

Pure numpy/scipy (no YADE needed: bonds by YADE's rule, ``bond_pairs``).

    /usr/bin/python3 cases/rod_diagnostics.py --n 5000 --seed 1
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import warnings

import numpy as np

_SCRIPT = __file__ if __file__.endswith("rod_diagnostics.py") else sys.argv[0]
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, os.path.dirname(HERE))
sys.path.insert(0, HERE)

import rod_resistance as rod  # noqa: E402
from yade_electro import ContactGraph, Electrode, eccentricity, solve_potential  # noqa: E402
from yade_electro.laws.factors import conductance  # noqa: E402
from yade_electro.laws.transmission import polyhedron_volume_fraction  # noqa: E402
from yade_electro.yade import packing as P  # noqa: E402


def diagnose(n=5000, seed=1, k=1.04):
    L, R, rho = rod.LENGTH, rod.RADIUS, rod.RHO_304L
    pk = P.dense_packing(P.Cylinder((0, 0, 0), (0, 0, L), R), n=n, seed=seed)
    c, r = pk.centers, pk.radii
    rm = float(r.mean())
    g = ContactGraph(c, r, P.bond_pairs(c, r, k))
    e = g.edges
    cc = conductance(g, rho)
    z = c[:, 2]
    rad = np.hypot(c[:, 0], c[:, 1])
    r_core = R - 2.5 * rm
    core = (rad < r_core) & (z > 3 * rm) & (z < L - 3 * rm)
    bottom, top = rod.end_layers(z, r, rm)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        sol = solve_potential(g.n_nodes, e, cc, [Electrode("top", np.flatnonzero(top), potential=1.0),
                                                 Electrode("bottom", np.flatnonzero(bottom), potential=0.0)])
    R_dem = sol.equivalent_resistance("top", "bottom")
    R_th = rod.theoretical_resistance(rm)
    u = sol.potential
    grad = np.polyfit(z[core], u[core], 1)[0]                  # dV/dz [V/m], > 0
    mid = L / 2
    lo_first = z[e[:, 0]] < mid
    cross = lo_first != (z[e[:, 1]] < mid)
    # current towards -z (from top to bottom) through the mid plane, core bonds only
    w_down = np.where(lo_first, -sol.branch_current, sol.branch_current)
    in_core = (rad[e[:, 0]] < r_core) & (rad[e[:, 1]] < r_core)
    I_core = float(np.sum(w_down[cross & in_core]))
    I_all = float(np.sum(w_down[cross]))
    A_core = np.pi * r_core ** 2
    k_core = (I_core / A_core) / grad * rho
    core_edges = core[e[:, 0]] & core[e[:, 1]]
    dz = c[e[:, 1], 2] - c[e[:, 0], 2]
    V_core = A_core * (L - 6 * rm)
    k_affine = float(np.sum(cc[core_edges] * dz[core_edges] ** 2) / V_core * rho)
    ecc = eccentricity(g)
    return {
        "case": "rod_diagnostics", "n": int(n), "seed": int(seed), "detection_factor": k,
        "error_pct": 100 * (R_dem - R_th) / R_th,
        "core_conductivity_ratio": k_core, "core_affine_ratio": k_affine,
        "non_affine_factor": k_core / k_affine,
        "surface_current_share": 1 - I_core / I_all, "surface_area_share": 1 - A_core / (np.pi * R ** 2),
        "core_share_e_above_0.4": float(np.mean(ecc[core] > 0.4)),
        "core_model_fv_mean": float(np.mean(polyhedron_volume_fraction(g.degree[core]))),
        "core_packing_fraction": float(np.sum(4 / 3 * np.pi * r[core] ** 3) / V_core),
    }


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--k", type=float, default=1.04)
    a = ap.parse_args(sys.argv[1:] if argv is None else argv)
    out = diagnose(a.n, a.seed, a.k)
    for key, v in out.items():
        print(f"{key:28s} {v:.4g}" if isinstance(v, float) else f"{key:28s} {v}")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
