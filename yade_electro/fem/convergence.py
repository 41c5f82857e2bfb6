"""Mesh-convergence study: Richardson extrapolation and Roache's grid convergence index.

Three solutions q1, q2, q3 on meshes of size h1 > h2 > h3 give the observed order p from

    (q1 - q2) / (q2 - q3) = (h1^p - h2^p) / (h2^p - h3^p),

the extrapolated value q_ext = q3 + (q3 - q2) h3^p / (h2^p - h3^p), and the grid
convergence index of the finest solution GCI = Fs ``|q3 - q2|`` / ((h2/h3)^p - 1) with the
safety factor Fs = 1.25 (Roache 1994, ASME V&V 20). GCI is the error estimate we quote
for the finest solution; ``|q_ext - q3|`` is the (smaller) Richardson estimate. When
convergence is not monotone (oscillating differences) or the observed order is
implausible, the expected order is used with Fs = 3, and ``monotone`` is False.
"""
from __future__ import annotations

import logging
import math
from dataclasses import dataclass

import numpy as np
from scipy.optimize import brentq

__all__ = ["converged", "Convergence", "richardson"]

logger = logging.getLogger(__name__)


@dataclass(frozen=True)
class Convergence:
    """Convergence study of one scalar.

    Attributes
    ----------
    h : ndarray
        Mesh sizes, coarsest first [m] (or any refinement parameter).
    values : ndarray
        Solutions on those meshes.
    order : float
        Observed (or, if not monotone, expected) order of convergence.
    extrapolated : float
        Richardson-extrapolated value.
    gci : float
        Grid convergence index: estimated absolute error of the finest solution.
    monotone : bool
        Whether the observed order could be used.
    """

    h: np.ndarray
    values: np.ndarray
    order: float
    extrapolated: float
    gci: float
    monotone: bool

    @property
    def finest(self) -> float:
        """Solution on the finest mesh."""
        return float(self.values[-1])

    @property
    def relative_error(self) -> float:
        """GCI relative to the finest solution."""
        return abs(self.gci / self.finest) if self.finest else math.inf

    def as_dict(self) -> dict:
        """Plain-python summary (for JSON)."""
        return {"h": self.h.tolist(), "values": self.values.tolist(), "order": self.order,
                "extrapolated": self.extrapolated, "finest": self.finest, "gci": self.gci,
                "relative_error": self.relative_error, "monotone": self.monotone}


def richardson(h, values, expected_order: float = 2.0, bounds=(0.3, 6.0)) -> Convergence:
    """Observed order, extrapolated value and GCI from the last three of ``values``.

    Parameters
    ----------
    h : sequence of float
        Refinement parameter, decreasing (at least 3).
    values : sequence of float
        The quantity on each mesh.
    expected_order : float
        Used when the observed order is out of ``bounds`` or convergence oscillates.
    """
    h = np.asarray(h, dtype=float)
    q = np.asarray(values, dtype=float)
    if h.shape != q.shape or h.size < 3:
        raise ValueError("give at least three (h, value) pairs")
    if np.any(np.diff(h) >= 0):
        raise ValueError(f"h must decrease, got {h}")
    (h1, h2, h3), (q1, q2, q3) = h[-3:], q[-3:]
    d21, d32 = q2 - q1, q3 - q2
    p, monotone = expected_order, False
    if d32 == 0.0:
        p, monotone = expected_order, True
    elif d21 * d32 > 0:
        target = d21 / d32

        def f(pp):
            return (h1 ** pp - h2 ** pp) / (h2 ** pp - h3 ** pp) - target

        lo, hi = bounds
        if f(lo) * f(hi) < 0:
            p, monotone = brentq(f, lo, hi, xtol=1e-10), True
    r = h2 / h3
    denom = r ** p - 1.0
    ext = q3 + d32 / denom
    gci = (1.25 if monotone else 3.0) * abs(d32) / denom
    if not monotone:
        logger.info("convergence not monotone (%s): expected order %s used", q[-3:], p)
    return Convergence(h=h, values=q, order=float(p), extrapolated=float(ext), gci=float(gci),
                       monotone=monotone)


def converged(compute, hs, expected_order: float = 2.0) -> dict:
    """Run ``compute(h)`` on each mesh size and study the convergence of every output.

    Parameters
    ----------
    compute : callable
        ``compute(h)`` -> float or dict name -> float.
    hs : sequence of float
        Decreasing mesh sizes (e.g. h, h/2, h/4); at least three.
    expected_order : float
        Fallback order (see :func:`richardson`).

    Returns
    -------
    dict
        name -> :class:`Convergence` (name ``"value"`` when ``compute`` returns a float).
    """
    hs = [float(h) for h in hs]
    rows = []
    for h in hs:
        out = compute(h)
        rows.append(out if isinstance(out, dict) else {"value": float(out)})
        logger.info("converged: h = %.4g -> %s", h, rows[-1])
    return {k: richardson(hs, [r[k] for r in rows], expected_order) for k in rows[0]}
