"""Radii of a packing: paper 000's eq. 1 mean radius and the uniform size distribution.

Units: metres, cubic metres.
"""
from __future__ import annotations

import numpy as np

__all__ = ["mean_radius_for_count", "uniform_radii"]


def mean_radius_for_count(volume, n, fraction=0.63) -> float:
    """Mean radius [m] giving ``n`` spheres in a container of ``volume`` [m^3] (paper eq. 1).

    ``r_mean = (fraction * V / (4/3 pi n))^(1/3)``; ``fraction`` 0.63 is the random packing
    density of monodisperse spheres.
    """
    volume, n, fraction = float(volume), int(n), float(fraction)
    if not volume > 0:
        raise ValueError(f"volume must be > 0 [m^3], got {volume}")
    if n < 1:
        raise ValueError(f"n must be >= 1, got {n}")
    if not 0 < fraction < 1:
        raise ValueError(f"fraction must be in (0, 1), got {fraction}")
    return (fraction * volume / (4.0 / 3.0 * np.pi * n)) ** (1.0 / 3.0)


def uniform_radii(n, r_mean, dispersion, rng) -> np.ndarray:
    """``n`` radii [m] uniform in ``r_mean * [1 - dispersion/2, 1 + dispersion/2]``, drawn from
    the numpy generator ``rng``."""
    if not 0 <= dispersion < 2:
        raise ValueError(f"dispersion must be in [0, 2), got {dispersion} (0.25 = radii in "
                         "r_mean*[0.875, 1.125])")
    return r_mean * (1.0 + dispersion * (rng.random(n) - 0.5))
