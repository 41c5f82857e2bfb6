"""The packing recipe at scale: ``dense_packing`` (FIRE jamming, numpy + the compiled pair
forces) of the rod case's cylinder (R = 1 mm, L = 5 mm, seed 1, no cache) and
``add_bonded_packing`` (real YADE bonds), timed apart. Both print progress lines on stderr
while they run. Targets (issue 11): 100k in < 3 min, 1M in < 30 min.

One JSON line per size::

    {"bench": "recipe", "n", "packing_s", "bonding_s", "total_s", "bonds", "peak_rss_mb", "load_average"}

    yade-electro -n -x bench/bench_recipe.py [--n 100000]
"""
from __future__ import annotations

import argparse
import json
import os
import resource
import sys
import time

_SCRIPT = __file__ if __file__.endswith("bench_recipe.py") else next(
    (a for a in sys.argv if a.endswith("bench_recipe.py")), __file__)
sys.path.insert(0, os.path.dirname(os.path.dirname(os.path.abspath(_SCRIPT))))

LENGTH, RADIUS = 5e-3, 1e-3     # m, the rod case's


def recipe(n: int, seed: int = 1) -> dict:
    import yade
    from yade_electro.geometry.shapes import Cylinder
    from yade_electro.yade import packing as P
    O = yade.Omega()
    t0 = time.perf_counter()
    pk = P.dense_packing(Cylinder((0, 0, 0), (0, 0, LENGTH), RADIUS), n=n, seed=seed, cache_dir=False)
    t1 = time.perf_counter()
    P.add_bonded_packing(pk)
    t2 = time.perf_counter()
    return {"bench": "recipe", "n": int(pk.radii.shape[0]), "packing_s": round(t1 - t0, 1),
            "bonding_s": round(t2 - t1, 1), "total_s": round(t2 - t0, 1),
            "bonds": int(sum(1 for i in O.interactions if i.isReal)),
            "peak_rss_mb": int(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss // 1024),
            "load_average": round(os.getloadavg()[0], 2)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=100000, help="number of spheres (default 100,000)")
    a = ap.parse_args(sys.argv[1:] if argv is None else argv)
    print(json.dumps(recipe(a.n)), flush=True)


if __name__ == "__main__":
    main()
