"""Graded packings: smaller elements where the field needs them (a ligament, a notch root),
the same number of elements in all (numpy only, no YADE).

A :class:`Refinement` gives each point of the container a relative size in ``[factor, 1]``;
:func:`graded_cloud` draws the initial centres with a number density proportional to
``size^-3`` (so that every region is filled alike) and the radii in proportion to the size at
each centre. :func:`yade_electro.packing.dense.dense_packing` then jams them as it jams a
uniform cloud: the spheres move by less than a radius, so each keeps the size of its place.

Units: SI (m).
"""
from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Refinement", "graded_cloud"]


@dataclass(frozen=True)
class Refinement:
    """Smaller elements inside ``region``: radius ``factor`` times the others' inside it, back
    to the full size over ``width`` [m] outside it (linear in the distance to the region).

    Parameters
    ----------
    region : Shape
        Where the elements are small, e.g. ``Box(...)`` around a ligament (any shape of
        :mod:`yade_electro.geometry.shapes`: its signed distance decides).
    factor : float in (0, 1]
        The radius there over the radius far from it (0.75: 2.4 times the number density).
    width : float
        Distance [m] over which the size grows back to 1 (>= 0; 0: a step).

    Raises
    ------
    ValueError
        A region without a signed distance, a factor outside (0, 1], a negative or
        non-finite width.
    """

    region: object
    factor: float
    width: float = 0.0

    def __post_init__(self):
        if not (hasattr(self.region, "sdf") and hasattr(self.region, "key")):
            raise ValueError(f"Refinement region must be a shape of yade_electro.geometry.shapes (Box, Cylinder, "
                             f"...), got {self.region!r}")
        f = float(self.factor)
        if not (math.isfinite(f) and 0.0 < f <= 1.0):
            raise ValueError(f"Refinement factor must be in (0, 1] (the radius inside the region over the radius "
                             f"far from it), got {self.factor!r}")
        w = float(self.width)
        if not (math.isfinite(w) and w >= 0.0):
            raise ValueError(f"Refinement width must be a finite distance >= 0 [m], got {self.width!r}")
        object.__setattr__(self, "factor", f)
        object.__setattr__(self, "width", w)

    def size(self, points) -> np.ndarray:
        """Relative size in [factor, 1] at ``points`` (n, 3) [m]."""
        d = np.asarray(self.region.sdf(np.asarray(points, float)), float)
        t = (d > 0).astype(float) if self.width == 0.0 else np.clip(d / self.width, 0.0, 1.0)
        return self.factor + (1.0 - self.factor) * t

    def key(self) -> dict:
        """What identifies the grading in the packing cache."""
        return {"region": self.region.key(), "factor": self.factor, "width": self.width}


def graded_cloud(shape, refinement: Refinement, n: int, dispersion: float, rng, batch: int = 200_000):
    """``n`` random centres [m] inside ``shape`` with a number density proportional to
    ``size^-3``, and their relative radii: the size at each centre times a factor uniform in
    ``[1 - dispersion/2, 1 + dispersion/2]``. Returns (centres (n, 3), relative radii (n,))."""
    if not 0 <= dispersion < 2:
        raise ValueError(f"dispersion must be in [0, 2), got {dispersion} (0.25 = radii in size*[0.875, 1.125])")
    lo, hi = (np.asarray(b, float) for b in shape.bounds())
    got, have = [], 0
    for _ in range(10_000):
        c = lo + (hi - lo) * rng.random((batch, 3))
        c = c[np.asarray(shape.sdf(c), float) < 0.0]
        c = c[rng.random(c.shape[0]) < (refinement.factor / refinement.size(c)) ** 3]
        got.append(c)
        have += c.shape[0]
        if have >= n:
            break
    else:
        raise ValueError("could not place the graded cloud inside the container: is it empty?")
    x = np.concatenate(got)[:n]
    rel = refinement.size(x) * (1.0 + dispersion * (rng.random(n) - 0.5))
    return x, rel
