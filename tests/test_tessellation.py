"""yade_electro.geometry.tessellation: the Voronoi diagram from qhull's Delaunay triangulation as arrays.
Checked against scipy.spatial.Voronoi (qhull's own Voronoi output) face by face, and the
slabbed, threaded path against the whole-set one; cospherical input (a lattice) gives the
cube faces and nothing else with area."""
import numpy as np
import pytest
from scipy.spatial import Voronoi

from yade_electro.geometry.tessellation import circumcentres, tessellate, tessellation_threads


def _reference_faces(pts, n_real):
    """{(i, j): area} of scipy's Voronoi ridges with i < n_real, bounded ones only."""
    vor = Voronoi(pts)
    out = {}
    for (a, b), rv in zip(vor.ridge_points, vor.ridge_vertices):
        i, j = min(a, b), max(a, b)
        if i >= n_real or -1 in rv:
            continue
        v = vor.vertices[rv]
        nrm = pts[j] - pts[i]
        nrm /= np.linalg.norm(nrm)
        c = v.mean(axis=0)
        e1 = np.cross(nrm, [1.0, 0, 0] if abs(nrm[0]) < 0.9 else [0, 1.0, 0])
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(nrm, e1)
        ang = np.arctan2((v - c) @ e2, (v - c) @ e1)
        q = (v - c)[np.argsort(ang)]
        out[(i, j)] = 0.5 * abs(np.cross(q, np.roll(q, -1, axis=0)).sum(axis=0) @ nrm)
    return out


def _cloud(n, seed):
    rng = np.random.default_rng(seed)
    inner = rng.random((n, 3)) * [1.0, 1.0, 3.0]
    # a shell of points around the block, so that every inner cell is bounded
    shell = rng.random((n // 2, 3)) * [1.6, 1.6, 3.6] - 0.3
    shell = shell[np.any((shell < 0) | (shell > [1, 1, 3]), axis=1)]
    return np.concatenate([inner, shell]), n


def test_faces_equal_qhull_voronoi_on_random_points():
    pts, n = _cloud(3000, 1)
    t = tessellate(pts, n)
    ref = _reference_faces(pts, n)
    area, centre, extent = t.face_geometry()
    got = {(int(i), int(j)): a for (i, j), a in zip(t.ridge_points, area)}
    assert set(ref) <= set(got)
    extra = set(got) - set(ref)                      # faces qhull's Voronoi leaves unbounded only
    assert all(min(p) < n for p in got)
    assert max(abs(got[k] - ref[k]) / ref[k] for k in ref) < 1e-9
    assert all(got[k] >= 0 for k in extra)
    # centres lie on the bisector planes, extents reach a vertex
    i, j = t.ridge_points[:, 0], t.ridge_points[:, 1]
    mid, d = 0.5 * (pts[i] + pts[j]), pts[j] - pts[i]
    keep = area > 0
    assert np.max(np.abs(np.einsum("ij,ij->i", centre - mid, d))[keep]) < 1e-9
    assert np.all(extent[keep] > 0)


def test_slabs_on_threads_give_the_whole_set_tessellation():
    pts, n = _cloud(20000, 2)
    whole = tessellate(pts, n, backend="qhull")
    slabbed = tessellate(pts, n, slab_points=3000, threads=2, backend="qhull")
    assert np.array_equal(whole.ridge_points, slabbed.ridge_points)
    aw, cw, ew = whole.face_geometry()
    as_, cs, es = slabbed.face_geometry()
    assert np.max(np.abs(aw - as_)) <= 1e-12 * aw.max()
    assert np.max(np.abs(cw - cs)) < 1e-12 and np.max(np.abs(ew - es)) < 1e-12
    # the same cells touch a marked vertex set
    mw = whole.vertices[:, 2] > 2.0
    ms = slabbed.vertices[:, 2] > 2.0
    assert np.array_equal(whole.cells_touching(mw)[:n], slabbed.cells_touching(ms)[:n])


def test_lattice_cospherical_points_give_only_the_cube_faces():
    k, j, i = np.meshgrid(np.arange(6), np.arange(6), np.arange(6), indexing="ij")
    pts = np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1).astype(float)
    inner = np.all((pts >= 1) & (pts <= 4), axis=1)
    order = np.r_[np.flatnonzero(inner), np.flatnonzero(~inner)]
    pts = pts[order]
    n = int(inner.sum())
    t = tessellate(pts, n)
    area = t.face_geometry()[0]
    d = np.linalg.norm(pts[t.ridge_points[:, 1]] - pts[t.ridge_points[:, 0]], axis=1)
    real = area > 1e-9
    assert np.allclose(area[real], 1.0) and np.allclose(d[real], 1.0)
    assert np.all(area[~real] < 1e-12)               # the triangulation's diagonals: no area
    # every inner point has its 6 unit faces
    both = t.ridge_points[real]
    deg = np.bincount(both.ravel(), minlength=pts.shape[0])
    assert np.all(deg[:n] == 6)


def test_flat_tetrahedra_take_a_neighbours_circumcentre():
    pts = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0], [0, 0, 1.0]])
    s = np.array([[0, 1, 2, 3], [0, 1, 2, 4]])          # the first is flat (coplanar)
    nb = np.array([[1, -1, -1, -1], [0, -1, -1, -1]])
    c = circumcentres(pts, s, nb)
    assert np.allclose(c[1], [0.5, 0.5, 0.5]) and np.allclose(c[0], c[1])
    assert np.all(np.isnan(circumcentres(pts, s)[0]))


