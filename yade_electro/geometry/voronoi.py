"""Voronoi faces of a packing, bounded by its container: the geometry of the ``voronoi``
conductance law.

Why: in a Voronoi tessellation the face between cells i and j is perpendicular to the
segment x_i x_j, so the two-point flux c_ij (u_j - u_i) with c_ij = A_ij / (rho l_ij) is the
exact flux of a uniform field through that face. A network of such conductances therefore
reproduces every uniform field exactly (the classical finite-volume / lattice-transport
argument, e.g. Bolander & Berton 2004 for rigid-body-spring lattices), with no constant to
choose. What remains is the discretisation of non-uniform fields and the boundary.

Boundary: cells are closed by mirror images ("ghosts") of the elements near the surface.
With a ``container`` (any object with ``sdf(x)``, negative inside, and ``gradient(x)``, the
outward unit normal, such as the shapes of ``yade_electro.yade.packing``) an element at
depth d gets a ghost at distance 2 d across the tangent plane of its nearest surface point,
and face parts that still stick out of the container are clipped. Without a container the
surface is estimated from the packing itself: an element whose neighbours are off-centre
(eccentricity > 0.4) gets a ghost at 2 r_i along the direction away from its neighbours'
barycentre (the boundary is then the tangent plane of the sphere, where a packing dense
against its walls has it).

Cracks (:meth:`VoronoiFaces.cracked`, the ``voronoi`` law's ``crack='facets'``): the crack
surface is the union of the broken bonds' own Voronoi faces (their *facets*). A pair bonded in
the reference configuration conducts while its bond is intact. A pair that never was bonded
(a Voronoi neighbour without a bond) conducts while its elements are linked by at most
``hops`` intact bonds, or by no more than in the reference when they were farther apart
there (a thin part; beyond 12 bonds: while the intact bonds link them at all; an element that
never had a bond conducts with its neighbours in one part of the intact bonds, the one it has
most face area with, so that it cannot bridge a crack that cut the solid in two), and the
segment between them crosses no broken facet: the point where
it crosses a broken pair's bisector plane is on that pair's face when no element centre is
nearer to it than the pair's two. Faces near a crack front whose segments pass beside the
broken facets keep conducting. Failure modes, measured on a 2 x 2 x 8 mm bar with an edge
crack over half its width (``cases/edge_crack.py``):

* the crack surface also runs through faces of pairs that were never bonded; a segment that
  crosses it only there is not cut (2-3 % of the crossing area of the cracked half at 10,000
  elements stays conducting, against 7-10 % by the path rule ``crack='paths'``);
* the front is where the last broken bond is: it is resolved to about one element spacing,
  so a crack's resistance increment converges only as the packing is refined;
* the faces are those of the reference configuration (small strain): a crack that opens
  wide or elements that rearrange are not re-tessellated.

Units: metres, m^2.
"""
from __future__ import annotations


import numpy as np

from ..core.graph import connected_parts
from .cells import bounded_cells
from .cell_clipping import clipped_by_planes
from .ghosts import ghost_points, tessellate_with_ghosts

__all__ = ["voronoi_faces", "VoronoiFaces", "voronoi_cell_volumes", "cell_volume_of"]


