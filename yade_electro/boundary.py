"""Boundary faces of a packing and surface boundary conditions: which elements a surface of the
container touches, through what area, at what distance.

The bounded Voronoi cells of a packing (:func:`yade_electro.voronoi.bounded_cells`) close on
the container's surface with *boundary faces* (area, outward normal, centroid). A surface
boundary condition acts on the boundary faces a surface selector picks
(:mod:`yade_electro.geometry`: ``shape.face('top')``, ``Plane``, a region, a callable):

* an electrode (or a fixed temperature) at a surface connects each element with faces on it
  through the *half-cell* conductance: the finite-volume Dirichlet condition,
  ``sum_f A_f / (rho d_f)`` with ``d_f`` the distance from the element's centre to the face's
  plane (exact for a uniform field across the surface);
* a heat flux acts on the faces' areas; convection acts on them in series with the half cell:
  ``sum_f A_f / (1/h + d_f/lambda)``.

:class:`SurfaceContact` holds, per element touched, the area and the geometric factor
``g = sum_f A_f / d_f`` [m] of a surface; :func:`boundary_areas` gives every element's
boundary-face area and mean outward normal for any container.

Units: metres, m^2.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import BoundaryConditionError
from .geometry import as_surface

__all__ = ["SurfaceContact", "surface_contact", "boundary_areas", "BoundaryOfGraph"]


@dataclass(frozen=True, eq=False)
class SurfaceContact:
    """The elements a surface touches.

    Attributes
    ----------
    name : str
    nodes : (k,) element indices (of the graph the cells were made for), unique, sorted
    area : (k,) boundary-face area of each on the surface [m^2]
    factor : (k,) half-cell geometric factor sum_f A_f / d_f [m]
    depth : (k,) area-weighted distance from the centre to the surface [m]
    """

    name: str
    nodes: np.ndarray
    area: np.ndarray
    factor: np.ndarray
    depth: np.ndarray

    @property
    def total_area(self) -> float:
        return float(self.area.sum())

    def convection_area(self, h, conductivity) -> np.ndarray:
        """Area A_eff with h A_eff = sum_f A_f / (1/h + d_f / lambda): convection in series with
        the half cell (per element, lambda its conductivity)."""
        lam = np.broadcast_to(np.asarray(conductivity, float), self.nodes.shape) if np.ndim(conductivity) == 0 \
            else np.asarray(conductivity, float)[self.nodes]
        return self._per_node(lambda a, d, k: a / (1.0 + h * d / lam[k]))

    def _per_node(self, fn):
        a, d, owner = self._faces
        k = np.searchsorted(self.nodes, owner)
        return np.bincount(k, fn(a, d, k), self.nodes.size)


def surface_contact(cells, pos, surface, name: str = "surface", what: str = "electrode") -> SurfaceContact:
    """The elements of ``cells`` (BoundedCells of the elements at ``pos``) whose boundary faces
    lie on ``surface`` (see :func:`yade_electro.geometry.as_surface`); raises
    BoundaryConditionError when it touches none."""
    sel = as_surface(surface)
    pos = np.asarray(pos, float)
    on = sel(cells.boundary_point, cells.boundary_normal)
    if not np.any(on):
        raise BoundaryConditionError(
            f"{what} {name!r}: the surface {sel!r} holds none of the packing's boundary faces (it is not on the "
            "container's surface, or the container is not the packing's): give a face of the container, e.g. "
            "container.face('top'), or a region around it")
    owner = cells.boundary_owner[on]
    area = cells.boundary_area[on]
    d = np.abs(np.einsum("ij,ij->i", cells.boundary_point[on] - pos[owner], cells.boundary_normal[on]))
    # an element centred on the surface itself: a thin half cell, never a zero one
    r_floor = 1e-3 * np.sqrt(area)
    d = np.maximum(d, r_floor)
    nodes = np.unique(owner)
    k = np.searchsorted(nodes, owner)
    A = np.bincount(k, area, nodes.size)
    g = np.bincount(k, area / d, nodes.size)
    depth = np.bincount(k, area * d, nodes.size) / A
    out = SurfaceContact(name, nodes, A, g, depth)
    object.__setattr__(out, "_faces", (area, d, owner))
    return out


def boundary_areas(cells, n: int):
    """Per element: boundary-face area [m^2] and area-weighted mean outward normal (unit, 0
    where there is none), from BoundedCells of ``n`` elements."""
    area = np.bincount(cells.boundary_owner, cells.boundary_area, n)
    vec = np.stack([np.bincount(cells.boundary_owner, cells.boundary_area * cells.boundary_normal[:, k], n)
                    for k in range(3)], axis=1)
    nrm = np.linalg.norm(vec, axis=1)
    normal = np.where(nrm[:, None] > 0, vec / np.maximum(nrm, 1e-300)[:, None], 0.0)
    return area, normal


class BoundaryOfGraph:
    """The bounded cells of a graph's elements in a container, made once per element set (on
    the first graph, or on ``reference`` (ids, pos, radius) when it holds the same elements)
    and shared (a 'voronoi' law with the same container gives its own)."""

    def __init__(self, container, law=None):
        if container is None or not (hasattr(container, "sdf") and hasattr(container, "gradient")):
            raise BoundaryConditionError(
                "surface boundary conditions need the solid's container (container=<the Shape>, or a packing "
                "made by dense_packing and bonded by add_bonded_packing, which carries it)")
        self.container, self.law = container, law
        self._key, self._cells, self._pos = None, None, None

    def cells(self, graph):
        """(BoundedCells, positions they were made at) of ``graph``'s elements."""
        if self.law is not None and getattr(self.law, "container", None) is self.container:
            faces = self.law.faces(graph)
            return faces.cells, self.law.reference[1]
        key = graph.ids.tobytes()
        if self._key != key:
            from .voronoi import bounded_cells
            self._cells = bounded_cells(graph.pos, graph.radius, self.container)
            self._pos = np.array(graph.pos)
            self._key = key
        return self._cells, self._pos
