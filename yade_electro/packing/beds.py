"""Figures of a granular bed settled in an upright cylinder, to compare packings made by two
engines (numpy/scipy only).

A bed is the centres and radii of spheres resting on a floor at ``floor`` [m] inside a
cylinder of radius ``R`` [m] along z through (0, 0). Its height is H = 2 mean(z - floor)
(exact for a bed of uniform density; the figures that matter use the core, away from floor
and top). Volume fractions of a region are measured by Monte Carlo: the fraction of
``samples`` uniform points of the region inside a sphere (standard error sqrt(phi (1 - phi)
/ samples), 1e-3 for 2e5 points).

Regions, with d the mean diameter: core = distance to the wall > 2 d and 2 d < z - floor
< H - 2 d; near the wall = the same heights within one d of the wall.
"""
from __future__ import annotations

from typing import Optional

import numpy as np
from scipy.spatial import cKDTree

__all__ = ["bed_statistics", "compare_beds", "contact_pairs", "volume_fraction_samples", "SCALARS"]

#: the scalar figures compared between two beds
SCALARS = ("n", "bed_height_m", "volume_fraction", "volume_fraction_core", "volume_fraction_wall",
           "coordination", "coordination_core", "overlap_mean", "overlap_median", "k_eff_over_k")


def contact_pairs(centers, radii) -> np.ndarray:
    """Index pairs (m, 2) of the spheres that overlap (d_ij < r_i + r_j): the bond rule with
    detection factor 1."""
    from .statistics import bond_pairs
    return bond_pairs(centers, radii, detection_factor=1.0)


def volume_fraction_samples(centers, radii, points, k: int = 12) -> np.ndarray:
    """True for each point inside at least one sphere (the ``k`` nearest centres within the
    largest radius are tested; points with ``k`` such centres are tested against all)."""
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    tree = cKDTree(c)
    r_max = float(r.max())
    dist, nb = tree.query(pts, k=k, distance_upper_bound=r_max)
    found = np.isfinite(dist)
    nb_safe = np.where(found, nb, 0)
    inside = np.any(found & (dist < r[nb_safe]), axis=1)
    crowded = np.flatnonzero(found[:, -1])
    for q in crowded:                    # more than k centres within r_max: test them all
        cand = np.asarray(tree.query_ball_point(pts[q], r_max))
        inside[q] = bool(np.any(np.sum((c[cand] - pts[q]) ** 2, axis=1) < r[cand] ** 2))
    return inside


def _cylinder_points(rng, n, r_lo, r_hi, z_lo, z_hi):
    rho = np.sqrt(rng.uniform(r_lo ** 2, r_hi ** 2, n))
    phi = rng.uniform(0.0, 2.0 * np.pi, n)
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), rng.uniform(z_lo, z_hi, n)])


