"""gmsh's Python API for the meshes of the validation geometries: a silent session with one
empty model, and the surface triangles of a gmsh mesh file (issue 35: grains from a closed
surface mesh, :class:`~yade_electro.geometry.surface_mesh.MeshShape`).

Units: as in the files (metres for the project's geometries).
"""
from __future__ import annotations

import numpy as np

from ..core.errors import ElectroError

__all__ = ["GmshSession", "gmsh_module", "surface_triangles", "MeshError"]


class MeshError(ElectroError, ValueError):
    """A geometry or mesh request is invalid (bad dimensions, h too large, gmsh missing)."""


def gmsh_module():
    """gmsh's Python API (imported when first needed), or MeshError saying how to install it."""
    try:
        import gmsh  # noqa: WPS433 (imported lazily: optional dependency)
    except ImportError as exc:  # pragma: no cover - depends on the machine
        raise MeshError("gmsh's Python API is needed for this geometry: "
                        "apt-get install python3-gmsh gmsh (Debian 12)") from exc
    return gmsh


class GmshSession:
    """Context manager: an initialised, silent gmsh with one empty model; finalised on exit."""

    def __enter__(self):
        self.gmsh = gmsh_module()
        self.gmsh.initialize(readConfigFiles=False)
        self.gmsh.option.setNumber("General.Terminal", 0)
        self.gmsh.option.setNumber("General.Verbosity", 1)
        self.gmsh.model.add("yade_electro")
        return self.gmsh

    def __exit__(self, *exc):
        self.gmsh.finalize()
        return False


def surface_triangles(path) -> tuple:
    """(vertices (n, 3), triangles (m, 3)) of the surface triangles of a gmsh mesh file."""
    with GmshSession() as gmsh:
        gmsh.open(str(path))
        tags, coords, _ = gmsh.model.mesh.getNodes()
        types, _, nodes = gmsh.model.mesh.getElements(2)
        tri = [np.asarray(n, np.int64).reshape(-1, 3) for t, n in zip(types, nodes) if t == 2]
    if not tri:
        raise MeshError(f"{str(path)!r} holds no surface triangles (gmsh element type 2)")
    index = np.full(int(np.max(tags)) + 1, -1, np.int64)
    index[np.asarray(tags, np.int64)] = np.arange(len(tags))
    t = index[np.concatenate(tri)]
    used, t = np.unique(t, return_inverse=True)
    return np.asarray(coords, float).reshape(-1, 3)[used], t.reshape(-1, 3)
