"""The Voronoi diagram of a point set, as arrays, from a Delaunay triangulation (CGAL's or qhull's).

``scipy.spatial.Voronoi`` returns its regions and ridges as Python lists of lists: at a
million points that is most of the tessellation's time and memory (measured on the lattice
rod of ``bench/bench_scale.py`` at 97,556 elements: 11.9 s of a 19.6 s ``voronoi`` law
setup, 1.46 GB). The Voronoi diagram is the dual of the Delaunay triangulation: its
vertices are the tetrahedra's circumcentres and the face between two points is the polygon
of the circumcentres of the tetrahedra around their Delaunay edge. :func:`tessellate` builds
exactly that with numpy, keeps the faces in CSR form (one row of vertex indices per face)
and computes face areas, centres and extents in chunks, so the memory stays a few hundred
bytes per point.

Degenerate input (cospherical points: a lattice) is triangulated by qhull into several
tetrahedra on one sphere, some of them flat (zero volume). Their circumcentres coincide, so
a face may list one position several times (:meth:`Tessellation.polygons` merges them), and
the Delaunay edges across a cospherical set give faces of zero area (qhull's Voronoi merges
those away; here they have area 0 and callers drop them). A flat tetrahedron has no
circumcentre of its own: it takes its neighbour's (they share the sphere).

Only faces with at least one of the first ``n_real`` points are kept (the others belong to
ghost or far points, whose cells nobody measures). Units: those of the points.
"""
from __future__ import annotations

import dataclasses
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass
from typing import Optional

import numpy as np
from scipy.spatial import Delaunay

__all__ = ["Tessellation", "tessellate", "circumcentres"]

#: the 6 edges of a tetrahedron (vertex positions in a simplex row)
_TET_EDGES = np.array([(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)])
#: faces are processed in chunks of this many rows (bounds the arrays' memory), on
#: :func:`tessellation_threads` threads
CHUNK = 100_000


def _canonical(simplices):
    """Each tetrahedron's vertices in increasing point index: the same four points then give the
    same circumcentre to the last bit whatever order a triangulation listed them in, so two
    tessellations of overlapping point sets agree exactly where they share tetrahedra (a rank's
    region and the whole packing number their points in the same relative order: real points by
    body id, then their ghosts, then the far points). Ordering by coordinates instead did the
    same for the regions but cost the cubic lattice its exactness (face and volume errors of
    9e-12 instead of 2e-14: ``cases/slab_transient.py``)."""
    return np.sort(np.asarray(simplices, dtype=np.int64), axis=1)


def circumcentres(points, simplices, neighbors=None):
    """Circumcentres (T, 3) of tetrahedra (T, 4), each computed from its vertices in increasing
    index (:func:`_canonical`: independent of the triangulation's listing).
    Flat ones (``|det|`` <= 1e-12 of the product of their edge lengths) take a non-flat
    neighbour's circumcentre (``neighbors``: qhull's (T, 4) adjacency, -1 for none); without
    neighbours they are NaN."""
    simplices = _canonical(simplices)
    a = points[simplices[:, 0]]
    u = points[simplices[:, 1]] - a
    v = points[simplices[:, 2]] - a
    w = points[simplices[:, 3]] - a
    vw = np.cross(v, w)
    det = np.einsum("ij,ij->i", u, vw)
    uu, vv, ww = (u * u).sum(axis=1), (v * v).sum(axis=1), (w * w).sum(axis=1)
    flat = np.abs(det) <= 1e-12 * np.sqrt(uu * vv * ww)
    num = uu[:, None] * vw + vv[:, None] * np.cross(w, u) + ww[:, None] * np.cross(u, v)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = a + num / (2.0 * np.where(flat, 1.0, det))[:, None]
    c[flat] = np.nan
    if neighbors is not None and np.any(flat):
        todo = np.flatnonzero(flat)
        for _ in range(64):                          # spread from the non-flat neighbours
            nb = neighbors[todo]
            ok = (nb >= 0) & ~np.isnan(c[np.maximum(nb, 0), 0])
            has = ok.any(axis=1)
            first = nb[np.arange(todo.size), np.argmax(ok, axis=1)]
            c[todo[has]] = c[first[has]]
            todo = todo[~has]
            if todo.size == 0:
                break
    return c


