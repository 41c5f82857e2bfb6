"""Point values, line profiles and slab averages of finite-element fields.

skfem's own ``CellBasis.probes`` finds the containing tetrahedron with a tolerance of a few
machine epsilons and then falls back to an all-element search; here points on faces, edges
or corners of the mesh (the plate's corner control point) and points a hair outside a
polygonal boundary (a point on the true circle) are accepted with an explicit tolerance.
"""
from __future__ import annotations

import numpy as np
from scipy.sparse import coo_matrix
from scipy.spatial import cKDTree

from ..core.errors import ElectroError

__all__ = ["probe_matrix", "find_cells", "ProbeError", "line_points", "slab_average",
           "subdomain_average"]


class ProbeError(ElectroError, ValueError):
    """A probe point lies outside the mesh (beyond the tolerance)."""


def _barycentric(p, t, cells, x):
    """Barycentric coordinates (npts, k, 4) of points x (npts, 3) in cells (npts, k)."""
    v0 = p[:, t[0, cells]]                       # (3, npts, k)
    m = np.stack([p[:, t[i, cells]] - v0 for i in (1, 2, 3)], axis=-1)  # (3, npts, k, 3)
    m = np.moveaxis(m, 0, -2)                    # (npts, k, 3, 3)
    rhs = (x.T[:, None, :] - np.moveaxis(v0, 0, -1))[..., None]          # (npts, k, 3, 1)
    lam = np.linalg.solve(m, rhs)[..., 0]
    return np.concatenate([1.0 - lam.sum(axis=-1, keepdims=True), lam], axis=-1)


def find_cells(mesh, x: np.ndarray, tol: float = 1e-6) -> np.ndarray:
    """Index of a tetrahedron containing each point.

    Parameters
    ----------
    mesh : skfem.MeshTet
    x : ndarray (3, npts)
        Points [m].
    tol : float
        Accepted negative barycentric coordinate (relative to the element): a point up to
        about ``tol * h`` outside the mesh is attributed to the nearest element and its
        value extrapolated from it.

    Raises
    ------
    ProbeError
        If a point is farther outside the mesh.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    if x.shape[0] != 3:
        raise ProbeError(f"points must be an array of shape (3, npts), got {x.shape}")
    if not np.all(np.isfinite(x)):
        raise ProbeError("probe points contain nan or inf")
    tree = getattr(mesh, "_yade_electro_tree", None)
    if tree is None:
        tree = cKDTree(mesh.p[:, mesh.t].mean(axis=1).T)
        object.__setattr__(mesh, "_yade_electro_tree", tree)
    nel = mesh.t.shape[1]
    k = min(48, nel)
    _, cand = tree.query(x.T, k)
    cand = np.asarray(cand).reshape(x.shape[1], k)
    lam = _barycentric(mesh.p, mesh.t, cand, x)
    score = lam.min(axis=-1)                     # (npts, k)
    best = score.argmax(axis=1)
    cells = cand[np.arange(x.shape[1]), best]
    ok = score[np.arange(x.shape[1]), best] >= -tol
    for i in np.nonzero(~ok)[0]:                 # rare: search every element
        allc = np.arange(nel)[None, :]
        s = _barycentric(mesh.p, mesh.t, allc, x[:, i:i + 1]).min(axis=-1)[0]
        j = int(np.argmax(s))
        if s[j] < -tol:
            raise ProbeError(f"point {tuple(x[:, i])} is outside the mesh (nearest element "
                             f"barycentric coordinate {s[j]:.3g} < -{tol})")
        cells[i] = j
    return cells


def probe_matrix(basis, x: np.ndarray, tol: float = 1e-6):
    """Sparse matrix P (npts, ndofs) with ``P @ u`` = values of ``u`` at points ``x``.

    Parameters
    ----------
    basis : skfem.CellBasis
        Scalar basis (P1 or P2 on tetrahedra).
    x : ndarray (3, npts)
        Points [m].
    tol : float
        See :func:`find_cells`.
    """
    x = np.atleast_2d(np.asarray(x, dtype=float))
    cells = find_cells(basis.mesh, x, tol)
    pts = basis.mapping.invF(x[:, :, np.newaxis], tind=cells)
    phis = np.array([np.asarray(basis.elem.gbasis(basis.mapping, pts, k, tind=cells)[0])
                     for k in range(basis.Nbfun)]).reshape(basis.Nbfun, -1)
    rows = np.tile(np.arange(x.shape[1]), basis.Nbfun)
    cols = basis.element_dofs[:, cells].ravel()
    return coo_matrix((phis.ravel(), (rows, cols)), shape=(x.shape[1], basis.N)).tocsr()


def line_points(start, end, n: int = 101) -> tuple:
    """``n`` equally spaced points from ``start`` to ``end``.

    Returns
    -------
    s : ndarray (n,)
        Distance from ``start`` [m].
    x : ndarray (3, n)
        Points [m].
    """
    start, end = np.asarray(start, float), np.asarray(end, float)
    if start.shape != (3,) or end.shape != (3,):
        raise ProbeError("start and end must be 3D points")
    s = np.linspace(0.0, 1.0, int(n))
    return s * np.linalg.norm(end - start), start[:, None] + (end - start)[:, None] * s


def slab_average(basis, u: np.ndarray, axis: int, edges) -> np.ndarray:
    """Volume averages of the field ``u`` over the slabs ``edges[i] <= x[axis] < edges[i+1]``.

    Quadrature points are binned, so elements cut by a slab boundary are split at the
    quadrature-point level (error O(h) on each slab, much smaller in practice). This is the
    quantity to compare with a DEM profile binned the same way.

    Returns
    -------
    ndarray (len(edges) - 1,)
        nan for an empty slab.
    """
    edges = np.asarray(edges, dtype=float)
    val = np.asarray(basis.interpolate(u))             # (nel, nqp)
    xq = np.asarray(basis.global_coordinates())[axis]  # (nel, nqp)
    w = basis.dx
    idx = np.digitize(xq.ravel(), edges) - 1
    keep = (idx >= 0) & (idx < len(edges) - 1)
    num = np.bincount(idx[keep], (val * w).ravel()[keep], minlength=len(edges) - 1)
    den = np.bincount(idx[keep], w.ravel()[keep], minlength=len(edges) - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return num / den


def subdomain_average(basis, u: np.ndarray, elements) -> float:
    """Volume average of ``u`` over the given elements (e.g. ``mesh.subdomains['notch']``)."""
    elements = np.asarray(elements)
    if elements.size == 0:
        raise ProbeError("the subdomain has no element")
    val = np.asarray(basis.interpolate(u))[elements]
    w = basis.dx[elements]
    return float(np.sum(val * w) / np.sum(w))
