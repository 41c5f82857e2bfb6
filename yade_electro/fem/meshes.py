"""Tetrahedral meshes of the validation geometries, with named boundaries and subdomains.

Every builder returns a :class:`skfem.MeshTet` whose ``boundaries`` map names to facet
indices and whose ``subdomains`` map names to element indices. Boxes are structured
(``MeshTet.init_tensor``, no gmsh needed); curved or notched geometries are meshed by gmsh
(OpenCASCADE kernel) and converted. Geometries that do not vary through their thickness
(plate with a source, notched bar, coaxial cylinders, rod) are meshed in 2D and extruded in
layers, which keeps the element count low for the same in-plane resolution and makes the
mesh exactly prismatic along the extrusion (the solution of these problems is invariant
along it, so nothing is lost).

Boundary names
--------------
::

    box            ``x0 x1 y0 y1 z0 z1`` and, along ``axis``, ``end0 end1`` and ``surface`` (the rest)
    rod            ``end0`` (z = 0), ``end1`` (z = L), ``surface`` (lateral)
    coax           ``inner`` (r = r1), ``outer`` (r = r2), ``end0``, ``end1``
    plate          ``bottom`` (y = 0, the ground), ``top``, ``left``, ``right``, ``front`` (z = 0),
                   ``back`` (z = t), ``source`` (the hole, r = d/2 around the centre)
    notched bar    ``end0`` (x = 0), ``end1`` (x = L), ``notch`` (notch faces), ``surface``
                   (every face except the ends; includes ``notch``); subdomain ``notch``
                   (``|x - L/2| <= notch_width/2``, meshed conformingly)

All lengths in metres.
"""
from __future__ import annotations

import functools
import logging
import math
from dataclasses import dataclass

import numpy as np
from skfem import MeshTet

from .gmsh_session import GmshSession as _GmshSession
from .gmsh_session import MeshError

__all__ = ["box_mesh", "rod_mesh", "coax_mesh", "plate_mesh", "notched_bar_mesh",
           "PlateGeometry", "NotchedBarGeometry", "MeshError", "mesh_size"]

logger = logging.getLogger(__name__)


def _positive(**values):
    for name, value in values.items():
        if not (np.isfinite(value) and value > 0):
            raise MeshError(f"{name} must be a positive finite length in m, got {value!r}")


def mesh_size(mesh: MeshTet) -> float:
    """Mean edge length of ``mesh`` [m] (the effective h of an unstructured mesh)."""
    e = mesh.p[:, mesh.edges]
    return float(np.mean(np.linalg.norm(e[:, 1] - e[:, 0], axis=0)))


# --------------------------------------------------------------------------- box (structured)
def box_mesh(lx: float, ly: float, lz: float, h: float | tuple = None, *, n=None,
             axis: int = 0) -> MeshTet:
    """Structured tetrahedral mesh of the box [0, lx] x [0, ly] x [0, lz].

    Parameters
    ----------
    lx, ly, lz : float
        Edge lengths [m].
    h : float, optional
        Target element size [m]; each edge gets ``ceil(l / h)`` divisions.
    n : tuple of 3 int, optional
        Divisions per direction (instead of ``h``).
    axis : int
        Axis of the two electrode faces ``end0`` / ``end1`` (0, 1 or 2).

    Returns
    -------
    skfem.MeshTet
        With boundaries ``x0 x1 y0 y1 z0 z1 end0 end1 surface``.
    """
    _positive(lx=lx, ly=ly, lz=lz)
    lengths = (lx, ly, lz)
    if n is None:
        if h is None:
            raise MeshError("give h or n")
        _positive(h=h)
        n = tuple(max(1, int(math.ceil(l / h - 1e-9))) for l in lengths)
    if len(n) != 3 or min(n) < 1:
        raise MeshError(f"n must be three positive division counts, got {n!r}")
    if axis not in (0, 1, 2):
        raise MeshError(f"axis must be 0, 1 or 2, got {axis!r}")
    mesh = MeshTet.init_tensor(*(np.linspace(0.0, l, k + 1) for l, k in zip(lengths, n)))
    tags = {}
    for d, l in enumerate(lengths):
        tol = 1e-9 * l
        tags["xyz"[d] + "0"] = (lambda x, d=d, tol=tol: np.abs(x[d]) < tol)
        tags["xyz"[d] + "1"] = (lambda x, d=d, l=l, tol=tol: np.abs(x[d] - l) < tol)
    tags["end0"] = tags["xyz"[axis] + "0"]
    tags["end1"] = tags["xyz"[axis] + "1"]
    la, tola = lengths[axis], 1e-9 * lengths[axis]
    tags["surface"] = lambda x: (np.abs(x[axis]) > tola) & (np.abs(x[axis] - la) > tola)
    return mesh.with_boundaries(tags)


