"""Rod equivalent resistance (paper 000, section 3.1, Table III and figure 7).

A rod of radius R = 1 mm and length L = 5 mm (axis z, from z = 0 to z = L), steel 304L
(rho_e = 0.73e-6 ohm m), is filled with N bonded elements; 1 V is applied between its two
end electrodes; the DEM equivalent resistance R_dem is compared with

    R_th = rho_e (L - 2 r_mean) / (pi R^2)

Electrode layers (precise definition)
--------------------------------------
The bottom electrode is every element whose sphere comes within ``gap * r_mean`` of the end
face z = 0, i.e. z_i - r_i <= gap r_mean (default gap = 0.1); the top electrode likewise at
z = L (L - z_i - r_i <= gap r_mean). The packing is dense against the container walls, so
these are the elements that touch the end faces: their centres sit one radius (on average
r_mean) from the face, which is why the theoretical length is L - 2 r_mean.

Run
---
    yade-electro -n -x cases/rod_resistance.py --n 5000 --seed 1         # one packing
    yade-electro -n -x cases/rod_resistance.py --sweep                     # Table III: 5 sizes x 3 seeds
    yade-electro batch cases/rod_resistance.table cases/rod_resistance.py  # the same through yade-batch
    yade-electro -n -x cases/rod_resistance.py --law voronoi --electrodes surface --sweep --sizes 5000,20000

Surface electrodes (``--electrodes surface``, law ``voronoi``): the electrodes are the end
faces themselves (each element whose bounded Voronoi cell has a face on an end face joins
its electrode through its half cell), and R_dem is compared with the nominal
rho_e L / (pi R^2), no L_eff.

The script ends by printing one line of JSON with its figures. It is also importable
(``run_rod``) by the tests.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

# yade's launcher runs scripts with execfile(), where __file__ is the launcher's: use argv
_SCRIPT = __file__ if __file__.endswith("rod_resistance.py") else (sys.argv[0] if sys.argv and sys.argv[0].endswith("rod_resistance.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
if os.path.dirname(HERE) not in sys.path:  # run from a checkout without installing
    sys.path.insert(0, os.path.dirname(HERE))
if HERE not in sys.path:
    sys.path.insert(0, HERE)
from caselib import apply_batch_table  # noqa: E402

from yade_electro.yade.runtime import import_yade  # noqa: E402

RADIUS = 1e-3          # m
LENGTH = 5e-3          # m
RHO_304L = 0.73e-6     # ohm m
SIZES = (1000, 2000, 5000, 10000, 20000)
SEEDS = (1, 2, 3)
#: Paper 000, Table III: (N, r_mean [um], errors [%] of the three generations)
PAPER_TABLE_III = {1000: (133, (6.08, 10.51, 9.19)), 2000: (106, (12.28, 12.57, 15.56)),
                   5000: (78, (4.11, 5.80, 4.04)), 10000: (62, (4.41, 3.60, 3.31)),
                   20000: (49, (2.60, 2.92, 3.04))}


def theoretical_resistance(r_mean: float, rho=RHO_304L, radius=RADIUS, length=LENGTH) -> float:
    """R_th = rho (L - 2 r_mean) / (pi R^2) [ohm]."""
    return rho * (length - 2.0 * r_mean) / (math.pi * radius ** 2)


def end_layers(z, r, r_mean, gap=0.1, length=LENGTH):
    """Masks of the bottom and top electrode layers (see module doc)."""
    bottom = (z - r) <= gap * r_mean
    top = (length - z - r) <= gap * r_mean
    return bottom, top


def build_rod(n=5000, seed=1, gap=0.1, detection_factor=None, cache_dir=None):
    """Reset YADE's scene and fill it with the bonded rod (the packing from the cache when it
    is there). Returns a dict: container (YADE predicate), packing, ids (body ids), r_mean,
    bottom and top (masks of the end layers, see :func:`end_layers`), t_packing_s (the
    dense packing) and t_bonding_s. ``detection_factor`` None: add_bonded_packing's default."""
    yade = import_yade()
    from yade import pack
    from yade_electro.yade import packing as P
    O = yade.Omega()
    O.reset()
    t0 = time.perf_counter()
    container = pack.inCylinder((0, 0, 0), (0, 0, LENGTH), RADIUS)
    packing = P.dense_packing(container, n=n, seed=seed, cache_dir=cache_dir)
    t_pack = time.perf_counter() - t0
    kw = {} if detection_factor is None else {"detection_factor": detection_factor}
    t1 = time.perf_counter()
    ids = np.asarray(P.add_bonded_packing(packing, **kw))
    t_bond = time.perf_counter() - t1
    r_mean = float(np.mean(packing.radii))
    bottom, top = end_layers(packing.centers[:, 2], packing.radii, r_mean, gap)
    return {"container": container, "packing": packing, "ids": ids, "r_mean": r_mean, "bottom": bottom,
            "top": top, "t_packing_s": t_pack, "t_bonding_s": t_bond}


