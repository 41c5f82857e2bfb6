"""Two resolved grains (bonded sub-packings) touching across a flat contact, joined element to
element through a contact resistance (issue 35; numpy only).

Each grain is a bonded packing of its shape whose elements are cells (the 'voronoi' law's
bounded cells): the part of the contact plane inside grain A's shape belongs, point by point,
to the element of A whose centre is nearest (the cells' faces on a plane are those points),
and likewise for B. Sampling the contact region on a fine grid gives, for each pair (i of A,
j of B), the area ``A_ij`` their faces share; the heat crosses it through i's half cell, the
contact and j's half cell in series:

    G_ij = A_ij / (d_i / lambda_A + R_c + d_j / lambda_B)

with ``d`` an element's distance to the plane and ``R_c`` [m^2 K/W] the specific contact
resistance (a constant, or from the pressure of rough surfaces: :func:`mikic_resistance`). The links are edges
between the two grains' elements: a network of both grains and their contact, for
:class:`~yade_electro.network.transient.HeatSolver`.

Units: m, m^2, W/(m K), m^2 K/W, W/K, Pa.
"""
from __future__ import annotations

import numpy as np

from ..core.errors import BoundaryConditionError

__all__ = ["plane_contact_geometry", "plane_contact_links", "contact_resistance_value", "mikic_resistance"]


def plane_contact_geometry(centres_a, centres_b, origin, normal, u_axis, extent_u, extent_v, samples: int = 200_000,
                           inside=None):
    """The geometry of a flat contact's links: (pairs (k, 2) of element indices (of A, of B),
    their shared face areas ``A_ij`` [m^2] (k,), the elements' distances to the plane ``d_i``,
    ``d_j`` [m] (k,) each, the sampled contact area [m^2]). Parameters as for
    :func:`plane_contact_links`."""
    from scipy.spatial import cKDTree
    n = np.asarray(normal, float)
    n = n / np.linalg.norm(n)
    u = np.asarray(u_axis, float) - np.dot(u_axis, n) * n
    u = u / np.linalg.norm(u)
    v = np.cross(n, u)
    (u0, u1), (v0, v1) = extent_u, extent_v
    area = (u1 - u0) * (v1 - v0)
    step = np.sqrt(area / samples)
    nu, nv = max(1, int(round((u1 - u0) / step))), max(1, int(round((v1 - v0) / step)))
    su = u0 + (np.arange(nu) + 0.5) * (u1 - u0) / nu
    sv = v0 + (np.arange(nv) + 0.5) * (v1 - v0) / nv
    U, V = np.meshgrid(su, sv, indexing="ij")
    pts = np.asarray(origin, float) + U.reshape(-1, 1) * u + V.reshape(-1, 1) * v
    if inside is not None:
        pts = pts[np.asarray(inside(pts), bool)]
    dA = area / (nu * nv)
    ca, cb = np.asarray(centres_a, float), np.asarray(centres_b, float)
    ia = cKDTree(ca).query(pts)[1]
    ib = cKDTree(cb).query(pts)[1]
    key = ia.astype(np.int64) * cb.shape[0] + ib
    uniq, count = np.unique(key, return_counts=True)
    pairs = np.column_stack([uniq // cb.shape[0], uniq % cb.shape[0]])
    da = np.abs((ca[pairs[:, 0]] - origin) @ n)
    db = np.abs((cb[pairs[:, 1]] - origin) @ n)
    return pairs, count * dA, da, db, float(pts.shape[0] * dA)


def contact_resistance_value(resistance) -> float:
    """``resistance`` [m^2 K/W] as a float, checked finite and >= 0 (BoundaryConditionError)."""
    try:
        R = float(resistance)
    except (TypeError, ValueError):
        R = float("nan")
    if not (np.isfinite(R) and R >= 0):
        raise BoundaryConditionError(f"a contact resistance must be finite and >= 0 (m^2 K/W), got {resistance!r}")
    return R


def plane_contact_links(centres_a, centres_b, origin, normal, u_axis, extent_u, extent_v, resistance,
                        conductivity_a, conductivity_b=None, samples: int = 200_000, inside=None):
    """Links across a flat contact: (pairs (k, 2) of element indices (of A, of B), conductances
    G [W/K] (k,), the sampled contact area [m^2]).

    Parameters
    ----------
    centres_a, centres_b : (n_a, 3), (n_b, 3) element centres [m] of the two grains
    origin, normal : a point of the contact plane and its normal [m]
    u_axis : a direction in the plane; v is normal x u
    extent_u, extent_v : (lo, hi) of the contact region along u and v from ``origin`` [m]
    resistance : the specific contact resistance R_c [m^2 K/W] >= 0
    conductivity_a, conductivity_b : the grains' conductivities [W/(m K)] (B: A's by default)
    samples : about how many sample points cover the region
    inside : optional ``f(points (m, 3)) -> mask``: the points of the region that are in
        contact (default all of it)
    """
    R = contact_resistance_value(resistance)
    lam_a = float(conductivity_a)
    lam_b = lam_a if conductivity_b is None else float(conductivity_b)
    if not (lam_a > 0 and lam_b > 0):
        raise BoundaryConditionError("the grains' conductivities must be > 0 (W/(m K))")
    pairs, A, da, db, area = plane_contact_geometry(centres_a, centres_b, origin, normal, u_axis, extent_u, extent_v,
                                                     samples, inside)
    return pairs, A / (da / lam_a + R + db / lam_b), area


def mikic_resistance(pressure, roughness: float, slope: float, hardness: float, conductivity: float):
    """Specific contact resistance [m^2 K/W] of two rough surfaces pressed together, plastic
    asperities (Mikic 1974; Yovanovich's 1982 correlation, ``../shared/DESIGN.md``): the
    contact conductance ``h_c = 1.25 k m / sigma (P / H)^0.95`` with ``sigma`` [m] the combined
    RMS roughness, ``m`` the combined mean absolute asperity slope, ``H`` [Pa] the
    micro-hardness of the softer surface and ``k`` [W/(m K)] the harmonic mean conductivity;
    ``R_c = 1 / h_c``."""
    P = np.asarray(pressure, float)
    if np.any(~np.isfinite(P)) or np.any(P <= 0):
        raise BoundaryConditionError(f"contact pressures must be finite and > 0 (Pa), got {pressure!r}")
    for name, val in (("roughness", roughness), ("slope", slope), ("hardness", hardness),
                      ("conductivity", conductivity)):
        if not (np.isfinite(val) and val > 0):
            raise BoundaryConditionError(f"mikic_resistance: {name} must be finite and > 0, got {val!r}")
    h = 1.25 * conductivity * slope / roughness * (P / hardness) ** 0.95
    return 1.0 / h
