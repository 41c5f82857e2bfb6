"""Pieces every case script shares: yade-batch parameters (run with `yade-electro batch`) and gathering per-run results.

Not a case itself (no JSON line); imported by the scripts in this folder.
"""
from __future__ import annotations

import csv
import glob
import json
import os


def apply_batch_table(args, columns=("n", "seed", "law"), attrs=None):
    """When the script runs under yade-batch (``YADE_BATCH`` set), overwrite ``args`` with the
    table line's values of ``columns`` (YADE eval()s the cells, so strings are quoted in the
    table). ``attrs`` maps a column to the argparse attribute when their names differ.
    The command-line values are the defaults of columns the table lacks."""
    if not os.environ.get("YADE_BATCH"):
        return args
    attrs = dict(attrs or {})
    from yade import utils
    defaults = {c: getattr(args, attrs.get(c, c)) for c in columns}
    utils.readParamsFromTable(noTableOk=True, **defaults)
    from yade.params import table
    for c in columns:
        setattr(args, attrs.get(c, c), type(defaults[c])(getattr(table, c)))
    return args


def collect_runs(out_dir, pattern, csv_name, fields, laws=()):
    """Rows of every per-run JSON file matching ``pattern`` in ``out_dir``, sorted by (n, seed,
    law in the order of ``laws``) and written to ``csv_name`` there with ``fields``."""
    rows = []
    for path in glob.glob(os.path.join(out_dir, pattern)):
        with open(path) as fh:
            rows.append(json.load(fh))
    order = {law: k for k, law in enumerate(laws)}
    rows.sort(key=lambda r: (r["n"], r["seed"], order.get(r["law"], len(order))))
    with open(os.path.join(out_dir, csv_name), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for r in rows:
            w.writerow(r)
    return rows


def public(row):
    """A result row without its private entries (keys starting with '_'), arrays as lists:
    what goes to JSON and CSV."""
    import numpy as np
    return {k: (v.tolist() if isinstance(v, np.ndarray) else v) for k, v in row.items()
            if not k.startswith("_")}


def sweep_runs(run_one, sizes, laws, out_dir, csv_name, fields, summary_line):
    """``run_one(n, law)`` for every size x law; each row is appended to ``csv_name`` in
    ``out_dir`` as it comes (so a crash keeps the rows done) and its summary line printed, then a
    progress line on stderr (runs done, time spent, an estimate of the time left).
    Returns the rows."""
    from yade_electro.core.progress import Progress
    os.makedirs(out_dir, exist_ok=True)
    rows = []
    runs = [(n, law) for n in sizes for law in laws]
    progress = Progress("sweep", "runs", len(runs), every=0.0)     # a line after every run, with the time left
    with open(os.path.join(out_dir, csv_name), "w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields, extrasaction="ignore")
        w.writeheader()
        for n, law in runs:
            row = run_one(n, law)
            rows.append(row)
            w.writerow(public(row))
            fh.flush()
            print(summary_line(row), flush=True)
            progress.update(len(rows))
    return rows


def frictional_bed(O, wall_shapes=(), gravity=(0, 0, -9.81), damping=0.2):
    """Give YADE's ``O`` the engines of a cohesionless frictional bed (``FrictMat`` with
    Cundall-Strack contacts) among walls of ``wall_shapes`` ('Facet', 'Wall'), and a time step
    of half the P-wave step. The granular cases share it."""
    from yade import utils
    from yade import wrapper as W
    bounds = [W.Bo1_Sphere_Aabb()] + [getattr(W, f"Bo1_{k}_Aabb")() for k in wall_shapes]
    geoms = [W.Ig2_Sphere_Sphere_ScGeom()] + [getattr(W, f"Ig2_{k}_Sphere_ScGeom")() for k in wall_shapes]
    O.engines = [W.ForceResetter(), W.InsertionSortCollider(bounds),
                 W.InteractionLoop(geoms, [W.Ip2_FrictMat_FrictMat_FrictPhys()],
                                   [W.Law2_ScGeom_FrictPhys_CundallStrack()]),
                 W.NewtonIntegrator(gravity=gravity, damping=damping)]
    O.dt = 0.5 * utils.PWaveTimeStep()
