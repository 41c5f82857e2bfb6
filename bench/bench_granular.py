"""Cost of the heat engine on a flowing granular bed: the rotating drum of
``cases/rotating_drum.py`` (about 2,000 copper particles, 20 rpm, smooth isothermal shell,
adiabatic ends), one process, blocks with and without the engine interleaved.

For each engine period (10 and 100 steps) prints one JSON line
``{"bench": "granular", "case": "drum", "n": ..., "period": ..., "ratio": wall_with /
wall_without, "engine_share": (wall_with - wall_without) / wall_with, "call_ms": ...,
"yade_step_ms": ..., "list_builds_per_call": ..., "load": ...}`` (target: engine_share < 0.2
every 10 steps). ``call_ms`` is the engine's own time per call, measured inside the calls.
Each block first turns the drum ``--warm`` steps with the engine so that its first call
(the first Verlet list, the solver setup) is not in the timed block.

    yade-electro -n -x bench/bench_granular.py [--n 2000] [--steps 2000] [--repeat 3]
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
    ap.add_argument("--steps", type=int, default=2000, help="steps per timed block")
    ap.add_argument("--repeat", type=int, default=3)
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
        t_with, t_without, call_s, calls, builds = [], [], 0.0, 0, 0
        for _ in range(args.repeat):
            t = time.perf_counter()
            O.run(args.steps, True)
            t_without.append(time.perf_counter() - t)
            engine = drum.heat_engine(ids, hot, label="bench_granular", iterPeriod=period, skin=args.skin)
            O.engines = O.engines + [engine.runner]
            O.run(2 * period, True)          # first calls out of the block
            c0, b0 = engine.reader.calls, engine.reader.list_builds
            inner = engine._step
            spent = [0.0]

            def timed(*a, **k):
                t_ = time.perf_counter()
                try:
                    return inner(*a, **k)
                finally:
                    spent[0] += time.perf_counter() - t_
            engine._step = timed
            t = time.perf_counter()
            O.run(args.steps, True)
            t_with.append(time.perf_counter() - t)
            call_s += spent[0]
            calls += engine.reader.calls - c0
            builds += engine.reader.list_builds - b0
            engine.remove()
        w, wo = min(t_with), min(t_without)
        row = {"bench": "granular", "case": "drum", "n": int(sph.size), "rpm": args.rpm, "period": period, "skin": engine.reader.skin,
               "ratio": round(w / wo, 3), "engine_share": round((w - wo) / w, 3),
               "call_ms": round(1e3 * call_s / max(calls, 1), 3),
               "yade_step_ms": round(1e3 * wo / args.steps, 3),
               "list_builds_per_call": round(builds / max(calls, 1), 3),
               "load": round(os.getloadavg()[0], 2)}
        out.append(row)
        print(json.dumps(row), flush=True)
    return out


if __name__ == "__main__":
    main()
