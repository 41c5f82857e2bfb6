"""Cost of the heat engine on a flowing granular bed: the rotating drum of
``cases/rotating_drum.py`` (about 2,000 copper particles, 20 rpm, smooth isothermal shell,
adiabatic ends), one process, blocks with and without the engine interleaved.

For each engine period (10 and 100 steps) and mode (``plain``: the default engine;
``overlap``: ``overlap=True``, its numpy work on a worker thread) one engine is made and
its first calls (the first Verlet list, the solver setup) run before the timing, and 20 more
give its time per call; then ``--pairs`` groups of three blocks of ``--steps`` steps each
run: one with the engine alive, one with it dead (its PyRunner skipped) and one with the
engine dead and a stand-in alive that only sleeps that time per call, the order reversed
every group. Prints one JSON line per period and mode::

    {"bench": "granular", "case": "drum", "n", "rpm", "period", "overlap", "skin",
     "ratio": wall_with / wall_without (sums over the blocks),
     "ratio_median_of_pairs": the median of the pairs' ratios (less sensitive to the
         machine's noise),
     "engine_share": 1 - 1 / ratio_median_of_pairs (target < 0.2 every 10 steps),
     "engine_share_of_sums": 1 - 1 / ratio,
     "calls_share": time inside the engine's calls / wall_with,
     "call_ms": the engine's own time per call (measured inside the calls; with ``overlap``
         the part that pauses YADE's loop, the worker thread's part not included),
     "yade_step_ms": wall_without / steps, "list_builds_per_call",
     "yade_engines_ms_with", "yade_engines_ms_without": the time per step inside YADE's own
         engines (their ``execTime``, ``O.timingEnabled``) with the engine alive and dead: how
         much the engine's calls slow YADE's own work down between them,
     "pause_ms", "pause_share", "pause_share_of_sums", "yade_engines_ms_pause": the same for a
         stand-in timed in the same groups of blocks: a PyRunner at the engine's period that
         only sleeps for the engine's own mean time per call (the 20 warm-up calls, then all
         its timed calls so far), no work and no memory touched. Its share is what any engine
         that stops YADE's loop that long costs on this machine,
     "block_timer": how the blocks were timed (:func:`_benchlib.run_steps`), "load"}

    yade-electro -n -x bench/bench_granular.py [--n 2000] [--steps 100] [--pairs 40] [--modes plain,overlap]
"""
from __future__ import annotations

import argparse
import builtins
import json
import os
import sys
import time

