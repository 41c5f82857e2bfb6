"""Convex polytopes clipped by planes, many at once (numpy, vectorised over all polytopes).

A batch of convex polytopes is held as its faces: ordered planar polygons, padded to a
common vertex count, each with the polytope it belongs to and a label (the Voronoi neighbour
behind it, or -1 for a face made by a clipping plane: a *cap*). :func:`clip` cuts every
polytope by at most one plane (``x . n <= n . p``) in one vectorised Sutherland-Hodgman pass
over all faces, and closes each cut polytope with its cap: the polygon of the crossing
points, ordered around their centre. Volumes are the pyramids from a point inside each
polytope (its seed) on its faces.

Used by :mod:`yade_electro.geometry.voronoi` to bound the Voronoi cells of a packing by its container
(cells, faces and boundary faces in one pass).

Units: those of the coordinates (metres, m^2, m^3).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

__all__ = ["polygon_samples", "FaceSet", "order_polygons", "polygon_vector_area", "clip", "volumes", "concat"]


@dataclass
class FaceSet:
    """Faces of a batch of convex polytopes.

    Attributes
    ----------
    verts : (F, P, 3) polygon vertices, ordered (cyclically), padded
    count : (F,) number of vertices of each face (faces with < 3 are empty)
    owner : (F,) polytope of each face
    label : (F,) what is behind the face: a neighbour index >= 0, or -1 for a cap
    plane : (F, 3) unit normal of each face's plane (any orientation)
    """

    verts: np.ndarray
    count: np.ndarray
    owner: np.ndarray
    label: np.ndarray
    plane: np.ndarray

    def keep(self, mask):
        return FaceSet(self.verts[mask], self.count[mask], self.owner[mask], self.label[mask], self.plane[mask])


def _valid(count, P):
    return np.arange(P)[None, :] < count[:, None]


def polygon_samples(verts, count):
    """Points spread over each padded, cyclically ordered polygon (F, P, 3) with ``count``
    vertices: its fan triangles' centroids, its edges' midpoints and the midpoints between
    its centre and its vertices; (F, 3 P, 3) and a (F, 3 P) mask of the real ones. What a
    check of "does a plane or a cell reach into the solid" looks at besides the vertices: at a
    re-entrant edge the solid can cross a face with no vertex in it."""
    verts = np.asarray(verts, float)
    count = np.asarray(count)
    P = verts.shape[1]
    valid = _valid(count, P)
    cen = np.where(valid[:, :, None], verts, 0.0).sum(axis=1) / np.maximum(count, 1)[:, None]
    nxt = np.where((np.arange(P)[None, :] + 1 < count[:, None])[:, :, None], np.roll(verts, -1, axis=1),
                   verts[:, :1])
    samples = np.concatenate([(cen[:, None] + verts + nxt) / 3.0, 0.5 * (verts + nxt), 0.5 * (cen[:, None] + verts)],
                             axis=1)
    ok = np.concatenate([valid, valid, valid], axis=1) & (count >= 3)[:, None]
    return samples, ok


def order_polygons(verts, count, normal):
    """Order the vertices of planar convex polygons (padded (F, P, 3)) by angle around their
    centre in the plane of ``normal`` (F, 3). Returns the reordered array."""
    F, P, _ = verts.shape
    valid = _valid(count, P)
    cen = np.where(valid[:, :, None], verts, 0.0).sum(axis=1) / np.maximum(count, 1)[:, None]
    a = np.cross(normal, np.array([1.0, 0.0, 0.0]))
    bad = np.linalg.norm(a, axis=1) < 0.1
    a[bad] = np.cross(normal[bad], np.array([0.0, 1.0, 0.0]))
    a /= np.linalg.norm(a, axis=1)[:, None]
    b = np.cross(normal, a)
    q = verts - cen[:, None, :]
    ang = np.arctan2(np.einsum("fpk,fk->fp", q, b), np.einsum("fpk,fk->fp", q, a))
    ang = np.where(valid, ang, np.inf)
    order = np.argsort(ang, axis=1, kind="stable")
    return np.take_along_axis(verts, order[:, :, None], axis=1)


def polygon_vector_area(verts, count):
    """Vector area 1/2 sum v_k x v_{k+1} of ordered polygons (F, P, 3) -> (F, 3)."""
    F, P, _ = verts.shape
    valid = _valid(count, P)
    nxt = (np.arange(P)[None, :] + 1) % np.maximum(count, 1)[:, None]
    vn = np.take_along_axis(verts, nxt[:, :, None], axis=1)
    cr = np.cross(verts, vn)
    return 0.5 * np.where(valid[:, :, None], cr, 0.0).sum(axis=1)


def _clip_rows(v, cnt, own, point, normal, size):
    """Sutherland-Hodgman on ordered polygons (f, P, 3): returns (new vertices (f, P + 1, 3),
    new counts, crossing points, their polytopes)."""
    f, P, _ = v.shape
    valid = _valid(cnt, P)
    p, n = point[own], normal[own]
    # vertices within rounding of the plane count as on its inner side: a plane that only
    # touches a polytope (or clips it again) leaves it as it is
    s = np.einsum("fpk,fk->fp", v - p[:, None, :], n)
    s = np.where(np.abs(s) <= 1e-12 * size[own][:, None], 0.0, s)
    nxt = (np.arange(P)[None, :] + 1) % np.maximum(cnt, 1)[:, None]
    s_n = np.take_along_axis(s, nxt, axis=1)
    v_n = np.take_along_axis(v, nxt[:, :, None], axis=1)
    inside, inside_n = s <= 0, s_n <= 0
    keep = inside & valid
    cross = (inside != inside_n) & valid
    with np.errstate(divide="ignore", invalid="ignore"):
        t = np.where(cross, s / (s - s_n), 0.0)
    x = v + (v_n - v) * t[:, :, None]
    # output: vertex k (if kept) then the crossing on edge k (if any), compacted to the front
    out = np.stack([v, x], axis=2).reshape(f, 2 * P, 3)
    mask = np.stack([keep, cross], axis=2).reshape(f, 2 * P)
    slot = np.cumsum(mask, axis=1) - 1
    new = np.zeros((f, P + 1, 3))
    rows = np.broadcast_to(np.arange(f)[:, None], mask.shape)
    new[rows[mask], slot[mask]] = out[mask]
    return new, mask.sum(axis=1), x[cross], np.repeat(own, cross.sum(axis=1))


def clip(faces: FaceSet, point, normal, active, size):
    """Clip the polytopes ``active`` (bool per polytope) by the planes (``point``, ``normal``)
    (one per polytope), keeping ``(x - point) . normal <= 0``, and add their caps.

    ``size`` (per polytope) sets the tolerance of the cap's vertex merging. Returns the new
    FaceSet (empty faces dropped)."""
    F, P, _ = faces.verts.shape
    on = active[faces.owner] & (faces.count >= 3)
    if not np.any(on):
        return faces
    idx = np.flatnonzero(on)
    cnt_all = faces.count[idx]
    # polygons in two groups by vertex count, so that the many small ones are not padded to
    # the few large ones
    small = cnt_all <= 8
    parts = []
    for grp, width in ((small, min(P, 8)), (~small, P)):
        if np.any(grp):
            r = idx[grp]
            parts.append((r, _clip_rows(faces.verts[r, :width], faces.count[r], faces.owner[r], point, normal,
                                        size)))
    P2 = max([P] + [int(nc.max(initial=0)) for _, (_, nc, _, _) in parts])
    verts = np.zeros((F, P2, 3))
    verts[:, :P] = faces.verts
    count = faces.count.copy()
    cps, cowns = [], []
    for r, (nv, nc, xcp, xown) in parts:
        verts[r] = 0.0
        w = min(nv.shape[1], P2)
        verts[r, :w] = nv[:, :w]
        count[r] = nc
        cps.append(xcp)
        cowns.append(xown)
    cp = np.concatenate(cps)
    cown = np.concatenate(cowns)
    # caps: the crossing points of each cut polytope, merged and ordered in its plane
    kept = FaceSet(verts, count, faces.owner, faces.label, faces.plane).keep(count >= 3)
    if cp.shape[0] == 0:
        return kept
    scale = np.maximum(size[cown], 1e-300)
    key = np.column_stack([cown, np.round(cp / (1e-9 * scale[:, None]))])
    _, first = np.unique(key, axis=0, return_index=True)
    cp, cown = cp[first], cown[first]
    srt = np.argsort(cown, kind="stable")
    cp, cown = cp[srt], cown[srt]
    cells, start, ncap = np.unique(cown, return_index=True, return_counts=True)
    good = ncap >= 3
    cells, start, ncap = cells[good], start[good], ncap[good]
    if cells.size == 0:
        return kept
    Pc = int(ncap.max())
    cap = np.zeros((cells.size, Pc, 3))
    row = np.repeat(np.arange(cells.size), ncap)
    take = np.repeat(start, ncap) + (np.arange(row.size) - np.repeat(np.cumsum(ncap) - ncap, ncap))
    pos_in = take - np.repeat(start, ncap)
    cap[row, pos_in] = cp[take]
    cap = order_polygons(cap, ncap, normal[cells])
    caps = FaceSet(cap, ncap, cells, np.full(cells.size, -1), normal[cells])
    Pm = max(kept.verts.shape[1], Pc)
    return FaceSet(np.concatenate([_pad(kept.verts, Pm), _pad(caps.verts, Pm)]),
                   np.concatenate([kept.count, caps.count]), np.concatenate([kept.owner, caps.owner]),
                   np.concatenate([kept.label, caps.label]), np.concatenate([kept.plane, caps.plane]))


def concat(sets) -> "FaceSet":
    """One FaceSet of several (padded to the largest vertex count)."""
    sets = [fs for fs in sets if fs.count.size]
    if not sets:
        return FaceSet(np.zeros((0, 3, 3)), np.zeros(0, np.int64), np.zeros(0, np.int64), np.zeros(0, np.int64),
                       np.zeros((0, 3)))
    P = max(fs.verts.shape[1] for fs in sets)
    return FaceSet(np.concatenate([_pad(fs.verts, P) for fs in sets]), np.concatenate([fs.count for fs in sets]),
                   np.concatenate([fs.owner for fs in sets]), np.concatenate([fs.label for fs in sets]),
                   np.concatenate([fs.plane for fs in sets]))


def _pad(v, P):
    if v.shape[1] == P:
        return v
    out = np.zeros((v.shape[0], P, 3))
    out[:, :v.shape[1]] = v
    return out


def volumes(faces: FaceSet, seeds, n_polytopes):
    """Volume of each polytope: pyramids from its seed (a point inside) on its faces."""
    A = polygon_vector_area(faces.verts, faces.count)
    area = np.abs(np.einsum("fk,fk->f", A, faces.plane))
    h = np.abs(np.einsum("fk,fk->f", faces.verts[:, 0] - seeds[faces.owner], faces.plane))
    return np.bincount(faces.owner, area * h / 3.0, n_polytopes)


def face_areas(faces: FaceSet) -> np.ndarray:
    """Area of each face (F,)."""
    A = polygon_vector_area(faces.verts, faces.count)
    return np.abs(np.einsum("fk,fk->f", A, faces.plane))


__all__ += ["face_areas"]