@dataclass(frozen=True, eq=False)
class Tessellation:
    """Voronoi diagram of ``points`` (see module doc).

    Attributes
    ----------
    points : (N, 3) the points
    vertices : (T, 3) Voronoi vertices (circumcentres, one per Delaunay tetrahedron)
    simplices : (T, 4) the tetrahedra (point indices)
    ridge_points : (m, 2) the point pairs of the faces (i < j, i < n_real)
    ridge_start : (m + 1,) CSR offsets into ``ridge_vertex``
    ridge_vertex : vertex indices of each face, unordered, positions possibly repeated
    """
    points: np.ndarray
    vertices: np.ndarray
    simplices: np.ndarray
    ridge_points: np.ndarray
    ridge_start: np.ndarray
    ridge_vertex: np.ndarray
    #: (area, centre, extent) of every face, when computed with the tessellation
    geometry: Optional[tuple] = None
    #: True when each face's vertices are listed in cyclic order (CGAL's edge circulator)
    ordered: bool = False

    @property
    def n_ridges(self) -> int:
        return int(self.ridge_points.shape[0])

    def ridge(self, k: int) -> np.ndarray:
        """Vertex indices of face ``k``."""
        return self.ridge_vertex[self.ridge_start[k]:self.ridge_start[k + 1]]

    def cells_touching(self, vertex_mask) -> np.ndarray:
        """(N,) bool: the points whose cell has a vertex in ``vertex_mask`` (T,)."""
        out = np.zeros(self.points.shape[0], bool)
        out[self.simplices[np.asarray(vertex_mask, bool)].ravel()] = True
        return out

    def polygons(self, rows, normals=None):
        """Padded vertices (r, P, 3) and counts of faces ``rows``: ordered by angle in the
        plane of the face's normal (the pair's direction, or ``normals``), coincident positions
        merged (within 1e-9 of the face's extent). Faces with fewer than 3 distinct vertices
        have count < 3 (zero area)."""
        from .clipping import order_polygons
        rows = np.asarray(rows, dtype=np.int64)
        lo, hi = self.ridge_start[rows], self.ridge_start[rows + 1]
        count = (hi - lo).astype(np.int64)
        P = int(count.max(initial=3))
        valid = np.arange(P)[None, :] < count[:, None]
        idx = np.where(valid, lo[:, None] + np.arange(P)[None, :], 0)
        verts = self.vertices[self.ridge_vertex[np.minimum(idx, max(self.ridge_vertex.size - 1, 0))]]
        verts = np.where(valid[:, :, None], verts, 0.0)
        if normals is None:
            rp = self.ridge_points[rows]
            normals = self.points[rp[:, 1]] - self.points[rp[:, 0]]
            normals = normals / np.linalg.norm(normals, axis=1)[:, None]
        verts = order_polygons(verts, count, normals)
        # merge coincident neighbours in the cyclic order
        valid = np.arange(P)[None, :] < count[:, None]
        cen = verts.sum(axis=1) / np.maximum(count, 1)[:, None]
        ext = np.where(valid, np.linalg.norm(verts - cen[:, None, :], axis=2), 0.0).max(axis=1)
        nxt = (np.arange(P)[None, :] + 1) % np.maximum(count, 1)[:, None]
        step = np.linalg.norm(verts - np.take_along_axis(verts, nxt[:, :, None], axis=1), axis=2)
        keep = valid & (step > 1e-9 * np.maximum(ext, 1e-300)[:, None])
        if not np.all(keep == valid):
            order = np.argsort(~keep, axis=1, kind="stable")
            verts = np.take_along_axis(verts, order[:, :, None], axis=1)
            count = keep.sum(axis=1)
            valid = np.arange(P)[None, :] < count[:, None]
            verts = np.where(valid[:, :, None], verts, 0.0)
            P2 = int(count.max(initial=3))
            verts = verts[:, :P2]
        return verts, count

    def face_geometry(self, rows=None, normals=None, chunk: int = CHUNK):
        """Area, centre and extent of faces ``rows`` (default all): the area of the convex
        polygon, its area centroid (the mean of its vertices when the area is 0) and the
        distance of its farthest vertex from that centre. Computed per vertex count, in
        chunks, with no padding (repeated positions add nothing to either)."""
        if rows is None and normals is None and self.geometry is not None:
            return self.geometry
        rows = np.arange(self.n_ridges) if rows is None else np.asarray(rows, dtype=np.int64)
        if normals is None:
            rp = self.ridge_points[rows]
            normals = self.points[rp[:, 1]] - self.points[rp[:, 0]]
            normals = normals / np.linalg.norm(normals, axis=1)[:, None]
        area, centre, extent = np.zeros(rows.size), np.zeros((rows.size, 3)), np.zeros(rows.size)
        count = self.ridge_start[rows + 1] - self.ridge_start[rows]
        tasks = []
        for k in np.unique(count):
            group = np.flatnonzero(count == k)
            tasks += [(int(k), group[s:s + chunk]) for s in range(0, group.size, chunk)]

        def one(task):
            k, g = task
            idx = self.ridge_start[rows[g]][:, None] + np.arange(k)[None, :]
            v = self.vertices[self.ridge_vertex[idx]]                        # (r, k, 3)
            area[g], centre[g], extent[g] = _convex_polygons(v, normals[g], self.ordered)
        threads = tessellation_threads() if rows.size > chunk else 1
        if threads > 1:                    # numpy releases the GIL in the array work
            with ThreadPoolExecutor(max_workers=threads) as ex:
                list(ex.map(one, tasks))
        else:
            for task in tasks:
                one(task)
        return area, centre, extent