# --------------------------------------------------------------------------- gmsh plumbing
def _background_field(gmsh, field):
    """Make ``field`` the mesh size everywhere (points and boundaries do not override it)."""
    gmsh.model.mesh.field.setAsBackgroundMesh(field)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)


def _refined_near_curves(gmsh, curves, size_min, size_max, dist_min, dist_max):
    """Mesh size size_min within dist_min of ``curves``, growing linearly to size_max at
    dist_max (gmsh Distance + Threshold fields), as the background field."""
    f = gmsh.model.mesh.field
    dist = f.add("Distance")
    f.setNumbers(dist, "CurvesList", list(curves))
    f.setNumber(dist, "NumPointsPerCurve", 200)
    thr = f.add("Threshold")
    f.setNumber(thr, "InField", dist)
    f.setNumber(thr, "SizeMin", size_min)
    f.setNumber(thr, "SizeMax", size_max)
    f.setNumber(thr, "DistMin", dist_min)
    f.setNumber(thr, "DistMax", dist_max)
    _background_field(gmsh, thr)


def _extruded_tets(gmsh, surfaces, thickness, h, size_field=None, layers=None):
    """Extrude 2D ``surfaces`` by ``thickness`` along z in layers (default ceil(t / h))
    and mesh; return (p, t)."""
    occ = gmsh.model.occ
    if layers is None:
        layers = max(1, int(math.ceil(thickness / h - 1e-9)))
    if int(layers) < 1:
        raise MeshError(f"layers must be a positive integer, got {layers!r}")
    layers = int(layers)
    occ.extrude(surfaces, 0.0, 0.0, thickness, numElements=[layers], recombine=False)
    occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)
    if size_field is not None:
        size_field(gmsh)
    gmsh.model.mesh.generate(3)
    return _tets_from_gmsh(gmsh)


def _tets_from_gmsh(gmsh):
    node_tags, coords, _ = gmsh.model.mesh.getNodes()
    coords = np.asarray(coords).reshape(-1, 3).T
    types, _, elem_nodes = gmsh.model.mesh.getElements(3)
    types = list(types)
    if 4 not in types or len(types) != 1:
        raise MeshError(f"gmsh produced volume elements of types {types}, expected only "
                        "linear tetrahedra (4)")
    t_tags = np.asarray(elem_nodes[0], dtype=np.int64).reshape(-1, 4).T
    index = np.full(int(np.max(node_tags)) + 1, -1, dtype=np.int64)
    index[np.asarray(node_tags, dtype=np.int64)] = np.arange(len(node_tags))
    t = index[t_tags]
    used, t_new = np.unique(t, return_inverse=True)
    return coords[:, used], t_new.reshape(t.shape)


def _fix_orientation(p, t):
    """Reorder tets to positive volume (skfem's facet normals and mappings like it)."""
    a, b, c, d = (p[:, t[i]] for i in range(4))
    vol = np.einsum("ij,ij->j", np.cross(b - a, c - a, axis=0), d - a)
    if np.any(np.abs(vol) < 1e-30):
        raise MeshError("degenerate (zero-volume) tetrahedra in the mesh")
    neg = vol < 0
    t = t.copy()
    t[1, neg], t[2, neg] = t[2, neg].copy(), t[1, neg].copy()
    return t


