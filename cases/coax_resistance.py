"""Radial resistance of a coaxial conductor with surface electrodes on both curved walls: the
check of the half cells' curvature correction (docs/guide/electrodes-and-boundaries.md).

A tube between r = a = 0.4 mm (a hole: a concave wall seen from the solid) and r = b = 1 mm
(a convex wall), L = 1 mm, 304L-like rho_e = 7.3e-7 ohm m, packed by ``dense_packing`` in the
exact tube (``Cylinder - Cylinder``). The inner wall is at 1 V, the outer one grounded, both
as surface electrodes; law ``voronoi``. The reference is the closed form
R = rho ln(b / a) / (2 pi L). ``--flat`` takes both walls as flat (no curvature correction of
the half cells, the behaviour before it): the difference is what the correction does.

Run (no YADE needed)::

    python3 cases/coax_resistance.py [--n 5000] [--seed 1] [--flat] [--sweep]

``--sweep`` runs seeds 1-3 at 5,000 elements and seed 1 at 20,000, with and without the
correction. Ends with one JSON line (``"case": "coax_resistance"``, ``"error_pct"``, or the
sweep's rows).
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith("coax_resistance.py")
                                       else __file__))
if os.path.dirname(HERE) not in sys.path:
    sys.path.insert(0, os.path.dirname(HERE))

from yade_electro.laws.law import Law  # noqa: E402
from yade_electro.physics.electrical import ElectricalModel  # noqa: E402
from yade_electro.geometry.shapes import Cylinder, Shape  # noqa: E402
from yade_electro.geometry.surfaces import SurfaceSelector  # noqa: E402
from yade_electro.core.graph import ContactGraph  # noqa: E402
from yade_electro.packing import bond_pairs, dense_packing  # noqa: E402

INNER, OUTER, LENGTH = 0.4e-3, 1e-3, 1e-3       # m
RHO = 7.3e-7                                      # ohm m


def tube():
    """The exact container: the outer cylinder less the hole."""
    return Cylinder((0, 0, 0), (0, 0, LENGTH), OUTER) - Cylinder((0, 0, -LENGTH), (0, 0, 2 * LENGTH), INNER)


class FlatWalls(Shape):
    """``shape`` with its walls taken as flat by the surface conditions (no curvature
    correction of the half cells, as before it existed); the same geometry otherwise."""

    def __init__(self, shape):
        self.shape = shape

    def sdf(self, x):
        return self.shape.sdf(x)

    def gradient(self, x, h=None):
        return self.shape.gradient(x, h)

    def wall_terms(self, x):
        return self.shape.wall_terms(x)

    def parts(self):
        return self.shape.parts()

    def bounds(self):
        return self.shape.bounds()

    @property
    def exact_volume(self):
        return self.shape.exact_volume

    def key(self):
        return self.shape.key()

    def wall_curvature(self, x, h=None):
        return np.zeros(np.asarray(x, float).reshape(-1, 3).shape[0])


def wall(radius, outward_sign):
    """The cylindrical wall r = ``radius`` as a surface selector: boundary faces within 0.3 a of
    it whose outward normal points away from the axis (+1, the outer wall) or towards it (-1,
    the hole)."""
    def on(points, normals):
        rr = np.hypot(points[:, 0], points[:, 1])
        out = outward_sign * np.einsum("ij,ij->i", points[:, :2], normals[:, :2]) / np.maximum(rr, 1e-300)
        return (np.abs(rr - radius) <= 0.3 * INNER) & (out > 0.5)
    return SurfaceSelector(on, f"the wall r = {radius} m")


def exact_resistance() -> float:
    return RHO * math.log(OUTER / INNER) / (2 * math.pi * LENGTH)


def run(n=5000, seed=1, flat=False) -> dict:
    pk = dense_packing(tube(), n=n, seed=seed)
    shape = FlatWalls(tube()) if flat else tube()
    g = ContactGraph(pk.centers, pk.radii, bond_pairs(pk.centers, pk.radii))
    model = ElectricalModel(RHO, {"inner": dict(surface=wall(INNER, -1), potential=1.0),
                                  "outer": dict(surface=wall(OUTER, 1), potential=0.0)},
                            law=Law("voronoi", container=shape))
    model.solve(g)
    R, R_th = float(model.equivalent_resistance), exact_resistance()
    return {"case": "coax_resistance", "n": int(g.n_nodes), "seed": int(seed), "half_cells": "flat" if flat else
            "curved", "r_mean": float(np.mean(pk.radii)), "R": R, "R_exact": R_th, "error_pct": 100.0 * (R / R_th - 1.0)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--flat", action="store_true", help="no curvature correction of the half cells")
    ap.add_argument("--sweep", action="store_true")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    if args.sweep:
        rows = [run(n, s, flat) for flat in (False, True) for n, s in ((5000, 1), (5000, 2), (5000, 3), (20000, 1))]
        for r in rows:
            print(f"coax {r['n']} elements, seed {r['seed']}, {r['half_cells']} half cells: "
                  f"R {r['R']:.6e} ohm, {r['error_pct']:+.3f} %", flush=True)
        out = {"case": "coax_resistance", "rows": rows}
    else:
        out = run(args.n, args.seed, args.flat)
        print(f"coax {out['n']} elements, {out['half_cells']} half cells: R {out['R']:.6e} ohm against "
              f"{out['R_exact']:.6e} ({out['error_pct']:+.3f} %)")
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
