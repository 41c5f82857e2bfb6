"""The theta family of time integrators and the explicit stability bound (paper 003).

``theta = 0`` forward Euler, ``1/2`` Crank-Nicolson, ``1`` backward Euler; see
:mod:`yade_electro.network.transient` for the scheme and the bound. Units: SI (J/K, W/K, s).
"""
from __future__ import annotations

import math

import numpy as np

__all__ = ["theta_of", "stable_time_step", "THETA_NAMES"]

#: names of the integrators and their theta
THETA_NAMES = {"explicit": 0.0, "forward-euler": 0.0, "crank-nicolson": 0.5,
               "backward-euler": 1.0, "implicit": 1.0}


def stable_time_step(capacity, edges, conductance, h_area=None, fixed=None) -> float:
    """Largest forward-Euler step keeping the maximum principle [s]:
    ``min_i C_i / (sum_j G_ij + h_i A_i)`` over the free nodes (``fixed`` a boolean mask of
    fixed-temperature nodes); inf when no free node exchanges heat."""
    C = np.asarray(capacity, dtype=float)
    n = C.shape[0]
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    g = np.asarray(conductance, dtype=float)
    d = np.bincount(e[:, 0], g, n) + np.bincount(e[:, 1], g, n)
    if h_area is not None:
        d = d + np.asarray(h_area, dtype=float)
    free = np.ones(n, bool) if fixed is None else ~np.asarray(fixed, bool)
    sel = free & (d > 0)
    return float(np.min(C[sel] / d[sel])) if np.any(sel) else math.inf


def theta_of(theta) -> float:
    """theta from a number in [0, 1] or a name ('explicit', 'crank-nicolson', 'backward-euler')."""
    if isinstance(theta, (bool, np.bool_)) or theta is None:
        raise ValueError(f"theta must be 'explicit', 'crank-nicolson', 'backward-euler' or a number in [0, 1], "
                         f"got {theta!r}")
    if isinstance(theta, str):
        try:
            return THETA_NAMES[theta.lower()]
        except KeyError:
            raise ValueError(f"unknown integrator {theta!r}; known: {', '.join(sorted(THETA_NAMES))} "
                             "or a number in [0, 1]") from None
    try:
        t = float(theta)
    except (TypeError, ValueError):
        raise ValueError(f"theta must be a name ({', '.join(sorted(THETA_NAMES))}) or a number in [0, 1], "
                         f"got {theta!r}") from None
    if not (0.0 <= t <= 1.0):
        raise ValueError(f"theta must be in [0, 1], got {theta}")
    return t
