"""Contacts of a granular bed found from positions: sphere pairs and sphere-wall contacts.

A bed whose contacts change every step cannot afford to rebuild its networks at each
change. The pairs are kept as a *Verlet list* (the device YADE's collider uses with its
``verletDist``): every pair closer than ``r_i + r_j + skin`` is a candidate edge; a
candidate conducts only while the two spheres overlap (its contact radius is 0 otherwise).
The list holds every contact until some sphere has moved by more than ``skin / 2`` since
it was made (two spheres then may have closed the gap by ``skin``): only then is it made
again. Between two lists a changing contact set is a change of values on a kept structure.

* :func:`candidate_pairs`: the Verlet list (a compiled cell grid; scipy's cKDTree without a
  compiler); :func:`periodic_candidate_pairs` in a periodic cell, with each pair's image;
* :class:`WallGeometry`: planes (YADE ``Wall``), boxes and triangles (``Facet``), in world
  coordinates;
* :func:`wall_overlaps`: the overlap delta = r - (distance from the centre to the wall) of
  each candidate sphere-wall pair (0 when they do not touch);
* :func:`plane_contact_radius`: the contact radius of a sphere on a plane, geometric
  (a^2 = 2 r delta - delta^2) or Hertz (a = sqrt(r delta), R* = r).

Units: metres.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional

import numpy as np

__all__ = ["sphere_tree", "candidate_pairs", "periodic_candidate_pairs", "cell_widths", "new_wall_contacts",
           "max_displacement", "WallGeometry", "wall_candidates", "wall_overlaps", "plane_contact_radius",
           "triangle_distance", "quaternion_matrices", "facet_vertices"]


def _ro(a):
    a = np.ascontiguousarray(a)
    a.setflags(write=False)
    return a


def sphere_tree(pos):
    """A KD-tree of the centres (scipy's cKDTree), to share between the searches of one list."""
    from scipy.spatial import cKDTree
    return cKDTree(np.asarray(pos, dtype=float))


#: radii within this ratio are searched together; a wider spread is split into classes of radii
#: within a factor 2, so that a few large spheres do not widen the search of every small one
#: (one sphere 10 times larger among 20,000: a list in 4.5 s against 22 ms by classes, 30 times
#: larger: 47 s against 20 ms; bench/bench_size_spread.py)
SIZE_CLASS_RATIO = 2.0


def _pairs_closer_than(pos, cut: float, tree=None) -> np.ndarray:
    """Pairs (i < j) of ``pos`` closer than ``cut`` [m]: the compiled cell grid, else
    ``tree`` (a :func:`sphere_tree` of ``pos``, made when None)."""
    pairs = _cell_pairs(pos, cut)                   # (i < j already)
    if pairs is None:
        tree = sphere_tree(pos) if tree is None else tree
        pairs = tree.query_pairs(cut, output_type="ndarray").astype(np.int64)
        pairs.sort(axis=1)
    return pairs


def _pairs_within_reach(pos, radius, skin: float, tree=None) -> np.ndarray:
    """Pairs (i < j, unsorted) closer than a reach that bounds r_i + r_j + skin: 2 r_max +
    skin when the radii are within :data:`SIZE_CLASS_RATIO`, else per pair of size classes
    (each class's largest radii)."""
    r_min, r_max = float(radius.min()), float(radius.max())
    if r_max <= SIZE_CLASS_RATIO * r_min:
        return _pairs_closer_than(pos, 2.0 * r_max + float(skin), tree)
    from scipy.spatial import cKDTree
    cls = np.floor(np.log2(radius / r_min)).astype(np.int64)
    members = [m for m in (np.flatnonzero(cls == k) for k in range(int(cls.max()) + 1)) if m.size]
    reach = [float(radius[m].max()) for m in members]
    trees = [cKDTree(pos[m]) for m in members]
    out = [np.zeros((0, 2), dtype=np.int64)]
    for a, m in enumerate(members):
        if m.size >= 2:
            out.append(m[_pairs_closer_than(pos[m], 2.0 * reach[a] + float(skin), trees[a])])
        for b in range(a + 1, len(members)):
            close = trees[a].sparse_distance_matrix(trees[b], reach[a] + reach[b] + float(skin), output_type="ndarray")
            out.append(np.column_stack([m[close["i"]], members[b][close["j"]]]).astype(np.int64))
    pairs = np.concatenate(out)
    pairs.sort(axis=1)
    return pairs


def candidate_pairs(pos, radius, skin: float, tree=None) -> np.ndarray:
    """Every pair (i < j) with ``|x_i - x_j| < r_i + r_j + skin`` [m], as an (m, 2) array in
    lexicographic order; ``tree``: :func:`sphere_tree` of ``pos`` if already made. Radii
    spread wider than :data:`SIZE_CLASS_RATIO` are searched by size classes."""
    pos = np.asarray(pos, dtype=float)
    radius = np.asarray(radius, dtype=float)
    if pos.shape[0] < 2:
        return np.zeros((0, 2), dtype=np.int64)
    pairs = _pairs_within_reach(pos, radius, skin, tree)
    if pairs.size == 0:
        return np.zeros((0, 2), dtype=np.int64)
    d = np.sqrt(((pos[pairs[:, 0]] - pos[pairs[:, 1]]) ** 2).sum(axis=1))
    pairs = pairs[d < radius[pairs[:, 0]] + radius[pairs[:, 1]] + skin]
    order = np.argsort(pairs[:, 0] * pos.shape[0] + pairs[:, 1], kind="stable")     # lexicographic
    return pairs[order]


def cell_widths(cell) -> np.ndarray:
    """Distances [m] between the opposite faces of a periodic cell whose base vectors [m] are
    the columns of ``cell`` (3, 3) (YADE's ``O.cell.hSize``)."""
    H = np.asarray(cell, dtype=float).reshape(3, 3)
    a, b, c = H[:, 0], H[:, 1], H[:, 2]
    vol = abs(float(np.linalg.det(H)))
    areas = np.array([np.linalg.norm(np.cross(b, c)), np.linalg.norm(np.cross(c, a)), np.linalg.norm(np.cross(a, b))])
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(areas > 0, vol / areas, 0.0)


def periodic_candidate_pairs(pos, radius, skin: float, cell):
    """The Verlet list of spheres in a periodic cell (base vectors [m] the columns of
    ``cell``, YADE's ``O.cell.hSize``, sheared or not): every pair (i < j) some image of
    which is closer than ``r_i + r_j + skin`` [m]. ``pos`` are the spheres' centres [m]
    anywhere (YADE does not wrap them into the cell).

    Returns ``(pairs, images)``: ``pairs`` (m, 2) in lexicographic order, and ``images``
    (m, 3) int64, the cell periods c such that the separation of the pair's contact is
    ``x_j - x_i + cell @ c`` for these positions. The centres are wrapped into the cell, the
    spheres within the search distance of a face are copied to the neighbouring images (the
    26 of them), and the pairs are found among the copies as in :func:`candidate_pairs`. A
    cell narrower than twice the search distance 2 r_max + skin (where a pair could touch
    through two images) raises GraphError."""
    import itertools
    from ..core.errors import GraphError
    pos = np.asarray(pos, dtype=float)
    radius = np.asarray(radius, dtype=float)
    H = np.asarray(cell, dtype=float).reshape(3, 3)
    n = pos.shape[0]
    empty = (np.zeros((0, 2), dtype=np.int64), np.zeros((0, 3), dtype=np.int64))
    if not np.all(np.isfinite(H)) or abs(float(np.linalg.det(H))) <= 0:
        raise GraphError(f"the periodic cell must have finite, independent base vectors, got {H.tolist()}")
    if n == 0:
        return empty
    cut = 2.0 * float(radius.max()) + float(skin)
    widths = cell_widths(H)
    if cut >= 0.5 * widths.min():
        raise GraphError(f"the periodic cell is too small for these spheres: its narrowest width is "
                         f"{widths.min():.6g} m, and a contact search of 2 r_max + skin = {cut:.6g} m must be below "
                         "half of it (a pair could then touch through two images). Make the cell larger")
    s = pos @ np.linalg.inv(H).T                      # reduced coordinates
    periods = np.floor(s)
    w = s - periods                                   # wrapped into [0, 1)
    margin = cut / widths
    idx, img = [np.arange(n)], [np.zeros((n, 3), dtype=np.int64)]
    for k in itertools.product((-1, 0, 1), repeat=3):
        if k == (0, 0, 0):
            continue
        wk = w + np.array(k)
        sel = np.flatnonzero(np.all((wk > -margin) & (wk < 1.0 + margin), axis=1))
        idx.append(sel)
        img.append(np.tile(np.array(k, dtype=np.int64), (sel.size, 1)))
    idx, img = np.concatenate(idx), np.concatenate(img)
    X = (w[idx] + img) @ H.T
    found = _pairs_within_reach(X, radius[idx], skin)
    if found.size == 0:
        return empty
    a, b = found[:, 0], found[:, 1]
    real = ~np.any(img[a] != 0, axis=1) | ~np.any(img[b] != 0, axis=1)      # one of the two in the cell
    a, b = a[real], b[real]
    i, j, k = idx[a], idx[b], img[b] - img[a]
    swap = i > j
    i, j = np.where(swap, j, i), np.where(swap, i, j)
    k = np.where(swap[:, None], -k, k)
    keep = i != j
    rows = np.unique(np.column_stack([i[keep], j[keep], k[keep]]), axis=0)
    if rows.size == 0:
        return empty
    pairs = rows[:, :2]
    images = rows[:, 2:] - periods[pairs[:, 1]].astype(np.int64) + periods[pairs[:, 0]].astype(np.int64)
    d = pos[pairs[:, 1]] - pos[pairs[:, 0]] + images @ H.T
    near = np.sqrt(np.einsum("ij,ij->i", d, d)) < radius[pairs[:, 0]] + radius[pairs[:, 1]] + skin
    pairs, images = pairs[near], images[near]
    order = np.argsort(pairs[:, 0] * n + pairs[:, 1], kind="stable")     # lexicographic
    return pairs[order], images[order]


_CELLS = []


def _cell_pairs(pos, cut):
    """Every pair closer than ``cut`` by the compiled cell grid (``FireSteps.pairs_within``),
    or None for a sparse box (spheres far apart, a grid with far more cells than spheres):
    there cKDTree is the better search."""
    span = np.ptp(pos, axis=0) if pos.shape[0] else np.zeros(3)
    cells = np.prod(np.maximum(1.0, np.floor(span / cut)))
    if not np.isfinite(cells) or cells > 8 * pos.shape[0] + 4096:
        return None
    from ..native import FireSteps
    if not _CELLS:
        _CELLS.append(FireSteps(threads=1))
    return _CELLS[0].pairs_within(np.ascontiguousarray(pos, dtype=np.float64), cut)


def max_displacement(pos, pos0) -> float:
    """Largest distance [m] between two position sets of the same spheres."""
    d = np.asarray(pos, dtype=float) - np.asarray(pos0, dtype=float)
    return float(np.sqrt(np.max(np.einsum("ij,ij->i", d, d), initial=0.0)))


@dataclass(frozen=True, eq=False)
class WallGeometry:
    """One conducting wall in world coordinates [m].

    ``kind``:

    * ``'plane'``: ``point`` (3,) and unit ``normal`` (3,); ``two_sided`` planes touch spheres
      on both sides (YADE's ``Wall`` with ``sense=0``), else only on the normal's side;
    * ``'box'``: ``center`` (3,), ``axes`` (3, 3) (rows: the box's unit axes) and ``extents``
      (3,) half sizes; spheres touch it from outside (YADE's ``Box``);
    * ``'triangles'``: ``vertices`` (k, 3, 3), one triangle per row (YADE facets, a facet
      mesh given as one wall).
    """

    kind: str
    point: Optional[np.ndarray] = None
    normal: Optional[np.ndarray] = None
    two_sided: bool = True
    center: Optional[np.ndarray] = None
    axes: Optional[np.ndarray] = None
    extents: Optional[np.ndarray] = None
    vertices: Optional[np.ndarray] = None

    def __post_init__(self):
        if self.kind == "plane":
            p, nrm = np.asarray(self.point, float).reshape(3), np.asarray(self.normal, float).reshape(3)
            ln = np.linalg.norm(nrm)
            if not (np.all(np.isfinite(p)) and np.isfinite(ln) and ln > 0):
                raise ValueError("a plane wall needs a finite point and a non-zero normal")
            object.__setattr__(self, "point", _ro(p))
            object.__setattr__(self, "normal", _ro(nrm / ln))
        elif self.kind == "box":
            c, ax = np.asarray(self.center, float).reshape(3), np.asarray(self.axes, float).reshape(3, 3)
            e = np.asarray(self.extents, float).reshape(3)
            if not (np.all(np.isfinite(c)) and np.all(np.isfinite(ax)) and np.all(e > 0)):
                raise ValueError("a box wall needs a finite centre and axes and extents > 0")
            for name, v in (("center", c), ("axes", ax), ("extents", e)):
                object.__setattr__(self, name, _ro(v))
        elif self.kind == "triangles":
            v = np.asarray(self.vertices, float).reshape(-1, 3, 3)
            if v.shape[0] == 0 or not np.all(np.isfinite(v)):
                raise ValueError("a triangle wall needs at least one triangle with finite vertices")
            object.__setattr__(self, "vertices", _ro(v))
        else:
            raise ValueError(f"wall kind must be 'plane', 'box' or 'triangles', got {self.kind!r}")

    @property
    def n_pieces(self) -> int:
        """Triangles of a triangle wall, else 1."""
        return self.vertices.shape[0] if self.kind == "triangles" else 1

    def reach(self) -> np.ndarray:
        """(pieces, 3) centres and (pieces,) radii of balls holding each piece (for the
        candidate search); planes have an infinite ball."""
        if self.kind == "triangles":
            c = self.vertices.mean(axis=1)
            r = np.sqrt(((self.vertices - c[:, None, :]) ** 2).sum(axis=2)).max(axis=1)
            return c, r
        if self.kind == "box":
            return self.center[None, :], np.array([float(np.linalg.norm(self.extents))])
        return self.point[None, :], np.array([np.inf])

    def moved(self, other: "WallGeometry") -> float:
        """Largest displacement [m] of this wall's defining points from ``other``'s (inf when
        they are not comparable: another kind or size); planes and boxes compare their
        corners or point plus normal turn (over a unit length)."""
        if other is None or other.kind != self.kind or other.n_pieces != self.n_pieces:
            return np.inf
        if self.kind == "triangles":
            return float(np.sqrt(((self.vertices - other.vertices) ** 2).sum(axis=2)).max())
        if self.kind == "box":
            corners = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], float)

            def pts(b):
                return b.center + (corners * b.extents) @ b.axes
            return float(np.sqrt(((pts(self) - pts(other)) ** 2).sum(axis=1)).max())
        # a plane: its offset along the normal; a turn of the normal moves far points without
        # limit, so any turn counts as a new list
        if not np.allclose(self.normal, other.normal, rtol=0, atol=1e-12):
            return np.inf
        return float(abs((self.point - other.point) @ self.normal))


