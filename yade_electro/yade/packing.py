"""Dense, bonded sphere packings of a container: the recipe equivalent to GranOO's *Cooker*.

The paper (000, section 2.1) fills a geometrical shape with spheres whose radii are uniform
in ``[r_mean (1 - d/2), r_mean (1 + d/2)]`` (``d = 0.25``), with ``r_mean`` from the wanted
count (eq. 1), and expects a volume fraction near 0.63, a mean coordination near 6-7 and
about two thirds of the elements with a neighbour eccentricity ``e < 0.4``.

Two steps, kept apart on purpose:

1. **Placement** (:func:`dense_packing`): numpy/scipy only, no YADE. Random centres inside
   the container are relaxed with FIRE on a harmonic overlap energy (sphere-sphere overlaps
   and penetration of the container wall, measured with the container's exact signed
   distance), while the radii are scaled up, bisecting on the scale at which the packing
   jams (the O'Hern et al. 2003 protocol). The result is the last *unjammed* state: the
   spheres do not overlap (up to a tolerance, default 1e-4 r_mean), lie inside the
   container and touch its walls. Results are cached on disk.
2. **Bonding** (:func:`add_bonded_packing`): the spheres are added to ``O.bodies`` with a
   cohesive material and every pair closer than ``detection_factor * (r_i + r_j)`` is
   bonded by YADE itself (one step with the enlarged detection factor, then the factor is
   reset to 1). :func:`bond_pairs` applies the same rule in numpy.

Containers are :class:`Shape` objects with an exact signed distance function
(:class:`Cylinder`, :class:`Box`, :class:`Sphere` and their differences, intersections and
unions). YADE predicates (``pack.inCylinder``, ``pack.inAlignedBox``, ``pack.inSphere`` and
their differences/intersections/unions) are converted by :func:`as_shape`: the primitive is
identified from its bounding box and checked against the predicate on sample points; a
predicate that cannot be identified is sampled on a grid and turned into a signed distance
field (Euclidean distance transform), accurate to about one voxel.

Units: SI (metres, cubic metres, seconds).
"""
from __future__ import annotations

import hashlib
import json
import logging
import os
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
from scipy.spatial import cKDTree

__all__ = [
    "Shape", "Cylinder", "Box", "Sphere", "Difference", "Intersection", "Union", "GridShape",
    "as_shape", "container_volume", "mean_radius_for_count", "SpherePacking", "dense_packing",
    "bond_pairs", "detection_factor_for_coordination", "packing_statistics",
    "add_bonded_packing", "steel_304L",
]

log = logging.getLogger(__name__)

PACKING_VERSION = 2  # bump when the placement algorithm changes (invalidates the cache)


# =========================================================================================
# Container shapes with exact signed distance
# =========================================================================================
def _pts(x) -> np.ndarray:
    x = np.asarray(x, dtype=float)
    return x.reshape(1, 3) if x.ndim == 1 else x


class Shape:
    """A closed region of space with a signed distance function (negative inside) [m].

    A shape is also a YADE-style predicate: ``shape(point, pad)`` is true when the sphere
    of radius ``pad`` centred at ``point`` lies inside, and ``aabb()``, ``center()``,
    ``dim()`` exist, so shapes can be passed to ``yade.pack`` functions too. ``a - b``,
    ``a & b`` and ``a | b`` build differences, intersections and unions.
    """

    def sdf(self, x) -> np.ndarray:
        """Signed distance of points ``x`` (n, 3) to the boundary [m]; < 0 inside."""
        raise NotImplementedError

    def bounds(self) -> tuple:
        """(lo, hi) corners of the axis-aligned bounding box [m], numpy arrays."""
        raise NotImplementedError

    @property
    def exact_volume(self):
        """Volume [m^3] if known in closed form, else None."""
        return None

    def key(self) -> tuple:
        """Hashable, JSON-serialisable description used for caching."""
        raise NotImplementedError

    # -- YADE predicate protocol --------------------------------------------------------
    def __call__(self, pt, pad=0.0) -> bool:
        return bool(self.sdf(np.asarray(pt, dtype=float).reshape(1, 3))[0] <= -pad)

    def aabb(self):
        lo, hi = self.bounds()
        return tuple(lo), tuple(hi)

    def center(self):
        lo, hi = self.bounds()
        return tuple(0.5 * (lo + hi))

    def dim(self):
        lo, hi = self.bounds()
        return tuple(hi - lo)

    def gradient(self, x, h=None) -> np.ndarray:
        """Unit outward normal (gradient of the signed distance) at points ``x``.

        Central differences; the step defaults to 1e-7 of the bounding-box size.
        """
        x = _pts(x)
        if h is None:
            lo, hi = self.bounds()
            h = 1e-7 * float(np.max(hi - lo))
        g = np.empty_like(x)
        for k in range(3):
            e = np.zeros(3)
            e[k] = h
            g[:, k] = self.sdf(x + e) - self.sdf(x - e)
        n = np.linalg.norm(g, axis=1)
        n[n == 0] = 1.0
        return g / n[:, None]

    def wall_terms(self, x) -> list:
        """Smooth pieces of the container constraint, for the placement energy.

        Returns a list of ``(g, normal)``: ``g`` (n,) is a signed distance [m] to one smooth
        constraint surface (a sphere of radius r is admissible for it when ``g + r <= 0``)
        and ``normal(idx)`` the unit outward normal of that surface at ``x[idx]``. The
        default is the signed distance itself; convex primitives return one term per face so
        that the energy stays smooth in corners.
        """
        x = _pts(x)
        return [(self.sdf(x), lambda idx: self.gradient(x[idx]))]

    def __sub__(self, other):
        return Difference(self, as_shape(other))

    def __and__(self, other):
        return Intersection(self, as_shape(other))

    def __or__(self, other):
        return Union(self, as_shape(other))


