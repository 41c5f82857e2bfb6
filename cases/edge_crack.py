"""Edge crack in a bonded bar: the resistance increment of a crack cut by breaking bonds.

A square bar W x W x L = 2 x 2 x 8 mm (z along its length), steel 304L, is packed with N
bonded elements in YADE and held at 1 V between its end faces (surface electrodes on the
faces z = 0 and z = L, law ``voronoi``). Its resistance R_intact is measured; then every
bond whose segment crosses the crack surface, the half plane z = L/2, x < a = W/2 (a
straight edge crack through half the width and the whole thickness in y), is broken in
YADE (``cohesionBroken = True``) and the engine, at its next call, gives R_crack. The
increment R_crack / R_intact - 1 is compared with

* the finite-element reference (``yade_electro.fem.cracked_bar_reference``): the bar with a
  true slit of zero thickness (the nodes of the crack plane duplicated), P2 elements, the
  mesh refined at the crack front, three mesh sizes, Richardson extrapolation with its
  grid-convergence index as the error estimate (expected order 1: the potential goes as
  r^(1/2) at the front);
* the closed form (4 W / (pi L)) ln sec(pi a / (2 W)) = 0.11032 (Johnson's conformal-map
  solution of the cracked strip, ``yade_electro.fem.edge_crack_increment``; the field does
  not depend on y, so the bar is exactly the 2D strip).

Both crack rules of the ``voronoi`` law are run on the same broken bonds: ``facets`` (the
default: a face is cut when the segment between its elements crosses a broken bond's own
Voronoi face) and ``paths`` (a face conducts while its elements are linked by <= 3 intact
bonds). ``leak_fraction`` is the share of the Voronoi face area across the cracked half
(segments crossing z = L/2 at x < a) that still conducts.

Run
---
    yade-electro -n -x cases/edge_crack.py --n 10000 --seed 1
    yade-electro -n -x cases/edge_crack.py --n 20000 --no-fem        # the closed form only

The FEM study (about ten minutes) is kept in ``<out>/fem.json`` and read back by later runs
with the same mesh sizes.

Ends with one line of JSON: ``increment_error_pct`` (facets, against the FEM extrapolated
value; against the closed form with --no-fem), per rule ``increment_<rule>``,
``leak_fraction_<rule>``, and the FEM study.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("edge_crack.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("edge_crack.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))

from yade_electro.yade.runtime import import_yade  # noqa: E402

WIDTH = 2e-3           # m
LENGTH = 8e-3          # m
DEPTH = 1e-3           # m, crack depth a (from the face x = 0)
RHO_304L = 0.73e-6     # ohm m
FEM_H = (0.35e-3, 0.25e-3, 0.18e-3)
RULES = ("facets", "paths")


def crossing_x(pos, pairs, z_crack=LENGTH / 2):
    """x where each pair's segment crosses the plane z = z_crack [m] (nan where it does not)."""
    a, b = pos[pairs[:, 0]], pos[pairs[:, 1]]
    across = (a[:, 2] - z_crack) * (b[:, 2] - z_crack) < 0
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(across, (z_crack - a[:, 2]) / (b[:, 2] - a[:, 2]), np.nan)
    return a[:, 0] + (b[:, 0] - a[:, 0]) * t


def run_crack(n=10000, seed=1, rules=RULES, cache_dir=None):
    """Build the bonded bar in YADE, measure R_intact, break the bonds across the crack and
    measure R_crack for each crack rule; returns a dict of figures. Resets YADE's scene."""
    yade = import_yade()
    from yade_electro.geometry.shapes import Box
    from yade_electro.yade import ElectricalEngine, Electrode, Law, Material, Reader
    from yade_electro.yade import packing as P

    O = yade.Omega()
    O.reset()
    bar = Box((0, 0, 0), (WIDTH, WIDTH, LENGTH))
    t0 = time.perf_counter()
    packing = P.dense_packing(bar, n=n, seed=seed, cache_dir=cache_dir)
    P.add_bonded_packing(packing)
    t_pack = time.perf_counter() - t0
    out = {"case": "edge_crack", "n": int(len(packing.radii)), "n_target": int(n), "seed": int(seed),
           "law": "voronoi", "r_mean": float(np.mean(packing.radii)), "t_packing_s": t_pack}
    bonds = [i for i in O.interactions if i.isReal and not i.phys.cohesionBroken]
    for k, rule in enumerate(rules):
        if k:                                     # heal the bonds for the next rule
            for i in bonds:
                i.phys.cohesionBroken = False
        engine = ElectricalEngine(
            material=Material(resistivity=RHO_304L),
            boundaries=[
                Electrode("top", surface=bar.face("z+"), potential=1.0),
                Electrode("bottom", surface=bar.face("z-"), potential=0.0)],
            law=Law("voronoi", container=bar, crack=rule),
            reader=Reader(bond_check="flags"),
            label=f"crack_{rule}")
        O.engines = O.engines + [engine.runner]
        t1 = time.perf_counter()
        O.step()
        t_first = time.perf_counter() - t1
        R_intact = engine.equivalent_resistance
        # the crack: every bond whose segment crosses z = L/2 at x < a
        pos = {b.id: np.array(b.state.pos) for b in O.bodies}
        seg = np.array([[pos[i.id1], pos[i.id2]] for i in bonds])
        pairs = np.arange(2 * len(bonds)).reshape(-1, 2)
        xc = crossing_x(seg.reshape(-1, 3), pairs)
        cut = np.isfinite(xc) & (xc < DEPTH)
        for i, c in zip(bonds, cut):
            if c:
                i.phys.cohesionBroken = True
        t1 = time.perf_counter()
        O.step()
        t_break = time.perf_counter() - t1
        R_crack = engine.equivalent_resistance
        # conducting area across the cracked half, in the reference tessellation
        law = engine.model.law
        graph = engine.graph
        faces = law.faces(graph)
        ref_pos = law.reference[1]
        x_f = crossing_x(ref_pos, faces.pairs)
        on = np.zeros(faces.pairs.shape[0], bool)
        at = faces.index_of(engine.model.network.edges[engine.model.network.factor > 0])
        on[at[at >= 0]] = True
        across = np.isfinite(x_f) & (x_f < DEPTH)
        out.update({f"R_intact_{rule}": float(R_intact), f"R_crack_{rule}": float(R_crack),
                    f"increment_{rule}": float(R_crack / R_intact - 1.0),
                    f"leak_fraction_{rule}": float(faces.area[across & on].sum() / faces.area[across].sum()),
                    f"t_first_call_{rule}_s": t_first, f"t_break_call_{rule}_s": t_break})
        out["broken_bonds"] = int(cut.sum())
        out["bonds"] = len(bonds)
        out["R_nominal"] = RHO_304L * LENGTH / WIDTH ** 2
        out[f"R_intact_error_pct_{rule}"] = float(100 * (R_intact / out["R_nominal"] - 1.0))
        engine.remove()
    return out


