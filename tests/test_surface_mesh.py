"""Shapes from closed triangulated surfaces (numpy, no YADE): STL in both encodings, the
closedness checks, the signed distance against the exact one, packings and the 'voronoi'
law's cells inside a mesh."""
import struct

import numpy as np
import pytest

from yade_electro.core.errors import BoundaryConditionError
from yade_electro.geometry.shapes import Box
from yade_electro.geometry.surface_mesh import MeshShape, check_closed, read_stl, winding_number

L = 1e-2
CUBE_V = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float) * L
CUBE_T = np.array([[0, 2, 1], [0, 3, 2], [4, 5, 6], [4, 6, 7], [0, 1, 5], [0, 5, 4], [1, 2, 6], [1, 6, 5],
                   [2, 3, 7], [2, 7, 6], [3, 0, 4], [3, 4, 7]])


def icosphere(r, levels=2):
    t = (1 + 5 ** 0.5) / 2
    V = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t), (0, -1, -t), (0, 1, -t),
         (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    F = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4), (11, 10, 2), (10, 7, 6),
         (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8), (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10),
         (8, 6, 7), (9, 8, 1)]
    V = [np.array(v, float) / np.linalg.norm(v) for v in V]
    for _ in range(levels):
        mid, out = {}, []

        def m(a, b):
            key = (min(a, b), max(a, b))
            if key not in mid:
                p = V[a] + V[b]
                V.append(p / np.linalg.norm(p))
                mid[key] = len(V) - 1
            return mid[key]
        for a, b, c in F:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            out += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        F = out
    return r * np.array(V), np.array(F)


def write_stl(path, V, T, binary):
    tri = V[T]
    if binary:
        with open(path, "wb") as fh:
            fh.write(b"\0" * 80 + struct.pack("<I", len(T)))
            for t in tri:
                fh.write(struct.pack("<12fH", 0, 0, 0, *t.ravel(), 0))
    else:
        with open(path, "w") as fh:
            fh.write("solid s\n")
            for t in tri:
                fh.write("facet normal 0 0 0\nouter loop\n" + "".join(f"vertex {x!r} {y!r} {z!r}\n" for x, y, z in t)
                         + "endloop\nendfacet\n")
            fh.write("endsolid s\n")


@pytest.mark.parametrize("binary", [True, False])
def test_stl_cube_is_the_box(tmp_path, binary):
    path = tmp_path / "cube.stl"
    write_stl(path, CUBE_V, CUBE_T, binary)
    V, T = read_stl(path)
    assert V.shape == (8, 3) and T.shape == (12, 3)
    m = MeshShape.from_file(path)
    assert m.exact_volume == pytest.approx(L ** 3, rel=1e-6)
    x = np.random.default_rng(1).uniform(-0.2 * L, 1.2 * L, (3000, 3))
    assert np.max(np.abs(m.sdf(x) - Box((0, 0, 0), (L, L, L)).sdf(x))) < m.voxel      # about a voxel


def test_winding_number_and_a_sphere_mesh():
    V, T = icosphere(1e-2, 2)
    assert winding_number(V, T, [[0, 0, 0], [2e-2, 0, 0]]) == pytest.approx([1.0, 0.0], abs=1e-9)
    assert winding_number(V, T[:, ::-1], [[0, 0, 0]])[0] == pytest.approx(-1.0)          # inward: -1, still inside
    m = MeshShape(V, T[:, ::-1], voxel=1e-2 / 16)
    assert m.exact_volume == pytest.approx(4 / 3 * np.pi * 1e-6, rel=0.05)                # the polyhedron's
    assert m.sdf([[0, 0, 0]])[0] == pytest.approx(-1e-2, abs=1.5 * m.voxel)


def test_open_or_misoriented_meshes_are_refused():
    with pytest.raises(BoundaryConditionError, match="not closed: 3 edge"):
        MeshShape(CUBE_V, CUBE_T[:-1], name="'grain.stl'")
    bad = CUBE_T.copy()
    bad[0] = bad[0, ::-1]
    with pytest.raises(BoundaryConditionError, match="not consistently oriented"):
        check_closed(bad)
    with pytest.raises(BoundaryConditionError, match="triangle indices"):
        MeshShape(CUBE_V, CUBE_T + 8)


def test_packing_and_voronoi_cells_in_a_mesh_grain():
    """A dense packing of an icosphere's solid, its bounded Voronoi cells: they fill it."""
    from yade_electro.core.graph import ContactGraph
    from yade_electro.laws.factors import make_law
    from yade_electro.packing import bond_pairs, dense_packing
    V, T = icosphere(1e-2, 2)
    m = MeshShape(V, T, voxel=1e-2 / 16)
    pk = dense_packing(m, n=400, seed=2)
    assert np.all(m.sdf(pk.centers) + pk.radii <= 1e-9)
    graph = ContactGraph(pk.centers, pk.radii, bond_pairs(pk.centers, pk.radii, 1.1))
    vol = make_law("voronoi", container=m).cell_volumes(graph)
    assert vol.sum() == pytest.approx(m.exact_volume, rel=0.03)                          # a voxel's worth


def test_mesh_distance_is_the_exact_distance_to_the_surface():
    from yade_electro.geometry.surface_mesh import mesh_distance
    x = np.random.default_rng(3).uniform(-1.0 * L, 2.0 * L, (500, 3))
    x = x[Box((0, 0, 0), (L, L, L)).sdf(x) > 0]                       # outside: the box's distance
    assert mesh_distance(x, CUBE_V, CUBE_T) == pytest.approx(Box((0, 0, 0), (L, L, L)).sdf(x), abs=1e-15)


def test_a_gmsh_surface_mesh_makes_a_shape(tmp_path):
    """A sphere meshed by gmsh (surface triangles, written as .msh), read back: a closed surface
    whose solid is the sphere to the mesh's resolution."""
    gmsh = pytest.importorskip("gmsh")
    from yade_electro.fem.gmsh_session import surface_triangles
    path = tmp_path / "ball.msh"
    gmsh.initialize(readConfigFiles=False)
    try:
        gmsh.option.setNumber("General.Terminal", 0)
        gmsh.model.occ.addSphere(0, 0, 0, 1e-2)
        gmsh.model.occ.synchronize()
        gmsh.option.setNumber("Mesh.MeshSizeMax", 2e-3)
        gmsh.model.mesh.generate(2)
        gmsh.write(str(path))
    finally:
        gmsh.finalize()
    V, T = surface_triangles(path)
    m = MeshShape(V, T, voxel=1e-2 / 16)
    assert m.exact_volume == pytest.approx(4 / 3 * np.pi * 1e-6, rel=0.02)
    assert m.sdf([[0, 0, 0]])[0] == pytest.approx(-1e-2, abs=2 * m.voxel)     # deep inside: the transforms'
    x = np.array([[1.02e-2, 0, 0], [0, -0.97e-2, 0], [0, 0, 1.5e-2]])            # near and beyond: exact
    assert m.sdf(x) == pytest.approx(np.linalg.norm(x, axis=1) - 1e-2, abs=1e-4)   # the polyhedron's chords
