"""Two packings of one container, one made by each engine, compared: LIGGGHTS 3.8.0 and YADE
settle the same spheres under gravity in the same cylinder.

Container: an upright cylinder of radius R = 12.5 mm on a floor at z = 0. Spheres: three size
classes, r = 0.8, 1.0, 1.2 mm in equal mass fractions; LIGGGHTS draws about ``n`` of them
(``settle`` template: ``insert/pack`` in the cylinder above the floor, then ``nve/sphere``)
and YADE gets the same radii (the same multiset), placed at random without overlap in the
same insertion region (random sequential addition). Material, the same in both: Y = 5 MPa
(the softened stiffness LIGGGHTS users take), nu = 0.3, rho = 2500 kg/m^3, restitution 0.5,
friction 0.5, no rolling friction; the same contact model (Hertz-Mindlin: LIGGGHTS ``gran
model hertz tangential history``, YADE ``MindlinPhys`` with ``en = es = 0.5``), no numerical
damping, the same time step (half of r_min sqrt(rho / Y)). Walls: LIGGGHTS' primitive
``zcylinder`` and ``zplane``; YADE a 96-facet ``facetCylinder`` and a ``Wall``. Both run
until the kinetic energy per particle is below ``ke_threshold`` (checked every 0.05 s).

Figures of each bed (``yade_electro.packing.beds``): count, height, volume fraction (global,
core, near the wall), coordination number (all, core), contact overlaps delta / (r_i + r_j)
(with the two-sample Kolmogorov-Smirnov test), the radial volume-fraction profile near the
wall and the effective conductivity k_eff / k of the core heights along z with the
``liggghts`` law. One table on stdout, one PNG.

Run
---
    yade-electro -n -x cases/cross_engine_packing.py              # about 5,000 spheres
    yade-electro -n -x cases/cross_engine_packing.py --n 400 --radius 0.006

Ends with one JSON line ``{"case": "cross_engine_packing", "n": ..., "liggghts": {...},
"yade": {...}, "relative_difference": {...}, "ks_pvalue": ..., "overlaps_differ": ...}``.
"""
from __future__ import annotations

import argparse
import json
import math
import os
import sys
import time

import numpy as np

_SCRIPT = __file__ if __file__.endswith("cross_engine_packing.py") else (
    sys.argv[0] if sys.argv and sys.argv[0].endswith("cross_engine_packing.py") else __file__)
HERE = os.path.dirname(os.path.abspath(_SCRIPT))
for _p in (os.path.dirname(HERE), HERE):
    if _p not in sys.path:        # run from a checkout without installing
        sys.path.insert(0, _p)

SIZE_CLASSES = (0.8e-3, 1.0e-3, 1.2e-3)     # m
MASS_FRACTIONS = (1 / 3, 1 / 3, 1 / 3)
MATERIAL = dict(young=5e6, poisson=0.3, density=2500.0, restitution=0.5, friction=0.5)
CONDUCTIVITY = 1.0                           # W/(m K): k_eff is reported as k_eff / k


def geometry(n, radius):
    """Insertion region and simulation box for ``n`` spheres in a cylinder of ``radius``: a
    region loose enough (volume fraction 0.3) that random placement succeeds."""
    from yade_electro.liggghts import CylinderRegion
    r = np.asarray(SIZE_CLASSES)
    w = np.asarray(MASS_FRACTIONS) / r ** 3            # number weights of the classes
    v_mean = float(np.sum(w * 4.0 / 3.0 * np.pi * r ** 3) / w.sum())
    r_max = float(r.max())
    inner = radius - 1.05 * r_max
    height = n * v_mean / (0.30 * np.pi * inner ** 2)
    region = CylinderRegion(inner, 1.05 * r_max, 1.05 * r_max + height)
    box = [[-radius - 2e-3, radius + 2e-3]] * 2 + [[-2e-3, region.z_high + 5e-3]]
    return region, box


def time_step():
    return 0.5 * min(SIZE_CLASSES) * math.sqrt(MATERIAL["density"] / MATERIAL["young"])


def liggghts_bed(n, radius, workdir, ke_threshold, settle_time, seed=32452843):
    from yade_electro import liggghts as L
    mat = L.GranularMaterial(**MATERIAL)
    region, box = geometry(n, radius)
    walls = [L.CylinderWall("z", radius), L.PlaneWall("z", 0.0)]
    t0 = time.perf_counter()
    p = L.settle_packing(walls, region, n, SIZE_CLASSES, MASS_FRACTIONS, mat, box, time_step(), workdir,
                         settle_time=settle_time, ke_threshold=ke_threshold, seed=seed)
    return p, {"wall_s": time.perf_counter() - t0, "settled": bool(p.settled), "time_s": p.time,
               "ke_per_particle_J": p.ke_per_particle, "steps": p.step}


