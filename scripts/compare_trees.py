#!/usr/bin/env python3
"""Run cases (or benches) with two checkouts, one after the other, and compare their last JSON
lines: the check that a refactoring changed no figure ("the same JSON numbers to 1e-10").

    python3 scripts/compare_trees.py OLD_TREE NEW_TREE [--only rod_continuum,two_spheres] [--out DIR]

OLD_TREE and NEW_TREE are checkouts (``git worktree add --detach /tmp/old <commit>``) whose
kernels are built. Each case runs as ``yade-electro -n -x`` with the tree first on PYTHONPATH;
every number of the two JSON lines is compared (times and paths left out) and one JSON line per
case is printed: how many numbers, the largest relative difference, the keys over 1e-10.
"""
import argparse
import json
import math
import os
import subprocess
import sys

CASES = {
    "rod_continuum": ("cases/rod_resistance.py", ["--n", "5000", "--law", "continuum"]),
    "rod_voronoi": ("cases/rod_resistance.py", ["--n", "5000", "--law", "voronoi"]),
    "rod_surface": ("cases/rod_resistance.py", ["--n", "5000", "--law", "voronoi", "--electrodes", "surface"]),
    "two_spheres": ("cases/two_spheres.py", []),
    "joule_rod": ("cases/joule_rod.py", ["--n", "5000"]),
    "powder_column": ("cases/powder_column.py", ["--random", "0"]),
    "coax": ("cases/coax_resistance.py", ["--n", "5000"]),
    "edge_crack": ("cases/edge_crack.py", ["--n", "10000", "--no-fem"]),
    "plate_voronoi_surface": ("cases/plate_potential.py", ["--n", "5000", "--law", "voronoi-surface"]),
    "notched_voronoi": ("cases/notched_joule.py", ["--n", "5000", "--law", "voronoi"]),
    "cross_engine_heat": ("cases/cross_engine_heat.py", []),
}
#: the long cases (5-16 min each), run by name with --only
LONG_CASES = {
    "pin_torsion": ("cases/pin_torsion.py", []),
    "container_heating": ("cases/container_heating.py", []),
    "falling_bed": ("cases/falling_bed.py", []),
    "rotating_drum": ("cases/rotating_drum.py", []),
    "cross_engine_packing": ("cases/cross_engine_packing.py", []),
}
#: keys left out of the comparison: times, and paths of written files
SKIPPED_PREFIXES = ("t_", "time_s", "wall_s", "png", "csv", "vtk", "out")


def last_json(text):
    for line in reversed(text.splitlines()):
        if line.strip().startswith("{"):
            try:
                return json.loads(line)
            except ValueError:
                continue
    return None


def leaves(d, prefix=""):
    if isinstance(d, dict):
        for k, v in d.items():
            yield from leaves(v, f"{prefix}.{k}" if prefix else k)
    elif isinstance(d, list):
        for i, v in enumerate(d):
            yield from leaves(v, f"{prefix}[{i}]")
    else:
        yield prefix, d


def skipped(key):
    return any(p.startswith(SKIPPED_PREFIXES) or p.endswith("_s") for p in key.split("."))


def run(tree, script, args, out):
    os.makedirs(out, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=tree)
    p = subprocess.run([sys.executable, "-m", "yade_electro.yade.launcher", "-n", "-x", os.path.join(tree, script)]
                       + args, cwd=out, env=env, capture_output=True, text=True)
    if p.returncode:
        raise RuntimeError(f"{script} failed in {tree}:\n{p.stderr[-2000:]}")
    return last_json(p.stdout)


def compare(a, b):
    la, lb = dict(leaves(a)), dict(leaves(b))
    worst, n, over = 0.0, 0, []
    for k, va in la.items():
        vb = lb.get(k)
        if skipped(k) or isinstance(va, bool) or not isinstance(va, (int, float)) or not isinstance(vb, (int, float)):
            continue
        n += 1
        if va == vb or (math.isnan(va) and math.isnan(vb)):
            continue
        rel = abs(va - vb) / max(abs(va), abs(vb), 1e-300)
        worst = max(worst, rel)
        if rel > 1e-10:
            over.append([k, va, vb, rel])
    over.sort(key=lambda o: -o[3])                  # the largest differences first
    return {"numbers": n, "max_rel_diff": worst, "over_1e-10": over[:10], "n_over_1e-10": len(over)}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("old")
    ap.add_argument("new")
    ap.add_argument("--only", default=None, help="comma-separated case names (default: all but the long ones)")
    ap.add_argument("--out", default="out/compare_trees")
    args = ap.parse_args(argv)
    names = args.only.split(",") if args.only else list(CASES)
    for name in names:
        script, cargs = {**CASES, **LONG_CASES}[name]
        a = run(os.path.abspath(args.old), script, cargs, os.path.join(args.out, name, "old"))
        b = run(os.path.abspath(args.new), script, cargs, os.path.join(args.out, name, "new"))
        print(json.dumps({"case": name, **compare(a, b)}), flush=True)


if __name__ == "__main__":
    main()
