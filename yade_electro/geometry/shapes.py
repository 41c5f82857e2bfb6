"""Container shapes with exact signed distances: the geometry of packings, Voronoi cells and
surface boundary conditions (numpy only, no YADE).

A :class:`Shape` is a closed region of space with a signed distance function (negative
inside), an outward normal (``gradient``) and a bounding box. :class:`Cylinder`, :class:`Box`
and :class:`Sphere` are exact; :class:`Difference`, :class:`Intersection` and :class:`Union`
combine them (a notched bar is ``Box(...) - Box(...)``). Shapes are also YADE-style
predicates (``shape(point, pad)``, ``aabb()``, ``center()``, ``dim()``), so they can be given
to ``yade.pack`` functions. :func:`as_shape` converts YADE predicates (``pack.inCylinder``,
``pack.inAlignedBox``, ``pack.inSphere`` and their combinations) into shapes by duck typing,
without importing YADE; a predicate it cannot identify is sampled on a grid
(:class:`GridShape`).

Units: metres (signed distances, bounds), cubic metres (volumes).
"""
from __future__ import annotations

import logging
import time

import numpy as np

from .surfaces import OnSurface, Plane, SurfaceSelector

__all__ = ["Shape", "Cylinder", "Box", "Sphere", "Difference", "Intersection", "Union", "GridShape",
           "as_shape"]

log = logging.getLogger(__name__)


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

    def wall_curvature(self, x, h=None) -> np.ndarray:
        """Sum of the principal curvatures k1 + k2 [1/m] of the wall at points ``x`` (n, 3)
        on or near it: > 0 where the wall is convex seen from the solid (a rod's side,
        1/R), < 0 where it is concave (a hole, -1/R), 0 on planes.

        The Laplacian of the signed distance of the smooth piece of the wall nearest to each
        point (:meth:`wall_terms`), by central differences of step ``h`` (default 1e-4 of
        the bounding box): the pieces are smooth, so the creases of the whole shape's signed
        distance (edges, corners) do not enter."""
        x = _pts(x)
        if h is None:
            lo, hi = self.bounds()
            h = 1e-4 * float(np.max(hi - lo))
        g0 = np.stack([g for g, _ in self.wall_terms(x)], axis=1)
        lap = -6.0 * g0
        for k in range(3):
            for s in (1.0, -1.0):
                e = np.zeros(3)
                e[k] = s * h
                lap += np.stack([g for g, _ in self.wall_terms(x + e)], axis=1)
        lap /= h * h
        nearest = np.argmin(np.abs(g0), axis=1)
        return lap[np.arange(x.shape[0]), nearest]

    def parts(self) -> tuple:
        """The shapes this one is combined from (empty for a primitive)."""
        return ()

    def surface(self, tol=None) -> "SurfaceSelector":
        """This shape's whole boundary as a surface selector (points within ``tol`` of it;
        default 1e-6 of the bounding box)."""
        return OnSurface(self, tol)

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

    def face(self, name: str, tol=None) -> "SurfaceSelector":
        """One face as a surface selector: ``'top'`` (the end at ``c2``), ``'bottom'`` (at
        ``c1``) or ``'side'`` (the lateral surface)."""
        if name == "top":
            return Plane(self.c2, self.axis, tol if tol is not None else 1e-6 * self.length)
        if name == "bottom":
            return Plane(self.c1, -self.axis, tol if tol is not None else 1e-6 * self.length)
        if name == "side":
            cyl = self
            t = tol if tol is not None else 1e-6 * self.length

            def side(points, normals):
                p = np.asarray(points, float) - cyl.c1
                ax = p @ cyl.axis
                q = p - ax[:, None] * cyl.axis
                rho = np.linalg.norm(q, axis=1)
                radial = np.einsum("ij,ij->i", np.asarray(normals, float), q / np.maximum(rho, 1e-300)[:, None])
                # tangent-plane pieces of a curved wall sit slightly outside it: h^2 / (8 R)
                return (np.abs(rho - cyl.radius) <= max(t, 0.05 * cyl.radius)) & (ax > -t) & (ax < cyl.length + t) \
                    & (radial > 0.5)
            return SurfaceSelector(side, f"{self!r}.face('side')")
        raise ValueError(f"a Cylinder has the faces 'top', 'bottom' and 'side', not {name!r}")

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

    def gradient(self, x, h=None):
        """Exact outward unit normal of the box's signed distance at ``x``."""
        x = _pts(x)
        c, hw = 0.5 * (self.lo + self.hi), 0.5 * (self.hi - self.lo)
        p = x - c
        q = np.abs(p) - hw
        s = np.where(p >= 0, 1.0, -1.0)
        outside = np.maximum(q, 0.0)
        no = np.linalg.norm(outside, axis=1)
        g = np.zeros_like(x)
        out = no > 0
        g[out] = s[out] * outside[out] / no[out, None]
        # inside: the nearest face's normal; at points equally near several faces (edges,
        # corners, a lattice's corner elements) the sdf has no gradient: their normals' mean,
        # as a central difference gives
        qi = q[~out]
        tie = qi >= qi.max(axis=1, keepdims=True) - 1e-12 * float(np.max(hw))
        gi = np.where(tie, s[~out], 0.0)
        g[~out] = gi / np.linalg.norm(gi, axis=1)[:, None]
        return g

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

    def face(self, name: str, tol=None) -> "SurfaceSelector":
        """One face as a surface selector: ``'x-'``, ``'x+'``, ``'y-'``, ``'y+'``, ``'z-'``,
        ``'z+'``."""
        names = {f"{a}{sg}": (k, sg) for k, a in enumerate("xyz") for sg in "-+"}
        if name not in names:
            raise ValueError(f"a Box has the faces {', '.join(names)}, not {name!r}")
        k, sg = names[name]
        n = np.zeros(3)
        n[k] = 1.0 if sg == "+" else -1.0
        p = self.hi.copy() if sg == "+" else self.lo.copy()
        return Plane(p, n, tol if tol is not None else 1e-6 * float(np.max(self.hi - self.lo)))

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

    def parts(self):
        return (self.a, self.b)

    #: the faces of ``b`` face the other way on the combined surface (a difference's cut)
    _flip_b = False

    def face(self, name: str, tol=None) -> "SurfaceSelector":
        """A face of one of the shapes this one is made of: ``name`` as that shape names it
        (``'top'``, ``'x+'``, ...) when one part alone has it, or ``'a.<name>'`` /
        ``'b.<name>'`` for the first or second part (nested: ``'a.b.top'``). A face of what a
        difference cuts away faces out of the remaining solid (its normal turned round)."""
        if not isinstance(name, str):
            raise ValueError(f"a face is named by a string, got {name!r}")
        head, _, rest = name.partition(".")
        if head in ("a", "b") and rest:
            sel = getattr(self, head).face(rest, tol)
            return _turned(sel) if head == "b" and self._flip_b else sel
        found, errors = [], []
        for key, part in (("a", self.a), ("b", self.b)):
            try:
                sel = part.face(name, tol)
            except (AttributeError, ValueError) as exc:
                errors.append(f"{key}: {exc}" if not isinstance(exc, AttributeError) else f"{key}: {part!r} has no faces")
                continue
            found.append((key, _turned(sel) if key == "b" and self._flip_b else sel))
        if len(found) == 1:
            return found[0][1]
        if found:
            raise ValueError(f"both parts of {self!r} have a face {name!r}: name it 'a.{name}' or 'b.{name}'")
        raise ValueError(f"no part of {type(self).__name__} has a face {name!r} ({'; '.join(errors)})")

    def __repr__(self):
        return f"{type(self).__name__}({self.a!r}, {self.b!r})"


