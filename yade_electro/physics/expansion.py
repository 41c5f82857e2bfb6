"""Thermal expansion and thermal stress of a particle assembly, as pure functions on arrays.

The thermal strain of an element at temperature ``T`` [K] is the integral of its linear
expansion coefficient ``alpha`` [1/K] from the reference temperature ``T_ref`` [K]:

    eps(T) = int_{T_ref}^{T} alpha(tau) d tau

(``alpha (T - T_ref)`` for a constant coefficient; an :class:`AlphaTable` is integrated exactly,
piecewise linear between its points and constant beyond them). Two ways to give it to a DEM
packing (:func:`bond_rest_increments`, :func:`radius_growth`):

* **bonds**: each cohesive bond's rest length grows by ``eps_1 h_1 + eps_2 h_2``, its two
  halves (``h_k``, the part of the rest length on element k's side, in proportion to the radii)
  each with its own element's strain; the radii, the geometry and the conductances are kept
  (what the closed forms isolate). A uniform ``eps`` scales every rest length by ``1 + eps``:
  a homothety, zero force, strain ``eps`` (the free-expansion check);
* **radii**: ``r = r_ref (1 + eps)``, mass kept (the density follows), the inertia ``2/5 m r^2``;
  contact overlaps, areas, Voronoi faces and conductances follow the new radii.

Thermal stress (:func:`element_stress`): the Love-Weber average of one element,
``sigma_i = (1 / V_i) sum_c sym((x_c - x_i) (x) f_c)``, over its interactions ``c`` with contact
point ``x_c`` and force ``f_c`` on element i; tension positive (YADE's ``getStress`` sign). The
sum of ``V_i sigma_i`` over all elements is the packing's Love-Weber stress times its volume.

Units: SI (K, 1/K, m, N, Pa).
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Tuple, Union

import numpy as np

from ..core.errors import MaterialError
from ..core.materials import real_number

__all__ = ["AlphaTable", "check_alpha", "thermal_strain", "bond_rest_increments", "radius_growth",
           "contact_points", "element_stress", "von_mises", "EXPANSION_MODES"]

#: the two ways expansion enters the packing
EXPANSION_MODES = ("bonds", "radii")


@dataclass(frozen=True)
class AlphaTable:
    """A temperature-dependent linear expansion coefficient ``alpha(T)`` [1/K]: piecewise linear
    through ``points`` = ((T [K], alpha [1/K]), ...), T increasing, constant beyond the ends."""

    points: Tuple[Tuple[float, float], ...]

    def __post_init__(self):
        try:
            p = np.asarray(self.points, dtype=float)
        except (TypeError, ValueError):
            raise MaterialError(f"AlphaTable points must be pairs (T [K], alpha [1/K]), got {self.points!r}") from None
        if p.ndim != 2 or p.shape[1] != 2 or p.shape[0] < 1:
            raise MaterialError(f"AlphaTable points must be pairs (T [K], alpha [1/K]), got shape {p.shape}")
        if not np.all(np.isfinite(p)):
            raise MaterialError(f"AlphaTable points must be finite, got {p.tolist()}")
        if np.any(p[:, 0] <= 0):
            raise MaterialError(f"AlphaTable temperatures must be > 0 K, got {p[:, 0].tolist()}")
        if np.any(np.diff(p[:, 0]) <= 0):
            raise MaterialError(f"AlphaTable temperatures must increase, got {p[:, 0].tolist()}")
        if np.any(p[:, 1] < 0):
            raise MaterialError(f"alpha must be >= 0 1/K (a contracting solid is not modelled), got {p[:, 1].tolist()}")
        object.__setattr__(self, "points", tuple((float(a), float(b)) for a, b in p))

    def integral(self, T) -> np.ndarray:
        """``int_{T_0}^{T} alpha`` [-] from the first point's temperature ``T_0`` (array-wise)."""
        p = np.asarray(self.points)
        t, a = p[:, 0], p[:, 1]
        T = np.asarray(T, dtype=float)
        if t.size == 1:
            return a[0] * (T - t[0])
        cum = np.concatenate([[0.0], np.cumsum(0.5 * (a[1:] + a[:-1]) * np.diff(t))])
        k = np.clip(np.searchsorted(t, T, side="right") - 1, 0, t.size - 2)    # the segment
        slope = (a[k + 1] - a[k]) / (t[k + 1] - t[k])
        dt = T - t[k]
        inside = cum[k] + a[k] * dt + 0.5 * slope * dt * dt
        out = np.where(T < t[0], a[0] * (T - t[0]), inside)
        return np.where(T >= t[-1], cum[-1] + a[-1] * (T - t[-1]), out)

    def __call__(self, T) -> np.ndarray:
        """alpha(T) [1/K]."""
        p = np.asarray(self.points)
        return np.interp(np.asarray(T, dtype=float), p[:, 0], p[:, 1])


Alpha = Union[float, AlphaTable]