def quaternion_matrices(q) -> np.ndarray:
    """Rotation matrices (k, 3, 3) of unit quaternions (k, 4) stored (x, y, z, w), as YADE's
    ``Quaternion[i]`` gives them."""
    q = np.asarray(q, dtype=float).reshape(-1, 4)
    x, y, z, w = q[:, 0], q[:, 1], q[:, 2], q[:, 3]
    R = np.empty((q.shape[0], 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 0, 2] = 1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)
    R[:, 1, 0], R[:, 1, 1], R[:, 1, 2] = 2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)
    R[:, 2, 0], R[:, 2, 1], R[:, 2, 2] = 2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)
    return R


def facet_vertices(pos, quat, local) -> np.ndarray:
    """World vertices (k, 3, 3) [m] of k rigid triangles (YADE facets): ``pos`` (k, 3) [m]
    plus the rotation of unit quaternion ``quat`` (k, 4), stored (x, y, z, w), applied to
    the vertices in the body frame ``local`` (k, 3, 3) [m]. Compiled
    (:func:`yade_electro.native.facet_vertices`: 96 facets of the drum in a few
    microseconds, where numpy's operations take about 0.2 ms; the numpy form is the tests'
    reference)."""
    from ..native import facet_vertices as compiled
    return compiled(pos, quat, local)


