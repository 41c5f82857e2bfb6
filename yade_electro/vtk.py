"""Legacy VTK files (ParaView, VisIt) of element fields and bonds, written with numpy only.

* :func:`write_elements` : the elements as points (``POLYDATA`` vertices) with their radius
  and any per-element fields as point data (glyph them with spheres scaled by ``radius``);
* :func:`write_bonds` : bonds as line segments between element centres, with per-bond cell
  data (e.g. ``broken`` = 1 for a broken bond: threshold on it to see the cracks).

ASCII format, version 3.0: readable by every ParaView version. Units: whatever the arrays
hold (SI in this package).
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
        if not name.replace("_", "").isalnum():
            raise ValueError(f"VTK field names must be letters, digits and _, got {name!r}")
        out[name] = np.where(np.isfinite(a), a, 0.0)   # VTK readers choke on nan/inf
    return out


def _write(path, header_lines, data_blocks):
    os.makedirs(os.path.dirname(os.path.abspath(path)), exist_ok=True)
    with open(path, "w") as fh:
        fh.write("\n".join(header_lines) + "\n")
        for block in data_blocks:
            fh.write(block)


def _scalars(name, values):
    return (f"SCALARS {name} double 1\nLOOKUP_TABLE default\n"
            + "\n".join(f"{x:.9g}" for x in values) + "\n")


def write_elements(path: str, centers, radii, fields: Optional[Mapping[str, np.ndarray]] = None,
                   title: str = "yade-electro elements") -> str:
    """Write the elements as a POLYDATA of vertices with point data ``radius`` and ``fields``
    (non-finite values written as 0). Returns the path."""
    x = np.asarray(centers, dtype=float).reshape(-1, 3)
    n = x.shape[0]
    fields = _check_fields(dict(fields or {}, radius=radii), n, "element")
    pts = "\n".join(f"{a:.9g} {b:.9g} {c:.9g}" for a, b, c in x)
    verts = "\n".join(f"1 {i}" for i in range(n))
    header = ["# vtk DataFile Version 3.0", title[:255], "ASCII", "DATASET POLYDATA", f"POINTS {n} double", pts,
              f"VERTICES {n} {2 * n}", verts, f"POINT_DATA {n}"]
    _write(path, header, [_scalars(k, v) for k, v in fields.items()])
    return path


def write_bonds(path: str, centers, pairs, fields: Optional[Mapping[str, np.ndarray]] = None,
                title: str = "yade-electro bonds") -> str:
    """Write bonds (``pairs``: (m, 2) indices into ``centers``) as LINES with cell data
    ``fields`` (non-finite values written as 0). Returns the path."""
    x = np.asarray(centers, dtype=float).reshape(-1, 3)
    p = np.asarray(pairs, dtype=np.int64).reshape(-1, 2)
    if p.size and (p.min() < 0 or p.max() >= x.shape[0]):
        raise ValueError(f"bond indices must be in [0, {x.shape[0]}), got [{p.min()}, {p.max()}]")
    m = p.shape[0]
    fields = _check_fields(fields, m, "bond")
    pts = "\n".join(f"{a:.9g} {b:.9g} {c:.9g}" for a, b, c in x)
    lines = "\n".join(f"2 {a} {b}" for a, b in p)
    header = ["# vtk DataFile Version 3.0", title[:255], "ASCII", "DATASET POLYDATA", f"POINTS {x.shape[0]} double",
              pts, f"LINES {m} {3 * m}", lines, f"CELL_DATA {m}"]
    _write(path, header, [_scalars(k, v) for k, v in fields.items()])
    return path