class Cylinder(Shape):
    """Capped cylinder between the centres of its end faces ``c1``, ``c2`` [m], radius [m]."""

    def __init__(self, c1, c2, radius):
        self.c1 = np.asarray(c1, dtype=float).reshape(3)
        self.c2 = np.asarray(c2, dtype=float).reshape(3)
        self.radius = float(radius)
        self.length = float(np.linalg.norm(self.c2 - self.c1))
        if not (self.radius > 0 and self.length > 0):
            raise ValueError(f"Cylinder needs radius > 0 and distinct end centres; got radius="
                             f"{radius}, c1={tuple(self.c1)}, c2={tuple(self.c2)}")
        self.axis = (self.c2 - self.c1) / self.length

    def sdf(self, x):
        p = _pts(x) - self.c1
        t = p @ self.axis
        q = p - t[:, None] * self.axis
        dr = np.sqrt(np.einsum("ij,ij->i", q, q)) - self.radius
        dz = np.abs(t - 0.5 * self.length) - 0.5 * self.length
        return np.minimum(np.maximum(dr, dz), 0.0) + np.hypot(np.maximum(dr, 0), np.maximum(dz, 0))

    def gradient(self, x, h=None):
        p = _pts(x) - self.c1
        t = p @ self.axis
        q = p - t[:, None] * self.axis
        rho = np.sqrt(np.einsum("ij,ij->i", q, q))
        dr = rho - self.radius
        dz = np.abs(t - 0.5 * self.length) - 0.5 * self.length
        rad = q / np.where(rho > 0, rho, 1.0)[:, None]
        ax = np.sign(t - 0.5 * self.length)[:, None] * self.axis
        a, b = np.maximum(dr, 0), np.maximum(dz, 0)
        out = np.where((a > 0) | (b > 0), 1, 0)
        hyp = np.hypot(a, b)
        hyp[hyp == 0] = 1.0
        g_out = (a / hyp)[:, None] * rad + (b / hyp)[:, None] * ax
        g_in = np.where((dr >= dz)[:, None], rad, ax)
        return np.where(out[:, None] == 1, g_out, g_in)

    def wall_terms(self, x):
        p = _pts(x) - self.c1
        t = p @ self.axis
        q = p - t[:, None] * self.axis
        rho = np.sqrt(np.einsum("ij,ij->i", q, q))

        def radial(idx):
            return q[idx] / np.where(rho[idx] > 0, rho[idx], 1.0)[:, None]
        ax = self.axis
        return [(rho - self.radius, radial),
                (t - self.length, lambda idx: np.broadcast_to(ax, (len(idx), 3))),
                (-t, lambda idx: np.broadcast_to(-ax, (len(idx), 3)))]

    def bounds(self):
        a = self.axis
        ext = self.radius * np.sqrt(np.clip(1.0 - a * a, 0.0, 1.0))
        lo = np.minimum(self.c1, self.c2) - ext
        hi = np.maximum(self.c1, self.c2) + ext
        return lo, hi

    @property
    def exact_volume(self):
        return np.pi * self.radius ** 2 * self.length

    def key(self):
        return ("Cylinder", self.c1.tolist(), self.c2.tolist(), self.radius)

    def __repr__(self):
        return f"Cylinder(c1={tuple(self.c1)}, c2={tuple(self.c2)}, radius={self.radius})"


class Box(Shape):
    """Axis-aligned box between corners ``lo`` and ``hi`` [m]."""

    def __init__(self, lo, hi):
        self.lo = np.asarray(lo, dtype=float).reshape(3)
        self.hi = np.asarray(hi, dtype=float).reshape(3)
        if np.any(self.hi <= self.lo):
            raise ValueError(f"Box needs hi > lo on every axis; got lo={tuple(self.lo)}, "
                             f"hi={tuple(self.hi)}")

    def sdf(self, x):
        c, h = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
        q = np.abs(_pts(x) - c) - h
        return np.linalg.norm(np.maximum(q, 0.0), axis=1) + np.minimum(q.max(axis=1), 0.0)

    def wall_terms(self, x):
        x = _pts(x)
        out = []
        for k in range(3):
            e = np.zeros(3)
            e[k] = 1.0
            out.append((x[:, k] - self.hi[k], lambda idx, e=e: np.broadcast_to(e, (len(idx), 3))))
            out.append((self.lo[k] - x[:, k], lambda idx, e=-e: np.broadcast_to(e, (len(idx), 3))))
        return out

    def bounds(self):
        return self.lo.copy(), self.hi.copy()

    @property
    def exact_volume(self):
        return float(np.prod(self.hi - self.lo))

    def key(self):
        return ("Box", self.lo.tolist(), self.hi.tolist())

    def __repr__(self):
        return f"Box(lo={tuple(self.lo)}, hi={tuple(self.hi)})"


class Sphere(Shape):
    """Ball of centre ``center`` and radius ``radius`` [m]."""

    def __init__(self, center, radius):
        self.c = np.asarray(center, dtype=float).reshape(3)
        self.radius = float(radius)
        if not self.radius > 0:
            raise ValueError(f"Sphere needs radius > 0, got {radius}")

    def sdf(self, x):
        return np.linalg.norm(_pts(x) - self.c, axis=1) - self.radius

    def bounds(self):
        return self.c - self.radius, self.c + self.radius

    @property
    def exact_volume(self):
        return 4.0 / 3.0 * np.pi * self.radius ** 3

    def key(self):
        return ("Sphere", self.c.tolist(), self.radius)

    def __repr__(self):
        return f"Sphere(center={tuple(self.c)}, radius={self.radius})"


class _Binary(Shape):
    def __init__(self, a, b):
        self.a, self.b = as_shape(a), as_shape(b)

    def key(self):
        return (type(self).__name__, self.a.key(), self.b.key())

    def __repr__(self):
        return f"{type(self).__name__}({self.a!r}, {self.b!r})"


class Difference(_Binary):
    """Points of ``a`` not in ``b`` (a notched bar: ``bar - notch``). The signed distance
    ``max(sdf_a, -sdf_b)`` is exact inside, a bound outside."""

    def sdf(self, x):
        return np.maximum(self.a.sdf(x), -self.b.sdf(x))

    def wall_terms(self, x):
        x = _pts(x)
        return self.a.wall_terms(x) + [(-self.b.sdf(x), lambda idx: -self.b.gradient(x[idx]))]

    def bounds(self):
        return self.a.bounds()


class Intersection(_Binary):
    """Points in both ``a`` and ``b``."""

    def sdf(self, x):
        return np.maximum(self.a.sdf(x), self.b.sdf(x))

    def wall_terms(self, x):
        return self.a.wall_terms(x) + self.b.wall_terms(x)

    def bounds(self):
        (l1, h1), (l2, h2) = self.a.bounds(), self.b.bounds()
        return np.maximum(l1, l2), np.minimum(h1, h2)


class Union(_Binary):
    """Points in ``a`` or ``b``."""

    def sdf(self, x):
        return np.minimum(self.a.sdf(x), self.b.sdf(x))

    def bounds(self):
        (l1, h1), (l2, h2) = self.a.bounds(), self.b.bounds()
        return np.minimum(l1, l2), np.maximum(h1, h2)