def _to_skfem(p, t) -> MeshTet:
    return MeshTet(np.ascontiguousarray(p), np.ascontiguousarray(_fix_orientation(p, t)))


# --------------------------------------------------------------------------- rod / coax
@functools.lru_cache(maxsize=16)
def rod_mesh(radius: float, length: float, h: float, layers: int | None = None) -> MeshTet:
    """Cylinder of ``radius`` around the z axis, from z = 0 to z = ``length``.

    The disk is meshed by gmsh with element size ``h`` (its boundary is a polygon with
    vertices on the circle, so the meshed area is smaller than pi R^2 by O(h^2)) and
    extruded in ``layers`` layers (default ``ceil(length / h)``).

    Returns
    -------
    skfem.MeshTet
        Boundaries ``end0`` (z = 0), ``end1`` (z = L), ``surface``.
    """
    _positive(radius=radius, length=length, h=h)
    if h > radius:
        raise MeshError(f"h = {h} m is larger than the radius {radius} m: refine")
    with _GmshSession() as gmsh:
        disk = gmsh.model.occ.addDisk(0.0, 0.0, 0.0, radius, radius)
        p, t = _extruded_tets(gmsh, [(2, disk)], length, h, layers=layers)
    mesh = _to_skfem(p, t)
    tol = 1e-9 * length
    return mesh.with_boundaries({
        "end0": lambda x: np.abs(x[2]) < tol,
        "end1": lambda x: np.abs(x[2] - length) < tol,
        "surface": lambda x: (np.abs(x[2]) > tol) & (np.abs(x[2] - length) > tol),
    })


@functools.lru_cache(maxsize=16)
def coax_mesh(r_inner: float, r_outer: float, length: float, h: float,
              layers: int | None = None) -> MeshTet:
    """Hollow cylinder r_inner <= r <= r_outer around z, 0 <= z <= length, extruded in
    ``layers`` layers (default ``ceil(length / h)``).

    Returns
    -------
    skfem.MeshTet
        Boundaries ``inner``, ``outer``, ``end0``, ``end1``.
    """
    _positive(r_inner=r_inner, r_outer=r_outer, length=length, h=h)
    if r_inner >= r_outer:
        raise MeshError(f"r_inner ({r_inner}) must be smaller than r_outer ({r_outer})")
    with _GmshSession() as gmsh:
        occ = gmsh.model.occ
        outer = occ.addDisk(0.0, 0.0, 0.0, r_outer, r_outer)
        inner = occ.addDisk(0.0, 0.0, 0.0, r_inner, r_inner)
        ring, _ = occ.cut([(2, outer)], [(2, inner)])
        p, t = _extruded_tets(gmsh, ring, length, h, layers=layers)
    mesh = _to_skfem(p, t)
    tol = 1e-9 * length
    rmid = 0.5 * (r_inner + r_outer)
    side = lambda x: (np.abs(x[2]) > tol) & (np.abs(x[2] - length) > tol)  # noqa: E731
    return mesh.with_boundaries({
        "inner": lambda x: side(x) & (np.hypot(x[0], x[1]) < rmid),
        "outer": lambda x: side(x) & (np.hypot(x[0], x[1]) > rmid),
        "end0": lambda x: np.abs(x[2]) < tol,
        "end1": lambda x: np.abs(x[2] - length) < tol,
    })


