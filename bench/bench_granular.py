"""Cost of the heat engine on a flowing granular bed: the rotating drum of
``cases/rotating_drum.py`` (about 2,000 copper particles, 20 rpm, smooth isothermal shell,
adiabatic ends), one process, blocks with and without the engine interleaved.

For each engine period (10 and 100 steps) one engine is made and its first calls (the
first Verlet list, the solver setup) run before the timing; then ``--pairs`` pairs of blocks
of ``--steps`` steps each run, one with the engine alive and one with it dead (its PyRunner
skipped), the order swapped every pair. Prints one JSON line per period::

    {"bench": "granular", "case": "drum", "n", "rpm", "period", "skin",
     "ratio": wall_with / wall_without (sums over the blocks),
     "ratio_median_of_pairs": the median of the pairs' ratios (less sensitive to the
         machine's noise),
     "engine_share": 1 - 1 / ratio_median_of_pairs (target < 0.2 every 10 steps),
     "engine_share_of_sums": 1 - 1 / ratio,
     "calls_share": time inside the engine's calls / wall_with,
     "call_ms": the engine's own time per call (measured inside the calls),
     "yade_step_ms": wall_without / steps, "list_builds_per_call", "load"}

    yade-electro -n -x bench/bench_granular.py [--n 2000] [--steps 500] [--pairs 8]
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time

_SCRIPT = __file__ if __file__.endswith("bench_granular.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_granular.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, HERE)
import _benchlib  # noqa: E402,F401  (puts the project and cases/ on the path)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--rpm", type=float, default=20.0)
    ap.add_argument("--steps", type=int, default=500, help="steps per timed block")
    ap.add_argument("--pairs", type=int, default=8, help="pairs of blocks (with / without the engine)")
    ap.add_argument("--periods", default="10,100")
    ap.add_argument("--skin", type=float, default=None, help="Verlet skin in smallest radii (engine default)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    import numpy as np
    import rotating_drum as drum
    from yade_electro.yade.runtime import import_yade
    yade = import_yade()
    O = yade.Omega()
    ids = drum.build_drum(args.n, verbose=False)
    drum.start_rotation(ids, args.rpm)
    O.run(int(0.3 / O.dt), True)            # the bed is flowing before the first block
    sph = np.array(ids["spheres"])
    hot = sph[: sph.size // 2]
    out = []
    for period in (int(p) for p in args.periods.split(",")):
        engine = drum.heat_engine(ids, hot, label="bench_granular", iterPeriod=period, skin=args.skin)
        O.engines = O.engines + [engine.runner]
        O.run(max(2 * period, args.steps), True)      # first calls and the skin's adaptation out of the blocks
        inner = engine._step
        spent = [0.0]

        def timed(*a, **k):
            t_ = time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                spent[0] += time.perf_counter() - t_
        engine._step = timed
        c0, b0 = engine.reader.calls, engine.reader.list_builds
        wall = {"with": 0.0, "without": 0.0}
        pair_ratios = []
        for k in range(args.pairs):
            w = {}
            for mode in (("without", "with") if k % 2 == 0 else ("with", "without")):
                engine.runner.dead = mode == "without"
                t = time.perf_counter()
                O.run(args.steps, True)
                w[mode] = time.perf_counter() - t
                wall[mode] += w[mode]
            pair_ratios.append(w["with"] / w["without"])
        calls = engine.reader.calls - c0
        builds = engine.reader.list_builds - b0
        engine.remove()
        ratio, med = wall["with"] / wall["without"], float(np.median(pair_ratios))
        row = {"bench": "granular", "case": "drum", "n": int(sph.size), "rpm": args.rpm, "period": period,
               "skin": engine.reader.skin, "ratio": round(ratio, 3), "ratio_median_of_pairs": round(med, 3),
               "engine_share": round(1.0 - 1.0 / med, 3), "engine_share_of_sums": round(1.0 - 1.0 / ratio, 3),
               "calls_share": round(spent[0] / wall["with"], 3),
               "call_ms": round(1e3 * spent[0] / max(calls, 1), 3),
               "yade_step_ms": round(1e3 * wall["without"] / (args.pairs * args.steps), 3),
               "list_builds_per_call": round(builds / max(calls, 1), 3),
               "load": round(os.getloadavg()[0], 2)}
        out.append(row)
        print(json.dumps(row), flush=True)
    return out


if __name__ == "__main__":
    main()