def _convex_polygons(v, normal, ordered=False):
    """Area, area centroid and extent of convex polygons given by unordered vertices (r, k, 3)
    in planes of unit ``normal`` (r, 3) (``ordered``: already in cyclic order). Polygons of area below 1e-9 of their squared extent
    are centred at the mean of their vertices."""
    r, k, _ = v.shape
    mean = v.mean(axis=1)
    if k < 3:
        return np.zeros(r), mean, np.linalg.norm(v - mean[:, None, :], axis=2).max(axis=1)
    q = v - mean[:, None, :]
    a = np.cross(normal, np.array([1.0, 0.0, 0.0]))
    bad = np.linalg.norm(a, axis=1) < 0.1
    a[bad] = np.cross(normal[bad], np.array([0.0, 1.0, 0.0]))
    a /= np.linalg.norm(a, axis=1)[:, None]
    b = np.cross(normal, a)
    x, y = np.einsum("rkj,rj->rk", q, a), np.einsum("rkj,rj->rk", q, b)
    if not ordered:
        order = np.argsort(np.arctan2(y, x), axis=1)
        x, y = np.take_along_axis(x, order, axis=1), np.take_along_axis(y, order, axis=1)
        q = np.take_along_axis(q, order[:, :, None], axis=1)
    # fan triangles from vertex 0, in the polygon's own 2D coordinates
    x1, y1 = x[:, 1:-1] - x[:, :1], y[:, 1:-1] - y[:, :1]
    x2, y2 = x[:, 2:] - x[:, :1], y[:, 2:] - y[:, :1]
    ta = 0.5 * (x1 * y2 - x2 * y1)                                            # (r, k - 2)
    tot = ta.sum(axis=1)
    tc = (q[:, :1, :] + q[:, 1:-1, :] + q[:, 2:, :]) / 3.0                     # (r, k - 2, 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.einsum("rt,rtj->rj", ta, tc) / tot[:, None]
    # a (nearly) zero area has no centroid to speak of: the mean of the vertices then
    spread = np.einsum("rkj,rkj->rk", q, q).max(axis=1)
    c = np.where((np.abs(tot) > 1e-9 * spread)[:, None] & np.isfinite(c), c, 0.0)
    centre = mean + c
    extent = np.linalg.norm(v - centre[:, None, :], axis=2).max(axis=1)
    return np.abs(tot), centre, extent


#: above this many points the tessellation is made in slabs (:func:`tessellate`)
SLAB_POINTS = 120_000


def tessellation_threads() -> int:
    """Threads for the slabs: ``YADE_ELECTRO_TESSELLATION_THREADS``, default the number of
    cores (qhull releases the GIL)."""
    env = os.environ.get("YADE_ELECTRO_TESSELLATION_THREADS")
    if env:
        if not env.isdigit() or int(env) < 1:
            raise ValueError(f"YADE_ELECTRO_TESSELLATION_THREADS must be an integer >= 1, got {env!r}")
        return int(env)
    return max(1, len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1))


def _edges_of(s, keep_lo, N):
    """Delaunay edges (lo, hi) of tetrahedra ``s`` (T, 4) whose ``lo`` passes ``keep_lo``,
    grouped: (unique keys lo * N + hi, CSR starts, tetrahedron of each entry)."""
    T = s.shape[0]
    a = s[:, _TET_EDGES[:, 0]].ravel()
    b = s[:, _TET_EDGES[:, 1]].ravel()
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    tet = np.repeat(np.arange(T, dtype=np.int64), 6)
    keep = keep_lo(lo)
    key = lo[keep] * N + hi[keep]
    tet = tet[keep]
    del a, b, lo, hi, keep
    order = np.argsort(key, kind="stable")
    key, tet = key[order], tet[order]
    first = np.r_[True, key[1:] != key[:-1]] if key.size else np.zeros(0, bool)
    starts = np.flatnonzero(first)
    return key[starts], np.r_[starts, key.size].astype(np.int64), tet


