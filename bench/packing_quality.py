"""Quality and cost of the dense packing recipe on the paper's rod (paper 000, section 3.1).

Rod: radius 1 mm, length 5 mm along z. For every N: placement (numpy/scipy, cached),
statistics of the bonds YADE would create for several detection factors, and, when YADE is
available (``yade-electro -n -x`` or /usr/bin/python3 with the Debian package), the real bonding
with :func:`add_bonded_packing` to check that YADE creates exactly those bonds.

Usage::

    yade-electro -n -x bench/packing_quality.py --n 5000
    /usr/bin/python3 bench/packing_quality.py --n 1000 2000 5000 --plots docs/img --no-cache

Prints a table and one JSON line (prefix ``JSON``) with all figures.
"""
import argparse
import json
import os
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.dirname(HERE))
if "/usr/lib/x86_64-linux-gnu/yade-double/py" not in sys.path:
    sys.path.append("/usr/lib/x86_64-linux-gnu/yade-double/py")

import numpy as np  # noqa: E402

from yade_electro.yade import packing as P  # noqa: E402

PAPER = {"volume_fraction": 0.63, "mean_coordination": 6.7, "e_below_0.4": 0.67}


def have_yade():
    try:
        import yade  # noqa: F401
        return True
    except Exception:
        return False


def yade_bond_check(pk, k):
    """Bond with real YADE; return (bonds, equal to numpy rule, seconds, max displacement
    after 100 steps / r_mean)."""
    import yade
    O = yade.Omega()
    O.reset()
    t = time.perf_counter()
    ids = P.add_bonded_packing(pk, detection_factor=k)
    dt = time.perf_counter() - t
    pairs = {tuple(sorted((i.id1, i.id2))) for i in O.interactions if i.isReal}
    ids = np.asarray(ids)
    ref = {tuple(sorted(p)) for p in ids[P.bond_pairs(pk.centers, pk.radii, k)].tolist()}
    coh = all((not i.phys.cohesionBroken) for i in O.interactions if i.isReal)
    O.run(100, True)
    pos = np.array([O.bodies[int(i)].state.pos for i in ids])
    disp = float(np.abs(pos - pk.centers).max() / pk.r_mean)
    O.reset()
    return dict(yade_bonds=len(pairs), yade_equal_numpy=(pairs == ref), yade_cohesive=coh,
                yade_bond_time_s=dt, yade_max_disp_100_steps=disp)


