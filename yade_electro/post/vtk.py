"""VTK files (ParaView, VisIt) of element fields and bonds, written by meshio.

* :func:`write_elements` : the elements as points (``vertex`` cells) with their radius and any
  per-element fields as point data (glyph them with spheres scaled by ``radius``);
* :func:`write_bonds` : bonds as line segments between element centres, with per-bond cell
  data (e.g. ``broken`` = 1 for a broken bond: threshold on it to see the cracks); in a
  periodic cell, bonds that cross a face are drawn to the neighbour's image.

The format follows the file name (``.vtu``: VTK XML unstructured grid, what the cases write;
``.vtk``: legacy). Non-finite values are written as 0 (VTK readers do not take nan/inf).
Units: whatever the arrays hold (SI in this package).
"""
from __future__ import annotations

import os
from typing import Mapping, Optional

import numpy as np

__all__ = ["write_elements", "write_bonds"]


def _check_fields(fields, n, what):
    out = {}
    for name, v in (fields or {}).items():
        a = np.asarray(v, dtype=float)
        if a.shape != (n,):
            raise ValueError(f"{what} field {name!r} must have shape ({n},), got {a.shape}")
        out[name] = np.where(np.isfinite(a), a, 0.0)
    return out


def _write(path, points, cells, point_data=None, cell_data=None):
    import meshio
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    meshio.Mesh(points, cells, point_data=point_data or {}, cell_data=cell_data or {}).write(path)
    return path


def write_elements(path: str, centers, radii, fields: Optional[Mapping[str, np.ndarray]] = None) -> str:
    """Write the elements as vertices with point data ``radius`` and ``fields``. Returns the path."""
    x = np.asarray(centers, dtype=float).reshape(-1, 3)
    n = x.shape[0]
    data = _check_fields(dict(fields or {}, radius=radii), n, "element")
    return _write(path, x, [("vertex", np.arange(n, dtype=np.int64).reshape(-1, 1))], point_data=data)


def write_bonds(path: str, centers, pairs, fields: Optional[Mapping[str, np.ndarray]] = None,
                vectors=None) -> str:
    """Write bonds (``pairs``: (m, 2) indices into ``centers``) as lines with cell data
    ``fields``. Returns the path.

    ``vectors`` (m, 3) [m], optional: each bond's separation x_j - x_i as the model sees it
    (in a periodic cell, to the image of j next to i: ``ContactGraph.edge_vectors()``). A
    bond whose vector is not ``centers[j] - centers[i]`` (it crosses a face of the cell) is
    drawn from x_i to x_i + vector, an extra point at j's image, instead of across the cell."""
    x = np.asarray(centers, dtype=float).reshape(-1, 3)
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if p.size and (p.min() < 0 or p.max() >= x.shape[0]):
        raise ValueError(f"bond indices must be in [0, {x.shape[0]}), got [{p.min()}, {p.max()}]")
    data = _check_fields(fields, p.shape[0], "bond")
    if vectors is not None:
        d = np.asarray(vectors, dtype=float)
        if d.shape != p.shape[:1] + (3,) or not np.all(np.isfinite(d)):
            raise ValueError(f"vectors must be finite with shape ({p.shape[0]}, 3), got {d.shape}")
        direct = x[p[:, 1]] - x[p[:, 0]]
        scale = float(np.max(np.abs(x))) if x.size else 0.0
        across = np.flatnonzero(np.any(np.abs(d - direct) > 1e-9 * max(scale, 1e-300), axis=1))
        if across.size:
            p = p.copy()
            p[across, 1] = x.shape[0] + np.arange(across.size)
            x = np.vstack([x, x[p[across, 0]] + d[across]])
    return _write(path, x, [("line", p)], cell_data={k: [v] for k, v in data.items()})
