"""Boundary faces of a packing and surface boundary conditions: which elements a surface of the
container touches, through what area, at what distance.

The bounded Voronoi cells of a packing (:func:`yade_electro.geometry.voronoi.bounded_cells`) close on
the container's surface with *boundary faces* (area, outward normal, centroid). A surface
boundary condition acts on the boundary faces a surface selector picks
(:mod:`yade_electro.geometry.shapes`: ``shape.face('top')``, ``Plane``, a region, a callable):

* an electrode (or a fixed temperature) at a surface connects each element with faces on it
  through the *half-cell* conductance: the finite-volume Dirichlet condition,
  ``sum_f A_f / (rho L_f)`` with ``L_f`` the distance d_f from the element's centre to the
  face's plane (exact for a uniform field across a flat surface), corrected for the wall's
  curvature kappa = k1 + k2 (:func:`half_cell_length`: L = -ln(1 - kappa d) / kappa, exact
  across a cylindrical wall);
* a heat flux acts on the faces' areas; convection acts on them in series with the half cell:
  ``sum_f A_f / (1/h + L_f/lambda)``.

:class:`SurfaceContact` holds, per element touched, the area and the geometric factor
``g = sum_f A_f / d_f`` [m] of a surface; :func:`boundary_areas` gives every element's
boundary-face area and mean outward normal for any container.

Units: metres, m^2.
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..core.errors import BoundaryConditionError
from .shapes import as_surface

__all__ = ["SurfaceContact", "surface_contact", "half_cell_length", "SavedSurface", "SurfaceMembership",
           "check_surface", "boundary_areas", "BoundaryOfGraph"]


@dataclass(frozen=True, eq=False)
class SurfaceContact:
    """The elements a surface touches, and through which boundary faces.

    Attributes
    ----------
    name : str
    nodes : (k,) element indices (of the graph the cells were made for), unique, sorted
    area : (k,) boundary-face area of each on the surface [m^2]
    factor : (k,) half-cell geometric factor sum_f A_f / L_f [m]
    depth : (k,) area-weighted distance from the centre to the surface [m]
    face_area, face_depth : (f,) each boundary face's area [m^2] and half-cell length L_f [m]
        (the distance d_f from the centre to the face, corrected for the wall's curvature
        when the container was known: :func:`half_cell_length`)
    face_slot : (f,) the position in ``nodes`` of each face's element
    """

    name: str
    nodes: np.ndarray
    area: np.ndarray
    factor: np.ndarray
    depth: np.ndarray
    face_area: np.ndarray
    face_depth: np.ndarray
    face_slot: np.ndarray

    @property
    def total_area(self) -> float:
        return float(self.area.sum())

    def convection_area(self, h, conductivity) -> np.ndarray:
        """Per element, the area A_eff [m^2] with h A_eff = sum_f A_f / (1/h + L_f / lambda):
        convection ``h`` [W/(m^2 K)] in series with the half cell (``conductivity`` lambda
        [W/(m K)], a scalar or one per element of the graph)."""
        lam = np.asarray(conductivity, float)
        lam = np.broadcast_to(lam, self.nodes.shape) if lam.ndim == 0 else lam[self.nodes]
        k = self.face_slot
        return np.bincount(k, self.face_area / (1.0 + h * self.face_depth / lam[k]), self.nodes.size)

    def moved_to(self, nodes, keep=None) -> "SurfaceContact":
        """The same contact on another element numbering: ``nodes[s]`` is the new index of
        the element in slot s; ``keep`` (bool per slot) drops elements that are gone."""
        nodes = np.asarray(nodes, dtype=np.int64)
        keep = np.ones(self.nodes.size, bool) if keep is None else np.asarray(keep, bool)
        order = np.argsort(nodes[keep])
        old_slots = np.flatnonzero(keep)[order]
        new_slot = np.full(self.nodes.size, -1, dtype=np.int64)
        new_slot[old_slots] = np.arange(old_slots.size)
        f = new_slot[self.face_slot] >= 0
        return SurfaceContact(self.name, nodes[old_slots], self.area[old_slots], self.factor[old_slots],
                              self.depth[old_slots], self.face_area[f], self.face_depth[f],
                              new_slot[self.face_slot[f]])


#: bounds of kappa d in the curvature correction (beyond them the wall bends on the scale of
#: the cell itself, where no local correction holds)
CURVATURE_LIMITS = (-1.0, 0.5)


def half_cell_length(depth, curvature):
    """Effective length L [m] of a half cell of depth ``depth`` [m] under a wall of curvature
    sum ``curvature`` k1 + k2 [1/m] (> 0 convex seen from the solid, < 0 concave), so that
    its conductance is A / (rho L) with A the face's area on the wall.

    Across a curved wall the current spreads (concave wall) or gathers (convex): the
    parallel surfaces at depth s under the wall have areas A (1 - kappa s + ...), and the
    resistance of the half cell is rho/A int_0^d ds / (1 - kappa s), so
    ``L = -ln(1 - kappa d) / kappa``: exact for a cylindrical wall (a ln(1 + d/a) under a
    hole of radius a, R ln(R / (R - d)) under a rod's side), d + d^2/R to second order under
    a sphere, d on a plane. kappa d is held within ``CURVATURE_LIMITS``."""
    d = np.asarray(depth, float)
    x = np.clip(np.asarray(curvature, float) * d, *CURVATURE_LIMITS)
    small = np.abs(x) < 1e-8
    ratio = np.where(small, 1.0 + 0.5 * x, -np.log1p(-np.where(small, 0.0, x)) / np.where(small, 1.0, x))
    return d * ratio


def surface_contact(cells, pos, surface, name: str = "surface", what: str = "electrode",
                    container=None) -> SurfaceContact:
    """The elements of ``cells`` (BoundedCells of the elements at ``pos``) whose boundary faces
    lie on ``surface`` (see :func:`yade_electro.geometry.shapes.as_surface`); raises
    BoundaryConditionError when it touches none. With the ``container`` (a Shape), each
    face's half cell is corrected for the wall's curvature there (:func:`half_cell_length`);
    without it the wall is taken as flat."""
    sel = as_surface(surface)
    pos = np.asarray(pos, float)
    on = np.asarray(sel(cells.boundary_point, cells.boundary_normal), bool)
    facing = getattr(sel, "normal", None)
    if facing is not None and container is not None and hasattr(container, "gradient") and np.any(on):
        # a plane holds the container's faces that face its way: not the slivers of a wall it
        # cuts across (a plane inside the solid, or given a wide tolerance)
        g = np.asarray(container.gradient(cells.boundary_point[on]), float)
        g = g / np.maximum(np.linalg.norm(g, axis=1), 1e-300)[:, None]
        across = g @ np.asarray(facing, float) <= 0.5
        if np.all(across):
            raise BoundaryConditionError(
                f"{what} {name!r}: the surface {sel!r} crosses the container's surface only where that faces "
                "another way (a plane inside the solid, or a tolerance wider than the elements): give a face of the "
                "container, e.g. container.face('top')")
        on[np.flatnonzero(on)[across]] = False
    if not np.any(on):
        raise BoundaryConditionError(
            f"{what} {name!r}: the surface {sel!r} holds none of the packing's boundary faces (it is not on the "
            "container's surface, or the container is not the packing's): give a face of the container, e.g. "
            "container.face('top'), or a region around it")
    owner = cells.boundary_owner[on]
    area = cells.boundary_area[on]
    d = np.abs(np.einsum("ij,ij->i", cells.boundary_point[on] - pos[owner], cells.boundary_normal[on]))
    # an element centred on the surface itself: a thin half cell, never a zero one
    d = np.maximum(d, 1e-3 * np.sqrt(area))
    length = d
    if container is not None and hasattr(container, "wall_curvature"):
        length = half_cell_length(d, container.wall_curvature(cells.boundary_point[on]))
    nodes = np.unique(owner)
    k = np.searchsorted(nodes, owner)
    A = np.bincount(k, area, nodes.size)
    g = np.bincount(k, area / length, nodes.size)
    depth = np.bincount(k, area * d, nodes.size) / A
    return SurfaceContact(name, nodes, A, g, depth, area, length, k)


def shared_faces(a: SurfaceContact, b: SurfaceContact, ids_a=None, ids_b=None) -> int:
    """How many boundary faces two surface contacts both hold (the same element's face of the
    same area and depth); the elements are compared by index, or by ``ids_a``/``ids_b`` (the
    body ids of each contact's nodes) when given."""
    na = np.asarray(a.nodes if ids_a is None else ids_a)[a.face_slot]
    nb = np.asarray(b.nodes if ids_b is None else ids_b)[b.face_slot]
    common = np.intersect1d(na, nb)
    if not common.size:
        return 0
    ka = {(int(n), float(x), float(y)) for n, x, y in zip(na, a.face_area, a.face_depth) if n in set(common.tolist())}
    return sum((int(n), float(x), float(y)) in ka for n, x, y in zip(nb, b.face_area, b.face_depth))


@dataclass(frozen=True, eq=False)
class SavedSurface:
    """A surface already resolved on a packing, by body id: what an engine saves with the
    scene (the surface selectors themselves hold functions, which cannot be saved). It is
    accepted wherever a surface is."""

    ids: np.ndarray
    contact: SurfaceContact

    def __repr__(self):
        return f"SavedSurface({self.contact.name!r}, {self.ids.size} elements)"


class SurfaceMembership:
    """Which elements a surface condition acts on: resolved on the first graph from the
    bounded cells, then kept by element id (elements that are gone drop out; an error when
    none is left). ``saved`` gives what to keep with a scene."""

    def __init__(self, name: str, surface, what: str = "electrode"):
        self.name, self.what = name, what
        self.surface = surface
        self._ids, self._contact = (surface.ids, surface.contact) if isinstance(surface, SavedSurface) else (None, None)

    @property
    def resolved(self) -> bool:
        return self._ids is not None

    @property
    def saved(self) -> SavedSurface:
        if self._ids is None:
            raise BoundaryConditionError(f"{self.what} {self.name!r}: not resolved on a packing yet")
        return SavedSurface(self._ids, self._contact)

    def contact(self, graph, boundary) -> SurfaceContact:
        """The contact on ``graph`` (``boundary``: a BoundaryOfGraph, used the first time)."""
        if self._ids is None:
            if boundary is None:
                raise BoundaryConditionError(f"{self.what} {self.name!r} is a surface: it needs the solid's container "
                                             "(container=<the Shape>)")
            cells, pos = boundary.cells(graph)
            c = surface_contact(cells, pos, self.surface, self.name, self.what, container=boundary.container)
            self._ids, self._contact = graph.ids[c.nodes].copy(), c
            return c
        present = np.isin(self._ids, graph.ids)
        if not np.any(present):
            raise BoundaryConditionError(f"{self.what} {self.name!r}: none of its elements is left in the packing")
        nodes = np.full(self._ids.size, -1, dtype=np.int64)
        nodes[present] = graph.index_of(self._ids[present])
        return self._contact.moved_to(nodes, present)


def check_surface(surface, what: str):
    """Raise BoundaryConditionError unless ``surface`` is something a surface condition takes."""
    if isinstance(surface, SavedSurface):
        return
    try:
        as_surface(surface)
    except ValueError as exc:
        raise BoundaryConditionError(f"{what}: {exc}") from None


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
    the first graph, or on ``reference`` (ids, pos, radius) when it holds the same elements;
    a later set taken back to the container's frame by the solid's rigid motion since) and
    shared (a 'voronoi' law with the same container gives its own)."""

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
            from .cells import bounded_cells
            from .rigid import back_to_reference
            pos = np.array(graph.pos)
            if self._key is not None:     # the solid moved since: back to the container's frame
                back = back_to_reference(self._ids, self._pos, graph.ids, pos, 1e-9 * float(np.max(graph.radius)))
                pos = pos if back is None else back
            self._cells = bounded_cells(pos, graph.radius, self.container)
            self._pos, self._ids = pos, np.array(graph.ids)
            self._key = key
        return self._cells, self._pos
