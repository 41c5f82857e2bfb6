"""What the electrical engine costs in the pin torsion case: the engine's share of the wall time
with the engine every step and every 100 steps, each law, in the elastic range of the twist.

The pin of ``cases/pin_torsion.py`` (kept calibration) is twisted at the paper's rate; blocks
of ``--block`` steps alternate between the engine's PyRunner alive and dead, ``--blocks`` pairs,
the order swapped every pair. YADE's own timing (``O.timingEnabled``, ``PyRunner.execTime``)
gives the time inside the engine's calls.

One JSON line per (law, period)::

    {"bench": "pin", "n", "law", "period", "engine_share": time in the engine / wall of the
     blocks with it, "ratio": wall with / wall without, "step_ms_without", "step_ms_with",
     "moment_check_share": the moment-strength check's share (it runs in both), "block_timer", "load_average"}

    yade-electro -n -x bench/bench_pin.py [--n 5000] [--block 400] [--blocks 3]
"""
from __future__ import annotations

import argparse
import json
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__ if __file__.endswith("bench_pin.py") else sys.argv[0]))
for _p in (os.path.dirname(HERE), os.path.join(os.path.dirname(HERE), "cases"), HERE):
    if _p not in sys.path:
        sys.path.insert(0, _p)
from _benchlib import BLOCK_TIMER, run_steps  # noqa: E402


def bench(n=5000, seed=1, laws=("voronoi", "continuum"), periods=(1, 100), block=400, blocks=3):
    import pin_torsion as PT
    from yade_electro.yade import ElectricalEngine, Law, Material, Output, Reader, electrodes_from_dict
    cal = PT.load_calibration(n, seed)
    rate = PT.paper_rate()
    pin = PT.build_pin(n, seed, cal["young"], cal["strength"], rate=rate, ramp_time=2 * PT.RAMP_ANGLE / rate)
    O, cyl = pin["O"], pin["container"]
    O.timingEnabled = True
    out = []
    for law in laws:
        for period in periods:
            el, params = PT.pin_electrodes(pin, law)
            eng = ElectricalEngine(
                material=Material(resistivity=PT.RESISTIVITY),
                boundaries=electrodes_from_dict(el),
                law=Law(law, **{**(params or {}), "container": cyl}),
                reader=Reader(bond_check="flags"),
                output=Output(write_back=None),
                iterPeriod=period,
                label=f"bench_{law}_{period}")
            O.engines = O.engines + [eng.runner]
            O.step()                                   # the first call builds everything: not timed
            wall = {True: 0.0, False: 0.0}
            steps = {True: 0, False: 0}
            eng.runner.execTime = 0
            check = pin["strength_check"].runner
            check.execTime = 0
            for k in range(blocks):
                for alive in ((True, False) if k % 2 == 0 else (False, True)):
                    eng.runner.dead = not alive
                    wall[alive] += run_steps(O, block)
                    steps[alive] += block
            row = {"bench": "pin", "n": len(pin["ids"]), "law": law, "period": period,
                   "engine_share": eng.runner.execTime * 1e-9 / wall[True], "ratio": wall[True] / wall[False],
                   "step_ms_without": 1e3 * wall[False] / steps[False], "step_ms_with": 1e3 * wall[True] / steps[True],
                   "moment_check_share": check.execTime * 1e-9 / (wall[True] + wall[False]),
                   "theta_end": pin["rig"].theta, "broken": int(pin["strength_check"].broken),
                   "block_timer": BLOCK_TIMER, "load_average": os.getloadavg()[0]}
            print(json.dumps(row), flush=True)
            out.append(row)
            eng.remove()
    return out


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--block", type=int, default=400)
    ap.add_argument("--blocks", type=int, default=3)
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    return bench(args.n, block=args.block, blocks=args.blocks)


if __name__ == "__main__":
    main()