class GridShape(Shape):
    """Signed distance field of an arbitrary predicate, sampled on a regular grid.

    The predicate is evaluated (``pred(point, 0)``) at the centres of voxels of size
    ``voxel`` covering ``bounds`` enlarged by two voxels; the signed distance comes from
    Euclidean distance transforms of the inside and outside masks and is interpolated
    trilinearly. Error: about one voxel near the boundary. Outside the grid the distance to
    the grid box is returned (a lower bound with the right sign).
    """

    def __init__(self, predicate, bounds, voxel, max_points=4_000_000):
        from scipy import ndimage
        lo, hi = (np.asarray(b, dtype=float) for b in bounds)
        if not np.all(np.isfinite(lo)) or not np.all(np.isfinite(hi)):
            raise ValueError("GridShape needs finite bounds; pass the container's bounds")
        voxel = float(voxel)
        lo, hi = lo - 2 * voxel, hi + 2 * voxel
        shape = np.maximum(np.ceil((hi - lo) / voxel).astype(int), 2)
        if np.prod(shape) > max_points:
            voxel *= (np.prod(shape) / max_points) ** (1 / 3)
            shape = np.maximum(np.ceil((hi - lo) / voxel).astype(int), 2)
            log.warning("GridShape: voxel enlarged to %.3g m to keep %d grid points", voxel,
                        np.prod(shape))
        self.lo, self.voxel, self.shape = lo, voxel, tuple(int(s) for s in shape)
        self.hi = lo + voxel * shape
        self._key = ("GridShape", type(predicate).__name__, lo.tolist(), self.hi.tolist(), voxel)
        axes = [lo[k] + voxel * (np.arange(shape[k]) + 0.5) for k in range(3)]
        inside = np.zeros(self.shape, dtype=bool)
        t0 = time.perf_counter()
        for a, xa in enumerate(axes[0]):
            for b, yb in enumerate(axes[1]):
                inside[a, b, :] = [bool(predicate((xa, yb, zc), 0.0)) for zc in axes[2]]
        log.info("GridShape: sampled %d points in %.1f s", inside.size, time.perf_counter() - t0)
        if not inside.any():
            raise ValueError("the predicate contains no grid point: is it empty, or the voxel "
                             "too coarse?")
        d_out = ndimage.distance_transform_edt(~inside, sampling=voxel)
        d_in = ndimage.distance_transform_edt(inside, sampling=voxel)
        # boundary sits half a voxel between an inside and an outside centre
        self.field = np.where(inside, -(d_in - 0.5 * voxel), d_out - 0.5 * voxel)
        self.inside_fraction = float(inside.mean())

    def sdf(self, x):
        from scipy.ndimage import map_coordinates
        x = _pts(x)
        u = (x - self.lo) / self.voxel - 0.5
        v = map_coordinates(self.field, u.T, order=1, mode="nearest")
        q = np.maximum(np.maximum(self.lo - x, x - self.hi), 0.0)
        return v + np.linalg.norm(q, axis=1)

    def bounds(self):
        return self.lo + 2 * self.voxel, self.hi - 2 * self.voxel

    def key(self):
        return self._key


def _sample_in(bounds, n, seed):
    lo, hi = bounds
    return lo + (hi - lo) * np.random.default_rng(seed).random((n, 3))


def _matches(pred, shape, bounds, n=3000, seed=7) -> bool:
    pts = _sample_in(bounds, n, seed)
    s = shape.sdf(pts)
    size = float(np.max(bounds[1] - bounds[0]))
    keep = np.abs(s) > 1e-6 * size
    inside = s[keep] <= 0
    got = np.array([bool(pred(tuple(p), 0.0)) for p in pts[keep]])
    return bool(np.all(got == inside))


def as_shape(predicate, voxel=None, bounds=None) -> Shape:
    """Convert a container description into a :class:`Shape`.

    Parameters
    ----------
    predicate : Shape or YADE predicate
        A :class:`Shape` is returned unchanged. A YADE ``PredicateDifference`` /
        ``PredicateIntersection`` / ``PredicateUnion`` is converted recursively. A primitive
        predicate is matched, from its bounding box, against a box, a sphere and the three
        axis-aligned cylinders, the candidate being accepted only if it agrees with the
        predicate on 3,000 sample points. Anything else becomes a :class:`GridShape`.
    voxel : float, optional
        Voxel size [m] of the :class:`GridShape` fallback; default 1/100 of the largest
        side of ``bounds``.
    bounds : (lo, hi), optional
        Region used for predicates with an infinite bounding box (e.g. ``notInNotch``).
    """
    if isinstance(predicate, Shape):
        return predicate
    name = type(predicate).__name__
    combos = {"PredicateDifference": Difference, "PredicateIntersection": Intersection,
              "PredicateUnion": Union}
    if name in combos:
        lo, hi = (np.asarray(v, dtype=float) for v in predicate.aabb())
        if bounds is None or (np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))):
            bounds = (lo, hi)
        return combos[name](as_shape(predicate.A, voxel, bounds),
                            as_shape(predicate.B, voxel, bounds))
    if not callable(predicate) or not hasattr(predicate, "aabb"):
        raise ValueError(f"cannot use {predicate!r} as a container: pass a yade_electro Shape "
                         "(Cylinder, Box, Sphere, ...) or a YADE predicate (pack.inCylinder, ...)")
    lo, hi = (np.asarray(v, dtype=float) for v in predicate.aabb())
    finite = np.all(np.isfinite(lo)) and np.all(np.isfinite(hi))
    if finite:
        dim, c = hi - lo, 0.5 * (lo + hi)
        cands = [Box(lo, hi)]
        for k in range(3):
            o = [i for i in range(3) if i != k]
            if np.isclose(dim[o[0]], dim[o[1]], rtol=1e-9):
                c1, c2 = c.copy(), c.copy()
                c1[k], c2[k] = lo[k], hi[k]
                cands.append(Cylinder(c1, c2, 0.5 * dim[o[0]]))
        if np.allclose(dim, dim[0], rtol=1e-9):
            cands.append(Sphere(c, 0.5 * dim[0]))
        for cand in cands:
            if _matches(predicate, cand, (lo, hi)):
                return cand
        bounds = (lo, hi)
    if bounds is None:
        raise ValueError(f"the predicate {name} has an infinite bounding box; pass bounds=(lo, hi)")
    b = (np.asarray(bounds[0], float), np.asarray(bounds[1], float))
    if voxel is None:
        voxel = float(np.max(b[1] - b[0])) / 100.0
    log.info("as_shape: %s not recognised, sampling it on a grid (voxel %.3g m)", name, voxel)
    return GridShape(predicate, b, voxel)


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


