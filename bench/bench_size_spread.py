"""Verlet list of a bed with a wide size spread: the search by size classes against one
search at 2 r_max + skin, side by side in one process (numpy/scipy and the compiled cell
grid; no YADE).

20,000 spheres of r = 1 mm at random in a box (about 55 % of it by volume), and one sphere
``--ratios`` (10, 30) times larger; ``candidate_pairs`` once each way (the single search by
setting ``SIZE_CLASS_RATIO`` to infinity), after one warm-up call. Prints one JSON line per
ratio::

    {"bench": "size_spread", "n", "ratio", "pairs", "classes_ms", "single_reach_ms",
     "speedup", "same_pairs", "monodisperse_ms", "load"}

    python3 bench/bench_size_spread.py [--n 20000] [--ratios 10,30]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=20000)
    ap.add_argument("--ratios", default="10,30")
    args = ap.parse_args(argv)
    import numpy as np
    from yade_electro.geometry import contacts
    rng = np.random.default_rng(1)
    n = args.n
    side = (n * 8e-9 * 1.9) ** (1 / 3)            # r = 1 mm spheres at about 55 % of the box
    pos = rng.random((n, 3)) * side
    mono = np.full(n, 1e-3)
    skin = 0.2e-3
    contacts.candidate_pairs(pos, mono, skin)      # warm-up: the compiled grid is built once
    t = time.perf_counter()
    contacts.candidate_pairs(pos, mono, skin)
    mono_ms = (time.perf_counter() - t) * 1e3
    for ratio in (float(r) for r in args.ratios.split(",")):
        rad = mono.copy()
        rad[0] = ratio * 1e-3
        t = time.perf_counter()
        classed = contacts.candidate_pairs(pos, rad, skin)
        classes_ms = (time.perf_counter() - t) * 1e3
        kept = contacts.SIZE_CLASS_RATIO
        contacts.SIZE_CLASS_RATIO = float("inf")
        try:
            t = time.perf_counter()
            single = contacts.candidate_pairs(pos, rad, skin)
            single_ms = (time.perf_counter() - t) * 1e3
        finally:
            contacts.SIZE_CLASS_RATIO = kept
        print(json.dumps({"bench": "size_spread", "n": n, "ratio": ratio, "pairs": int(len(classed)),
                          "classes_ms": round(classes_ms, 1), "single_reach_ms": round(single_ms, 1),
                          "speedup": round(single_ms / classes_ms, 1),
                          "same_pairs": bool(np.array_equal(classed, single)),
                          "monodisperse_ms": round(mono_ms, 1), "load": round(os.getloadavg()[0], 2)}), flush=True)


if __name__ == "__main__":
    main()
