"""Paper 003's two-particle test (issue 35): two thin cylinders in contact through a contact
resistance, lumped against resolved against a finite-element reference.

Geometry (paper 003, section 5: two thin cylinders of the same radius and width, contact
surface 0.02 m^2; its Table 3 is not in our copy, so the values are ours, in the same regime):
r = 0.5 m, w = 0.1 m, overlap p = 0.0202 m, so that the flat contact cut at the overlap's chord
has S_c = 2 h w = 0.0200 m^2 (h = 0.1 m). Material: rho c = 2e6 J/(m^3 K), k = 1 W/(m K)
(``low_k``) or 100 W/(m K) (``high_k``, the paper's hundredfold). Contact: R_c = 0.2 m^2 K/W, so
that the contact's resistance R_c / S_c = 10 K/W is that of each particle from its bulk to the
contact at low k (Feng's pipe-network estimate (1 / (pi k w)) (1.5 - ln alpha) = 10 K/W with
alpha = h / r). Everything else insulated. A starts at 400 K, B at 300 K; 30 instants over
three decay times of the lumped model (tau = C / (2 S_c / R_c)).

* **FEM** (:mod:`yade_electro.fem.two_discs`): the two disc segments in 2D (nothing varies
  across the width), linear triangles (scikit-fem, meshed by gmsh), the interface term
  (1/R_c)(T_A - T_B) on the chord with the local temperatures, Crank-Nicolson; mesh
  h = 0.025 m (3,020 nodes a disc), step tau / 100 (from h = 0.05 m, tau / 50 the mean of B
  moves by 0.04 K at most: the reference is converged to 0.04 % of the span).
* **lumped** (the DEM convention, one temperature per particle): C dT_A/dt = S_c (T_B - T_A) / R_c,
  exact: T_B = 350 - 50 exp(-t / tau).
* **resolved** (:mod:`yade_electro.network.grain_contact`): each cylinder a dense packing of
  ``--n`` spheres (``dense_packing`` in the cut disc) with the 'voronoi' law inside (bonded
  where the gap is under 10 % of the radii's sum), the second the mirror image of the first;
  the two grains' elements joined across the contact through their half cells and R_c,
  element pair by element pair (the faces' shared areas sampled on the contact); backward
  Euler steps of tau / 100 (the heat solver of the engines).

Figures: the mean over the 30 instants of |T_B - T_B(FEM)| in per cent of the initial
difference (100 K), for each model and conductivity (``resolved_vs_fem_pct`` at low k,
``lumped_vs_fem_pct_low_k``, ``lumped_vs_fem_pct_high_k``...).

Run
---
    /usr/bin/python3 cases/two_grains.py [--n 3000]      # numpy + scikit-fem + gmsh, no YADE

Ends with one JSON line.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
if os.path.dirname(HERE) not in sys.path:      # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))

R, W, P = 0.5, 0.1, 0.0202              # m
RHO_C = 2e6                             # J/(m^3 K)
R_C = 0.2                               # m^2 K/W
K_LOW = 1.0                             # W/(m K)
T_A0, T_B0 = 400.0, 300.0               # K


def geometry():
    from yade_electro.fem.two_discs import TwoDiscs
    return TwoDiscs(R, W, P)


def times(g):
    tau = RHO_C * g.segment_area * g.w / (2.0 * g.contact_area / R_C)
    return tau, np.linspace(0.0, 3.0 * tau, 31)[1:]


def lumped(g, t):
    tau = RHO_C * g.segment_area * g.w / (2.0 * g.contact_area / R_C)
    mid = 0.5 * (T_A0 + T_B0)
    return mid - (mid - T_B0) * np.exp(-np.asarray(t) / tau)


def grain(g, n: int, cache_dir=None):
    """(centres, radii, edges, factors g [m], cell volumes [m^3]) of grain A: a dense packing of
    the disc segment with the 'voronoi' law (:func:`~yade_electro.packing.grains.grain_template`)."""
    from yade_electro.geometry.shapes import Box, Cylinder, Intersection
    from yade_electro.packing.grains import grain_template
    shape = Intersection(Cylinder((0, 0, 0), (0, 0, g.w), g.r), Box((-2 * g.r, -2 * g.r, -g.w), (0.5 * g.d, 2 * g.r, 2 * g.w)))
    t = grain_template(shape, n, seed=1, cache_dir=cache_dir)
    return t.centres, t.radii, t.edges, t.factor, t.volume


def resolved(g, k: float, t, n: int, cache_dir=None) -> dict:
    """The two resolved grains' mean temperatures of B at ``t`` [s] (backward Euler)."""
    from yade_electro.network.grain_contact import plane_contact_links
    from yade_electro.network.transient import HeatSolver
    c, r, e, fac, vol = grain(g, n, cache_dir)
    cb = c.copy()
    cb[:, 0] = g.d - cb[:, 0]                               # B: A mirrored about the contact plane
    na = c.shape[0]
    pairs, G, area = plane_contact_links(c, cb, (0.5 * g.d, 0.0, 0.5 * g.w), (1, 0, 0), (0, 1, 0),
                                         (-g.half_chord, g.half_chord), (-0.5 * g.w, 0.5 * g.w), R_C, k)
    edges = np.concatenate([e, e + na, np.column_stack([pairs[:, 0], na + pairs[:, 1]])])
    cond = np.concatenate([k * fac, k * fac, G])
    C = RHO_C * np.concatenate([vol, vol])
    T0 = np.concatenate([np.full(na, T_A0), np.full(na, T_B0)])
    heat = HeatSolver(C, edges, cond, T0, theta="backward-euler", solver="direct")
    dt = (t[1] - t[0]) / 10.0
    out = []
    for t_next in t:
        while heat.time < t_next - 1e-9 * t_next:
            heat.advance(min(dt, t_next - heat.time))
        T = heat.temperature
        out.append(float(C[na:] @ T[na:] / C[na:].sum()))
    return {"mean_B": np.array(out), "elements_per_grain": na, "contact_pairs": int(pairs.shape[0]),
            "contact_area_sampled_m2": area, "volume_over_exact": float(vol.sum() / (g.segment_area * g.w)),
            "heat_ledger": float(abs(heat.heat_content(0.0) - C @ T0) / (C @ T0))}