# =========================================================================================
# Radii
# =========================================================================================
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


def _base_radii(n, r_mean, dispersion, rng) -> np.ndarray:
    if not 0 <= dispersion < 2:
        raise ValueError(f"dispersion must be in [0, 2), got {dispersion} (0.25 = radii in "
                         "r_mean*[0.875, 1.125])")
    return r_mean * (1.0 + dispersion * (rng.random(n) - 0.5))


# =========================================================================================
# Placement: FIRE relaxation of a soft-sphere energy with radius growth (numpy/scipy only)
# =========================================================================================
class _Relaxer:
    """Soft-sphere overlap energy minimiser in units of the mean radius.

    Energy U = 1/2 sum_pairs max(0, s(rho_i + rho_j) - d_ij)^2
             + 1/2 sum_i max(0, sdf(x_i) + s rho_i)^2,
    minimised with FIRE (Bitzek et al. 2006) using a Verlet pair list (cKDTree).
    """

    def __init__(self, shape, rho, r0, skin=0.4):
        self.shape, self.rho, self.r0, self.skin = shape, rho, r0, skin
        self.rho_max = float(rho.max())
        self.pairs = None
        self.x_ref = None
        self.s_ref = None
        self.n_rebuild = 0
        self.n_force = 0

    def _pairs(self, x, s):
        if self.pairs is not None:
            disp = np.sqrt(np.max(np.einsum("ij,ij->i", x - self.x_ref, x - self.x_ref)))
            if 2 * disp + 2 * (s - self.s_ref) * self.rho_max < self.skin:
                return self.pairs
        cut = 2 * s * self.rho_max + self.skin
        self.pairs = cKDTree(x).query_pairs(cut, output_type="ndarray")
        self.x_ref, self.s_ref = x.copy(), s
        self.n_rebuild += 1
        return self.pairs

    def forces(self, x, s):
        """Forces (n, 3) and the largest overlap (sphere-sphere or wall penetration)."""
        self.n_force += 1
        n = x.shape[0]
        p = self._pairs(x, s)
        i, j = p[:, 0], p[:, 1]
        d = x[j] - x[i]
        d2 = np.einsum("ij,ij->i", d, d)
        rs = s * (self.rho[i] + self.rho[j])
        m = d2 < rs * rs
        F = np.zeros((n, 3))
        maxov = 0.0
        energy = 0.0
        if np.any(m):
            i, j, d, rs = i[m], j[m], d[m], rs[m]
            dist = np.sqrt(d2[m])
            ov = rs - dist
            maxov = float(ov.max())
            energy = 0.5 * float(ov @ ov)
            f = d * (ov / np.maximum(dist, 1e-12))[:, None]
            for k in range(3):
                F[:, k] += np.bincount(j, f[:, k], n) - np.bincount(i, f[:, k], n)
        rad = s * self.rho
        for g, normal in self.shape.wall_terms(x * self.r0):
            phi = g / self.r0 + rad
            w = np.flatnonzero(phi > 0)
            if w.size:
                F[w] -= phi[w, None] * normal(w)
                maxov = max(maxov, float(phi[w].max()))
                energy += 0.5 * float(phi[w] @ phi[w])
        self.energy = energy
        return F, maxov

    def minimise(self, x, s, tol, max_steps, dt0=0.1, dt_max=0.5, window=200, stall=0.7):
        """FIRE from ``x`` at scale ``s``. Returns (x, max_overlap, status, steps) where
        status is "ok" (max overlap < tol), "jammed" (the energy fell by less than a factor
        ``stall`` over the last ``window`` steps, or the forces balance with overlaps left)
        or "budget" (max_steps reached)."""
        x = x.copy()
        v = np.zeros_like(x)
        dt, alpha, n_pos = dt0, 0.1, 0
        F, maxov = self.forces(x, s)
        e_hist = []
        for step in range(1, max_steps + 1):
            if maxov < tol:
                return x, maxov, "ok", step
            if step % window == 0:
                e_hist.append(self.energy)
                if len(e_hist) >= 2 and e_hist[-1] > stall * e_hist[-2]:
                    return x, maxov, "jammed", step
            fmax = np.sqrt(np.max(np.einsum("ij,ij->i", F, F)))
            if fmax < 1e-3 * maxov:
                return x, maxov, "jammed", step
            P = np.einsum("ij,ij->", F, v)
            if P > 0:
                vn = np.sqrt(np.einsum("ij,ij->", v, v))
                fn = np.sqrt(np.einsum("ij,ij->", F, F))
                v = (1 - alpha) * v + alpha * vn / max(fn, 1e-300) * F
                n_pos += 1
                if n_pos > 5:
                    dt = min(dt * 1.1, dt_max)
                    alpha *= 0.99
            else:
                v[:] = 0.0
                dt *= 0.5
                alpha, n_pos = 0.1, 0
            v += F * dt
            x += v * dt
            F, maxov = self.forces(x, s)
        return x, maxov, ("ok" if maxov < tol else "budget"), max_steps


def _random_inside(shape, rad, r0, rng, max_rounds=200):
    """Uniform random centres (dimensionless, units of r0) with sdf <= -rad (or <= 0 if a
    sphere does not fit anywhere)."""
    lo, hi = shape.bounds()
    lo, hi = lo / r0, hi / r0
    n = rad.size
    out = np.empty((n, 3))
    todo = np.arange(n)
    for _ in range(max_rounds):
        m = todo.size
        if m == 0:
            return out
        cand = lo + (hi - lo) * rng.random((4 * m + 16, 3))
        sd = shape.sdf(cand * r0) / r0
        ok = cand[sd <= 0]
        sd_ok = sd[sd <= 0]
        take = min(m, ok.shape[0])
        # accept a candidate for a given sphere only if the sphere fits
        fits = sd_ok[:take] <= -rad[todo[:take]]
        idx = todo[:take][fits]
        out[idx] = ok[:take][fits]
        todo = np.concatenate([todo[:take][~fits], todo[take:]])
    raise ValueError("could not place the spheres inside the container: the radii are too "
                     "large for it (ask for more spheres or a smaller r_mean)")


