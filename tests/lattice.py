"""Simple-cubic lattice graphs for the tests: ``from lattice import cubic_lattice``.

A lattice of ``nx * ny * nz`` spheres of radius ``r`` on a grid of spacing ``2 r`` (touching
spheres), bonded to their nearest neighbours (up to 6). Node ``(i, j, k)`` has index
``i + nx * (j + ny * k)``, so a layer of constant ``k`` is a contiguous block of
``nx * ny`` nodes and z is the long axis of a rod.

Classes of nodes of a lattice with every side >= 3 (what the continuum model makes of them,
see tests/test_surfaces.py):

========  ==========  ============  ===================  ======================
class     neighbours  eccentricity  f (threshold 0.4)    S_i / r^2
========  ==========  ============  ===================  ======================
interior  6           0             1                    alpha(6) = 4
face      5           2/5 = 0.4     1 (strict ``>``)     alpha(5) = 3 sqrt3 + 2
edge      4           sqrt2/2       2                    alpha(4)/2 = 3 sqrt3
corner    3           2/sqrt3       2                    alpha(3)/2 = (9 sqrt3 - 2)/2
========  ==========  ============  ===================  ======================
"""
import numpy as np

from yade_electro.core.graph import ContactGraph

__all__ = ["cubic_lattice", "lattice_index", "lattice_coords", "node_class", "lattice_edges"]


def lattice_index(i, j, k, shape):
    """Node index of grid point (i, j, k) in a lattice of ``shape = (nx, ny, nz)``."""
    nx, ny, _ = shape
    return np.asarray(i) + nx * (np.asarray(j) + ny * np.asarray(k))


def lattice_coords(shape):
    """(n, 3) int array of the grid coordinates (i, j, k) of every node, in node order."""
    nx, ny, nz = shape
    k, j, i = np.meshgrid(np.arange(nz), np.arange(ny), np.arange(nx), indexing="ij")
    return np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)


def lattice_edges(shape):
    """(m, 2) nearest-neighbour bonds, each as (lower index, higher index), x bonds first,
    then y, then z."""
    nx, ny, nz = shape
    ijk = lattice_coords(shape)
    idx = np.arange(nx * ny * nz)
    out = []
    for axis, n_axis in enumerate(shape):
        has = ijk[:, axis] < n_axis - 1
        step = (1, nx, nx * ny)[axis]
        out.append(np.stack([idx[has], idx[has] + step], axis=1))
    return np.concatenate(out).reshape(-1, 2)


def cubic_lattice(shape, r=1.0, origin=(0.0, 0.0, 0.0), ids=None):
    """A :class:`ContactGraph` of a simple-cubic lattice of touching spheres.

    Parameters
    ----------
    shape : (nx, ny, nz)
    r : sphere radius [m]; the spacing is 2 r.
    origin : centre of node (0, 0, 0) [m].
    ids : optional caller ids (default 0..n-1).
    """
    shape = tuple(int(s) for s in shape)
    pos = np.asarray(origin, dtype=float) + 2.0 * r * lattice_coords(shape)
    return ContactGraph(pos, np.full(pos.shape[0], float(r)), lattice_edges(shape), ids=ids)


def node_class(shape):
    """(n,) array of the number of lattice faces each node lies on, clipped to 3:
    0 interior, 1 face, 2 edge, 3 corner (for every side >= 3)."""
    ijk = lattice_coords(shape)
    on = (ijk == 0) | (ijk == np.asarray(shape) - 1)
    return on.sum(axis=1)


def end_selectors(shape, r=1.0):
    """Selectors ``f(pos, radius) -> mask`` of the bottom (z = 0) and top layers of a
    lattice rod built by :func:`cubic_lattice` with this shape and radius (origin 0)."""
    z_top = 2 * r * (shape[2] - 1)

    def bottom(pos, radius):
        return pos[:, 2] < r

    def top(pos, radius):
        return pos[:, 2] > z_top - r
    return bottom, top