# --------------------------------------------------------------------------- plate
@dataclass(frozen=True)
class PlateGeometry:
    """Thick plate grounded on its bottom edge with a cylindrical potential source.

    The plate spans [0, width] x [0, height] x [0, thickness]; the source is a hole of
    ``source_diameter`` through the thickness, centred at ``source_centre`` (x, y), default
    the plate centre; its surface is the electrode ``source``; the face y = 0 is ``bottom``.
    Paper 000 section 3.2 gives only the source diameter (6 mm); the plate size is ours.
    """

    width: float = 40e-3
    height: float = 40e-3
    thickness: float = 5e-3
    source_diameter: float = 6e-3
    source_centre: tuple | None = None

    def __post_init__(self):
        _positive(width=self.width, height=self.height, thickness=self.thickness,
                  source_diameter=self.source_diameter)
        cx, cy = self.centre
        r = 0.5 * self.source_diameter
        if not (r < cx < self.width - r and r < cy < self.height - r):
            raise MeshError(f"the source (centre {self.centre}, radius {r}) must lie "
                            "strictly inside the plate")

    @property
    def centre(self) -> tuple:
        """Source centre (x, y) [m]."""
        if self.source_centre is None:
            return (0.5 * self.width, 0.5 * self.height)
        return tuple(float(c) for c in self.source_centre)

    def control_points(self) -> dict:
        """The two control points of paper 000 (mid-thickness) [m].

        ``mid``: halfway between the ground (y = 0) and the near edge of the source,
        below the source centre; ``corner``: the top-left corner (0, height).
        """
        cx, cy = self.centre
        z = 0.5 * self.thickness
        return {"mid": (cx, 0.5 * (cy - 0.5 * self.source_diameter), z),
                "corner": (0.0, self.height, z)}


@functools.lru_cache(maxsize=16)
def plate_mesh(geometry: PlateGeometry = PlateGeometry(), h: float = 1e-3,
               source_refinement: float = 0.5, layers: int | None = None) -> MeshTet:
    """Mesh of :class:`PlateGeometry` with size ``h``, graded to ``source_refinement * h``
    on the source hole (the potential gradient is largest there), extruded in ``layers``
    layers (default ceil(thickness / h); the potential does not vary through the
    thickness, so few layers lose nothing).

    Returns
    -------
    skfem.MeshTet
        Boundaries ``bottom top left right front back source``.
    """
    g = geometry
    _positive(h=h, source_refinement=source_refinement)
    r = 0.5 * g.source_diameter
    cx, cy = g.centre
    h_src = min(h, source_refinement * h)

    def sizes(gmsh):
        _refined_near_curves(gmsh, hole_curves, h_src, h, 0.0, 2.0 * r)

    with _GmshSession() as gmsh:
        occ = gmsh.model.occ
        rect = occ.addRectangle(0.0, 0.0, 0.0, g.width, g.height)
        disk = occ.addDisk(cx, cy, 0.0, r, r)
        surf, _ = occ.cut([(2, rect)], [(2, disk)])
        occ.synchronize()
        hole_curves = []
        for dim, tag in gmsh.model.getBoundary(surf, oriented=False):
            x0, y0, _, x1, y1, _ = gmsh.model.getBoundingBox(dim, tag)
            if x0 > 1e-9 and x1 < g.width - 1e-9 and y0 > 1e-9 and y1 < g.height - 1e-9:
                hole_curves.append(tag)
        p, t = _extruded_tets(gmsh, surf, g.thickness, h, size_field=sizes,
                              layers=layers)
    mesh = _to_skfem(p, t)
    tw, th, tt = 1e-9 * g.width, 1e-9 * g.height, 1e-9 * g.thickness
    return mesh.with_boundaries({
        "bottom": lambda x: np.abs(x[1]) < th,
        "top": lambda x: np.abs(x[1] - g.height) < th,
        "left": lambda x: np.abs(x[0]) < tw,
        "right": lambda x: np.abs(x[0] - g.width) < tw,
        "front": lambda x: np.abs(x[2]) < tt,
        "back": lambda x: np.abs(x[2] - g.thickness) < tt,
        "source": lambda x: ((np.hypot(x[0] - cx, x[1] - cy) < r + 0.1 * h_src)
                             & (np.abs(x[2]) > tt) & (np.abs(x[2] - g.thickness) > tt)),
    })