def _jam(shape, rho, r0, rng, *, phi_start, s_max, tol, ds0, ds_min, max_steps, skin, volume):
    """Grow the radius scale ``s`` from ``phi_start`` to jamming (bisection on ``s``)."""
    n = rho.size
    phi_nom = float(np.sum(4 / 3 * np.pi * (rho * r0) ** 3)) / volume  # fraction at s = 1
    s = min(s_max, (phi_start / phi_nom) ** (1 / 3))
    rel = _Relaxer(shape, rho, r0, skin=skin)
    x = _random_inside(shape, s * rho, r0, rng)
    x, ov, status, steps = rel.minimise(x, s, tol, 20 * max_steps)
    total = steps
    if status != "ok":
        raise RuntimeError(f"could not remove the overlaps of the initial random cloud "
                           f"(fraction {phi_start}); max overlap {ov:.3g} r_mean")
    x_ok, s_ok, ds = x, s, ds0
    trials = 0
    while ds >= ds_min and s_ok < s_max:
        s_try = min(s_max, s_ok * (1 + ds))
        x_try, ov, status, steps = rel.minimise(x_ok, s_try, tol, max_steps)
        total += steps
        trials += 1
        log.debug("jam: s=%.5f fraction=%.4f %s in %d steps (ds=%.2g)", s_try,
                  phi_nom * s_try ** 3, status, steps, ds)
        if status == "ok":
            x_ok, s_ok = x_try, s_try
            ds = min(ds * 1.5, 0.05)
        else:
            ds *= 0.5
    info = dict(fire_steps=int(total), trials=trials, pair_rebuilds=rel.n_rebuild,
                radius_scale=float(s_ok))
    return x_ok, s_ok, info


# =========================================================================================
# Result, cache, public placement entry point
# =========================================================================================
@dataclass(frozen=True, eq=False)
class SpherePacking:
    """Spheres filling a container (placement only, no bonds).

    Attributes
    ----------
    centers : (n, 3) float array
        Sphere centres [m].
    radii : (n,) float array
        Sphere radii [m].
    container_volume : float
        Volume of the container [m^3].
    volume_method : str
        ``"exact"`` or the Monte Carlo settings used for ``container_volume``.
    volume_fraction : float
        ``sum(4/3 pi r^3) / container_volume``.
    seed : int
        Seed of the random generator (radii and initial positions).
    r_mean : float
        Mean of ``radii`` [m].
    r_mean_requested : float
        Eq. 1 radius (from ``n``) or the ``r_mean`` asked for [m]; the spheres are scaled
        by ``radius_scale`` from it (< 1 when the packing jams first).
    radius_scale : float
        ``radii / (radii drawn at r_mean_requested)``.
    max_overlap : float
        Largest overlap ``r_i + r_j - d_ij`` between spheres, or penetration of the
        container wall, divided by ``r_mean`` (<= 0 means no overlap).
    time_s : float
        Wall time of the generation [s] (of the original run when read from the cache).
    from_cache : bool
        True when read from the disk cache.
    params : dict
        Every parameter of the generation (also the cache key) and solver counters.
    shape : Shape
        The container (not stored in the cache; the caller's).
    """

    centers: np.ndarray
    radii: np.ndarray
    container_volume: float
    volume_method: str
    volume_fraction: float
    seed: int
    r_mean: float
    r_mean_requested: float
    radius_scale: float
    max_overlap: float
    time_s: float
    from_cache: bool = False
    params: dict = field(default_factory=dict)
    shape: Shape = field(default=None, repr=False)

    @property
    def n(self) -> int:
        return int(self.radii.size)

    def distance_to_surface(self, points=None) -> np.ndarray:
        """Distance of ``points`` (default: the centres) to the container boundary [m]
        (>= 0 inside)."""
        return -self.shape.sdf(self.centers if points is None else points)


def _default_cache_dir() -> Path:
    env = os.environ.get("YADE_ELECTRO_CACHE")
    return Path(env) if env else Path.home() / ".cache" / "yade_electro"


def _max_overlap(centers, radii, shape) -> float:
    """Largest sphere-sphere overlap or wall penetration [m] (negative: none)."""
    tree = cKDTree(centers)
    p = tree.query_pairs(2 * radii.max(), output_type="ndarray")
    worst = -np.inf
    if len(p):
        d = np.linalg.norm(centers[p[:, 1]] - centers[p[:, 0]], axis=1)
        worst = float(np.max(radii[p[:, 0]] + radii[p[:, 1]] - d))
    if shape is not None:
        worst = max(worst, float(np.max(shape.sdf(centers) + radii)))
    return worst


def _shrink_to_remove_overlaps(centers, radii, shape) -> float:
    """Smallest relative shrink ``eps`` of all radii after which no pair overlaps and no
    sphere crosses the container's wall constraints (plus 1e-9 for rounding)."""
    eps = 0.0
    p = cKDTree(centers).query_pairs(2 * radii.max(), output_type="ndarray")
    if len(p):
        d = np.linalg.norm(centers[p[:, 1]] - centers[p[:, 0]], axis=1)
        rs = radii[p[:, 0]] + radii[p[:, 1]]
        eps = max(eps, float(np.max((rs - d) / rs)))
    for g, _ in shape.wall_terms(centers):
        eps = max(eps, float(np.max((g + radii) / radii)))
    return eps + 1e-9 if eps > 0 else 0.0


