"""Shared pieces of the benchmark scripts: timing and the bonded rod of the rod case."""
from __future__ import annotations

import os
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
for _p in (os.path.dirname(HERE), os.path.join(os.path.dirname(HERE), "cases")):
    if _p not in sys.path:
        sys.path.insert(0, _p)


def best(fn, repeat):
    """Best wall time [s] of ``repeat`` calls of fn (and the last result)."""
    t_best, out = float("inf"), None
    for _ in range(repeat):
        t = time.perf_counter()
        out = fn()
        t_best = min(t_best, time.perf_counter() - t)
    return t_best, out


def bonded_rod(n, seed=1):
    """Reset YADE's scene and build the bonded rod of ``cases/rod_resistance.py`` (cached
    packing). Returns (O, body ids, bottom mask, top mask) in packing order."""
    from yade_electro.yade import packing as P
    from yade_electro.yade.runtime import import_yade
    import rod_resistance as rod
    yade = import_yade()
    from yade import pack
    O = yade.Omega()
    O.reset()
    packing = P.dense_packing(pack.inCylinder((0, 0, 0), (0, 0, rod.LENGTH), rod.RADIUS), n=n, seed=seed)
    ids = np.asarray(P.add_bonded_packing(packing))
    bottom, top = rod.end_layers(packing.centers[:, 2], packing.radii, float(np.mean(packing.radii)))
    return O, ids, bottom, top


def to_ms(out, keep=()):
    """Convert the ``*_ms`` entries of ``out`` (measured in s) to ms, rounded; ``keep``
    names entries already in ms."""
    for k in list(out):
        if k.endswith("_ms") and k not in keep:
            out[k] = round(out[k] * 1e3, 3)
    return out


def run_sizes(bench_size, name, argv=None, **extra):
    """Parse ``--sizes``/``--repeat``, run ``bench_size(n, repeat)`` for each size, print the
    table (one column per size) and one JSON line ``{"bench": name, **extra, "results": [...]}``."""
    import argparse
    import json
    ap = argparse.ArgumentParser()
    ap.add_argument("--sizes", default="5000,20000")
    ap.add_argument("--repeat", type=int, default=5)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    results = [bench_size(int(n), args.repeat) for n in args.sizes.split(",")]
    width = max(len(k) for k in results[0]) + 2
    print(f"{'':{width}s}" + "".join(f"{r['n']:>14d}" for r in results))
    for k in (k for k in results[0] if k != "n"):
        print(f"{k:{width}s}" + "".join(f"{r[k]:>14.4g}" if isinstance(r[k], float) else f"{r[k]:>14}"
                                         for r in results))
    print(json.dumps({"bench": name, **extra, "results": results}))
    return results