def run_rod(n=5000, seed=1, rho=RHO_304L, voltage=1.0, law="continuum", law_params=None, solver="cg",
            gap=0.1, detection_factor=None, cache_dir=None, history=None, elements_csv=None, electrodes="layers"):
    """Build (or load from the cache) the bonded rod in YADE, solve it with the electrical
    engine, and return a dict of figures (n, r_mean, R_dem, R_th, error_pct, packing stats,
    timings). Resets YADE's scene first. ``electrodes='layers'``: the paper's element layers,
    against R_th = rho (L - 2 r_mean) / (pi R^2); ``'surface'``: electrodes on the end faces
    themselves (needs the 'voronoi' law), against the nominal rho L / (pi R^2)."""
    if electrodes not in ("layers", "surface"):
        raise ValueError(f"electrodes must be 'layers' or 'surface', got {electrodes!r}")
    if electrodes == "surface" and law != "voronoi":
        raise ValueError("surface electrodes need the 'voronoi' law (its cells give the end faces): --law voronoi")
    yade = import_yade()
    from yade_electro.yade import ElectricalEngine, Law, Material, Output, electrodes_from_dict
    from yade_electro.yade import packing as P

    O = yade.Omega()
    if detection_factor is None:
        import inspect
        detection_factor = inspect.signature(P.add_bonded_packing).parameters["detection_factor"].default
    built = build_rod(n, seed, gap, detection_factor, cache_dir)
    container, packing, ids, r_mean = built["container"], built["packing"], built["ids"], built["r_mean"]
    bottom, top, t_pack = built["bottom"], built["top"], built["t_packing_s"]
    r = packing.radii
    if law == "voronoi":
        law_params = {"container": P.as_shape(container), **(law_params or {})}
    if electrodes == "surface":
        rod = P.as_shape(container)
        spec = {"top": dict(surface=rod.face("top"), potential=voltage),
                "bottom": dict(surface=rod.face("bottom"), potential=0.0)}
    else:
        spec = {"top": dict(select=ids[top], potential=voltage), "bottom": dict(select=ids[bottom], potential=0.0)}
    engine = ElectricalEngine(
        material=Material(resistivity=rho),
        boundaries=electrodes_from_dict(spec),
        law=Law(law, **(law_params or {})),
        output=Output(history=history),
        solver=solver,
        iterPeriod=1,
        label="rod")
    O.engines = O.engines + [engine.runner]
    t1 = time.perf_counter()
    O.step()
    t_solve = time.perf_counter() - t1
    g = engine.bond_graph           # the bonds (the 'voronoi' law conducts on a wider network)
    from yade_electro.laws.transmission import eccentricity
    e = eccentricity(g)
    R_dem = engine.equivalent_resistance
    R_th = theoretical_resistance(r_mean, rho) if electrodes == "layers" else rho * LENGTH / (math.pi * RADIUS ** 2)
    sol = engine.solution
    engine.remove()
    if elements_csv is not None:        # per-element results
        np.savetxt(elements_csv,
                   np.column_stack([g.ids, g.pos, g.radius, g.degree, e, engine.potential]),
                   delimiter=",", header="body_id,x,y,z,radius,neighbours,eccentricity,potential",
                   comments="", fmt=["%d", "%.9e", "%.9e", "%.9e", "%.9e", "%d", "%.6f", "%.9e"])
    return {
        "case": "rod_resistance", "n": int(g.n_nodes), "n_target": int(n), "seed": int(seed), "law": law,
        "electrodes": electrodes,
        "detection_factor": detection_factor,
        "r_mean": r_mean, "R_dem": float(R_dem), "R_th": float(R_th),
        "error_pct": float(100.0 * (R_dem - R_th) / R_th),
        "volume_fraction": float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / (math.pi * RADIUS ** 2 * LENGTH)),
        "mean_coordination": float(np.mean(g.degree)),
        "frac_e_below_0.4": float(np.mean(e < 0.4)),
        "n_bottom": int(bottom.sum()) if electrodes == "layers" else int(engine.model.surfaces["bottom"].saved.ids.size),
        "n_top": int(top.sum()) if electrodes == "layers" else int(engine.model.surfaces["top"].saved.ids.size),
        "current_imbalance": float(sol.current_imbalance), "residual": float(sol.residual),
        "t_packing_s": t_pack, "t_step_s": t_solve,
    }