def test_thread_setting(monkeypatch):
    monkeypatch.setenv("YADE_ELECTRO_TESSELLATION_THREADS", "3")
    assert tessellation_threads() == 3
    monkeypatch.setenv("YADE_ELECTRO_TESSELLATION_THREADS", "zero")
    with pytest.raises(ValueError, match="integer >= 1"):
        tessellation_threads()


def test_cgal_and_qhull_give_the_same_faces(monkeypatch, capsys):
    from yade_electro.core import progress
    from yade_electro.native import cgal_executable
    cgal_executable()                                # built at install (make install brings g++ and CGAL)
    pts, n = _cloud(5000, 3)
    capsys.readouterr()
    monkeypatch.setattr(progress, "PROGRESS_EVERY", 0.0)        # the helper's wait shows progress
    a = tessellate(pts, n, backend="cgal")
    assert "points triangulated by CGAL: done in" in capsys.readouterr().err
    monkeypatch.setattr(progress, "PROGRESS_EVERY", 10.0)
    b = tessellate(pts, n, backend="qhull")
    aa, ca, _ = a.face_geometry()
    ab, cb, _ = b.face_geometry()
    ka = {tuple(p): (x, c) for p, x, c in zip(a.ridge_points.tolist(), aa, ca) if x > 1e-15}
    kb = {tuple(p): (x, c) for p, x, c in zip(b.ridge_points.tolist(), ab, cb) if x > 1e-15}
    assert set(ka) == set(kb)
    assert max(abs(ka[k][0] - kb[k][0]) / kb[k][0] for k in kb) < 1e-9
    assert max(np.abs(ka[k][1] - kb[k][1]).max() for k in kb) < 1e-9


def test_backend_setting(monkeypatch):
    from yade_electro.native import delaunay_backend
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "qhull")
    assert delaunay_backend() == "qhull"
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "cgal")
    assert delaunay_backend() == "cgal"
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "fast")
    with pytest.raises(ValueError, match="'auto', 'cgal' or 'qhull'"):
        delaunay_backend()


def test_without_cgal_auto_falls_back_and_cgal_says_why(monkeypatch):
    import yade_electro.native as native
    from yade_electro.native import loader
    monkeypatch.setattr(loader, "HERE", native.Path("/nonexistent"))     # as if the helper was not built
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "auto")
    assert native.delaunay_backend() == "qhull"
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "cgal")
    with pytest.raises(native.NativeError, match="helper program 'delaunay_cgal' is not built"):
        native.delaunay_backend()
    pts, n = _cloud(500, 4)
    monkeypatch.setenv("YADE_ELECTRO_DELAUNAY", "auto")
    t = tessellate(pts, n)                                          # qhull, no error
    assert t.n_ridges > 0 and not t.ordered