def dense_packing(predicate, n=None, r_mean=None, dispersion=0.25, seed=0, cache_dir=None,
                  **opts) -> SpherePacking:
    """Fill a container densely with spheres (placement only; numpy/scipy, no YADE).

    The radii are uniform in ``r_mean * [1 - dispersion/2, 1 + dispersion/2]``. Random
    centres are relaxed with FIRE on a soft-sphere overlap energy, including the exact
    container wall, while the radii are scaled up; the scale is bisected until the packing
    jams (O'Hern et al. 2003). The last unjammed state is kept and shrunk by the tiny
    factor that removes its residual overlaps, so the spheres do not overlap, lie inside the
    container and touch its walls.

    Parameters
    ----------
    predicate : Shape or YADE predicate
        The container (see :func:`as_shape`), e.g. ``Cylinder((0,0,0), (0,0,5e-3), 1e-3)``
        or ``pack.inCylinder((0,0,0), (0,0,5e-3), 1e-3)``.
    n : int, optional
        Wanted number of spheres; ``r_mean`` then follows paper eq. 1 with ``fraction``.
    r_mean : float, optional
        Wanted mean radius [m] (instead of ``n``); ``n = round(fraction V / (4/3 pi
        r_mean^3))``.
    dispersion : float
        Relative width of the uniform radius distribution (paper: 0.25).
    seed : int
        Seed of ``numpy.random.default_rng`` (radii and initial positions).
    cache_dir : str or Path or False, optional
        Where results are cached as ``.npz`` (key: hash of all parameters); default
        ``$YADE_ELECTRO_CACHE`` or ``~/.cache/yade_electro``. ``False`` disables the cache.
    **opts
        ``fraction`` (0.63) of eq. 1; ``method``: ``"jam"`` (default, no overlap, the
        radii stop growing where the packing jams) or ``"target"`` (keep the eq. 1 radii,
        i.e. the requested fraction, and minimise the overlaps, which then remain, a few %
        of r_mean); ``tol`` (2e-3) overlap tolerance of the relaxation in units of r_mean;
        ``ds_min`` (2.5e-4) resolution of the bisection on the radius scale; ``max_steps``
        (3000) FIRE steps per trial; ``phi_start`` (0.35) initial volume fraction; ``skin``
        (0.4) Verlet skin in units of r_mean; ``volume_samples`` (4e6) Monte Carlo points for
        the volume of a non-primitive container.

    Returns
    -------
    SpherePacking

    Raises
    ------
    ValueError
        For inconsistent arguments (both or neither of ``n``/``r_mean``, unknown options,
        a container the spheres cannot fit in).
    """
    defaults = dict(fraction=0.63, method="jam", tol=2e-3, ds_min=2.5e-4, max_steps=3000,
                    phi_start=0.35, skin=0.4, volume_samples=4_000_000)
    unknown = set(opts) - set(defaults)
    if unknown:
        raise ValueError(f"unknown option(s) {sorted(unknown)}; valid: {sorted(defaults)}")
    o = {**defaults, **opts}
    if o["method"] not in ("jam", "target"):
        raise ValueError(f"method must be 'jam' or 'target', got {o['method']!r}")
    if (n is None) == (r_mean is None):
        raise ValueError("give exactly one of n (number of spheres) or r_mean (mean radius [m])")
    shape = as_shape(predicate)
    t0 = time.perf_counter()
    volume, vmethod = container_volume(shape, n_samples=int(o["volume_samples"]))
    if n is not None:
        n = int(n)
        if n < 2:
            raise ValueError(f"n must be >= 2, got {n}")
        r_req = mean_radius_for_count(volume, n, o["fraction"])
    else:
        r_req = float(r_mean)
        if not r_req > 0:
            raise ValueError(f"r_mean must be > 0 [m], got {r_mean}")
        n = int(round(o["fraction"] * volume / (4.0 / 3.0 * np.pi * r_req ** 3)))
        if n < 2:
            raise ValueError(f"r_mean={r_req} m is too large for a container of volume "
                             f"{volume:.4g} m^3 ({n} sphere(s)); use a smaller r_mean")
    key = dict(version=PACKING_VERSION, shape=shape.key(), n=n, r_mean=r_req,
               dispersion=float(dispersion), seed=int(seed),
               **{k: (float(v) if isinstance(v, (int, float)) and k != "max_steps" else v)
                  for k, v in o.items()})
    if isinstance(shape, GridShape) or "GridShape" in json.dumps(key["shape"], default=str):
        key["grid_hash"] = _grid_hash(shape)
    blob = json.dumps(key, sort_keys=True, default=str)
    digest = hashlib.sha256(blob.encode()).hexdigest()[:20]
    path = None
    if cache_dir is not False:
        path = Path(cache_dir) if cache_dir is not None else _default_cache_dir()
        path = path / f"packing-{digest}.npz"
        if path.exists():
            try:
                with np.load(path, allow_pickle=False) as z:
                    meta = json.loads(str(z["meta"]))
                    return SpherePacking(z["centers"], z["radii"], shape=shape,
                                         from_cache=True, **meta)
            except Exception as exc:  # corrupt or old file: regenerate
                log.warning("ignoring unreadable cache file %s (%s)", path, exc)

    rng = np.random.default_rng(int(seed))
    rho = _base_radii(n, 1.0, float(dispersion), rng)  # units of r_req
    log.info("dense_packing: %d spheres, r_mean %.4g m, container %.4g m^3 (%s)", n, r_req,
             volume, vmethod)
    x, s, info = _jam(shape, rho, r_req, rng, phi_start=o["phi_start"], s_max=1.0,
                      tol=o["tol"], ds0=0.02, ds_min=o["ds_min"], max_steps=int(o["max_steps"]),
                      skin=o["skin"], volume=volume)
    if o["method"] == "target" and s < 1.0:
        rel = _Relaxer(shape, rho, r_req, skin=o["skin"])
        x, _, _, steps = rel.minimise(x, 1.0, o["tol"], 10 * int(o["max_steps"]),
                                      window=1000, stall=0.99)
        info["fire_steps"] += steps
        s = 1.0
    centers, radii = x * r_req, s * rho * r_req
    if o["method"] == "jam":
        # shrink by the factor that removes the residual overlaps (<= tol r_mean)
        eps = _shrink_to_remove_overlaps(centers, radii, shape)
        if eps > 0:
            radii = radii * (1.0 - eps)
            s *= 1.0 - eps
    ov = _max_overlap(centers, radii, shape)
    r_m = float(radii.mean())
    info["radius_scale"] = float(s)
    meta = dict(container_volume=volume, volume_method=vmethod,
                volume_fraction=float(np.sum(4.0 / 3.0 * np.pi * radii ** 3) / volume),
                seed=int(seed), r_mean=r_m, r_mean_requested=r_req, radius_scale=float(s),
                max_overlap=ov / r_m, time_s=time.perf_counter() - t0,
                params={**json.loads(blob), **info})
    log.info("dense_packing: fraction %.4f, max overlap %.2g r_mean, %.1f s",
             meta["volume_fraction"], meta["max_overlap"], meta["time_s"])
    if path is not None:
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            tmp = path.with_name(path.name + f".{os.getpid()}.tmp.npz")
            np.savez(tmp, centers=centers, radii=radii, meta=json.dumps(meta))
            os.replace(tmp, path)
        except OSError as exc:
            log.warning("could not write the packing cache %s (%s)", path, exc)
    return SpherePacking(centers, radii, shape=shape, **meta)


def _grid_hash(shape) -> str:
    h = hashlib.sha256()

    def walk(s):
        if isinstance(s, GridShape):
            h.update(np.ascontiguousarray(s.field).tobytes())
        elif isinstance(s, _Binary):
            walk(s.a)
            walk(s.b)
    walk(shape)
    return h.hexdigest()