def voronoi_faces(pos, radius, container=None, neighbour_barycentre=None, threshold=0.4):
    """Pairs of neighbouring cells and the areas of their common faces.

    Parameters
    ----------
    pos, radius : element centres (n, 3) and radii (n,) [m]
    container : object with ``sdf`` and ``gradient``, optional (see module doc); with one,
        the faces are those of :func:`bounded_cells`
    neighbour_barycentre : (n, 3), needed without a container

    Returns
    -------
    pairs : (p, 2) int array, i < j, both real elements
    area : (p,) face areas [m^2] (clipped to the container when one is given)
    """
    pos = np.asarray(pos, float)
    if container is not None:
        cells = bounded_cells(pos, radius, container)
        return cells.pairs, cells.area
    n = pos.shape[0]
    ghosts, foot, nrm, mirrored = ghost_points(pos, radius, None, neighbour_barycentre=neighbour_barycentre,
                                               threshold=threshold)
    pts, tess = tessellate_with_ghosts(pos, radius, ghosts)
    rp = tess.ridge_points
    idx = np.flatnonzero((rp[:, 0] < n) & (rp[:, 1] < n))
    pairs = rp[idx]
    d = pts[pairs[:, 1]] - pts[pairs[:, 0]]
    normals = d / np.linalg.norm(d, axis=1)[:, None]
    area = tess.face_geometry(idx, normals)[0]
    # clip by the tangent planes of the surface elements of each face
    plane_of = {int(i): (foot[k], nrm[k]) for k, i in enumerate(mirrored)}
    for m, (i, j) in enumerate(pairs):
        planes = [plane_of[q] for q in (int(i), int(j)) if q in plane_of]
        if planes:
            area[m] = clipped_by_planes(tess.vertices[tess.ridge(idx[m])], normals[m], planes)
    keep = area > 0
    return pairs[keep], area[keep]