_SCRIPT = __file__ if __file__.endswith("bench_granular.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("bench_granular.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
sys.path.insert(0, HERE)
import _benchlib  # noqa: E402  (puts the project and cases/ on the path; run_steps)


def main(argv=None):
    ap = argparse.ArgumentParser()
    ap.add_argument("--n", type=int, default=2000)
    ap.add_argument("--rpm", type=float, default=20.0)
    ap.add_argument("--steps", type=int, default=100, help="steps per timed block")
    ap.add_argument("--pairs", type=int, default=40, help="pairs of blocks (with / without the engine)")
    ap.add_argument("--periods", default="10,100")
    ap.add_argument("--skin", type=float, default=None, help="Verlet skin in smallest radii (engine default)")
    ap.add_argument("--modes", default="plain,overlap",
                    help="engines to time at each period: 'plain' (default engine) and/or 'overlap' (overlap=True: "
                         "the numpy work on a worker thread while YADE steps on)")
    ap.add_argument("--reference", action="store_true",
                    help="also time three stand-in PyRunners every 10 steps (no engine): a 6 ms Python spin, the "
                         "sum of a fresh 16 MB array and a 6 ms sleep (no work at all), to see how any pause of "
                         "YADE's loop slows YADE's own engines; and the time of each of the 10 steps after such a "
                         "pause")
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
    if args.reference:
        out += reference_rows(yade, O, args)
    runs = [(int(p), m) for p in args.periods.split(",") for m in args.modes.split(",")]
    bad = {m for _, m in runs} - {"plain", "overlap"}
    if bad:
        ap.error(f"--modes: unknown {sorted(bad)}; give plain and/or overlap")
    for period, mode_name in runs:
        engine = drum.heat_engine(ids, hot, label="bench_granular", iterPeriod=period, skin=args.skin,
                                  overlap=mode_name == "overlap")
        O.engines = O.engines + [engine.runner]
        O.run(max(2 * period, args.steps), True)      # first calls and the skin's adaptation out of the blocks
        inner = engine._step
        call_s = []             # each call's time inside the engine [s]: 20 warm-up calls, then the timed ones

        def timed(*a, **k):
            t_ = time.perf_counter()
            try:
                return inner(*a, **k)
            finally:
                call_s.append(time.perf_counter() - t_)
        engine._step = timed
        O.run(20 * period, True)                      # the engine's time per call, for the stand-in
        warm = len(call_s)
        builtins._bench_granular_pause = float(np.mean(call_s))
        sleeper = yade.PyRunner(command="__import__('time').sleep(__import__('builtins')._bench_granular_pause)",
                                iterPeriod=period, dead=True)
        O.engines = O.engines + [sleeper]
        c0, b0 = engine.reader.calls, engine.reader.list_builds
        wall = {"with": 0.0, "without": 0.0, "pause": 0.0}
        own = {"with": 0.0, "without": 0.0, "pause": 0.0}         # YADE's own engines (execTime, ns)
        mechanics = [e for e in O.engines if type(e).__name__ != "PyRunner"]
        O.timingEnabled = True
        pair_ratios, pause_ratios = [], []
        for k in range(args.pairs):
            w = {}
            for mode in (("without", "with", "pause") if k % 2 == 0 else ("pause", "with", "without")):
                engine.runner.dead = mode != "with"
                sleeper.dead = mode != "pause"
                e0 = sum(e.execTime for e in mechanics)
                w[mode] = _benchlib.run_steps(O, args.steps)
                own[mode] += sum(e.execTime for e in mechanics) - e0
                wall[mode] += w[mode]
            pair_ratios.append(w["with"] / w["without"])
            pause_ratios.append(w["pause"] / w["without"])
            builtins._bench_granular_pause = float(np.mean(call_s))    # the engine's mean call so far
        O.timingEnabled = False
        sleeper.dead = True
        O.engines = [e for e in O.engines if e is not sleeper]
        engine.sync()
        spent = sum(call_s[warm:])
        calls = engine.reader.calls - c0
        builds = engine.reader.list_builds - b0
        engine.remove()
        ratio, med = wall["with"] / wall["without"], float(np.median(pair_ratios))
        row = {"bench": "granular", "case": "drum", "n": int(sph.size), "rpm": args.rpm, "period": period,
               "overlap": mode_name == "overlap",
               "skin": engine.reader.skin, "ratio": round(ratio, 3), "ratio_median_of_pairs": round(med, 3),
               "engine_share": round(1.0 - 1.0 / med, 3), "engine_share_of_sums": round(1.0 - 1.0 / ratio, 3),
               "calls_share": round(spent / wall["with"], 3),
               "call_ms": round(1e3 * spent / max(calls, 1), 3),
               "yade_step_ms": round(1e3 * wall["without"] / (args.pairs * args.steps), 3),
               "list_builds_per_call": round(builds / max(calls, 1), 3),
               "yade_engines_ms_with": round(1e-6 * own["with"] / (args.pairs * args.steps), 3),
               "yade_engines_ms_without": round(1e-6 * own["without"] / (args.pairs * args.steps), 3),
               "pause_ms": round(1e3 * builtins._bench_granular_pause, 3),
               "pause_share": round(1.0 - 1.0 / float(np.median(pause_ratios)), 3),
               "pause_share_of_sums": round(1.0 - wall["without"] / wall["pause"], 3),
               "yade_engines_ms_pause": round(1e-6 * own["pause"] / (args.pairs * args.steps), 3),
               "block_timer": _benchlib.BLOCK_TIMER, "load": round(os.getloadavg()[0], 2)}
        out.append(row)
        print(json.dumps(row), flush=True)
    return out


def _spin(ms):
    t = time.perf_counter()
    while time.perf_counter() - t < ms * 1e-3:
        pass


def reference_rows(yade, O, args):
    """Stand-ins for the engine, every 10 steps, blocks interleaved with dead ones as for the
    engine: ``spin`` (a 6 ms pure-Python loop), ``alloc`` (numpy sums a fresh 16 MB array)
    and ``sleep`` (``time.sleep(0.006)``: no work, no memory touched, only a pause of YADE's
    loop); and two that hand their work to a worker thread as ``overlap=True`` does, so that
    YADE's loop goes on at once: ``thread_spin`` (a 2 ms pure-Python loop on the thread) and
    ``thread_sleep`` (a 2 ms sleep on the thread: the hand-over alone). One JSON line each:
    the time per step in YADE's own engines alive and dead; then :func:`pause_decay`'s line."""
    from concurrent.futures import ThreadPoolExecutor
    pool, pending = ThreadPoolExecutor(max_workers=1), []

    def on_thread(job):
        while pending:
            pending.pop().result()
        pending.append(pool.submit(job))
    builtins._bench_granular_spin = _spin
    builtins._bench_granular_thread = {"spin": lambda: on_thread(lambda: _spin(2.0)),
                                       "sleep": lambda: on_thread(lambda: time.sleep(0.002))}
    runners = {"spin": yade.PyRunner(command="__import__('builtins')._bench_granular_spin(6.0)", iterPeriod=10),
               "alloc": yade.PyRunner(command="__import__('numpy').random.rand(2000000).sum()", iterPeriod=10),
               "sleep": yade.PyRunner(command="__import__('time').sleep(0.006)", iterPeriod=10),
               "thread_spin": yade.PyRunner(command="__import__('builtins')._bench_granular_thread['spin']()",
                                            iterPeriod=10),
               "thread_sleep": yade.PyRunner(command="__import__('builtins')._bench_granular_thread['sleep']()",
                                             iterPeriod=10)}
    O.engines = O.engines + list(runners.values())
    mechanics = [e for e in O.engines if type(e).__name__ != "PyRunner"]
    O.timingEnabled = True
    own, wall = {}, {}
    for k in range(args.pairs):
        modes = ["dead"] + list(runners)
        for mode in (modes if k % 2 == 0 else modes[::-1]):
            for name, r in runners.items():
                r.dead = name != mode
            e0 = sum(e.execTime for e in mechanics)
            wall[mode] = wall.get(mode, 0.0) + _benchlib.run_steps(O, args.steps)
            own[mode] = own.get(mode, 0.0) + sum(e.execTime for e in mechanics) - e0
    O.timingEnabled = False
    O.engines = [e for e in O.engines if e not in runners.values()]
    while pending:
        pending.pop().result()
    pool.shutdown()
    steps = args.pairs * args.steps
    rows = []
    for name in runners:
        row = {"bench": "granular", "case": "drum_reference", "runner": name, "period": 10,
               "share_of_sums": round(1.0 - wall["dead"] / wall[name], 3),
               "yade_engines_ms_with": round(1e-6 * own[name] / steps, 3),
               "yade_engines_ms_without": round(1e-6 * own["dead"] / steps, 3),
               "yade_engines_slowdown": round(own[name] / own["dead"] - 1.0, 3),
               "block_timer": _benchlib.BLOCK_TIMER, "load": round(os.getloadavg()[0], 2)}
        rows.append(row)
        print(json.dumps(row), flush=True)
    rows.append(pause_decay(O, args.pairs))
    return rows


def pause_decay(O, repeats, pause_ms=6.0, steps=10):
    """The shape of that slowdown: each of ``steps`` single ``O.step()`` calls timed after
    no pause, a ``pause_ms`` sleep and a ``pause_ms`` Python spin, the three in turn,
    ``repeats`` times. One JSON line with the mean time of each step after each [ms]."""
    import numpy as np
    pauses = {"none": lambda: None, "sleep": lambda: time.sleep(pause_ms * 1e-3), "spin": lambda: _spin(pause_ms)}
    spent = {name: np.zeros(steps) for name in pauses}
    for _ in range(repeats):
        for name, pause in pauses.items():
            pause()
            for k in range(steps):
                t = time.perf_counter()
                O.step()
                spent[name][k] += time.perf_counter() - t
    row = {"bench": "granular", "case": "drum_pause_decay", "pause_ms": pause_ms, "repeats": repeats,
           **{f"step_ms_after_{name}": np.round(1e3 * v / repeats, 3).tolist() for name, v in spent.items()},
           "load": round(os.getloadavg()[0], 2)}
    print(json.dumps(row), flush=True)
    return row


if __name__ == "__main__":
    main()