def yade_bed(radii, radius, ke_threshold, settle_time, seed=1):
    """Settle ``radii`` in YADE (:func:`yade_electro.yade.settling.settle_in_cylinder`); returns
    (centres, radii, figures)."""
    from yade_electro import liggghts as L
    from yade_electro.yade.settling import settle_in_cylinder
    region, _ = geometry(radii.size, radius)
    bed = settle_in_cylinder(radii, radius, region, L.GranularMaterial(**MATERIAL), time_step(),
                             settle_time=settle_time, ke_threshold=ke_threshold, seed=seed)
    figs = {"wall_s": bed.wall_s, "settled": bed.settled, "time_s": bed.time, "ke_per_particle_J": bed.ke_per_particle,
            "steps": bed.steps, "lost": bed.lost}
    return bed.centers, bed.radii, figs


TABLE = (("n", "spheres", "{:.0f}"), ("bed_height_m", "bed height [mm]", "{:.2f}", 1e3),
         ("volume_fraction", "volume fraction, global", "{:.4f}"),
         ("volume_fraction_core", "volume fraction, core", "{:.4f}"),
         ("volume_fraction_wall", "volume fraction, within 1 d of the wall", "{:.4f}"),
         ("coordination", "coordination number, all", "{:.3f}"),
         ("coordination_core", "coordination number, core", "{:.3f}"),
         ("overlap_mean", "mean overlap delta/(r1+r2) [1e-3]", "{:.4f}", 1e3),
         ("overlap_median", "median overlap delta/(r1+r2) [1e-3]", "{:.4f}", 1e3),
         ("first_peak_s_over_d", "wall layer: first peak at s/d", "{:.2f}"),
         ("k_eff_over_k", "k_eff / k (liggghts law, core)", "{:.5f}"))


def table(a, b, cmp):
    lines = ["| figure | LIGGGHTS | YADE | YADE / LIGGGHTS - 1 |", "| --- | --- | --- | --- |"]
    for row in TABLE:
        key, label, fmt = row[:3]
        scale = row[3] if len(row) > 3 else 1.0
        rel = cmp["relative_difference"].get(key)
        rel_s = f"{100 * rel:+.1f} %" if rel is not None and np.isfinite(rel) else "-"
        lines.append(f"| {label} | {fmt.format(a[key] * scale)} | {fmt.format(b[key] * scale)} | {rel_s} |")
    verdict = "differ" if cmp["overlaps_differ"] else "do not differ"
    lines.append(f"| overlaps, Kolmogorov-Smirnov | D = {cmp['ks_statistic']:.3f} | p = {cmp['ks_pvalue']:.2g} | "
                 f"{verdict} at {100 * cmp['alpha']:.0f} % |")
    return "\n".join(lines)


def plot(a, b, cmp, path):
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    fig, axes = plt.subplots(1, 4, figsize=(18, 4))
    ax = axes[0]
    for st, lab, st_ in ((a, "LIGGGHTS", "k-"), (b, "YADE", "b-")):
        ov = np.sort(st["overlaps"]) * 1e3
        ax.plot(ov, np.arange(1, ov.size + 1) / ov.size, st_, label=f"{lab} ({ov.size} contacts)")
    ax.set_xlabel("overlap delta / (r1 + r2) [1e-3]")
    ax.set_ylabel("cumulative fraction")
    ax.set_title(f"contact overlaps: KS p = {cmp['ks_pvalue']:.2g}")
    ax.legend(fontsize=8)
    ax = axes[1]
    for st, lab, st_ in ((a, "LIGGGHTS", "k-"), (b, "YADE", "b-")):
        ax.plot(st["profile_s_over_d"], st["profile_phi"], st_, label=lab)
    ax.set_xlabel("distance to the wall s / d")
    ax.set_ylabel("local volume fraction")
    ax.set_title("radial wall layering (core heights)")
    ax.legend(fontsize=8)
    ax = axes[2]
    for st, lab, st_ in ((a, "LIGGGHTS", "ks-"), (b, "YADE", "bo-")):
        ax.plot(st["overlap_profile_mean"] * 1e3, st["overlap_profile_z_over_H"], st_, ms=4, label=lab)
    ax.set_xlabel("mean overlap delta / (r1 + r2) [1e-3]")
    ax.set_ylabel("height z / H")
    ax.set_title("overlap against height (the load)")
    ax.legend(fontsize=8)
    ax = axes[3]
    keys = ["volume_fraction", "volume_fraction_core", "volume_fraction_wall", "coordination_core",
            "overlap_mean", "k_eff_over_k"]
    rel = [100 * cmp["relative_difference"][k] for k in keys]
    ax.barh(range(len(keys)), rel, color=["C0" if abs(x) < 5 else "C3" for x in rel])
    ax.set_yticks(range(len(keys)))
    ax.set_yticklabels(keys, fontsize=8)
    ax.axvline(0, color="k", lw=0.8)
    ax.set_xlabel("YADE / LIGGGHTS - 1 [%]")
    ax.set_title("same container, same spheres")
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)
    return path