def triangle_distance(points, triangles) -> np.ndarray:
    """Distance [m] from each point (k, 3) to the triangle (k, 3, 3) of the same row (the
    closest point of the triangle, faces, edges or corners; Ericson, Real-Time Collision
    Detection, 5.1.5). Compiled (:func:`yade_electro.native.triangle_distance`; the numpy form
    with the same regions and precedence is the tests' reference)."""
    from ..native import triangle_distance as compiled
    return compiled(points, triangles)


def _distance(wall: WallGeometry, pos, piece):
    if wall.kind == "plane":
        s = (pos - wall.point) @ wall.normal
        return np.abs(s) if wall.two_sided else np.where(s >= 0, s, np.inf)
    if wall.kind == "box":
        local = (pos - wall.center) @ wall.axes.T
        out = np.clip(np.abs(local) - wall.extents, 0.0, None)
        return np.sqrt((out ** 2).sum(axis=1))
    return triangle_distance(pos, wall.vertices[piece])


def wall_candidates(wall: WallGeometry, pos, radius, skin: float, tree=None):
    """Sphere-piece pairs that may touch within the next ``skin / 2`` of motion: (spheres,
    pieces) index arrays, spheres sorted; ``tree``: :func:`sphere_tree` of ``pos`` if made."""
    pos = np.asarray(pos, float)
    radius = np.asarray(radius, float)
    if wall.kind != "triangles":
        d = _distance(wall, pos, None)
        s = np.flatnonzero(d < radius + skin)
        return s, np.zeros(s.size, dtype=np.int64)
    c, rc = wall.reach()
    reach = rc + float(radius.max()) + float(skin)
    if tree is None:              # compiled: a grid of the spheres
        from ..native import triangle_candidates
        return triangle_candidates(pos, radius, skin, wall.vertices, c, reach)
    # a tree of the spheres is already made (the sphere pairs' search): query it
    lists = tree.query_ball_point(c, reach)
    pieces = np.repeat(np.arange(len(lists)), [len(x) for x in lists])
    spheres = np.fromiter((i for x in lists for i in x), dtype=np.int64, count=pieces.size)
    if spheres.size:
        d = triangle_distance(pos[spheres], wall.vertices[pieces])
        keep = d < radius[spheres] + skin
        spheres, pieces = spheres[keep], pieces[keep]
    order = np.lexsort((pieces, spheres))
    return spheres[order], pieces[order]