# --------------------------------------------------------------------------- notched bar
@dataclass(frozen=True)
class NotchedBarGeometry:
    """Rectangular bar along x with a notch at mid-length, through the thickness (z).

    The bar spans [0, length] x [0, width] x [0, thickness]. ``kind``:

    - ``"rect"``: a slot ``notch_width`` long (x) and ``notch_depth`` deep (y);
    - ``"v"``: a V of opening ``notch_width`` at the edge and depth ``notch_depth``;
    - ``"circular"``: a circular segment of chord ``notch_width`` and depth ``notch_depth``
      (a half disk when depth = width / 2).

    ``sides`` is ``"both"`` (y = 0 and y = width, symmetric) or ``"one"`` (y = 0 only).
    The ligament (narrowest section) is ``width - 2 depth`` (both) or ``width - depth`` wide.
    """

    length: float = 10e-3
    width: float = 2e-3
    thickness: float = 2e-3
    notch_width: float = 1e-3
    notch_depth: float = 0.5e-3
    kind: str = "rect"
    sides: str = "both"

    def __post_init__(self):
        _positive(length=self.length, width=self.width, thickness=self.thickness,
                  notch_width=self.notch_width, notch_depth=self.notch_depth)
        if self.kind not in ("rect", "v", "circular"):
            raise MeshError(f"unknown notch kind {self.kind!r}; known: 'rect', 'v', 'circular'")
        if self.sides not in ("both", "one"):
            raise MeshError(f"sides must be 'both' or 'one', got {self.sides!r}")
        if self.ligament <= 0:
            raise MeshError(f"notches of depth {self.notch_depth} m leave no ligament in a "
                            f"bar {self.width} m wide")
        if self.notch_width >= self.length:
            raise MeshError("the notch is longer than the bar")
        if self.kind == "circular" and self.notch_depth > 0.5 * self.notch_width:
            raise MeshError("a circular notch is at most a half disk: depth <= width / 2")

    @property
    def ligament(self) -> float:
        """Width of the narrowest section [m]."""
        return self.width - self.notch_depth * (2 if self.sides == "both" else 1)

    @property
    def notch_region(self) -> tuple:
        """x range of the notch [m] (the subdomain ``notch``)."""
        c = 0.5 * self.length
        return (c - 0.5 * self.notch_width, c + 0.5 * self.notch_width)

    @property
    def notch_centre(self) -> tuple:
        """Centre of the ligament at mid-thickness [m]."""
        y = 0.5 * self.width if self.sides == "both" else 0.5 * (self.notch_depth + self.width)
        return (0.5 * self.length, y, 0.5 * self.thickness)

    def in_notch_cut(self, x, y):
        """True where (x, y) is inside a notch (material removed)."""
        a, b = self.notch_region
        c, w, d = 0.5 * self.length, self.notch_width, self.notch_depth
        out = np.zeros(np.broadcast(x, y).shape, dtype=bool)
        edges = [(0.0, 1.0)] + ([(self.width, -1.0)] if self.sides == "both" else [])
        for y0, s in edges:
            depth = s * (y - y0)  # distance into the bar from that edge
            if self.kind == "rect":
                out |= (x > a) & (x < b) & (depth < d)
            elif self.kind == "v":
                out |= depth < d * (1.0 - np.abs(x - c) / (0.5 * w))
            else:
                rc = (0.25 * w * w + d * d) / (2.0 * d)   # circle through the chord ends
                out |= np.hypot(x - c, depth - (d - rc)) < rc
        return out


def _notch_tools(occ, g: NotchedBarGeometry):
    c, w, d, W = 0.5 * g.length, g.notch_width, g.notch_depth, g.width
    tools = []
    edges = [(0.0, 1.0)] + ([(W, -1.0)] if g.sides == "both" else [])
    big = 0.5 * d  # overshoot outside the bar, so the cut is clean
    for y0, s in edges:
        if g.kind == "rect":
            ylo = y0 - big if s > 0 else y0 - d
            tools.append((2, occ.addRectangle(c - 0.5 * w, ylo, 0.0, w, d + big)))
        elif g.kind == "v":
            pts = [occ.addPoint(c - 0.5 * w, y0, 0.0), occ.addPoint(c, y0 + s * d, 0.0),
                   occ.addPoint(c + 0.5 * w, y0, 0.0)]
            out = [occ.addPoint(c + 0.5 * w, y0 - s * big, 0.0),
                   occ.addPoint(c - 0.5 * w, y0 - s * big, 0.0)]
            ring = pts + out
            lines = [occ.addLine(ring[i], ring[(i + 1) % len(ring)]) for i in range(len(ring))]
            tools.append((2, occ.addPlaneSurface([occ.addCurveLoop(lines)])))
        else:
            rc = (0.25 * w * w + d * d) / (2.0 * d)
            tools.append((2, occ.addDisk(c, y0 + s * (d - rc), 0.0, rc, rc)))
    return tools