# =========================================================================================
# Bonds and statistics (numpy)
# =========================================================================================
DEFAULT_DETECTION_FACTOR = 1.04


def bond_pairs(centers, radii, detection_factor=DEFAULT_DETECTION_FACTOR) -> np.ndarray:
    """Pairs YADE bonds with a given interaction detection factor.

    The rule is YADE's (``Ig2_Sphere_Sphere_ScGeom6D.interactionDetectionFactor``): i and j
    are bonded when ``|x_i - x_j| < k (r_i + r_j)``, i.e. when their gap is below
    ``(k - 1)(r_i + r_j)``, about ``2 (k - 1) r_mean``.

    Returns
    -------
    (m, 2) int array with i < j, sorted.
    """
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    k = float(detection_factor)
    if not k >= 1.0:
        raise ValueError(f"detection_factor must be >= 1, got {k}")
    p = cKDTree(c).query_pairs(2 * r.max() * k, output_type="ndarray")
    if len(p) == 0:
        return np.zeros((0, 2), dtype=np.int64)
    d = np.linalg.norm(c[p[:, 1]] - c[p[:, 0]], axis=1)
    p = np.sort(p[d < k * (r[p[:, 0]] + r[p[:, 1]])], axis=1).astype(np.int64)
    return p[np.lexsort((p[:, 1], p[:, 0]))]


def detection_factor_for_coordination(centers, radii, coordination=6.7, k_max=1.5) -> float:
    """Smallest detection factor giving a mean coordination (2 bonds / n) of at least
    ``coordination`` (bisection on :func:`bond_pairs`)."""
    n = len(radii)
    z = lambda k: 2.0 * len(bond_pairs(centers, radii, k)) / n  # noqa: E731
    lo, hi = 1.0, float(k_max)
    if z(hi) < coordination:
        raise ValueError(f"coordination {coordination} not reached even with detection factor "
                         f"{k_max}; the packing is too loose")
    if z(lo) >= coordination:
        return lo
    for _ in range(30):
        mid = 0.5 * (lo + hi)
        lo, hi = (mid, hi) if z(mid) < coordination else (lo, mid)
    return hi


def _eccentricity(centers, radii, edges):
    n = len(radii)
    i, j = edges[:, 0], edges[:, 1]
    deg = np.bincount(edges.ravel(), minlength=n)
    s = np.stack([np.bincount(i, centers[j, k], n) + np.bincount(j, centers[i, k], n)
                  for k in range(3)], axis=1)
    bar = np.where(deg[:, None] > 0, s / np.maximum(deg, 1)[:, None], centers)
    return np.linalg.norm(bar - centers, axis=1) / radii, deg


def packing_statistics(centers, radii, edges, container_volume, distance_to_surface=None,
                       surface_depth=1.5) -> dict:
    """Quality figures of a bonded packing, to compare with paper 000 section 2.1.

    Parameters
    ----------
    centers : (n, 3) array [m]
    radii : (n,) array [m]
    edges : (m, 2) int array
        Bonded pairs (node indices).
    container_volume : float
        [m^3].
    distance_to_surface : (n,) array or callable, optional
        Distance of each centre to the container boundary [m] (or a function of the
        centres returning it, e.g. ``lambda x: -shape.sdf(x)``). Elements closer than
        ``surface_depth * r_mean`` are "surface" elements (1.5 separates the layer touching
        the wall), the others "core".

    Returns
    -------
    dict
        ``n``, ``r_mean`` [m], ``volume_fraction``, ``n_bonds``, ``mean_coordination``
        (2 m / n), ``coordination_histogram`` (counts of 0, 1, 2, ... bonds),
        ``isolated`` (elements without bond), ``e_below_0.4`` / ``e_above_0.7`` /
        ``e_above_1.2`` (fractions of elements), ``e_mean``, ``max_overlap`` (largest
        ``(r_i + r_j - d_ij) / r_mean`` over all pairs, bonded or not; <= 0: none) and, with
        ``distance_to_surface``, ``surface_fraction``, ``e_below_0.4_core``,
        ``e_below_0.4_surface``, ``mean_coordination_core``/``_surface``.
    """
    c = np.asarray(centers, dtype=float)
    r = np.asarray(radii, dtype=float)
    edges = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    n = r.size
    if c.shape != (n, 3):
        raise ValueError(f"centers must have shape ({n}, 3), got {c.shape}")
    if not container_volume > 0:
        raise ValueError(f"container_volume must be > 0 [m^3], got {container_volume}")
    e, deg = _eccentricity(c, r, edges)
    r_mean = float(r.mean())
    out = dict(n=int(n), r_mean=r_mean, r_min=float(r.min()), r_max=float(r.max()),
               volume_fraction=float(np.sum(4.0 / 3.0 * np.pi * r ** 3) / container_volume),
               n_bonds=int(len(edges)), mean_coordination=float(deg.mean()),
               coordination_histogram=np.bincount(deg).tolist(), isolated=int(np.sum(deg == 0)),
               e_mean=float(e.mean()))
    out["e_below_0.4"] = float(np.mean(e < 0.4))
    out["e_above_0.7"] = float(np.mean(e > 0.7))
    out["e_above_1.2"] = float(np.mean(e > 1.2))
    out["max_overlap"] = _max_overlap(c, r, None) / r_mean
    if distance_to_surface is not None:
        d = distance_to_surface(c) if callable(distance_to_surface) else np.asarray(distance_to_surface)
        surf = d < surface_depth * r_mean
        out["surface_fraction"] = float(surf.mean())
        out["e_below_0.4_core"] = float(np.mean(e[~surf] < 0.4)) if np.any(~surf) else float("nan")
        out["e_below_0.4_surface"] = float(np.mean(e[surf] < 0.4)) if np.any(surf) else float("nan")
        out["mean_coordination_core"] = float(deg[~surf].mean()) if np.any(~surf) else float("nan")
        out["mean_coordination_surface"] = float(deg[surf].mean()) if np.any(surf) else float("nan")
    return out


# =========================================================================================
# YADE: bodies and cohesive bonds
# =========================================================================================
def steel_304L(**overrides):
    """A ``CohFrictMat`` for 304L stainless steel (E = 210 GPa, nu = 0.3, 7900 kg/m^3).

    The bond strengths (``normalCohesion = shearCohesion = 5.2e8`` Pa, about the tensile
    strength) and the friction angle (atan 0.5) are placeholders, not a calibration of the
    bonded model; calibrate them (e.g. on a tensile test) before any fracture study.
    """
    from yade.wrapper import CohFrictMat
    kw = dict(young=210e9, poisson=0.3, density=7900.0, frictionAngle=float(np.arctan(0.5)),
              isCohesive=True, normalCohesion=5.2e8, shearCohesion=5.2e8,
              momentRotationLaw=True, label="steel_304L")
    kw.update(overrides)
    return CohFrictMat(**kw)


