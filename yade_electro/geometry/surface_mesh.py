"""Shapes from closed triangulated surfaces (STL, gmsh): a particle or a container of any form
(issue 35: grains "from a closed surface mesh").

:class:`MeshShape` checks that the surface is closed (every edge shared by exactly two
triangles, in opposite directions), finds which points of a regular grid lie inside by the
generalised winding number (the solid angles of the triangles seen from the point, Van
Oosterom and Strackee's formula, summed over the triangles and divided by 4 pi: 1 inside,
0 outside), and keeps the signed distance of the grid (Euclidean distance transforms, as
:class:`~yade_electro.geometry.shapes.GridShape`): a :class:`~yade_electro.geometry.shapes.Shape`
for ``dense_packing``, the 'voronoi' law's bounded cells and surface conditions. Within 2.5
voxels of the surface the grid holds the exact distance to the triangles (farther, the
transforms'), interpolated trilinearly (default voxel: 1/64 of the largest side).

:func:`read_stl` reads ASCII and binary STL; a gmsh mesh's surface triangles come from
:func:`yade_electro.fem.gmsh_session.surface_triangles` (``MeshShape(*surface_triangles(path))``).

Units: m.
"""
from __future__ import annotations

import os
import struct

import numpy as np

from ..core.errors import BoundaryConditionError
from .shapes import Shape, _pts

__all__ = ["MeshShape", "read_stl", "winding_number", "check_closed", "mesh_distance"]


def read_stl(path) -> tuple:
    """(vertices (n, 3), triangles (m, 3)) of an STL file, ASCII or binary, with the
    repeated corners merged (coordinates as written, in the file's units: give metres)."""
    path = os.fspath(path)
    with open(path, "rb") as fh:
        data = fh.read()
    if len(data) < 84:
        raise BoundaryConditionError(f"{path!r} is too short for an STL file ({len(data)} bytes)")
    count = struct.unpack("<I", data[80:84])[0]
    if len(data) == 84 + 50 * count:                       # binary
        rec = np.frombuffer(data, dtype=np.dtype([("n", "<f4", 3), ("v", "<f4", (3, 3)), ("a", "<u2")]),
                            count=count, offset=84)
        corners = rec["v"].reshape(-1, 3).astype(float)
    else:
        text = data.decode("ascii", errors="replace")
        rows = [ln.split()[1:4] for ln in text.splitlines() if ln.strip().startswith("vertex")]
        if not rows or len(rows) % 3:
            raise BoundaryConditionError(f"{path!r}: neither a binary STL (80-byte header, count, 50 bytes a "
                                         "triangle) nor an ASCII one ('vertex x y z' lines, three a facet)")
        try:
            corners = np.array(rows, dtype=float)
        except ValueError:
            raise BoundaryConditionError(f"{path!r}: an ASCII STL 'vertex' line that is not three numbers") from None
    if not np.all(np.isfinite(corners)):
        raise BoundaryConditionError(f"{path!r}: coordinates that are not finite")
    vertices, index = np.unique(corners, axis=0, return_inverse=True)
    return vertices, np.asarray(index, np.int64).reshape(-1, 3)


def check_closed(triangles, what: str = "the mesh") -> None:
    """BoundaryConditionError unless every edge of ``triangles`` is shared by exactly two of
    them, in opposite directions (a closed, consistently oriented surface)."""
    t = np.asarray(triangles, np.int64).reshape(-1, 3)
    if t.shape[0] < 4:
        raise BoundaryConditionError(f"{what} has {t.shape[0]} triangles: a closed surface needs at least 4")
    directed = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    undirected = np.sort(directed, axis=1)
    _, counts = np.unique(undirected, axis=0, return_counts=True)
    open_edges = int(np.count_nonzero(counts == 1))
    if open_edges or np.any(counts > 2):
        raise BoundaryConditionError(
            f"{what} is not closed: {open_edges} edge(s) belong to one triangle only and "
            f"{int(np.count_nonzero(counts > 2))} to more than two; a particle's surface must enclose its volume "
            "(close the holes, e.g. in gmsh or MeshLab, and export the whole surface)")
    _, dcounts = np.unique(directed, axis=0, return_counts=True)
    if np.any(dcounts > 1):
        raise BoundaryConditionError(f"{what}: its triangles are not consistently oriented (an edge is walked "
                                     "twice in the same direction); reorient them so that all normals point out")


