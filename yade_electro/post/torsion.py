"""Torsion of a circular bar: the elastic closed forms and the reading of a twist test.

Closed forms (Saint-Venant torsion of a solid circular bar, radius r, length h, shear modulus
G): polar moment J = pi r^4 / 2 [m^4], torque T = G J theta / h [N m] at the twist angle
theta [rad], maximum (surface) shear stress tau = T r / J = G r theta / h [Pa], first yield
at theta_y = tau_y h / (G r).

Reading a test (numpy only, no YADE): curves given as arrays over the twist angle are turned
into the figures a user acts on: the elastic stiffness error, the angle of the first broken
bond, the angles where R/R0 first exceeds given levels, the angle of separation (R = inf),
R/R0 at given angles.

Units: SI (m, rad, N m, Pa, ohm).
"""
from __future__ import annotations

import math
from typing import Dict, Iterable, Optional

import numpy as np

__all__ = ["polar_moment", "elastic_torque", "surface_shear_stress", "yield_angle", "elastic_slope",
           "first_crossing", "ratio_at", "crack_summary"]


def polar_moment(radius: float) -> float:
    """J = pi r^4 / 2 [m^4] of a solid circular section of radius r [m]."""
    return math.pi * float(radius) ** 4 / 2.0


def elastic_torque(shear_modulus: float, radius: float, length: float, theta) -> np.ndarray:
    """T = G J theta / h [N m] for the twist angle theta [rad] over the length h [m]."""
    return shear_modulus * polar_moment(radius) * np.asarray(theta, dtype=float) / float(length)


def surface_shear_stress(torque, radius: float) -> np.ndarray:
    """tau = T r / J = 2 T / (pi r^3) [Pa], the elastic shear stress at the surface."""
    return np.asarray(torque, dtype=float) * float(radius) / polar_moment(radius)


def yield_angle(yield_stress: float, shear_modulus: float, radius: float, length: float) -> float:
    """theta_y = tau_y h / (G r) [rad]: the twist at which the surface reaches tau_y."""
    return float(yield_stress) * float(length) / (float(shear_modulus) * float(radius))


def elastic_slope(theta, torque, theta_max: float, theta_min: float = 0.0) -> float:
    """Least-squares slope dT/dtheta [N m/rad] over theta_min < theta <= theta_max, through the
    first point of that range (so a torque offset at the start does not bias it)."""
    th, tq = np.asarray(theta, float), np.asarray(torque, float)
    keep = (th > theta_min) & (th <= theta_max) & np.isfinite(tq)
    if np.count_nonzero(keep) < 3:
        raise ValueError(f"fewer than 3 points with {theta_min} < theta <= {theta_max}: cannot fit the "
                         "elastic slope (record more often, or twist further)")
    x, y = th[keep] - th[keep][0], tq[keep] - tq[keep][0]
    return float(np.dot(x, y) / np.dot(x, x))


def first_crossing(theta, values, level: float) -> Optional[float]:
    """The first angle [rad] where ``values`` reaches ``level`` (linear interpolation between
    records; an infinite value counts as reached at its own record). None if never."""
    th, v = np.asarray(theta, float), np.asarray(values, float)
    at = np.flatnonzero(v >= level)
    if at.size == 0:
        return None
    k = int(at[0])
    if k == 0 or not np.isfinite(v[k]) or v[k] == v[k - 1]:
        return float(th[k])
    return float(th[k - 1] + (level - v[k - 1]) * (th[k] - th[k - 1]) / (v[k] - v[k - 1]))


def ratio_at(theta, ratio, angles: Iterable[float]) -> Dict[str, float]:
    """R/R0 at each angle (keys: the angle as a string, e.g. "0.05"), linear between records;
    inf once the pin has separated (a record with R = inf at or before the angle, or a test
    that ended separated before it); nan where a test that had not separated ended before it."""
    th, r = np.asarray(theta, float), np.asarray(ratio, float)
    out = {}
    for a in angles:
        key = f"{a:g}"
        if th.size == 0 or a > th[-1]:
            out[key] = float("inf") if th.size and np.isinf(r[-1]) else float("nan")
            continue
        upto = th <= a
        if np.any(np.isinf(r[upto])):
            out[key] = float("inf")
            continue
        k = int(np.searchsorted(th, a))
        if k == 0:
            out[key] = float(r[0])
        elif k < th.size and np.isinf(r[k]):     # separated between the records: last finite value
            out[key] = float(r[k - 1])
        else:
            out[key] = float(np.interp(a, th, r))
    return out


def crack_summary(theta, ratio, broken, levels=(0.01, 0.10, 1.00)) -> dict:
    """What the curves say about cracking.

    Parameters
    ----------
    theta : (k,) twist angles [rad], increasing
    ratio : (k,) R/R0 (inf once separated)
    broken : (k,) number of broken bonds at each record
    levels : relative rises of R to report (0.01 = +1 %)

    Returns
    -------
    dict with ``theta_first_break`` (first record with a broken bond, None if none),
    ``theta_R_rise`` {"1%": angle or None, ...}, ``theta_separation`` (first R = inf, None if
    never), ``broken_at_separation``, ``broken_final``.
    """
    th, r, nb = np.asarray(theta, float), np.asarray(ratio, float), np.asarray(broken, float)
    if not (th.shape == r.shape == nb.shape):
        raise ValueError(f"theta, ratio and broken must have one shape, got {th.shape}, {r.shape}, {nb.shape}")
    first = np.flatnonzero(nb > 0)
    sep = np.flatnonzero(np.isinf(r))
    return {
        "theta_first_break": float(th[first[0]]) if first.size else None,
        "theta_R_rise": {f"{100 * lv:g}%": first_crossing(th, r, 1.0 + lv) for lv in levels},
        "theta_separation": float(th[sep[0]]) if sep.size else None,
        "broken_at_separation": int(nb[sep[0]]) if sep.size else None,
        "broken_final": int(nb[-1]) if nb.size else 0,
    }
