"""Single bond breaks on the rod: does R_eq ever go down? (a property of the model)

The rod R = 1 mm, L = 5 mm (surface electrodes on its end faces) is solved intact, then with
one randomly chosen bond broken at a time (each from the intact rod), with paper 000's
``continuum`` law and with the ``voronoi`` law. Removing a conductance never lowers a
network's resistance (Rayleigh's monotonicity); with the continuum law a break also changes
the two elements' neighbour counts and eccentricities, and so the transmission surfaces of
their other bonds, and R_eq can go down.

Run::

    python3 cases/single_breaks.py --n 1000 --breaks 89       # also under yade-electro -n -x

Ends with one JSON line: per law the number of breaks, of decreases, the smallest and the
largest relative change.
"""
from __future__ import annotations

import argparse
import json
import os
import sys

import numpy as np

HERE = os.path.dirname(os.path.abspath(sys.argv[0] if sys.argv and sys.argv[0].endswith("single_breaks.py")
                                       else __file__))
if os.path.dirname(HERE) not in sys.path:
    sys.path.insert(0, os.path.dirname(HERE))

from yade_electro.laws.law import Law  # noqa: E402
from yade_electro.physics.electrical import ElectricalModel  # noqa: E402
from yade_electro.geometry.shapes import Cylinder  # noqa: E402
from yade_electro.core.graph import ContactGraph  # noqa: E402
from yade_electro.packing import bond_pairs, dense_packing  # noqa: E402

ROD = Cylinder((0, 0, 0), (0, 0, 5e-3), 1e-3)


def single_breaks(n=1000, seed=1, breaks=89, pick_seed=0):
    pk = dense_packing(ROD, n=n, seed=seed)
    g = ContactGraph(pk.centers, pk.radii, bond_pairs(pk.centers, pk.radii))
    pick = np.random.default_rng(pick_seed).choice(g.edges.shape[0], int(breaks), replace=False)
    out = {"case": "single_breaks", "n": int(g.n_nodes), "seed": int(seed), "bonds": int(g.edges.shape[0])}
    for law in ("continuum", "voronoi"):
        m = ElectricalModel(0.73e-6, {"top": dict(surface=ROD.face("top"), potential=1.0),
                                      "bottom": dict(surface=ROD.face("bottom"), potential=0.0)},
                            law=Law(law, container=ROD))
        m.solve(g)
        r0 = m.equivalent_resistance
        change = []
        for k, e in enumerate(pick):
            keep = np.ones(g.edges.shape[0], bool)
            keep[e] = False
            m.solve(g.subgraph(keep))
            change.append(m.equivalent_resistance / r0 - 1.0)
            if (k + 1) % 20 == 0:
                print(f"  {law}: {k + 1}/{len(pick)} breaks", flush=True)
        c = np.array(change)
        out[law] = {"breaks": int(c.size), "decreases": int(np.sum(c < -1e-12)), "min": float(c.min()),
                    "max": float(c.max())}
        print(f"{law}: {out[law]['decreases']} of {c.size} single breaks lower R_eq (min {c.min():+.3e}, "
              f"max {c.max():+.3e})", flush=True)
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=1000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--breaks", type=int, default=89)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    out = single_breaks(args.n, args.seed, args.breaks)
    print(json.dumps(out))
    return out


if __name__ == "__main__":
    main()