def _whole_cgal(points, n_real):
    """CGAL's triangulation, with the faces' polygons already in cyclic order."""
    from ..native import cgal_delaunay
    N = points.shape[0]
    s, cgal_cc, pairs, counts, around = cgal_delaunay(points, n_real)
    # circumcentres by our formula (relative to a vertex); with CGAL's inexact construction
    # a lattice's cell volumes were off by 5e-12, with this 3.4e-12 (qhull: 5e-15)
    vertices = circumcentres(points, s)
    flat = np.isnan(vertices[:, 0])
    vertices[flat] = cgal_cc[flat]
    del cgal_cc
    src_start = np.r_[0, np.cumsum(counts)].astype(np.int64)
    order = np.argsort(pairs[:, 0] * N + pairs[:, 1])          # faces in key order, as qhull's
    ln = counts[order]
    ridge_start = np.r_[0, np.cumsum(ln)].astype(np.int64)
    gather = np.repeat(src_start[order] - ridge_start[:-1], ln) + np.arange(ridge_start[-1])
    t = Tessellation(points=points, vertices=vertices, simplices=s, ridge_points=pairs[order],
                     ridge_start=ridge_start, ridge_vertex=around[gather], ordered=True)
    return dataclasses.replace(t, geometry=t.face_geometry())