def check_alpha(name: str, alpha) -> Alpha:
    """``alpha`` as a float >= 0 [1/K] or an :class:`AlphaTable` (a sequence of (T, alpha)
    pairs is made one); MaterialError naming ``name`` otherwise."""
    if isinstance(alpha, AlphaTable):
        return alpha
    if isinstance(alpha, (list, tuple)) and alpha and isinstance(alpha[0], (list, tuple)):
        return AlphaTable(tuple(tuple(p) for p in alpha))
    a = real_number(name, alpha, what="a linear expansion coefficient [1/K] (a number, or AlphaTable)")
    if a < 0:
        raise MaterialError(f"{name} must be >= 0 1/K, got {a!r} (a contracting solid is not modelled)")
    return a


def thermal_strain(T, T_ref, alpha: Alpha) -> np.ndarray:
    """``int_{T_ref}^{T} alpha`` [-] for temperatures ``T`` and ``T_ref`` [K] (arrays or
    scalars, broadcast)."""
    T = np.asarray(T, dtype=float)
    T_ref = np.asarray(T_ref, dtype=float)
    if isinstance(alpha, AlphaTable):
        return alpha.integral(T) - alpha.integral(T_ref)
    return float(alpha) * (T - T_ref)


def bond_rest_increments(pairs, radius, rest_length, eps_now, eps_before) -> np.ndarray:
    """How much each bond's rest length grows [m] when its elements' thermal strains go from
    ``eps_before`` to ``eps_now`` (one per element): ``(de_1 r_1 + de_2 r_2) L / (r_1 + r_2)``
    for the bond's current rest length ``L`` [m] (what the strains already applied made it:
    the halves are scaled back by ``1 + eps_before``)."""
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    r = np.asarray(radius, dtype=float)
    L = np.asarray(rest_length, dtype=float)
    e1, e0 = np.asarray(eps_now, dtype=float), np.asarray(eps_before, dtype=float)
    i, j = p[:, 0], p[:, 1]
    # the rest length's halves at the reference are L_ref r_k / (r_1 + r_2), and now
    # L = L_ref (r_1 (1 + e0_1) + r_2 (1 + e0_2)) / (r_1 + r_2)
    w = r[i] * (1.0 + e0[i]) + r[j] * (1.0 + e0[j])
    return L * (r[i] * (e1[i] - e0[i]) + r[j] * (e1[j] - e0[j])) / w


def radius_growth(radius, eps_now, eps_before) -> np.ndarray:
    """The radii [m] at strains ``eps_now`` of elements whose radii ``radius`` are at
    ``eps_before``: ``r (1 + eps_now) / (1 + eps_before)``."""
    return np.asarray(radius, dtype=float) * (1.0 + np.asarray(eps_now, float)) / (1.0 + np.asarray(eps_before, float))


def contact_points(pos, radius, pairs) -> np.ndarray:
    """Contact points (m, 3) [m] of sphere pairs: on the line of centres, in the middle of the
    overlap (or of the gap, for a bond in tension), as YADE's ScGeom places them."""
    x = np.asarray(pos, dtype=float)
    r = np.asarray(radius, dtype=float)
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    d = x[p[:, 1]] - x[p[:, 0]]
    dist = np.linalg.norm(d, axis=1)
    n = d / np.where(dist > 0, dist, 1.0)[:, None]
    depth = r[p[:, 0]] + r[p[:, 1]] - dist
    return x[p[:, 0]] + (r[p[:, 0]] - 0.5 * depth)[:, None] * n


def element_stress(pos, pairs, points, force_on_second, volume) -> np.ndarray:
    """Love-Weber stress (n, 3, 3) [Pa] of every element (module doc); tension positive.

    Parameters
    ----------
    pos : (n, 3) element centres [m]
    pairs : (m, 2) element indices of the interactions
    points : (m, 3) their contact points [m]
    force_on_second : (m, 3) the force [N] of each interaction on its second element (the
        first gets the opposite)
    volume : scalar or (n,) the elements' volumes [m^3] (their cells)
    """
    x = np.asarray(pos, dtype=float).reshape(-1, 3)
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    c = np.asarray(points, dtype=float).reshape(-1, 3)
    f = np.asarray(force_on_second, dtype=float).reshape(-1, 3)
    n = x.shape[0]
    V = np.broadcast_to(np.asarray(volume, dtype=float), (n,))
    if np.any(~np.isfinite(V) | (V <= 0)):
        raise ValueError("element volumes must be finite and > 0")
    s = np.zeros((n, 9))
    a = np.einsum("mi,mj->mij", c - x[p[:, 0]], -f).reshape(-1, 9)
    b = np.einsum("mi,mj->mij", c - x[p[:, 1]], f).reshape(-1, 9)
    for k in range(9):
        s[:, k] = np.bincount(p[:, 0], a[:, k], n) + np.bincount(p[:, 1], b[:, k], n)
    s = s.reshape(n, 3, 3)
    s = 0.5 * (s + s.transpose(0, 2, 1))
    return s / V[:, None, None]


def von_mises(stress) -> np.ndarray:
    """Von Mises equivalent stress [Pa] of (n, 3, 3) stresses."""
    s = np.asarray(stress, dtype=float)
    dev = s - np.trace(s, axis1=1, axis2=2)[:, None, None] / 3.0 * np.eye(3)
    return np.sqrt(1.5 * np.einsum("nij,nij->n", dev, dev))