@functools.lru_cache(maxsize=16)
def notched_bar_mesh(geometry: NotchedBarGeometry = NotchedBarGeometry(), h: float = 0.25e-3,
                     notch_refinement: float = 0.5, layers: int | None = None) -> MeshTet:
    """Mesh of :class:`NotchedBarGeometry`: size ``h`` away from the notch,
    ``notch_refinement * h`` within one notch width of it, extruded in ``layers``
    (default ceil(thickness / h)). The planes x = L/2 +- notch_width/2 are mesh faces,
    so the subdomain ``notch`` is exact.

    Returns
    -------
    skfem.MeshTet
        Boundaries ``end0 end1 notch surface``; subdomain ``notch``.
    """
    g = geometry
    _positive(h=h, notch_refinement=notch_refinement)
    if h > g.ligament:
        raise MeshError(f"h = {h} m is larger than the ligament ({g.ligament} m): refine")
    a, b = g.notch_region
    h_n = min(h, notch_refinement * h)

    def sizes(gmsh):
        f = gmsh.model.mesh.field
        box = f.add("Box")
        f.setNumber(box, "VIn", h_n)
        f.setNumber(box, "VOut", h)
        f.setNumber(box, "XMin", a - g.notch_width)
        f.setNumber(box, "XMax", b + g.notch_width)
        f.setNumber(box, "YMin", -1.0)
        f.setNumber(box, "YMax", g.width + 1.0)
        f.setNumber(box, "ZMin", -1.0)
        f.setNumber(box, "ZMax", g.thickness + 1.0)
        f.setNumber(box, "Thickness", g.notch_width)
        _background_field(gmsh, box)

    with _GmshSession() as gmsh:
        occ = gmsh.model.occ
        parts = [(2, occ.addRectangle(0.0, 0.0, 0.0, a, g.width)),
                 (2, occ.addRectangle(a, 0.0, 0.0, b - a, g.width)),
                 (2, occ.addRectangle(b, 0.0, 0.0, g.length - b, g.width))]
        tools = _notch_tools(occ, g)
        cut, _ = occ.cut(parts, tools)
        surf, _ = occ.fragment(cut, [])
        surf = [dt for dt in surf if dt[0] == 2]
        p, t = _extruded_tets(gmsh, surf, g.thickness, h, size_field=sizes,
                              layers=layers)
    mesh = _to_skfem(p, t)
    tl, tw = 1e-9 * g.length, 1e-9 * g.width
    ends = lambda x: (np.abs(x[0]) < tl) | (np.abs(x[0] - g.length) < tl)  # noqa: E731
    faces = lambda x: ((np.abs(x[1]) < tw) | (np.abs(x[1] - g.width) < tw)  # noqa: E731
                       | (np.abs(x[2]) < 1e-9 * g.thickness)
                       | (np.abs(x[2] - g.thickness) < 1e-9 * g.thickness))
    return mesh.with_boundaries({
        "end0": lambda x: np.abs(x[0]) < tl,
        "end1": lambda x: np.abs(x[0] - g.length) < tl,
        "notch": lambda x: ~ends(x) & ~faces(x),
        "surface": lambda x: ~ends(x),
    }).with_subdomains({
        "notch": lambda x: (x[0] > a - 1e-9 * g.length) & (x[0] < b + 1e-9 * g.length),
    })