def _whole(points, n_real, backend="qhull"):
    N = points.shape[0]
    if backend == "cgal":
        return _whole_cgal(points, n_real)
    tri = Delaunay(points)
    s = tri.simplices.astype(np.int64)
    vertices = circumcentres(points, s, tri.neighbors)
    del tri
    ukey, ridge_start, tet = _edges_of(s, lambda lo: lo < n_real, N)
    t = Tessellation(points=points, vertices=vertices, simplices=s,
                     ridge_points=np.column_stack([ukey // N, ukey % N]), ridge_start=ridge_start, ridge_vertex=tet)
    return dataclasses.replace(t, geometry=t.face_geometry())


def tessellate(points, n_real: int, n_far: int = 0, slab_points: int = SLAB_POINTS,
               threads: Optional[int] = None, progress=None, backend: Optional[str] = None) -> Tessellation:
    """The :class:`Tessellation` of ``points``, faces of the first ``n_real`` points only.
    The last ``n_far`` points are far bounding points (added to every slab).

    ``backend``: 'cgal' (the compiled helper of :mod:`yade_electro.native`, the whole set at
    once) or 'qhull' (scipy); default :func:`yade_electro.native.delaunay_backend`. The rest
    of this paragraph is the qhull path.

    Above ``slab_points`` points the set is cut into slabs along its longest axis, each
    triangulated with a halo of 2.5 mean spacings on both sides, ``threads`` at a time
    (default :func:`tessellation_threads`); a slab's tetrahedra around the points it owns are
    kept only when their circumspheres stay inside the slab, so the result is the
    tessellation of the whole set (a slab that fails is redone with a wider halo; after
    three failures the whole set is triangulated at once)."""
    points = np.ascontiguousarray(points, dtype=float)
    N = points.shape[0]
    body = N - n_far
    if backend is None:
        from ..native import delaunay_backend
        backend = delaunay_backend(body)
    if backend not in ("cgal", "qhull"):
        raise ValueError(f"backend must be 'cgal' or 'qhull', got {backend!r}")
    if backend == "cgal":
        from ..native import NativeError
        try:
            return _whole(points, n_real, "cgal")
        except NativeError as exc:               # coinciding points: qhull copes with them
            import warnings
            warnings.warn(f"{exc}; tessellating with qhull instead", stacklevel=2)
    if body <= slab_points:
        return _whole(points, n_real)
    X = points[:body]
    lo, hi = X.min(axis=0), X.max(axis=0)
    axis = int(np.argmax(hi - lo))
    z = X[:, axis]
    threads = tessellation_threads() if threads is None else int(threads)
    # as many slabs as it takes to keep each under slab_points, a multiple of the threads
    t_ = max(1, threads)
    k = t_ * int(np.ceil(body / (slab_points * t_)))
    cuts = np.quantile(z, np.linspace(0.0, 1.0, k + 1))
    cuts[0], cuts[-1] = -np.inf, np.inf
    spacing = float(np.prod(np.maximum(hi - lo, 1e-300)) / body) ** (1.0 / 3.0)
    slab_of = np.clip(np.searchsorted(cuts, z, side="right") - 1, 0, k - 1)
    owned_slab = np.full(N, -1, dtype=np.int64)
    owned_slab[:n_real] = slab_of[:n_real]
    far = np.arange(body, N)
    results = [None] * k

    def run(j, halo):
        zl, zh = cuts[j] - halo, cuts[j + 1] + halo
        members = np.flatnonzero((z >= zl) & (z <= zh))
        gidx = np.concatenate([members, far])
        owned_local = owned_slab[gidx] == j
        owned_global = owned_slab == j
        return _slab_run(points, gidx, owned_local, owned_global, zl, zh, axis)

    def job(j):
        halo = 2.5 * spacing
        for _ in range(3):
            r = run(j, halo)
            if r is not None:
                return r
            halo *= 2.0
        return None

    t0 = time.perf_counter()
    with ThreadPoolExecutor(max_workers=max(1, threads)) as ex:
        for done, (j, r) in enumerate(zip(range(k), ex.map(job, range(k))), start=1):
            results[j] = r
            if progress is not None:
                progress(done, k, time.perf_counter() - t0)
    if any(r is None for r in results):
        return _whole(points, n_real)
    verts, simp, keys, starts, tets, off_v, off_e = [], [], [], [], [], 0, 0
    # each face comes from the slab that owns its lower point: no face twice
    for cc, sg, ukey, st, tet, _ in results:
        verts.append(cc)
        simp.append(sg)
        keys.append(ukey)
        starts.append(st[:-1] + off_e)
        tets.append(tet + off_v)
        off_v += cc.shape[0]
        off_e += tet.size
    # faces in key order, as the whole-set path gives them
    ukey = np.concatenate(keys)
    order = np.argsort(ukey, kind="stable")
    st = np.concatenate(starts)
    ln = np.concatenate([np.diff(r[3]) for r in results])
    tet = np.concatenate(tets)
    st, ln, ukey = st[order], ln[order], ukey[order]
    ridge_start = np.r_[0, np.cumsum(ln)].astype(np.int64)
    gather = np.repeat(st - ridge_start[:-1], ln) + np.arange(ridge_start[-1])
    geometry = tuple(np.concatenate([r[5][q] for r in results])[order] for q in range(3))
    return Tessellation(points=points, vertices=np.concatenate(verts), simplices=np.concatenate(simp),
                        ridge_points=np.column_stack([ukey // N, ukey % N]), ridge_start=ridge_start,
                        ridge_vertex=tet[gather], geometry=geometry)


def _slab_run(points, gidx, owned_local, owned_global, lo_z, hi_z, axis):
    """One slab (the points ``gidx`` of ``points``): its Delaunay triangulation, the
    tetrahedra around the points it owns (None when one of them is not certainly one of the
    whole set's), the faces whose lower point it owns, and their geometry."""
    N = points.shape[0]
    P = points[gidx]
    tri = Delaunay(P)
    s = tri.simplices.astype(np.int64)
    cc = circumcentres(P, s, tri.neighbors)
    del tri
    R = np.linalg.norm(cc - P[s[:, 0]], axis=1)
    # a tetrahedron whose circumsphere stays inside the slab's range is one of the whole
    # set: every point that could be inside the sphere is in the slab, and none is
    valid = (cc[:, axis] - R >= lo_z) & (cc[:, axis] + R <= hi_z) & np.isfinite(R)
    touches = owned_local[s].any(axis=1)
    if np.any(touches & ~valid):
        return None
    keep_t = np.flatnonzero(touches)
    sg = gidx[s[keep_t]]
    ukey, starts, tet = _edges_of(sg, lambda lo: owned_global[lo], N)
    # the faces' geometry here, in the thread
    geo = Tessellation(points=None, vertices=cc[keep_t], simplices=sg, ridge_points=None, ridge_start=starts,
                       ridge_vertex=tet)
    rp = np.column_stack([ukey // N, ukey % N])
    nrm = points[rp[:, 1]] - points[rp[:, 0]]
    nrm /= np.linalg.norm(nrm, axis=1)[:, None]
    return cc[keep_t], sg, ukey, starts, tet, geo.face_geometry(np.arange(ukey.size), nrm)