def bed_statistics(centers, radii, cylinder_radius: float, floor: float = 0.0, conductivity: float = 1.0,
                   law="liggghts", samples: int = 200_000, profile_bins: int = 50, profile_depth: float = 5.0,
                   seed: int = 0, law_params: Optional[dict] = None) -> dict:
    """Figures of a bed (see the module docstring for the regions).

    Returns a dict with ``n``, ``d_mean`` [m], ``bed_height_m``, ``volume_fraction``
    (sum of sphere volumes / (pi R^2 H)), ``volume_fraction_core``, ``volume_fraction_wall``
    (Monte Carlo), ``coordination`` (2 contacts / n over every sphere), ``coordination_core``
    (spheres whose centre is in the core), ``overlaps`` (the array of delta / (r_i + r_j) of
    every contact), ``overlap_mean``, ``overlap_median``, ``overlap_profile_mean`` (mean
    overlap of the contacts in ten height bins, at ``overlap_profile_z_over_H``), the radial
    profile
    ``profile_s_over_d`` / ``profile_phi`` (local volume fraction against the distance s to
    the wall, in ``profile_bins`` bins up to ``profile_depth`` d or the axis, over the core
    heights),
    ``first_peak_s_over_d`` (the s of the profile's highest value within 1 d) and
    ``k_eff_over_k``: the effective conductivity along z of the core heights with the
    contact ``law`` (each contact conducts k g_ij), between the spheres within one d of
    the core's bottom and of its top, over the cross-section pi R^2, divided by ``k``.
    """
    from ..laws.factors import make_law
    from ..core.graph import ContactGraph
    from ..network.conduction import equivalent_resistance
    c = np.asarray(centers, dtype=float).reshape(-1, 3)
    r = np.asarray(radii, dtype=float).reshape(-1)
    R = float(cylinder_radius)
    if c.shape[0] != r.size or r.size < 2:
        raise ValueError("give at least two spheres, one radius per centre")
    z = c[:, 2] - floor
    d = 2.0 * float(r.mean())
    H = 2.0 * float(z.mean())
    if H < 6.0 * d:
        raise ValueError(f"the bed is {H / d:.1f} diameters high: at least 6 are needed for a core")
    rng = np.random.default_rng(seed)
    out = {"n": int(r.size), "d_mean": d, "bed_height_m": H,
           "volume_fraction": float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / (np.pi * R ** 2 * H))}
    z_lo, z_hi = floor + 2.0 * d, floor + H - 2.0 * d
    for name, (a, b) in (("core", (0.0, R - 2.0 * d)), ("wall", (R - d, R))):
        pts = _cylinder_points(rng, samples, a, b, z_lo, z_hi)
        out[f"volume_fraction_{name}"] = float(volume_fraction_samples(c, r, pts).mean())
    pairs = contact_pairs(c, r)
    deg = np.bincount(pairs.ravel(), minlength=r.size)
    rho = np.hypot(c[:, 0], c[:, 1])
    core = (rho < R - 2.0 * d) & (c[:, 2] > z_lo) & (c[:, 2] < z_hi)
    out["contacts"] = int(len(pairs))
    out["coordination"] = float(2.0 * len(pairs) / r.size)
    out["coordination_core"] = float(deg[core].mean()) if core.any() else float("nan")
    dist = np.linalg.norm(c[pairs[:, 0]] - c[pairs[:, 1]], axis=1)
    rs = r[pairs[:, 0]] + r[pairs[:, 1]]
    ov = (rs - dist) / rs
    out["overlaps"] = ov
    out["overlap_mean"] = float(ov.mean()) if ov.size else 0.0
    out["overlap_median"] = float(np.median(ov)) if ov.size else 0.0
    # overlap against height: it follows the load the contacts carry (weight minus wall friction)
    zc = 0.5 * (c[pairs[:, 0], 2] + c[pairs[:, 1], 2]) - floor
    hb = np.linspace(0.0, H, 11)
    kb = np.clip(np.digitize(zc, hb) - 1, 0, 9)
    nb = np.bincount(kb, minlength=10)
    with np.errstate(invalid="ignore", divide="ignore"):
        out["overlap_profile_mean"] = np.bincount(kb, weights=ov, minlength=10) / nb
    out["overlap_profile_z_over_H"] = 0.5 * (hb[1:] + hb[:-1]) / H
    profile_depth = min(float(profile_depth), R / d)      # no deeper than the axis
    depth = profile_depth * d
    pts = _cylinder_points(rng, 4 * samples, max(R - depth, 0.0), R, z_lo, z_hi)
    inside = volume_fraction_samples(c, r, pts)
    s = (R - np.hypot(pts[:, 0], pts[:, 1])) / d
    edges = np.linspace(0.0, profile_depth, profile_bins + 1)
    k = np.clip(np.digitize(s, edges) - 1, 0, profile_bins - 1)
    counts = np.bincount(k, minlength=profile_bins)
    with np.errstate(invalid="ignore", divide="ignore"):     # a bin without sample points: NaN
        phi = np.bincount(k, weights=inside, minlength=profile_bins) / counts
    mid = 0.5 * (edges[1:] + edges[:-1])
    out["profile_s_over_d"], out["profile_phi"] = mid, phi
    near = mid < 1.0
    out["first_peak_s_over_d"] = float(mid[near][np.nanargmax(phi[near])])
    # effective conductivity of the core heights
    band = (c[:, 2] > z_lo) & (c[:, 2] < z_hi)
    idx = np.flatnonzero(band)
    keep = band[pairs[:, 0]] & band[pairs[:, 1]]
    remap = -np.ones(r.size, dtype=np.int64)
    remap[idx] = np.arange(idx.size)
    e = remap[pairs[keep]]
    graph = ContactGraph(c[idx], r[idx], e)
    G = conductivity * make_law(law, **(law_params or {})).factor(graph)
    zz = c[idx, 2]
    bottom, top = np.flatnonzero(zz < z_lo + d), np.flatnonzero(zz > z_hi - d)
    R_th = equivalent_resistance(idx.size, e, G, bottom, top)
    length = float(zz[top].mean() - zz[bottom].mean())
    out["k_eff_over_k"] = float(length / (R_th * np.pi * R ** 2) / conductivity)
    return out


def compare_beds(a: dict, b: dict, alpha: float = 0.05) -> dict:
    """Compare two :func:`bed_statistics`: each scalar of :data:`SCALARS` with b / a - 1, and
    the overlap distributions by the two-sample Kolmogorov-Smirnov test (``ks_statistic``,
    ``ks_pvalue``, ``overlaps_differ`` = p < ``alpha``: the two samples are unlikely to come
    from one distribution)."""
    from scipy.stats import ks_2samp
    rel = {k: (float(b[k]) / float(a[k]) - 1.0 if float(a[k]) != 0 else float("nan")) for k in SCALARS}
    ks = ks_2samp(a["overlaps"], b["overlaps"])
    return {"relative_difference": rel, "ks_statistic": float(ks.statistic), "ks_pvalue": float(ks.pvalue),
            "overlaps_differ": bool(ks.pvalue < alpha), "alpha": alpha}