def winding_number(vertices, triangles, points, chunk: int = None) -> np.ndarray:
    """The generalised winding number of a closed surface at ``points`` (k, 3): the sum of the
    triangles' signed solid angles over 4 pi (1 inside an outward-oriented surface, 0 outside).
    Cost: points x triangles (about 2e6 pairs per chunk)."""
    V = np.asarray(vertices, float)
    T = np.asarray(triangles, np.int64)
    P = _pts(points)
    chunk = max(1, 2_000_000 // max(T.shape[0], 1)) if chunk is None else int(chunk)
    out = np.empty(P.shape[0])
    A0, B0, C0 = V[T[:, 0]], V[T[:, 1]], V[T[:, 2]]
    for s in range(0, P.shape[0], chunk):
        p = P[s:s + chunk, None, :]
        a, b, c = A0[None] - p, B0[None] - p, C0[None] - p
        la, lb, lc = (np.linalg.norm(v, axis=2) for v in (a, b, c))
        num = np.einsum("ijk,ijk->ij", a, np.cross(b, c))
        den = (la * lb * lc + np.einsum("ijk,ijk->ij", a, b) * lc + np.einsum("ijk,ijk->ij", b, c) * la
               + np.einsum("ijk,ijk->ij", c, a) * lb)
        out[s:s + chunk] = (2.0 * np.arctan2(num, den)).sum(axis=1) / (4.0 * np.pi)
    return out


def mesh_distance(points, vertices, triangles) -> np.ndarray:
    """The distance [m] of each of ``points`` (k, 3) to the nearest of ``triangles``: the
    triangles whose centroids could hold the nearest point (within the nearest centroid's
    distance plus twice the largest triangle's reach) are measured exactly
    (:func:`~yade_electro.geometry.contacts.triangle_distance`, compiled)."""
    from scipy.spatial import cKDTree
    from .contacts import triangle_distance
    P = _pts(points)
    tri = np.asarray(vertices, float)[np.asarray(triangles, np.int64)]
    cen = tri.mean(axis=1)
    reach = float(np.max(np.linalg.norm(tri - cen[:, None, :], axis=2)))
    tree = cKDTree(cen)
    d0, _ = tree.query(P)
    out = np.empty(P.shape[0])
    for s in range(0, P.shape[0], 20_000):
        lists = tree.query_ball_point(P[s:s + 20_000], d0[s:s + 20_000] + 2.0 * reach)
        rows = np.repeat(np.arange(len(lists)), [len(x) for x in lists])
        cols = np.fromiter((i for x in lists for i in x), dtype=np.int64, count=rows.size)
        d = triangle_distance(P[s + rows], tri[cols])
        best = np.full(len(lists), np.inf)
        np.minimum.at(best, rows, d)
        out[s:s + len(lists)] = best
    return out


class MeshShape(Shape):
    """The solid a closed triangulated surface encloses (see the module doc).

    Parameters
    ----------
    vertices : (n, 3) [m]; triangles : (m, 3) vertex indices
    voxel : grid spacing [m] of the signed distance (default 1/64 of the largest side)
    name : what messages call it (e.g. the file)
    """

    def __init__(self, vertices, triangles, voxel=None, name: str = "the mesh"):
        from scipy import ndimage
        V = np.asarray(vertices, float).reshape(-1, 3)
        T = np.asarray(triangles, np.int64).reshape(-1, 3)
        if T.size == 0 or T.min() < 0 or T.max() >= V.shape[0]:
            raise BoundaryConditionError(f"{name}: triangle indices out of the {V.shape[0]} vertices")
        check_closed(T, name)
        lo, hi = V.min(axis=0), V.max(axis=0)
        size = float(np.max(hi - lo))
        voxel = size / 64.0 if voxel is None else float(voxel)
        if not (np.isfinite(voxel) and voxel > 0):
            raise BoundaryConditionError(f"{name}: voxel must be finite and > 0 (m), got {voxel!r}")
        lo, hi = lo - 2 * voxel, hi + 2 * voxel
        shape = tuple(int(s) for s in np.maximum(np.ceil((hi - lo) / voxel).astype(int), 2))
        axes = [lo[k] + voxel * (np.arange(shape[k]) + 0.5) for k in range(3)]
        grid = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
        w = winding_number(V, T, grid).reshape(shape)
        inside = np.abs(w) > 0.5                   # either orientation
        if not inside.any():
            raise BoundaryConditionError(f"{name}: no grid point inside (voxel {voxel:.3g} m too coarse for it?)")
        d_out = ndimage.distance_transform_edt(~inside, sampling=voxel)
        d_in = ndimage.distance_transform_edt(inside, sampling=voxel)
        field = np.where(inside, -(d_in - 0.5 * voxel), d_out - 0.5 * voxel)
        near = np.abs(field) < 2.5 * voxel                  # near the surface: the exact distance
        field[near] = np.where(inside[near], -1.0, 1.0) * mesh_distance(grid[near.ravel()], V, T)
        self.field = field
        self.lo, self.hi, self.voxel, self.shape = lo, lo + voxel * np.array(shape), voxel, shape
        self.vertices, self.triangles, self.name = V, T, name
        self._volume = float(abs(np.einsum("ij,ij->i", V[T[:, 0]], np.cross(V[T[:, 1]], V[T[:, 2]])).sum()) / 6.0)
        import hashlib                             # the field itself: a packing cached for it is for it
        self._key = ("MeshShape", name, T.shape[0], voxel, hashlib.sha1(self.field.tobytes()).hexdigest()[:20])

    @classmethod
    def from_file(cls, path, voxel=None) -> "MeshShape":
        """The solid of an STL surface file (ASCII or binary)."""
        V, T = read_stl(path)
        return cls(V, T, voxel=voxel, name=repr(os.fspath(path)))

    def sdf(self, x):
        """Signed distance [m]: the grid's, interpolated; beyond the grid (outside the solid)
        the exact distance to the triangles (the Voronoi vertices of boundary cells reach
        far out, and their tangent planes need the true nearest point)."""
        from scipy.ndimage import map_coordinates
        x = _pts(x)
        u = (x - self.lo) / self.voxel - 0.5
        v = map_coordinates(self.field, u.T, order=1, mode="nearest")
        beyond = np.any((x < self.lo + 0.5 * self.voxel) | (x > self.hi - 0.5 * self.voxel), axis=1)
        if np.any(beyond):
            v[beyond] = mesh_distance(x[beyond], self.vertices, self.triangles)
        return v

    def bounds(self):
        return self.lo + 2 * self.voxel, self.hi - 2 * self.voxel

    def gradient(self, x, h=None) -> np.ndarray:
        """Unit outward normal at points ``x``: central differences over half a voxel (the
        field is trilinear in each voxel), and away from the mesh's centroid where the field
        is flat there."""
        x = _pts(x)
        g = super().gradient(x, 0.5 * self.voxel if h is None else h) * 1.0
        flat = ~np.all(np.isfinite(g), axis=1) | (np.linalg.norm(g, axis=1) < 0.5)
        if np.any(flat):
            d = x[flat] - self.vertices.mean(axis=0)
            n = np.linalg.norm(d, axis=1)
            n[n == 0] = 1.0
            g[flat] = d / n[:, None]
        return g

    @property
    def exact_volume(self):
        """The enclosed volume [m^3] (the divergence theorem on the triangles)."""
        return self._volume

    def wall_curvature(self, x, h=None):
        """Zero [1/m]: the field is interpolated from voxels (as for GridShape)."""
        return np.zeros(_pts(x).shape[0])

    def key(self):
        return self._key
