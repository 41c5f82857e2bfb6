"""Vectorised clipping of convex polytopes, and the bounded Voronoi cells built on it, against
exact volumes and areas."""
import numpy as np
import pytest

from yade_electro.geometry.clipping import FaceSet, clip, face_areas, order_polygons, volumes
from yade_electro.geometry.shapes import Box, Cylinder
from yade_electro.geometry.cells import bounded_cells


def cubes(offsets):
    q = np.array([[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0], [0, 0, 1], [1, 0, 1], [1, 1, 1], [0, 1, 1]], float)
    F = [[0, 1, 2, 3], [4, 5, 6, 7], [0, 1, 5, 4], [2, 3, 7, 6], [1, 2, 6, 5], [0, 3, 7, 4]]
    N = np.array([[0, 0, 1], [0, 0, 1], [0, 1, 0], [0, 1, 0], [1, 0, 0], [1, 0, 0]], float)
    verts = np.concatenate([(q + o)[np.array(F)] for o in offsets])
    planes = np.concatenate([N] * len(offsets))
    cnt = np.full(6 * len(offsets), 4)
    return FaceSet(order_polygons(verts, cnt, planes), cnt, np.repeat(np.arange(len(offsets)), 6),
                   np.arange(6 * len(offsets)), planes)


def test_cubes_cut_by_planes_in_one_pass():
    fs = cubes([(0, 0, 0), (5, 0, 0), (10, 0, 0)])
    seeds = np.array([[0.2, 0.2, 0.2], [5.5, 0.5, 0.1], [10.5, 0.5, 0.5]])
    np.testing.assert_allclose(volumes(fs, seeds, 3), 1.0, rtol=1e-14)
    n = np.array([[1, 1, 1], [0, 0, 1], [1, 0, 0]], float)
    n /= np.linalg.norm(n, axis=1)[:, None]
    p = np.array([[0.5, 0.5, 0.5], [5.5, 0.5, 0.25], [0, 0, 0]])
    out = clip(fs, p, n, np.array([True, True, False]), np.ones(3))
    np.testing.assert_allclose(volumes(out, seeds, 3), [0.5, 0.25, 1.0], rtol=1e-12)
    caps = out.label == -1
    assert caps.sum() == 2
    # the cube's mid cross-section normal to (1, 1, 1): a regular hexagon of side sqrt(2)/2
    np.testing.assert_allclose(np.sort(face_areas(out)[caps]), [1.0, 0.75 * np.sqrt(3)], rtol=1e-12)
    # a second plane on the first cube; a plane that only touches it changes nothing
    out2 = clip(out, np.array([[0.6, 0, 0], [5, 0, 0.25], [0, 0, 0]]),
                np.array([[1, 0, 0], [0, 0, 1], [1, 0, 0]], float), np.array([True, True, False]), np.ones(3))
    np.testing.assert_allclose(volumes(out2, seeds, 3), [0.5 - 0.604 / 6, 0.25, 1.0], rtol=1e-12)
    assert (out2.label == -1).sum() == 3


def test_bounded_cells_of_a_box_are_exact():
    rng = np.random.default_rng(1)
    box = Box((0, 0, 0), (2e-3, 1e-3, 3e-3))
    p = rng.uniform(0, 1, (500, 3)) * [2e-3, 1e-3, 3e-3]
    c = bounded_cells(p, np.full(len(p), 0.1e-3), box)
    assert c.volume.sum() == pytest.approx(6e-9, rel=1e-9)
    assert c.boundary_area.sum() == pytest.approx(2 * (2 * 1 + 1 * 3 + 2 * 3) * 1e-6, rel=1e-9)
    # boundary faces are on the walls, point out, and their areas projected on each wall
    # normal add up to that wall's area
    assert np.all(np.abs(box.sdf(c.boundary_point)) < 1e-12)
    np.testing.assert_allclose(np.linalg.norm(c.boundary_normal, axis=1), 1.0, rtol=1e-12)
    wall_n = box.gradient(c.boundary_point)
    proj = c.boundary_area * np.einsum("ij,ij->i", c.boundary_normal, wall_n)
    assert np.all(proj >= 0)
    for axis, other in ((0, 1 * 3), (1, 2 * 3), (2, 2 * 1)):
        for sign in (-1, 1):
            on = wall_n[:, axis] == sign
            assert proj[on].sum() == pytest.approx(other * 1e-6, rel=1e-9)


def test_bounded_cells_of_a_cylinder():
    """Curved wall: tangent planes, with the solid they leave out integrated over them."""
    rng = np.random.default_rng(2)
    cyl = Cylinder((0, 0, 0), (0, 0, 2e-3), 1e-3)
    q = rng.uniform(-1, 1, (4000, 3)) * [1e-3, 1e-3, 1e-3] + [0, 0, 1e-3]
    q = q[cyl.sdf(q) < -0.03e-3][:1200]
    c = bounded_cells(q, np.full(len(q), 0.05e-3), cyl)
    assert c.n_sampled == 0 and np.all(c.volume > 0)
    assert c.volume.sum() == pytest.approx(cyl.exact_volume, rel=1e-5)
    surface = 2 * np.pi * 1e-3 * 2e-3 + 2 * np.pi * 1e-6
    assert c.boundary_area.sum() == pytest.approx(surface, rel=3e-3)      # tangent planes: slightly more
    assert c.boundary_area.sum() > surface