def wall_overlaps(wall: WallGeometry, pos, radius, spheres, pieces):
    """The spheres touching ``wall`` among the candidate (sphere, piece) pairs and their
    overlap delta = r - distance [m] (> 0): ``(nodes, overlap)``, nodes sorted. A sphere
    touching several triangles of one mesh (an edge or a corner between them) counts once,
    with the deepest overlap (declare surfaces that meet at an angle, e.g. a drum shell and
    its baffles, as separate walls so that a sphere in the corner touches both)."""
    pos = np.asarray(pos, float)
    radius = np.asarray(radius, float)
    spheres = np.asarray(spheres, dtype=np.int64)
    if spheres.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    dl = radius[spheres] - _distance(wall, pos[spheres], pieces)
    touch = dl > 0
    s, dl = spheres[touch], dl[touch]
    if s.size == 0:
        return np.zeros(0, dtype=np.int64), np.zeros(0)
    if s.size > 1 and np.all(s[1:] >= s[:-1]):       # sorted by sphere (wall_candidates' order)
        first = np.flatnonzero(np.r_[True, s[1:] != s[:-1]])
        return s[first], np.maximum.reduceat(dl, first)
    nodes, inv = np.unique(s, return_inverse=True)
    deepest = np.zeros(nodes.size)
    np.maximum.at(deepest, inv, dl)
    return nodes, deepest


