"""Surfaces: which boundary faces a surface boundary condition acts on.

A :class:`SurfaceSelector` picks boundary faces (a point on each and its outward normal);
:class:`Plane` and :class:`OnSurface` are made by ``Shape.face(name)`` and ``Shape.surface()``
(:mod:`yade_electro.geometry.shapes`). Units: m.
"""
import numpy as np

__all__ = ["SurfaceSelector", "Plane", "OnSurface"]


class SurfaceSelector:
    """Picks boundary faces (a point on each and its outward normal) that lie on a surface.

    ``SurfaceSelector(fn)`` wraps ``fn(points (b, 3), normals (b, 3)) -> bool mask``. Made by
    :class:`Plane`, ``Shape.face(name)``, ``Shape.surface()`` and :func:`as_surface`.
    """

    def __init__(self, fn, description="surface"):
        self.fn, self.description = fn, description

    def __call__(self, points, normals) -> np.ndarray:
        return np.asarray(self.fn(np.asarray(points, float), np.asarray(normals, float)), dtype=bool)

    def __repr__(self):
        return self.description


class Plane(SurfaceSelector):
    """The faces on the plane through ``point`` with outward ``normal`` (within ``tol`` [m]),
    facing the same way (normal . n > 0.5)."""

    def __init__(self, point, normal, tol):
        self.point = np.asarray(point, float).reshape(3)
        n = np.asarray(normal, float).reshape(3)
        if not np.linalg.norm(n) > 0:
            raise ValueError("a Plane needs a non-zero normal")
        self.normal = n / np.linalg.norm(n)
        self.tol = float(tol)
        if not self.tol > 0:
            raise ValueError(f"a Plane needs tol > 0 [m], got {tol}")
        super().__init__(self._select, f"Plane(point={tuple(self.point)}, normal={tuple(self.normal)})")

    def _select(self, points, normals):
        return (np.abs((points - self.point) @ self.normal) <= self.tol) & (normals @ self.normal > 0.5)


class OnSurface(SurfaceSelector):
    """The faces on a shape's boundary (``|sdf|`` <= tol)."""

    def __init__(self, shape, tol=None):
        lo, hi = shape.bounds()
        self.shape = shape
        self.tol = float(tol) if tol is not None else 1e-6 * float(np.max(hi - lo))
        super().__init__(lambda p, n: np.abs(shape.sdf(p)) <= self.tol, f"{shape!r}.surface()")