def _turned(sel):
    """The surface selector ``sel`` with the faces' normals turned round (a cut's faces)."""
    if isinstance(sel, Plane):
        return Plane(sel.point, -sel.normal, sel.tol)
    return SurfaceSelector(lambda p, n: sel(p, -np.asarray(n, float)), f"{sel!r}, facing out of the difference")


class Difference(_Binary):
    """Points of ``a`` not in ``b`` (a notched bar: ``bar - notch``). The signed distance
    ``max(sdf_a, -sdf_b)`` is exact inside, a bound outside. Faces: ``a``'s, and ``b``'s
    facing out of the remaining solid (:meth:`_Binary.face`)."""

    _flip_b = True

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

    def wall_curvature(self, x, h=None):
        """Zero [1/m]: a field interpolated trilinearly from voxels has no usable second
        derivative, so the walls of a sampled shape are taken as flat (surface conditions on
        them get no curvature correction; see :mod:`yade_electro.geometry.boundary`)."""
        return np.zeros(_pts(x).shape[0])

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


def as_surface(surface) -> SurfaceSelector:
    """A surface selector from a SurfaceSelector, a callable ``f(points, normals) -> mask``,
    or a region (a Shape or YADE predicate: the faces whose centre lies inside it)."""
    if isinstance(surface, SurfaceSelector):
        return surface
    if isinstance(surface, Shape) or (callable(surface) and hasattr(surface, "aabb")):
        region = surface if isinstance(surface, Shape) else None
        if region is not None:
            return SurfaceSelector(lambda p, n: region.sdf(p) <= 0, f"faces inside {region!r}")
        pred = surface
        return SurfaceSelector(lambda p, n: np.array([bool(pred(tuple(x), 0.0)) for x in p], dtype=bool),
                               f"faces inside {type(pred).__name__}")
    if callable(surface):
        return SurfaceSelector(surface, getattr(surface, "__name__", "surface"))
    raise ValueError(f"a surface is a face of a shape (shape.face(...)), a Plane, a region (a Shape or YADE "
                     f"predicate holding the faces) or a callable f(points, normals) -> mask; got {surface!r}")


__all__ += ["as_surface"]

