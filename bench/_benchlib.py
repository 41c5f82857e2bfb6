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
