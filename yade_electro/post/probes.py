"""Values of element fields at points, along lines and on planes; means over cross-sections
and regions; per-element gradients (current density, heat flux).

The element values of a DEM solution (potential [V], temperature [K], ...) live at the
element centres, which are scattered. A probe at a point p fits the values of the elements
within ``radius`` of p with a linear function, ``v ~ a + g . (x - p)`` (least squares), and
returns ``a`` (and the gradient ``g``). Give ``axis`` to fit the elements within ``radius``
of the *line* through p along it instead (a field known not to vary along that axis, e.g.
through a plate's thickness: more elements for the same radius).

Error behaviour (what to expect):

* exact for a linear field, whatever the radius and the placement of the elements (tested);
* a curved field is biased in proportion to its curvature times r_fit^2: inside the solid
  (elements all around p) the fitted value is the mean of the field over the ball, about
  ``v + v'' r_fit^2 / 10`` (the mean of d_x^2 over a ball is r^2 / 5); at a wall (elements on
  one side only) the one-sided line undershoots a convex field by a similar amount (tested:
  both scale as r_fit^2). So the radius trades bias (grows as r_fit^2) against scatter
  (falls as 1/sqrt(k), k the elements used).
  2.5 r_mean (about 40 elements inside a solid) is a good default; a probe with fewer than
  ``min_points`` (6) elements raises ProbeError.

Means weight the elements by the volumes they stand for (bounded Voronoi cell volumes, or
any weights given), so that a mean over a cross-section slab or a region is the discrete
counterpart of the volume average of the field.

Gradients of an element field (:func:`element_gradients`) are least-squares fits over each
element's network neighbours; ``-grad(V) / rho_e`` is the current density [A/m^2] and
``-lambda grad(T)`` the heat flux [W/m^2].

Units: SI (positions in m; the values' own units).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from scipy.spatial import cKDTree

from ..core.errors import ElectroError

__all__ = ["ProbeError", "ProbeValues", "probe", "line_probe", "plane_probe", "section_mean", "region_mean",
           "slab_means", "element_gradients"]


class ProbeError(ElectroError, ValueError):
    """A probe with too few elements around it, or bad probe input."""


@dataclass(frozen=True, eq=False)
class ProbeValues:
    """Probe results at m points.

    value : (m,) or (m, c) the fitted value at each point
    gradient : (m, 3) or (m, 3, c) the fitted gradient [units / m]
    n_used : (m,) elements in each fit
    residual : (m,) or (m, c) rms misfit of the elements to the linear fit
    points : (m, 3) the points [m]
    """

    value: np.ndarray
    gradient: np.ndarray
    n_used: np.ndarray
    residual: np.ndarray
    points: np.ndarray


def _points(points):
    p = np.asarray(points, dtype=float)
    if p.ndim == 1:
        p = p.reshape(1, -1)
    if p.ndim != 2 or p.shape[1] != 3 or not np.all(np.isfinite(p)):
        raise ProbeError(f"points must be finite (3,) or (m, 3) positions [m], got shape {np.shape(points)}")
    return p


def _check(pos, values):
    pos = np.asarray(pos, dtype=float)
    v = np.asarray(values, dtype=float)
    if pos.ndim != 2 or pos.shape[1] != 3:
        raise ProbeError(f"pos must be (n, 3) element centres [m], got shape {pos.shape}")
    if v.shape[0] != pos.shape[0]:
        raise ProbeError(f"values must have one row per element ({pos.shape[0]}), got shape {v.shape}")
    ok = np.all(np.isfinite(v.reshape(v.shape[0], -1)), axis=1)
    return pos, v, ok


def probe(pos, values, points, radius: float, axis=None, min_points: int = 6) -> ProbeValues:
    """Fit the element ``values`` (n,) or (n, c) at ``pos`` (n, 3) around each of ``points``
    (see the module doc): the elements within ``radius`` [m] of the point (or of the line
    through it along ``axis``), linear least squares, evaluated at the point. Elements with
    non-finite values are left out. Raises ProbeError for fewer than ``min_points``."""
    pos, v, ok = _check(pos, values)
    p = _points(points)
    if not (np.isfinite(radius) and radius > 0):
        raise ProbeError(f"radius must be > 0 [m], got {radius}")
    flat = v.reshape(v.shape[0], -1)
    idx_ok = np.flatnonzero(ok)
    if axis is not None:
        a = np.asarray(axis, dtype=float).reshape(3)
        if not np.linalg.norm(a) > 0:
            raise ProbeError("axis must be a non-zero vector")
        a = a / np.linalg.norm(a)
        proj = lambda x: x - np.outer(x @ a, a)        # noqa: E731 - distances across the axis
        tree = cKDTree(proj(pos[idx_ok]))
        near = tree.query_ball_point(proj(p), radius)
    else:
        tree = cKDTree(pos[idx_ok])
        near = tree.query_ball_point(p, radius)
    m, c = p.shape[0], flat.shape[1]
    val, grad = np.zeros((m, c)), np.zeros((m, 3, c))
    res, used = np.zeros((m, c)), np.zeros(m, dtype=np.int64)
    for k, nb in enumerate(near):
        sel = idx_ok[np.asarray(nb, dtype=np.int64)]
        used[k] = sel.size
        if sel.size < min_points:
            where = "the line along the axis through" if axis is not None else "the point"
            raise ProbeError(f"only {sel.size} element(s) within {radius:.3g} m of {where} {tuple(p[k])}; at "
                             f"least {min_points} are needed: increase radius, or the point is outside the packing")
        d = pos[sel] - p[k]
        X = np.column_stack([np.ones(sel.size), d])
        coef, *_ = np.linalg.lstsq(X, flat[sel], rcond=None)
        if axis is not None:         # no information along the axis: the gradient across it only
            coef[1:] -= np.outer(a, a @ coef[1:])
        val[k], grad[k] = coef[0], coef[1:]
        res[k] = np.sqrt(np.mean((flat[sel] - X @ coef) ** 2, axis=0))
    shape = v.shape[1:]
    return ProbeValues(val.reshape((m,) + shape), grad.reshape((m, 3) + shape), used, res.reshape((m,) + shape), p)


def line_probe(pos, values, start, end, n_points: int, radius: float, **kw):
    """``probe`` at ``n_points`` points evenly spaced from ``start`` to ``end`` [m]; returns
    (arc length s [m] of each point, ProbeValues)."""
    a, b = _points(start)[0], _points(end)[0]
    if int(n_points) < 2:
        raise ProbeError("n_points must be >= 2")
    t = np.linspace(0.0, 1.0, int(n_points))
    pts = a + np.outer(t, b - a)
    return t * float(np.linalg.norm(b - a)), probe(pos, values, pts, radius, **kw)


def plane_probe(pos, values, origin, u, v, shape, radius: float, **kw):
    """``probe`` on a grid of the plane through ``origin`` spanned by the vectors ``u`` and
    ``v`` [m] (their lengths are the grid's sides), ``shape = (nu, nv)`` points; returns
    (points (nu, nv, 3), ProbeValues of the flattened grid)."""
    o, uu, vv = _points(origin)[0], _points(u)[0], _points(v)[0]
    nu, nv = (int(s) for s in shape)
    if nu < 1 or nv < 1:
        raise ProbeError("shape must be two counts >= 1")
    su = np.linspace(0.0, 1.0, nu) if nu > 1 else np.zeros(1)
    sv = np.linspace(0.0, 1.0, nv) if nv > 1 else np.zeros(1)
    grid = o + su[:, None, None] * uu + sv[None, :, None] * vv
    return grid, probe(pos, values, grid.reshape(-1, 3), radius, **kw)


def _weights(weights, n):
    w = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    if w.shape != (n,) or not np.all(np.isfinite(w)) or np.any(w < 0):
        raise ProbeError(f"weights (element volumes) must be finite, >= 0, one per element ({n})")
    return w


def region_mean(values, weights=None, mask=None):
    """Mean of element ``values`` over ``mask`` (all elements if None), weighted by
    ``weights`` (the elements' volumes [m^3]; equal weights if None). Non-finite values are
    left out; raises ProbeError when nothing is left."""
    v = np.asarray(values, dtype=float)
    n = v.shape[0]
    w = _weights(weights, n)
    sel = np.ones(n, bool) if mask is None else np.asarray(mask, bool)
    if sel.shape != (n,):
        raise ProbeError(f"mask must have one entry per element ({n})")
    sel = sel & np.all(np.isfinite(v.reshape(n, -1)), axis=1)
    if not np.any(sel) or w[sel].sum() <= 0:
        raise ProbeError("the region holds no element (with a finite value and a weight > 0)")
    ww = w[sel].reshape((-1,) + (1,) * (v.ndim - 1))
    return (ww * v[sel]).sum(axis=0) / w[sel].sum()


def section_mean(pos, values, point, normal, thickness: float, weights=None):
    """Mean of element ``values`` over the slab of ``thickness`` [m] centred on the plane
    through ``point`` with ``normal``, weighted by ``weights`` (element volumes): the
    cross-section mean of the field."""
    pos = np.asarray(pos, dtype=float)
    n = _points(normal)[0]
    n = n / np.linalg.norm(n)
    if not (np.isfinite(thickness) and thickness > 0):
        raise ProbeError(f"thickness must be > 0 [m], got {thickness}")
    s = (pos - _points(point)[0]) @ n
    return region_mean(values, weights, np.abs(s) <= 0.5 * thickness)


def slab_means(pos, values, axis, edges, weights=None):
    """Weighted means of ``values`` in the slabs ``edges[k] <= x . axis < edges[k+1]``;
    NaN for an empty slab. Returns (slab centres [m], means)."""
    pos = np.asarray(pos, dtype=float)
    a = _points(axis)[0]
    a = a / np.linalg.norm(a)
    e = np.asarray(edges, dtype=float)
    v = np.asarray(values, dtype=float)
    w = _weights(weights, v.shape[0])
    s = pos @ a
    k = np.searchsorted(e, s, side="right") - 1
    inside = (k >= 0) & (k < e.size - 1) & np.isfinite(v)
    num = np.bincount(k[inside], w[inside] * v[inside], e.size - 1)
    den = np.bincount(k[inside], w[inside], e.size - 1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return 0.5 * (e[1:] + e[:-1]), np.where(den > 0, num / den, np.nan)


def element_gradients(pos, edges, values) -> np.ndarray:
    """Least-squares gradient (n, 3) [units/m] of an element field over each element's
    neighbours in ``edges`` (m, 2): ``g_i = argmin sum_j (v_j - v_i - g . (x_j - x_i))^2``
    (exact for a linear field). Elements with fewer than 3 neighbours, or neighbours on a
    line or in a plane, get NaN."""
    pos = np.asarray(pos, dtype=float)
    e = np.asarray(edges, dtype=np.int64).reshape(-1, 2)
    v = np.asarray(values, dtype=float)
    n = pos.shape[0]
    i = np.concatenate([e[:, 0], e[:, 1]])
    j = np.concatenate([e[:, 1], e[:, 0]])
    d = pos[j] - pos[i]
    dv = v[j] - v[i]
    M = np.zeros((n, 3, 3))
    np.add.at(M, i, d[:, :, None] * d[:, None, :])
    b = np.zeros((n, 3))
    np.add.at(b, i, d * dv[:, None])
    out = np.full((n, 3), np.nan)
    cond = np.linalg.cond(M)
    good = np.isfinite(cond) & (cond < 1e8)
    if np.any(good):
        out[good] = np.linalg.solve(M[good], b[good][:, :, None])[:, :, 0]
    return out
