"""Shared pieces of the benchmark scripts: timing (of Python calls and of YADE's runs) and
the bonded rod of the rod case."""
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


#: how the benches time YADE's blocks (a field of their JSON rows; rows without it were timed
#: with ``O.run(n, True)``, whose 40 ms tick rounded every block up)
BLOCK_TIMER = "run_steps: O.running polled every 0.5 ms"


def run_steps(O, n: int, poll: float = 5e-4) -> float:
    """Run ``n`` steps of YADE and return their wall time [s], to about ``poll`` s.

    Do not time blocks with ``O.run(n, True)``: it returns on a 40 ms polling tick (measured
    on 2026-12-04: a run of 1 or of 3,000 steps of a small scene, 0.05 and 15 ms of work,
    took 40.2 ms; one of 10,000 steps, 46 ms of work, took 80.3 ms), so each block's time is
    rounded up to a multiple of 40 ms. This starts the run and polls ``O.running`` every
    ``poll`` seconds: 0.5 ms did not slow YADE's loop measurably (10,000 steps in 46.4 ms,
    as with 2 ms); 0.1 ms slowed it by about 20 %."""
    i0 = O.iter
    t = time.perf_counter()
    O.run(int(n), False)
    while O.running:
        time.sleep(poll)
    wall = time.perf_counter() - t
    if O.iter != i0 + int(n):
        raise RuntimeError(f"run_steps: YADE ran {O.iter - i0} steps, not {n} (did an engine stop it?)")
    return wall


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