def add_bonded_packing(packing, material=None, detection_factor=DEFAULT_DETECTION_FACTOR,
                       engines="default", damping=0.2, dt_safety=0.5, color=None):
    """Add a packing to ``O.bodies`` and bond neighbours with cohesive YADE interactions.

    Every pair with ``|x_i - x_j| < detection_factor (r_i + r_j)`` (see :func:`bond_pairs`)
    is bonded by YADE: one step with an engine list whose ``Bo1_Sphere_Aabb.
    aabbEnlargeFactor`` and ``Ig2_Sphere_Sphere_ScGeom6D.interactionDetectionFactor``
    equal ``detection_factor`` and whose Ip2 sets the cohesion now; no integrator runs
    during that step, so nothing moves. The factors are then reset to 1 and cohesion is not
    given to later contacts. With ``CohFrictMat``, each bond's reference normal
    displacement (``CohFrictPhys.unp``) is set to its initial penetration (negative across
    a gap), so the bonded packing starts stress-free instead of pulling the gaps shut.

    Parameters
    ----------
    packing : SpherePacking
        From :func:`dense_packing`.
    material : yade Material or int or str, optional
        A ``CohFrictMat`` (default :func:`steel_304L`) or ``JCFpmMat`` instance, or the id
        or label of a material already in ``O.materials``.
    detection_factor : float
        >= 1; 1.04 (gap below ~8 % of r_mean) gives the paper's coordination of 6.7 on the
        5,000-element rod (see docs/packing.md).
    engines : "default" or list or None
        ``"default"``: ForceResetter, InsertionSortCollider, InteractionLoop with the
        cohesive law, NewtonIntegrator(damping) and ``O.dt = dt_safety * PWaveTimeStep()``.
        A list: installed as ``O.engines`` after bonding (its functors must accept the
        bond types: ScGeom6D + CohFrictPhys, or ScGeom + JCFpmPhys). None: the bonding
        engines are left in place (factors reset to 1, no integrator) and ``O.dt`` untouched.
    damping : float
        NewtonIntegrator numerical damping of the default engines.
    dt_safety : float
        Fraction of ``PWaveTimeStep()`` used for ``O.dt`` with the default engines.
    color : 3-tuple, optional
        Colour of the spheres.

    Returns
    -------
    list of int
        Body ids of the spheres, in the order of ``packing.centers``.
    """
    import yade
    from yade import utils
    from yade import wrapper as W
    O = yade.Omega()
    k = float(detection_factor)
    if not k >= 1.0:
        raise ValueError(f"detection_factor must be >= 1, got {k}")
    if material is None:
        mat_id = O.materials.append(steel_304L())
    elif isinstance(material, (int, str)):
        mat_id = O.materials[material].id
    else:
        mat_id = material.id if material.id >= 0 else O.materials.append(material)
    mat = O.materials[mat_id]
    kind = type(mat).__name__
    if kind == "CohFrictMat":
        if not mat.isCohesive:
            raise ValueError("the CohFrictMat must have isCohesive=True to be bonded")
        ig2 = W.Ig2_Sphere_Sphere_ScGeom6D(interactionDetectionFactor=k)
        ip2 = W.Ip2_CohFrictMat_CohFrictMat_CohFrictPhys(setCohesionNow=True,
                                                        setCohesionOnNewContacts=False)
        law = W.Law2_ScGeom6D_CohFrictPhys_CohesionMoment()
    elif kind == "JCFpmMat":
        ig2 = W.Ig2_Sphere_Sphere_ScGeom(interactionDetectionFactor=k)
        ip2 = W.Ip2_JCFpmMat_JCFpmMat_JCFpmPhys(cohesiveTresholdIteration=1)
        law = W.Law2_ScGeom_JCFpmPhys_JointedCohesiveFrictionalPM()
    else:
        raise ValueError(f"material must be a CohFrictMat or a JCFpmMat, got {kind}")
    kw = {} if color is None else {"color": tuple(color)}
    ids = O.bodies.append([utils.sphere(tuple(c), float(r), material=mat_id, **kw)
                           for c, r in zip(packing.centers.tolist(), packing.radii.tolist())])
    bo1 = W.Bo1_Sphere_Aabb(aabbEnlargeFactor=k)
    collider = W.InsertionSortCollider([bo1])
    # the cohesive law must not run during the bonding step: it would break the bonds across
    # gaps before their reference distance (unp) is set. A frictional law that never erases
    # interactions stands in (it handles ScGeom6D/CohFrictPhys through their base classes).
    # (JCFpm stores the initial distance itself, its own law is safe.)
    stand_in = (W.Law2_ScGeom_FrictPhys_CundallStrack(neverErase=True) if kind == "CohFrictMat"
                else law)
    loop = W.InteractionLoop([ig2], [ip2], [stand_in])
    saved_engines, saved_dt = O.engines, O.dt
    newton = W.NewtonIntegrator(damping=damping, dead=True)  # the collider wants one
    O.engines = [W.ForceResetter(), collider, loop, newton]
    O.dt = min(O.dt, utils.PWaveTimeStep()) if O.dt > 0 else utils.PWaveTimeStep()
    O.step()
    O.dt = saved_dt
    bo1.aabbEnlargeFactor = 1.0
    ig2.interactionDetectionFactor = 1.0
    if kind == "CohFrictMat":
        ip2.setCohesionNow = False
    else:
        ip2.cohesiveTresholdIteration = O.iter  # no cohesion for later contacts
    ours = set(ids)
    n_bonds = 0
    for i in O.interactions:
        if i.id1 in ours and i.id2 in ours:
            if kind == "CohFrictMat":
                i.phys.unp = i.geom.penetrationDepth
            n_bonds += 1
    loop.lawDispatcher.functors = [law]
    log.info("add_bonded_packing: %d spheres, %d bonds (detection factor %.4g)", len(ids),
             n_bonds, k)
    if engines == "default":
        newton.dead = False
        O.engines = [W.ForceResetter(), collider, loop, newton]
        O.dt = dt_safety * utils.PWaveTimeStep()
    elif engines is None:
        pass  # bonding engines stay, the integrator still dead
    else:
        O.engines = list(engines)
    del saved_engines
    return list(ids)