def plots(pk, k, outdir):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    edges = P.bond_pairs(pk.centers, pk.radii, k)
    from yade_electro.core.graph import ContactGraph
    from yade_electro.laws.transmission import eccentricity
    graph = ContactGraph(pk.centers, pk.radii, edges)
    e, deg = eccentricity(graph), graph.degree
    os.makedirs(outdir, exist_ok=True)
    tag = f"rod{pk.n}"
    fig, ax = plt.subplots(figsize=(5, 3.5))
    bins = np.arange(deg.max() + 2) - 0.5
    ax.hist(deg, bins=bins, color="tab:blue", edgecolor="k")
    ax.set_xlabel("number of bonded neighbours")
    ax.set_ylabel("number of elements")
    ax.set_title(f"{pk.n}-element rod, k={k}: mean {deg.mean():.2f} (paper 6.7)")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, f"{tag}_neighbours.png"), dpi=110)
    plt.close(fig)
    fig, ax = plt.subplots(figsize=(5, 3.5))
    ax.hist(e, bins=np.arange(0, 2.0001, 0.05), color="tab:orange", edgecolor="k")
    for x in (0.4, 0.7, 1.2):
        ax.axvline(x, color="k", ls="--", lw=0.8)
    ax.set_xlabel("eccentricity e")
    ax.set_ylabel("number of elements")
    ax.set_title(f"{pk.n}-element rod: e<0.4 for {np.mean(e < 0.4):.0%} (paper 67%)")
    fig.tight_layout()
    fig.savefig(os.path.join(outdir, f"{tag}_eccentricity.png"), dpi=110)
    plt.close(fig)


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--n", type=int, nargs="+", default=[5000])
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--k", type=float, default=P.DEFAULT_DETECTION_FACTOR,
                    help="detection factor of the headline row")
    ap.add_argument("--k-scan", type=float, nargs="*", default=[1.005, 1.01, 1.02, 1.03, 1.04, 1.05, 1.07, 1.1])
    ap.add_argument("--method", default="jam", choices=["jam", "target"])
    ap.add_argument("--no-cache", action="store_true", help="regenerate (measures the time)")
    ap.add_argument("--no-yade", action="store_true", help="skip the real YADE bonding")
    ap.add_argument("--plots", default=None, help="directory for the PNG histograms")
    a = ap.parse_args(argv)
    shape = P.Cylinder((0, 0, 0), (0, 0, 5e-3), 1e-3)
    use_yade = (not a.no_yade) and have_yade()
    rows = []
    for n in a.n:
        pk = P.dense_packing(shape, n=n, seed=a.seed, method=a.method,
                             cache_dir=False if a.no_cache else None)
        scan = []
        for k in sorted(set(a.k_scan) | {a.k}):
            st = P.packing_statistics(pk.centers, pk.radii, P.bond_pairs(pk.centers, pk.radii, k),
                                      pk.container_volume, pk.distance_to_surface)
            scan.append(dict(k=k, z=st["mean_coordination"], e04=st["e_below_0.4"],
                             e04_core=st["e_below_0.4_core"], e04_surf=st["e_below_0.4_surface"]))
            if k == a.k:
                head = st
        row = dict(n=pk.n, seed=a.seed, method=a.method, r_mean=pk.r_mean,
                   r_mean_eq1=pk.r_mean_requested, volume_fraction=pk.volume_fraction,
                   max_overlap=pk.max_overlap, time_s=pk.time_s, from_cache=pk.from_cache,
                   fire_steps=pk.params.get("fire_steps"), k=a.k,
                   mean_coordination=head["mean_coordination"],
                   coordination_histogram=head["coordination_histogram"],
                   isolated=head["isolated"],
                   e_below_04=head["e_below_0.4"], e_below_04_core=head["e_below_0.4_core"],
                   e_below_04_surface=head["e_below_0.4_surface"],
                   e_above_07=head["e_above_0.7"], e_above_12=head["e_above_1.2"],
                   surface_fraction=head["surface_fraction"], k_scan=scan)
        if use_yade:
            row.update(yade_bond_check(pk, a.k))
        if a.plots:
            plots(pk, a.k, a.plots)
        rows.append(row)

    print(f"rod R=1 mm L=5 mm, seed {a.seed}, method {a.method}, detection factor {a.k}")
    print(f"{'N':>6} {'phi':>6} {'z':>5} {'e<0.4':>6} {'core':>5} {'surf':>5} {'e>0.7':>6} "
          f"{'maxov/r':>9} {'time s':>7} {'yade=np':>7}")
    for r in rows:
        print(f"{r['n']:6d} {r['volume_fraction']:6.3f} {r['mean_coordination']:5.2f} "
              f"{r['e_below_04']:6.3f} {r['e_below_04_core']:5.2f} {r['e_below_04_surface']:5.2f} "
              f"{r['e_above_07']:6.3f} {r['max_overlap']:9.2e} {r['time_s']:7.1f}"
              f"{'*' if r['from_cache'] else ' '} {str(r.get('yade_equal_numpy', '-')):>7}")
    print(f"{'paper':>6} {PAPER['volume_fraction']:6.3f} {PAPER['mean_coordination']:5.2f} "
          f"{PAPER['e_below_0.4']:6.3f}   (* = read from cache, time of the original run)")
    print("coordination / e<0.4 vs detection factor k (bond if d < k (r_i + r_j)):")
    for r in rows:
        print(f"  N={r['n']}: " + "  ".join(f"k={s['k']:.3f}: z={s['z']:.2f} e<.4={s['e04']:.2f}"
                                            for s in r["k_scan"]))
    print("JSON " + json.dumps(dict(bench="packing_quality", paper=PAPER, rows=rows)))


if __name__ == "__main__":
    main(sys.argv[1:] if "yade" not in os.path.basename(sys.argv[0]) else
         [x for x in sys.argv[1:] if x != os.path.abspath(__file__)])