class VoronoiFaces:
    """Face areas of a tessellation, looked up by node pairs (vectorised).

    Parameters
    ----------
    pairs : (p, 2) int array (i < j)
    area : (p,) [m^2]
    n_nodes : int
    """

    def __init__(self, pairs, area, n_nodes, centre=None, extent=None):
        key = pairs[:, 0].astype(np.int64) * n_nodes + pairs[:, 1]
        order = np.argsort(key)
        self.key, self.area, self.pairs, self.n = key[order], np.asarray(area)[order], pairs[order], n_nodes
        self.centre = None if centre is None else np.asarray(centre)[order]
        self.extent = None if extent is None else np.asarray(extent)[order]

    @classmethod
    def of(cls, graph, container, radius_range=None, bounds=None):
        """Faces of ``graph``'s elements in ``container``, from :func:`bounded_cells` (kept,
        with the cell volumes and boundary faces of the same pass; ``radius_range`` and
        ``bounds`` as there)."""
        cells = bounded_cells(graph.pos, graph.radius, container, radius_range=radius_range, bounds=bounds)
        faces = cls(cells.pairs, cells.area, graph.n_nodes, cells.face_centre, cells.face_extent)
        faces.cells = cells
        return faces

    cells = None

    def cell_volumes(self) -> np.ndarray:
        """Bounded cell volumes [m^3] of the elements (from the same pass as the faces)."""
        if self.cells is None:
            raise ValueError("these faces were not made by VoronoiFaces.of: no cell volumes")
        return self.cells.volume

    def area_of(self, edges) -> np.ndarray:
        """Face area of each (i, j) edge; 0 where i and j are not Voronoi neighbours."""
        e = np.sort(np.asarray(edges, dtype=np.int64), axis=1)
        k = e[:, 0] * self.n + e[:, 1]
        pos = np.clip(np.searchsorted(self.key, k), 0, max(self.key.size - 1, 0))
        hit = self.key.size > 0
        found = (self.key[pos] == k) if hit else np.zeros(k.size, bool)
        return np.where(found, self.area[pos] if hit else 0.0, 0.0)

    def index_of(self, edges):
        """Position of each (i, j) among the faces, -1 where i and j are not neighbours."""
        e = np.sort(np.asarray(edges, dtype=np.int64).reshape(-1, 2), axis=1)
        k = e[:, 0] * self.n + e[:, 1]
        if self.key.size == 0:
            return np.full(k.size, -1)
        pos = np.clip(np.searchsorted(self.key, k), 0, self.key.size - 1)
        return np.where(self.key[pos] == k, pos, -1)

    def linked(self, bonds, hops: int, pairs=None) -> np.ndarray:
        """Per face (or per row of ``pairs``): are its two elements linked by a path of at
        most ``hops`` of ``bonds``?

        By the compiled breadth-first helper (:func:`yade_electro.native.hops_linked`:
        memory of a few arrays per node; at 1M elements 0.24 s; the tests' reference is the
        powers of the sparse adjacency matrix)."""
        import scipy.sparse as sp
        from ..native import hops_linked
        n = self.n
        b = np.asarray(bonds, dtype=np.int64).reshape(-1, 2)
        sym = sp.csr_matrix((np.ones(2 * len(b), dtype=np.int8),
                             (np.concatenate([b[:, 0], b[:, 1]]), np.concatenate([b[:, 1], b[:, 0]]))),
                            shape=(n, n))
        return hops_linked(sym.indptr, sym.indices, self.pairs if pairs is None else pairs, hops)

    #: the farthest reference hop distance looked up for a pair not linked within ``hops``
    FAR_HOPS = 12

    #: :meth:`reference_hops` of a pair linked in the reference only by more than FAR_HOPS bonds
    FAR = FAR_HOPS + 1
    #: :meth:`reference_hops` of a pair not linked at all in the reference (an element that
    #: never had a bond)
    UNLINKED = np.iinfo(np.int64).max

    def reference_hops(self, reference_bonds, hops: int) -> np.ndarray:
        """Per face, its two elements' hop distance along ``reference_bonds`` when it exceeds
        ``hops`` (up to :attr:`FAR_HOPS`; beyond: :attr:`FAR` when the reference bonds link
        them at all, else :attr:`UNLINKED`), else ``hops``. Kept for one reference (the faces
        are made once per element set)."""
        ref = np.asarray(reference_bonds, dtype=np.int64).reshape(-1, 2)
        key = (int(hops), ref.shape[0], hash(ref.tobytes()))
        if getattr(self, "_ref_hops", None) is not None and self._ref_hops[0] == key:
            return self._ref_hops[1]
        dist = np.full(self.pairs.shape[0], int(hops), dtype=np.int64)
        far = np.flatnonzero(~self.linked(ref, hops))
        for h in range(int(hops) + 1, self.FAR_HOPS + 1):
            if not far.size:
                break
            got = self.linked(ref, h, self.pairs[far])
            dist[far[got]] = h
            far = far[~got]
        if far.size:
            label = connected_parts(self.n, ref)[1]
            same = label[self.pairs[far, 0]] == label[self.pairs[far, 1]]
            dist[far] = np.where(same, self.FAR, self.UNLINKED)
        self._ref_hops = (key, dist)
        return dist

    def supported_pairs(self, bonds, hops: int = 2) -> np.ndarray:
        """The Voronoi pairs that conduct given the bonds: those whose two elements are linked
        by a path of at most ``hops`` intact bonds (1 = bonded pairs only; 2 = also through a
        common neighbour), plus the bonds themselves."""
        b = np.sort(np.asarray(bonds, dtype=np.int64).reshape(-1, 2), axis=1)
        out = np.concatenate([self.pairs[self.linked(b, hops)], b])
        key = np.unique(out[:, 0] * self.n + out[:, 1])  # np.unique(out, axis=0), by one int64 key
        return np.column_stack([key // self.n, key % self.n])

    def _lone_faces_kept(self, sel, ref, label) -> np.ndarray:
        """Which of the faces ``sel`` (pairs no reference bond linked) conduct: between elements
        that both had bonds, all; an element that never had a bond (a rattler, inside the
        solid) conducts with the neighbours of one part of the intact bonds only, the part
        its faces with bonded neighbours have most area with, so that it cannot bridge a crack
        that has cut the solid in two (in an intact solid that is every neighbour). ``label``:
        the elements' parts of the intact bonds (:func:`~yade_electro.core.graph.connected_parts`)."""
        n = self.n
        lone = np.bincount(ref.ravel(), minlength=n) == 0
        i, j = self.pairs[sel, 0], self.pairs[sel, 1]
        one = lone[i] ^ lone[j]
        k = np.where(lone[i], i, j)[one]
        m = np.where(lone[i], j, i)[one]
        chosen = np.full(n, -1, dtype=np.int64)
        if k.size:
            keys, inv = np.unique(k * n + label[m], return_inverse=True)
            total = np.bincount(inv, weights=self.area[sel[one]])
            kk, ll = keys // n, keys % n
            order = np.lexsort((-total, kk))
            first = order[np.r_[True, kk[order][1:] != kk[order][:-1]]]
            chosen[kk[first]] = ll[first]
        keep = np.ones(sel.size, bool)
        keep[one] = label[m] == chosen[k]
        both = lone[i] & lone[j]
        keep[both] = chosen[i[both]] == chosen[j[both]]
        return keep

    def cracked(self, pos, bonds, reference_bonds, hops: int = 3) -> np.ndarray:
        """The Voronoi pairs that conduct after the bonds ``reference_bonds - bonds`` broke, by
        the crack-facet rule (see the module doc): a pair bonded in the reference conducts while
        its bond is intact; an unbonded pair conducts while its elements are linked by at most
        ``hops`` intact bonds and no broken bond's facet lies across it. Returns the pairs
        (plus the intact bonds)."""
        from scipy.spatial import cKDTree
        pos = np.asarray(pos, float)
        b = np.sort(np.asarray(bonds, dtype=np.int64).reshape(-1, 2), axis=1)
        ref = np.sort(np.asarray(reference_bonds, dtype=np.int64).reshape(-1, 2), axis=1)
        n = self.n
        now_key = np.unique(b[:, 0] * n + b[:, 1])
        ref_key = ref[:, 0] * n + ref[:, 1]
        broken = ref[~np.isin(ref_key, now_key)]
        was_bond = np.zeros(self.pairs.shape[0], bool)
        at = self.index_of(ref)
        was_bond[at[at >= 0]] = True
        # an unbonded pair conducts while its elements are as near along intact bonds as they
        # were in the reference, or within ``hops``: in a thin part (a ligament two elements
        # wide) faces of pairs farther apart than ``hops`` are solid too, and a 0.2 mm
        # ligament lost up to 1.2 % of its section when they did not conduct
        dist = self.reference_hops(ref, hops)
        keep = ~was_bond & self.linked(b, hops)
        farther = ~was_bond & ~keep & (dist > hops)
        # beyond FAR_HOPS: while the intact bonds still link them at all (not once a crack has
        # cut the part in two); a pair no bond linked in the reference: the facet test alone
        label = connected_parts(n, b)[1] if np.any(farther & (dist > self.FAR_HOPS)) else None
        for h in np.unique(dist[farther]):
            sel = np.flatnonzero(farther & (dist == h))
            if h == self.UNLINKED:
                keep[sel] = self._lone_faces_kept(sel, ref, label)
            elif h == self.FAR:
                keep[sel] = label[self.pairs[sel, 0]] == label[self.pairs[sel, 1]]
            else:
                keep[sel] = self.linked(b, int(h), self.pairs[sel])
        bi = self.index_of(broken)
        bi = bi[bi >= 0]
        cand = np.flatnonzero(keep)
        if bi.size and cand.size and self.centre is not None:
            c_b, r_b = self.centre[bi], self.extent[bi]
            p, q = self.pairs[bi, 0], self.pairs[bi, 1]
            n_b = pos[q] - pos[p]
            n_b /= np.linalg.norm(n_b, axis=1)[:, None]
            i, j = self.pairs[cand, 0], self.pairs[cand, 1]
            mid = 0.5 * (pos[i] + pos[j])
            reach = float(r_b.max()) + 0.5 * float(np.linalg.norm(pos[j] - pos[i], axis=1).max())
            hits = cKDTree(c_b).query_ball_point(mid, reach)
            ci = np.repeat(np.arange(cand.size), [len(h) for h in hits])
            cb = np.concatenate([np.asarray(h, dtype=np.int64) for h in hits]) if ci.size else np.zeros(0, np.int64)
            if ci.size:
                xi, xj = pos[i[ci]], pos[j[ci]]
                si = np.einsum("ij,ij->i", xi - c_b[cb], n_b[cb])
                sj = np.einsum("ij,ij->i", xj - c_b[cb], n_b[cb])
                across = si * sj < 0
                with np.errstate(divide="ignore", invalid="ignore"):
                    t = np.where(across, si / (si - sj), 0.0)
                x = xi + (xj - xi) * t[:, None]
                # the disc around the broken face's centre is a first sieve; the crossing point
                # is on the face itself when no element is nearer to it than the pair's two
                # (the definition of their Voronoi face)
                inside = across & (np.linalg.norm(x - c_b[cb], axis=1) <= r_b[cb])
                k = np.flatnonzero(inside)
                if k.size:
                    d, nb = cKDTree(pos).query(x[k], k=3)
                    pk, qk = p[cb[k]], q[cb[k]]
                    d_pq = np.linalg.norm(x[k] - pos[pk], axis=1)
                    other = np.where((nb != pk[:, None]) & (nb != qk[:, None]), d, np.inf).min(axis=1)
                    inside[k] = other >= d_pq * (1.0 - 1e-9)
                cut = np.zeros(cand.size, bool)
                cut[ci[inside]] = True
                keep[cand[cut]] = False
        out = np.concatenate([self.pairs[keep], b])
        key = np.unique(out[:, 0] * n + out[:, 1])      # np.unique(out, axis=0), by one int64 key
        return np.column_stack([key // n, key % n])


def voronoi_cell_volumes(pos, radius, container, rel_tol: float = 3e-3, return_info: bool = False):
    """Volumes [m^3] of the Voronoi cells of the element centres, bounded by the container:
    the volume of solid each element stands for (heat capacity ``rho c V_cell``); see
    :func:`bounded_cells`, which this calls.

    For planar walls the volumes are exact, so the volumes of a packing in a box sum to the
    box volume to rounding. On a curved wall the cells are bounded by tangent planes, and
    the solid those planes leave out is taken away by integrating the protrusion of the
    surface over them (exact for quadratic surfaces): measured on the rod R = 1 mm, L = 5 mm,
    the volumes sum to the cylinder's within -4e-7 at 5,000 elements.

    Parameters
    ----------
    pos : (n, 3) element centres [m]
    radius : (n,) radii [m] (set the width of the band of mirrored elements)
    container : object with ``sdf`` and ``gradient`` (a :mod:`yade_electro.geometry.shapes` shape)
    rel_tol : clipping tolerance (see :func:`bounded_cells`)
    return_info : bool
        Also return a dict: ``total`` (sum of the volumes), ``container_volume`` (exact if
        the container knows it, else None), ``relative_excess`` and ``n_clipped``.

    Returns
    -------
    volumes : (n,) [m^3] (and ``info`` with ``return_info``)
    """
    if container is None or not (hasattr(container, "sdf") and hasattr(container, "gradient")):
        raise ValueError("voronoi_cell_volumes needs container=<the solid's shape>, an object with sdf(x) "
                         f"and gradient(x); got {container!r}")
    cells = bounded_cells(pos, radius, container, rel_tol=rel_tol)
    vol = cells.volume
    if not return_info:
        return vol
    cv = getattr(container, "exact_volume", None)
    total = float(vol.sum())
    return vol, {"total": total, "container_volume": cv,
                 "relative_excess": (total / cv - 1.0) if cv else None, "n_clipped": cells.n_clipped,
                 "n_sampled": cells.n_sampled}


def cell_volume_of(container, **kwargs):
    """``f(graph) -> (n,)`` bounded Voronoi cell volumes [m^3] of the graph's elements, for
    ``ElectroThermalModel(cell_volume=...)`` / ``heat_capacity(cell_volume=...)``: the heat
    capacities that go with the 'voronoi' conductance law (``C_i = rho c V_cell_i``, cells
    filling the solid instead of paper 000's ``V_i / fv_i``). The volumes are kept while
    the element set (ids) is the same; other keywords go to :func:`voronoi_cell_volumes`."""
    cache = {}

    def cell_volume(graph):
        key = (graph.n_nodes, graph.ids.tobytes())
        if cache.get("key") != key:
            cache["key"] = key
            cache["volumes"] = voronoi_cell_volumes(graph.pos, graph.radius, container, **kwargs)
        return cache["volumes"]
    cell_volume.container = container
    return cell_volume
