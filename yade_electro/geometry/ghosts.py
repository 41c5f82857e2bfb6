"""Mirror images ("ghosts") of the elements near the surface, which close their Voronoi cells,
and the tessellation of the elements with their ghosts (with progress on long runs).

See :mod:`yade_electro.geometry.voronoi` for the construction. Units: m.
"""
from __future__ import annotations


import numpy as np

from .tessellation import tessellate

__all__ = ["ghost_points", "tessellate_with_ghosts", "progress_lines"]


def ghost_points(pos, radius, container=None, band=None, neighbour_barycentre=None, threshold=0.4):
    """Mirror images [m], (k, 3), of the elements near the surface, and the tangent plane
    (point, outward normal) of each mirrored element, (k, 3) and (k, 3), with the index of
    the element mirrored (k,)."""
    pos = np.asarray(pos, float)
    radius = np.asarray(radius, float)
    if band is None:
        band = 4.0 * radius.max()
    if container is not None:
        d = np.asarray(container.sdf(pos), float)            # < 0 inside
        near = np.flatnonzero(d > -band)
        nrm = np.asarray(container.gradient(pos[near]), float)
        nrm /= np.linalg.norm(nrm, axis=1)[:, None]
        foot = pos[near] - d[near, None] * nrm                 # nearest surface point
        ghost = 2.0 * foot - pos[near]
        # a ghost is kept only where its mirror plane is a supporting plane of the solid:
        # its foot is on the surface and it is (at least) as far outside as the element is
        # inside. Elsewhere (edges and corners where the normal is ambiguous, concave
        # parts) the cell is left open there and its faces are clipped instead.
        tol = 1e-6 * radius[near]
        good = (np.abs(np.asarray(container.sdf(foot), float)) <= tol + 1e-6 * np.abs(d[near])) & \
               (np.asarray(container.sdf(ghost), float) >= -d[near] * (1.0 - 1e-6) - tol) & \
               (-d[near] > tol)                                  # not on the surface itself
        near, nrm, foot = near[good], nrm[good], foot[good]
    else:
        if neighbour_barycentre is None:
            raise ValueError("without a container, give neighbour_barycentre "
                             "(ContactGraph.neighbour_barycentre())")
        off = pos - np.asarray(neighbour_barycentre, float)
        e = np.linalg.norm(off, axis=1) / radius
        near = np.flatnonzero(e > threshold)
        nrm = off[near] / np.linalg.norm(off[near], axis=1)[:, None]
        foot = pos[near] + radius[near, None] * nrm             # sphere tangent plane
    ghosts = 2.0 * foot - pos[near]
    return ghosts, foot, nrm, near


def tessellate_with_ghosts(pos, radius, ghosts, bounds=None, r_max=None):
    """Voronoi tessellation of the elements, their ghosts and eight far points (which keep
    every cell of a real element finite). Returns (all points, :class:`Tessellation` with the
    faces of the elements: with each other and with ghosts). ``bounds`` (lo, hi) [m] and
    ``r_max`` [m]: those of the whole packing when ``pos`` is a part of it (the far points,
    which bound a cell left open, are then the whole's); default: those of ``pos``."""
    lo, hi = (pos.min(axis=0), pos.max(axis=0)) if bounds is None else (np.asarray(bounds[0], float),
                                                                         np.asarray(bounds[1], float))
    span = max(float(np.max(hi - lo)), float(np.max(radius) if r_max is None else r_max) * 4)
    mid = 0.5 * (lo + hi)
    far = mid + 10.0 * span * np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    pts = np.concatenate([pos, ghosts, far])
    return pts, tessellate(pts, pos.shape[0], n_far=far.shape[0], progress=progress_lines(pts.shape[0]))


def progress_lines(n_points):
    """A progress callback for the qhull slabs (:class:`yade_electro.core.progress.Progress`: a
    line on stderr at most every PROGRESS_EVERY s, with the slabs done and the time left)."""
    from ..core.progress import Progress
    report = Progress("voronoi", f"{n_points:,} points, slabs tessellated")     # the clock starts here

    def progress(done, total, elapsed):
        report.total = int(total)
        report.update(done)
        if done == total:
            report.done()
    return progress