# --------------------------------------------------------------------------- cracked bar
@dataclass(frozen=True)
class CrackedBarGeometry:
    """A square bar ``width`` x ``width`` x ``length`` [m] (z along its length) with a planar
    edge crack of zero thickness at z = ``crack_z`` (default mid-length), from the face x = 0
    to x = ``crack_depth`` (default half the width), through the whole thickness in y."""

    width: float = 2e-3
    length: float = 8e-3
    crack_depth: float = 1e-3
    crack_z: float = None

    def __post_init__(self):
        _positive(width=self.width, length=self.length, crack_depth=self.crack_depth)
        if self.crack_z is None:
            object.__setattr__(self, "crack_z", 0.5 * self.length)
        if not (0 < self.crack_depth < self.width) or not (0 < self.crack_z < self.length):
            raise MeshError("the crack must lie inside the bar: 0 < crack_depth < width, 0 < crack_z < length")


@functools.lru_cache(maxsize=16)
def cracked_bar_mesh(geometry: CrackedBarGeometry = CrackedBarGeometry(), h: float = 0.25e-3,
                     front_refinement: float = 0.25) -> MeshTet:
    """Mesh of :class:`CrackedBarGeometry`: size ``h``, ``front_refinement * h`` near the
    crack front (the line x = crack_depth, z = crack_z), the crack a true slit: the bar is
    meshed in four blocks that share the plane z = crack_z, and the nodes of that plane with
    x < crack_depth are duplicated for the blocks above it, so nothing conducts across the
    crack while the ligament (x > crack_depth) and the front itself stay joined.

    Returns
    -------
    skfem.MeshTet
        Boundaries ``end0`` (z = 0), ``end1`` (z = length).
    """
    g = geometry
    _positive(h=h, front_refinement=front_refinement)
    a, zc, W, L = g.crack_depth, g.crack_z, g.width, g.length
    h_f = front_refinement * h

    def sizes(gmsh):
        _refined_near_curves(gmsh, [front], h_f, h, 2 * h_f, 2 * h)

    with _GmshSession() as gmsh:
        occ = gmsh.model.occ
        blocks = [(3, occ.addBox(0, 0, 0, a, W, zc)), (3, occ.addBox(a, 0, 0, W - a, W, zc)),
                  (3, occ.addBox(0, 0, zc, a, W, L - zc)), (3, occ.addBox(a, 0, zc, W - a, W, L - zc))]
        occ.fragment(blocks, [])
        occ.synchronize()
        # the crack front: the curve on x = a, z = zc
        front = None
        tb = 1e-2 * h_f                               # OCC bounding boxes carry a tolerance
        for dim, tag in gmsh.model.getEntities(1):
            bb = gmsh.model.getBoundingBox(dim, tag)
            if abs(bb[0] - a) < tb and abs(bb[3] - a) < tb and abs(bb[2] - zc) < tb and abs(bb[5] - zc) < tb:
                front = tag
        if front is None:
            raise MeshError("could not find the crack front curve in the gmsh model")
        gmsh.option.setNumber("Mesh.MeshSizeMax", h)
        gmsh.option.setNumber("Mesh.MeshSizeMin", 0.0)
        sizes(gmsh)
        gmsh.model.mesh.generate(3)
        p, t = _tets_from_gmsh(gmsh)
    # the slit: nodes of z = zc with x < a (not the front) get a twin for the tets above
    tol = 1e-9 * L
    on_crack = (np.abs(p[2] - zc) < tol) & (p[0] < a - 1e-9 * W)
    cen_z = p[2][t].mean(axis=0)
    twin = np.full(p.shape[1], -1, dtype=np.int64)
    idx = np.flatnonzero(on_crack)
    twin[idx] = p.shape[1] + np.arange(idx.size)
    p = np.concatenate([p, p[:, idx]], axis=1)
    above = cen_z > zc
    t = t.copy()
    sub = t[:, above]
    sub = np.where(twin[sub] >= 0, twin[sub], sub)
    t[:, above] = sub
    mesh = _to_skfem(p, t)
    return mesh.with_boundaries({"end0": lambda x: np.abs(x[2]) < tol, "end1": lambda x: np.abs(x[2] - L) < tol})
