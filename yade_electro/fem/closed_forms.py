"""Closed-form solutions the finite-element reference is checked against (SI units)."""
from __future__ import annotations

import math

import numpy as np

__all__ = ["bar_resistance", "coax_resistance", "adiabatic_joule_temperature",
           "joule_parabola", "slab_temperature", "edge_crack_increment"]


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


def edge_crack_increment(width: float, length: float, depth: float) -> float:
    """Closed-form R_crack / R_intact - 1 of a bar of square (or any rectangular) section
    ``width`` [m] across the crack, ``length`` [m] between equipotential ends, with a straight
    through-thickness edge crack of ``depth`` [m] far from the ends:

        R_crack / R_intact - 1 = (4 W / (pi L)) ln sec(pi a / (2 W)).

    Why: the field does not depend on the thickness, so the problem is the 2D strip of width
    W with an edge slit; mirrored across the cracked edge it is the strip of width 2 W with
    a centre crack of length 2 a, whose potential is Johnson's conformal-map solution (H. H.
    Johnson, Materials Research & Standards 5 (1965) 442; the potential-drop calibration of
    ASTM E647). Far from the crack the potential drop exceeds the uncracked one by the field
    times (4 W / pi) ln sec(pi a / 2 W). The ends' distortion of the field decays as
    exp(-pi z / W): for the 2 x 2 x 8 mm bar with the crack 4 mm from either end the
    correction is of order exp(-4 pi) ~ 4e-6, relative.
    """
    vals = [float(width), float(length), float(depth)]
    if not all(math.isfinite(v) and v > 0 for v in vals) or not depth < width:
        raise ValueError(f"need 0 < depth < width and length > 0 (m), got width={width}, length={length}, "
                         f"depth={depth}")
    return 4.0 * width / (math.pi * length) * math.log(1.0 / math.cos(math.pi * depth / (2.0 * width)))