def sweep(sizes=SIZES, seeds=SEEDS, out_dir="out/rod_resistance", law="continuum", **kw):
    """Table III: every size x seed; writes a CSV and a PNG like figure 7; returns the rows."""
    os.makedirs(out_dir, exist_ok=True)
    rows = []
    tag = law if kw.get("electrodes", "layers") == "layers" else f"{law}_surface"
    csv_path = os.path.join(out_dir, f"rod_resistance_{tag}.csv")
    import csv
    with open(csv_path, "w", newline="") as fh:
        w = None
        for n in sizes:
            for s in seeds:
                row = run_rod(n, s, law=law, **kw)
                rows.append(row)
                if w is None:
                    w = csv.DictWriter(fh, fieldnames=list(row))
                    w.writeheader()
                w.writerow(row)
                fh.flush()
                print(f"N={n:6d} seed={s} n={row['n']:6d} r_mean={row['r_mean'] * 1e6:6.1f} um "
                      f"R_dem={row['R_dem'] * 1e3:.4f} mohm R_th={row['R_th'] * 1e3:.4f} mohm "
                      f"error={row['error_pct']:+.2f} %", flush=True)
    plot_sweep(rows, os.path.join(out_dir, f"rod_resistance_{tag}.png"))
    return rows


def table_markdown(rows) -> str:
    """Markdown table like the paper's Table III (ours next to the paper's)."""
    by_n = {}
    for r in rows:
        by_n.setdefault(r["n_target"], []).append(r)
    lines = ["| N | r_mean (um) | error 1 (%) | error 2 (%) | error 3 (%) | mean (%) | paper r_mean | paper errors (%) |",
             "|---|---|---|---|---|---|---|---|"]
    for n in sorted(by_n):
        rs = sorted(by_n[n], key=lambda r: r["seed"])
        errs = [r["error_pct"] for r in rs]
        pr, pe = PAPER_TABLE_III.get(n, (float("nan"), ()))
        lines.append(f"| {n} | {np.mean([r['r_mean'] for r in rs]) * 1e6:.0f} | "
                     + " | ".join(f"{e:+.2f}" for e in errs) + " | " * (3 - len(errs))
                     + f" | {np.mean(errs):+.2f} | {pr} | {', '.join(f'{x:.2f}' for x in pe)} |")
    return "\n".join(lines)