def plane_contact_radius(radius, overlap, model: str = "geometric") -> np.ndarray:
    """Contact radius a [m] of a sphere of ``radius`` pressed by ``overlap`` into a plane:
    'geometric' a^2 = 2 r delta - delta^2 (the circle where the sphere crosses the plane),
    'hertz' a = sqrt(r delta) (R* = r for a sphere on a half-space). 0 where delta <= 0."""
    r = np.asarray(radius, float)
    dl = np.clip(np.asarray(overlap, float), 0.0, None)
    if model == "hertz":
        return np.sqrt(r * dl)
    if model == "geometric":
        return np.sqrt(np.clip(2.0 * r * dl - dl ** 2, 0.0, None))
    raise ValueError(f"contact radius model must be 'geometric' or 'hertz', got {model!r}")


def new_wall_contacts(what: str, old, nodes, overlap):
    """Contacts (nodes, overlaps [m]) given for a wall, checked (ValueError naming ``what``
    unless the overlaps are finite, >= 0 and one per node); None when they equal ``old``
    (nothing to update)."""
    nd = np.asarray(nodes, dtype=np.int64).reshape(-1)
    dl = np.asarray(overlap, dtype=float).reshape(-1)
    if dl.shape != nd.shape or not np.all(np.isfinite(dl)) or np.any(dl < 0):
        raise ValueError(f"{what}: overlaps must be finite, >= 0 and one per node")
    if old is not None and np.array_equal(nd, old[0]) and np.array_equal(dl, old[1]):
        return None
    return nd, dl