def fem_reference(hs=FEM_H, order=2, cache=None):
    """The FEM study of the increment (see the module doc), as a plain dict; kept in the JSON
    file ``cache`` (when given) and read back from it for the same mesh sizes and order."""
    if cache is not None and os.path.exists(cache):
        with open(cache) as fh:
            kept = json.load(fh)
        if kept.get("fem_h") == [float(h) for h in hs] and kept.get("fem_order") == order:
            print(f"FEM study read from {cache}", flush=True)
            return kept
    from yade_electro.fem import cracked_bar_reference
    t0 = time.perf_counter()
    ref = cracked_bar_reference(hs=hs, order=order, progress=lambda m: print(m, flush=True))
    conv = ref["convergence"]
    out = {"fem_order": order, "fem_h": [float(h) for h in hs], "fem_increments": conv.values.tolist(),
           "fem_extrapolated": conv.extrapolated, "fem_gci": conv.gci, "fem_observed_order": conv.order,
           "fem_monotone": conv.monotone, "fem_ndofs": [r["ndofs"] for r in ref["runs"]],
           "closed_form": ref["closed_form"], "fem_time_s": time.perf_counter() - t0}
    if cache is not None:
        with open(cache, "w") as fh:
            json.dump(out, fh)
    return out


def _params(argv):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=10000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--no-fem", action="store_true", help="compare with the closed form only")
    ap.add_argument("--fem-h", type=lambda s: tuple(float(x) * 1e-3 for x in s.split(",")), default=FEM_H,
                    help="FEM mesh sizes in mm, coarsest first (default 0.35,0.25,0.18)")
    ap.add_argument("--fem-order", type=int, default=2)
    ap.add_argument("--out", default="out/edge_crack")
    return ap.parse_args(argv)


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    from yade_electro.fem import edge_crack_increment
    row = run_crack(args.n, args.seed)
    exact = edge_crack_increment(WIDTH, LENGTH, DEPTH)
    row["closed_form"] = exact
    os.makedirs(args.out, exist_ok=True)
    if not args.no_fem:
        row.update(fem_reference(args.fem_h, args.fem_order, os.path.join(args.out, "fem.json")))
        ref, against = row["fem_extrapolated"], "fem"
    else:
        ref, against = exact, "closed_form"
    row["reference"] = against
    for rule in RULES:
        row[f"increment_error_pct_{rule}"] = float(100 * (row[f"increment_{rule}"] / ref - 1.0))
        row[f"increment_error_closed_form_pct_{rule}"] = float(100 * (row[f"increment_{rule}"] / exact - 1.0))
    row["increment_error_pct"] = row["increment_error_pct_facets"]
    with open(os.path.join(args.out, f"edge_crack_n{args.n}_s{args.seed}.json"), "w") as fh:
        json.dump(row, fh)
    print(f"bar {WIDTH * 1e3:g} x {WIDTH * 1e3:g} x {LENGTH * 1e3:g} mm, {row['n']} elements, "
          f"{row['broken_bonds']} bonds broken: increment facets {row['increment_facets']:.4f} "
          f"({row['increment_error_pct_facets']:+.2f} %), paths {row['increment_paths']:.4f} "
          f"({row['increment_error_pct_paths']:+.2f} %) against the {against.replace('_', ' ')} {ref:.5f}")
    print(json.dumps(row))
    return row


if __name__ == "__main__":
    main()