def error_pct(model, reference) -> float:
    return float(100.0 * np.mean(np.abs(np.asarray(model) - np.asarray(reference))) / (T_A0 - T_B0))


def main(argv=None) -> dict:
    from yade_electro.fem.two_discs import two_discs_transient
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=3000, help="spheres per grain (resolved)")
    ap.add_argument("--h", type=float, default=0.025, help="FEM mesh size [m]")
    ap.add_argument("--cache-dir", default=None)
    args = ap.parse_args(argv)
    g = geometry()
    tau, t = times(g)
    out = {"case": "two_grains", "r_m": R, "w_m": W, "overlap_m": P, "contact_area_m2": g.contact_area,
           "rho_c": RHO_C, "contact_resistance_m2K_per_W": R_C, "tau_s": tau}
    for label, k in (("low_k", K_LOW), ("high_k", 100.0 * K_LOW)):
        t0 = time.perf_counter()
        fem = two_discs_transient(g, k, RHO_C, R_C, T_A0, T_B0, t, h=args.h, dt=tau / 100.0)
        t_fem = time.perf_counter() - t0
        t0 = time.perf_counter()
        res = resolved(g, k, t, args.n, args.cache_dir)
        t_res = time.perf_counter() - t0
        lum = lumped(g, t)
        out[label] = {"conductivity": k, "fem_mean_B_K": fem["mean_B"].round(4).tolist(),
                      "fem_nodes_per_disc": fem["nodes"], "fem_s": t_fem, "resolved_s": t_res,
                      "resolved_vs_fem_pct": error_pct(res["mean_B"], fem["mean_B"]),
                      "lumped_vs_fem_pct": error_pct(lum, fem["mean_B"]),
                      "resolved_vs_fem_max_pct": float(100 * np.max(np.abs(res["mean_B"] - fem["mean_B"])) / 100.0),
                      **{k2: v for k2, v in res.items() if k2 != "mean_B"}}
    out["resolved_vs_fem_pct"] = out["low_k"]["resolved_vs_fem_pct"]
    out["resolved_vs_fem_pct_high_k"] = out["high_k"]["resolved_vs_fem_pct"]
    out["lumped_vs_fem_pct_low_k"] = out["low_k"]["lumped_vs_fem_pct"]
    out["lumped_vs_fem_pct_high_k"] = out["high_k"]["lumped_vs_fem_pct"]
    print(json.dumps(out), flush=True)
    return out


if __name__ == "__main__":
    main()
