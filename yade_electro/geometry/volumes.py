"""The volume of a container: exact for the primitives, else Monte Carlo with a fixed seed.

Units: m^3.
"""
from __future__ import annotations

import numpy as np

from .shapes import as_shape

__all__ = ["container_volume"]


def container_volume(shape, n_samples=4_000_000, seed=20240607) -> tuple:
    """Volume of a container [m^3] and the method used.

    Exact for :class:`Cylinder`, :class:`Box`, :class:`Sphere`. Otherwise Monte Carlo with
    ``n_samples`` uniform points in the bounding box and a fixed ``seed`` (relative standard
    error ``sqrt((1-p)/(p n))`` for an inside fraction ``p``, about 3e-4 for a notched bar).

    Returns
    -------
    (volume, method) : (float, str)
        ``method`` is ``"exact"`` or ``"monte-carlo(n=..., seed=...)"``.
    """
    shape = as_shape(shape)
    v = shape.exact_volume
    if v is not None:
        return float(v), "exact"
    lo, hi = shape.bounds()
    rng = np.random.default_rng(seed)
    hits, done, batch = 0, 0, 500_000
    while done < n_samples:
        m = min(batch, n_samples - done)
        hits += int(np.count_nonzero(shape.sdf(lo + (hi - lo) * rng.random((m, 3))) <= 0))
        done += m
    return float(np.prod(hi - lo) * hits / n_samples), f"monte-carlo(n={n_samples}, seed={seed})"
