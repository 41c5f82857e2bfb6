"""Bonds and quality figures of a packing (numpy/scipy): YADE's bonding rule applied in numpy,
the detection factor for a wanted coordination, and the statistics paper 000 section 2.1
reports (volume fraction, coordination, neighbour eccentricity).

Units: metres, cubic metres.
"""
from __future__ import annotations

import numpy as np
from scipy.spatial import cKDTree

from ..core.graph import ContactGraph
from ..laws.transmission import eccentricity
from .jamming import max_overlap

__all__ = ["DEFAULT_DETECTION_FACTOR", "bond_pairs", "detection_factor_for_coordination", "packing_statistics"]

DEFAULT_DETECTION_FACTOR = 1.04


def bond_pairs(centers, radii, detection_factor=DEFAULT_DETECTION_FACTOR) -> np.ndarray:
    """Pairs YADE bonds with a given interaction detection factor.

    The rule is YADE's (``Ig2_Sphere_Sphere_ScGeom6D.interactionDetectionFactor``): i and j
    are bonded when ``|x_i - x_j| < k (r_i + r_j)``, i.e. when their gap is below
    ``(k - 1)(r_i + r_j)``, about ``2 (k - 1) r_mean``.

    Returns
    -------
    (m, 2) int array with i < j, sorted.
    """
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    k = float(detection_factor)
    if not k >= 1.0:
        raise ValueError(f"detection_factor must be >= 1, got {k}")
    p = cKDTree(c).query_pairs(2 * r.max() * k, output_type="ndarray")
    if len(p) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    d = np.linalg.norm(c[p[:, 1]] - c[p[:, 0]], axis=1)
    p = np.sort(p[d < k * (r[p[:, 0]] + r[p[:, 1]])], axis=1).astype(np.int64)
    return p[np.lexsort((p[:, 1], p[:, 0]))]


def detection_factor_for_coordination(centers, radii, coordination=6.7, k_max=1.5) -> float:
    """Smallest detection factor giving a mean coordination (2 bonds / n) of at least
    ``coordination`` (bisection on :func:`bond_pairs`)."""
    n = len(radii)
    z = lambda k: 2.0 * len(bond_pairs(centers, radii, k)) / n  # noqa: E731
    lo, hi = 1.0, float(k_max)
    if z(hi) < coordination:
        raise ValueError(f"coordination {coordination} not reached even with detection factor "
                         f"{k_max}; the packing is too loose")
    if z(lo) >= coordination:
        return lo
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if z(mid) < coordination else (lo, mid)
    return hi


def packing_statistics(centers, radii, edges, container_volume, distance_to_surface=None,
                       surface_depth=1.5) -> dict:
    """Quality figures of a bonded packing, to compare with paper 000 section 2.1.

    Parameters
    ----------
    centers : (n, 3) array [m]
    radii : (n,) array [m]
    edges : (m, 2) int array
        Bonded pairs (node indices).
    container_volume : float
        [m^3].
    distance_to_surface : (n,) array or callable, optional
        Distance of each centre to the container boundary [m] (or a function of the
        centres returning it, e.g. ``lambda x: -shape.sdf(x)``). Elements closer than
        ``surface_depth * r_mean`` are "surface" elements (1.5 separates the layer touching
        the wall), the others "core".

    Returns
    -------
    dict
        ``n``, ``r_mean`` [m], ``volume_fraction``, ``n_bonds``, ``mean_coordination``
        (2 m / n), ``coordination_histogram`` (counts of 0, 1, 2, ... bonds),
        ``isolated`` (elements without bond), ``e_below_0.4`` / ``e_above_0.7`` /
        ``e_above_1.2`` (fractions of elements), ``e_mean``, ``max_overlap`` (largest
        ``(r_i + r_j - d_ij) / r_mean`` over all pairs, bonded or not; <= 0: none) and, with
        ``distance_to_surface``, ``surface_fraction``, ``e_below_0.4_core``,
        ``e_below_0.4_surface``, ``mean_coordination_core``/``_surface``.
    """
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    n = r.size
    if c.shape != (n, 3):
        raise ValueError(f"centers must have shape ({n}, 3), got {c.shape}")
    if not container_volume > 0:
        raise ValueError(f"container_volume must be > 0 [m^3], got {container_volume}")
    graph = ContactGraph(c, r, edges)
    e, deg = eccentricity(graph), graph.degree
    r_mean = float(r.mean())
    out = dict(n=int(n), r_mean=r_mean, r_min=float(r.min()), r_max=float(r.max()),
               volume_fraction=float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / container_volume),
               n_bonds=int(len(edges)), mean_coordination=float(deg.mean()),
               coordination_histogram=np.bincount(deg).tolist(), isolated=int(np.sum(deg == 0)),
               e_mean=float(e.mean()))
    out["e_below_0.4"] = float(np.mean(e < 0.4))
    out["e_above_0.7"] = float(np.mean(e > 0.7))
    out["e_above_1.2"] = float(np.mean(e > 1.2))
    out["max_overlap"] = max_overlap(c, r, None) / r_mean
    if distance_to_surface is not None:
        d = distance_to_surface(c) if callable(distance_to_surface) else np.asarray(distance_to_surface)
        surf = d < surface_depth * r_mean
        out["surface_fraction"] = float(surf.mean())
        out["e_below_0.4_core"] = float(np.mean(e[~surf] < 0.4)) if np.any(~surf) else float("nan")
        out["e_below_0.4_surface"] = float(np.mean(e[surf] < 0.4)) if np.any(surf) else float("nan")
        out["mean_coordination_core"] = float(deg[~surf].mean()) if np.any(~surf) else float("nan")
        out["mean_coordination_surface"] = float(deg[surf].mean()) if np.any(surf) else float("nan")
    return out


