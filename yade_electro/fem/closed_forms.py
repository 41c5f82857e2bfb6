"""Closed-form solutions the finite-element reference is checked against (SI units)."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["bar_resistance", "coax_resistance", "adiabatic_joule_temperature",
           "joule_parabola", "slab_temperature"]


def bar_resistance(rho: float, length: float, area: float) -> float:
    """R = rho L / A [ohm] of a prismatic conductor between its end faces."""
    return rho * length / area


def coax_resistance(rho: float, r_inner: float, r_outer: float, length: float) -> float:
    """Radial resistance between coaxial cylinders: rho ln(r2 / r1) / (2 pi L) [ohm]."""
    return rho * math.log(r_outer / r_inner) / (2.0 * math.pi * length)


def adiabatic_joule_temperature(t, voltage: float, length: float, rho: float, rho_c: float,
                                T0: float = 293.15):
    """Uniform adiabatic Joule heating of a bar: T0 + V^2 / (rho L^2) t / rho_c [K]."""
    return T0 + voltage ** 2 / (rho * length ** 2) * np.asarray(t, dtype=float) / rho_c


def joule_parabola(x, length: float, current_density: float, rho: float, lambda_: float,
                   T0: float = 293.15):
    """Steady 1D Joule heating, both ends at T0: T0 + J^2 rho / (2 lambda) x (L - x) [K]."""
    x = np.asarray(x, dtype=float)
    return T0 + current_density ** 2 * rho / (2.0 * lambda_) * x * (length - x)


def slab_temperature(x, t, length: float, alpha: float, T0: float, T1: float,
                     nterms: int = 400):
    """Slab 0 <= x <= L insulated at x = 0, held at T1 at x = L from t = 0, initially T0.

    (T - T1) / (T0 - T1) = sum_n 4 (-1)^n / ((2n+1) pi) cos(k_n x) exp(-k_n^2 alpha t),
    k_n = (2n+1) pi / (2L) (Carslaw & Jaeger; paper 003's 1D check).

    Parameters
    ----------
    x : array [m]
    t : float [s] (> 0 for a converged series)
    alpha : float
        Thermal diffusivity lambda / (rho c) [m^2/s].
    """
    x = np.asarray(x, dtype=float)
    n = np.arange(nterms)[:, None]
    k = (2 * n + 1) * np.pi / (2.0 * length)
    terms = 4.0 * (-1.0) ** n / ((2 * n + 1) * np.pi) * np.cos(k * x.ravel()[None, :]) \
        * np.exp(-k ** 2 * alpha * t)
    return (T1 + (T0 - T1) * terms.sum(axis=0)).reshape(x.shape)