def run(n=5000, radius=0.0125, out="out/cross_engine_packing", ke_threshold=1e-10, settle_time=3.0, seed=1,
        reuse=False):
    """Both packings (made again, or with ``reuse`` read from the last run's
    ``packings_n<n>.npz``), their figures and the comparison."""
    from yade_electro.packing.beds import bed_statistics, compare_beds
    os.makedirs(out, exist_ok=True)
    saved = os.path.join(out, f"packings_n{n}.npz")
    if reuse and os.path.exists(saved):
        z = np.load(saved, allow_pickle=False)
        lig_c, lig_r, pos, rad = z["liggghts_centers"], z["liggghts_radii"], z["yade_centers"], z["yade_radii"]
        lig_figs, yade_figs = json.loads(str(z["liggghts_settle"])), json.loads(str(z["yade_settle"]))
        print(f"packings read from {saved}", flush=True)
    else:
        lig, lig_figs = liggghts_bed(n, radius, os.path.join(out, "liggghts"), ke_threshold, settle_time)
        print(f"LIGGGHTS: {lig.n} spheres settled in {lig_figs['time_s']:.2f} s simulated, {lig_figs['wall_s']:.0f} s "
              "wall", flush=True)
        lig_c, lig_r = lig.centers, lig.radii
        radii = np.random.default_rng(seed).permutation(lig_r)
        pos, rad, yade_figs = yade_bed(radii, radius, ke_threshold, settle_time, seed)
        print(f"YADE: {rad.size} spheres settled in {yade_figs['time_s']:.2f} s simulated, {yade_figs['wall_s']:.0f} s "
              "wall", flush=True)
        np.savez(saved, liggghts_centers=lig_c, liggghts_radii=lig_r, yade_centers=pos, yade_radii=rad,
                 liggghts_settle=json.dumps(lig_figs), yade_settle=json.dumps(yade_figs))
    a = bed_statistics(lig_c, lig_r, radius, conductivity=CONDUCTIVITY)
    b = bed_statistics(pos, rad, radius, conductivity=CONDUCTIVITY)
    cmp = compare_beds(a, b)
    print(table(a, b, cmp), flush=True)
    png = plot(a, b, cmp, os.path.join(out, f"cross_engine_packing_n{n}.png"))

    def scalars(st, figs):
        return {**{k: v for k, v in st.items() if np.ndim(v) == 0}, "settle": figs}

    res = {"case": "cross_engine_packing", "n": int(lig_r.size), "cylinder_radius_m": radius,
           "size_classes_m": list(SIZE_CLASSES), "mass_fractions": list(MASS_FRACTIONS), "material": MATERIAL,
           "time_step_s": time_step(), "liggghts": scalars(a, lig_figs), "yade": scalars(b, yade_figs),
           "relative_difference": cmp["relative_difference"], "ks_statistic": cmp["ks_statistic"],
           "ks_pvalue": cmp["ks_pvalue"], "overlaps_differ": cmp["overlaps_differ"],
           "profile_s_over_d": a["profile_s_over_d"].tolist(), "profile_phi_liggghts": a["profile_phi"].tolist(),
           "profile_phi_yade": b["profile_phi"].tolist(),
           "overlap_profile_z_over_H": a["overlap_profile_z_over_H"].tolist(),
           "overlap_profile_liggghts": a["overlap_profile_mean"].tolist(),
           "overlap_profile_yade": b["overlap_profile_mean"].tolist(), "png": png}
    with open(os.path.join(out, f"cross_engine_packing_n{n}.json"), "w") as fh:
        json.dump(res, fh)
    return res


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--n", type=int, default=5000)
    ap.add_argument("--radius", type=float, default=0.0125, help="cylinder radius [m]")
    ap.add_argument("--ke-threshold", type=float, default=1e-10, help="settled below this kinetic energy [J/particle]")
    ap.add_argument("--settle-time", type=float, default=3.0, help="at most this simulated time [s]")
    ap.add_argument("--out", default="out/cross_engine_packing")
    ap.add_argument("--reuse", action="store_true", help="compare the packings of the last run again (no settling)")
    args = ap.parse_args(sys.argv[1:] if argv is None else argv)
    res = run(args.n, args.radius, args.out, args.ke_threshold, args.settle_time, reuse=args.reuse)
    print(json.dumps(res))
    return res


if __name__ == "__main__":
    main()