def plot_sweep(rows, path):
    """Error versus element count (figure 7 of the paper), ours and the paper's."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, ax = plt.subplots(figsize=(6, 4))
    n = np.array([r["n"] for r in rows])
    err = np.array([r["error_pct"] for r in rows])
    ax.plot(n, err, "o", label="yade-electro (each packing)")
    ns = sorted({r["n_target"] for r in rows})
    ax.plot(ns, [np.mean([r["error_pct"] for r in rows if r["n_target"] == k]) for k in ns], "-",
            label="yade-electro (mean of 3)")
    pn = sorted(PAPER_TABLE_III)
    ax.plot(pn, [np.mean(PAPER_TABLE_III[k][1]) for k in pn], "s--", label="paper 000, Table III (|error|)")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xscale("log")
    ax.set_xlabel("number of elements")
    ax.set_ylabel("(R_dem - R_th) / R_th  [%]")
    ax.set_title("Rod R = 1 mm, L = 5 mm: equivalent resistance")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


def _params(argv):
    """Parameters from the command line, or from a yade-electro batch table line."""
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--law", default="continuum")
    ap.add_argument("--solver", default="cg")
    ap.add_argument("--gap", type=float, default=0.1, help="electrode layer: z - r <= gap r_mean")
    ap.add_argument("--electrodes", choices=("layers", "surface"), default="layers",
                    help="element layers (the paper's, against L - 2 r_mean) or the end faces (nominal L)")
    ap.add_argument("--k", type=float, default=None,
                    help="bond detection factor (default that of add_bonded_packing, 1.04)")
    ap.add_argument("--sweep", action="store_true", help="all sizes x 3 seeds (Table III)")
    ap.add_argument("--demo", action="store_true",
                    help="the paper's continuum law and the voronoi law (element layers and end faces) side by side")
    ap.add_argument("--sizes", type=lambda s: tuple(int(x) for x in s.split(",")), default=SIZES)
    ap.add_argument("--out", default="out/rod_resistance")
    args = ap.parse_args(argv)
    return apply_batch_table(args)      # under yade-batch, the table line gives n, seed, law


def demo(n=5000, seed=1, solver="cg", gap=0.1):
    """The laws side by side on one packing: the paper's continuum law and the voronoi law
    with element-layer electrodes (against L - 2 r_mean), the voronoi law with the end faces
    as electrodes (against the nominal L). Prints a table; returns the rows."""
    rows = [run_rod(n, seed, law=law, solver=solver, gap=gap, electrodes=el)
            for law, el in (("continuum", "layers"), ("voronoi", "layers"), ("voronoi", "surface"))]
    print(f"rod R = {RADIUS * 1e3:g} mm, L = {LENGTH * 1e3:g} mm, {rows[0]['n']} elements "
          f"(r_mean {rows[0]['r_mean'] * 1e6:.1f} um), 1 V:")
    print(f"  {'law':<22} {'electrodes':<15} {'R_dem [mohm]':>12}  {'theory [mohm]':<24} {'error':>8}")
    for r in rows:
        el = "element layers" if r["electrodes"] == "layers" else "end faces"
        th = "L - 2 r_mean" if r["electrodes"] == "layers" else "L"
        name = "continuum (paper 000)" if r["law"] == "continuum" else "voronoi"
        theory = f"{r['R_th'] * 1e3:.5f} ({th})"
        print(f"  {name:<22} {el:<15} {r['R_dem'] * 1e3:12.5f}  {theory:<24} {r['error_pct']:+7.2f} %")
    return rows


def main(argv=None):
    args = _params(sys.argv[1:] if argv is None else argv)
    if args.demo:
        rows = demo(args.n, args.seed, args.solver, args.gap)
        summary = {"case": "rod_resistance", "demo": True, "n": rows[0]["n"], "rows": [
            {k: r[k] for k in ("law", "electrodes", "R_dem", "R_th", "error_pct")} for r in rows]}
        print(json.dumps(summary))
        return summary
    if args.sweep:
        rows = sweep(args.sizes, SEEDS, args.out, law=args.law, solver=args.solver, gap=args.gap,
                     detection_factor=args.k, electrodes=args.electrodes)
        print(table_markdown(rows))
        summary = {"case": "rod_resistance", "law": args.law, "electrodes": args.electrodes, "rows": [
            {k: r[k] for k in ("n", "n_target", "seed", "r_mean", "R_dem", "R_th", "error_pct")} for r in rows]}
        for n in sorted({r["n_target"] for r in rows}):
            summary[f"mean_error_pct_{n}"] = float(np.mean([r["error_pct"] for r in rows if r["n_target"] == n]))
        print(json.dumps(summary))
        return summary
    os.makedirs(args.out, exist_ok=True)
    stem = os.path.join(args.out, f"rod_n{args.n}_s{args.seed}_{args.law}"
                        + ("" if args.electrodes == "layers" else "_surface"))
    row = run_rod(args.n, args.seed, law=args.law, solver=args.solver, gap=args.gap, detection_factor=args.k,
                  history=stem + "_history.csv", elements_csv=stem + "_elements.csv", electrodes=args.electrodes)
    with open(stem + ".json", "w") as fh:
        json.dump(row, fh)
    plot_profile(stem + "_elements.csv", row, stem + ".png")
    print(f"rod R = {RADIUS * 1e3:g} mm, L = {LENGTH * 1e3:g} mm, {row['n']} elements (r_mean "
          f"{row['r_mean'] * 1e6:.1f} um), law {args.law}: R_dem = {row['R_dem'] * 1e3:.5f} mohm, "
          f"R_th = {row['R_th'] * 1e3:.5f} mohm, error {row['error_pct']:+.2f} %")
    print(f"wrote {stem}_history.csv, {stem}_elements.csv, {stem}.png")
    print(json.dumps(row))
    return row


def plot_profile(elements_csv, row, path):
    """Element potentials along the rod axis against the linear theory between the electrode
    planes (z = r_mean and z = L - r_mean; with surface electrodes the end faces)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    d = np.genfromtxt(elements_csv, delimiter=",", names=True)
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(d["z"] * 1e3, d["potential"], ".", ms=2, alpha=0.4, label="elements")
    rm = row["r_mean"] if row.get("electrodes", "layers") == "layers" else 0.0
    ax.plot([rm * 1e3, (LENGTH - rm) * 1e3], [0, 1], "k-", lw=1, label="uniform field (theory)")
    ax.set_xlabel("z [mm]")
    ax.set_ylabel("potential [V]")
    ax.set_title(f"rod, {row['n']} elements, {row['law']}: R error {row['error_pct']:+.2f} %")
    ax.legend()
    fig.tight_layout()
    fig.savefig(path, dpi=120)
    plt.close(fig)


if __name__ == "__main__":
    main()
