"""The same container packed by YADE and by LIGGGHTS, and the two beds compared.

LIGGGHTS draws spheres of three sizes into an upright cylinder and lets them settle; YADE
settles the same spheres in the same cylinder with the same Hertz-Mindlin contacts and time
step. The beds are then compared figure by figure (volume fractions, coordination, overlaps
and the effective conductivity of their contact network).
Run: ``yade-electro -n -x examples/packing_cross_check.py`` (Debian's LIGGGHTS on the PATH).
"""
import json

import numpy as np

from yade_electro import liggghts as L
from yade_electro.packing.beds import bed_statistics, compare_beds
from yade_electro.yade.settling import settle_in_cylinder

N, RADIUS = 300, 6e-3                                   # spheres, cylinder radius [m]
SIZES, FRACTIONS = (0.8e-3, 1.0e-3, 1.2e-3), (1 / 3, 1 / 3, 1 / 3)    # radii [m], mass fractions
grains = L.GranularMaterial(young=5e6, poisson=0.3, density=2500.0, restitution=0.5, friction=0.5)
dt = 0.5 * min(SIZES) * np.sqrt(grains.density / grains.young)          # s
region = L.CylinderRegion(RADIUS - 1.3e-3, 1.3e-3, 0.07)                 # where the spheres start
box = [[-RADIUS - 2e-3, RADIUS + 2e-3]] * 2 + [[-2e-3, 0.075]]           # LIGGGHTS' domain [m]

lig = L.settle_packing([L.CylinderWall("z", RADIUS), L.PlaneWall("z", 0.0)], region, N, SIZES, FRACTIONS, grains,
                       box, dt, "out/packing_cross_check", settle_time=1.0, ke_threshold=1e-9)
yade = settle_in_cylinder(lig.radii, RADIUS, region, grains, dt, settle_time=1.0, ke_threshold=1e-9)

a, b = bed_statistics(lig.centers, lig.radii, RADIUS), bed_statistics(yade.centers, yade.radii, RADIUS)
cmp = compare_beds(a, b)
print(f"{'figure':28s} {'LIGGGHTS':>10s} {'YADE':>10s} {'YADE/LIGGGHTS-1':>16s}")
for key in ("n", "bed_height_m", "volume_fraction", "coordination", "overlap_mean", "k_eff_over_k"):
    print(f"{key:28s} {a[key]:10.4g} {b[key]:10.4g} {100 * cmp['relative_difference'][key]:+15.1f}%")
print(f"overlaps, Kolmogorov-Smirnov p = {cmp['ks_pvalue']:.3g}")
print(json.dumps({"example": "packing_cross_check", "n": int(a["n"]), "settled": [bool(lig.settled), yade.settled],
                  "liggghts": {k: float(a[k]) for k in ("bed_height_m", "volume_fraction", "coordination")},
                  "yade": {k: float(b[k]) for k in ("bed_height_m", "volume_fraction", "coordination")},
                  "relative_difference": cmp["relative_difference"], "ks_pvalue": cmp["ks_pvalue"]}))
