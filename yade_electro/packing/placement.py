"""Random sequential placement of spheres in a region, with no overlap (numpy only).

Units: m.
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["random_placement_in_cylinder"]


def random_placement_in_cylinder(radii, radius: float, z_low: float, z_high: float, seed: int = 1,
                                 max_tries: int = 20000, center=(0.0, 0.0)) -> np.ndarray:
    """Centres (n, 3) [m] for spheres of ``radii`` [m] placed at random, larger first, inside an
    upright cylinder of ``radius`` about ``center`` (x, y) between ``z_low`` and ``z_high``,
    with no two overlapping (random sequential addition, cell lists of the largest diameter).

    Raises
    ------
    RuntimeError
        A sphere found no room after ``max_tries`` tries: make the region larger.
    """
    radii = np.asarray(radii, dtype=float).reshape(-1)
    rng = np.random.default_rng(seed)
    order = np.argsort(-radii, kind="stable")
    cell = 2.0 * float(radii.max())
    grid, placed = {}, np.zeros((radii.size, 3))
    shifts = [(dx, dy, dz) for dx in (-1, 0, 1) for dy in (-1, 0, 1) for dz in (-1, 0, 1)]

    def free(p, r, key):
        """No placed sphere in the 27 cells around ``key`` overlaps a sphere r at p."""
        return not any(np.sum((placed[j] - p) ** 2) < (r + radii[j]) ** 2
                       for dx, dy, dz in shifts for j in grid.get((key[0] + dx, key[1] + dy, key[2] + dz), ()))

    for k in order:
        r = radii[k]
        for _ in range(max_tries):
            rho = (radius - r) * math.sqrt(rng.random())
            ang = 2.0 * math.pi * rng.random()
            p = np.array([center[0] + rho * math.cos(ang), center[1] + rho * math.sin(ang),
                          rng.uniform(z_low + r, z_high - r)])
            key = tuple((p // cell).astype(int))
            if free(p, r, key):
                placed[k] = p
                grid.setdefault(key, []).append(k)
                break
        else:
            raise RuntimeError(f"no room for sphere {k} (r = {r}) after {max_tries} tries: make the region taller")
    return placed
